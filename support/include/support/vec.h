/* vec.h -- the small vector algebra of the programs on lensprim's lp_vec3
 * (support floor; the library keeps its own).
 *
 * Plain component formulas, each written once here: a x b = (ay bz - az
 * by, az bx - ax bz, ax by - ay bx) (handedness shows only in the order
 * the caller takes), v3_madd(a, b, s) = a + s b.  Pure and inline. */
#ifndef SUPPORT_VEC_H
#define SUPPORT_VEC_H

#include <math.h>

#include "lensprim.h"

static inline lp_vec3 v3(double x, double y, double z)
{
    lp_vec3 r = {x, y, z};
    return r;
}

static inline lp_vec3 v3_add(lp_vec3 a, lp_vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline lp_vec3 v3_sub(lp_vec3 a, lp_vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline lp_vec3 v3_scale(lp_vec3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline double v3_dot(lp_vec3 a, lp_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static inline lp_vec3 v3_madd(lp_vec3 a, lp_vec3 b, double s)
{
    return v3(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z);
}

static inline lp_vec3 v3_cross(lp_vec3 a, lp_vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

static inline double v3_len(lp_vec3 a) { return sqrt(v3_dot(a, a)); }

/* a / |a|; the caller makes sure |a| > 0. */
static inline lp_vec3 v3_unit(lp_vec3 a)
{
    double l = v3_len(a);
    return v3(a.x / l, a.y / l, a.z / l);
}

/* a / |a|, or a itself when |a| is 0 or not a number. */
static inline lp_vec3 v3_unit_or_self(lp_vec3 a)
{
    double l = v3_len(a);
    return l > 0.0 ? v3(a.x / l, a.y / l, a.z / l) : a;
}

static inline int v3_finite(lp_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

#endif
