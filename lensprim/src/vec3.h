/* vec3.h -- small 3-vector helpers, by value (internal).
 * Conventions: doubles, right-handed arithmetic; handedness of the scene
 * never enters here. */
#ifndef LP_VEC3_H
#define LP_VEC3_H

#include <float.h>
#include <math.h>
#include "lensprim.h"

#define LP_PI 3.14159265358979323846

static inline lp_vec3 v3(double x, double y, double z) { lp_vec3 v = {x, y, z}; return v; }
static inline lp_vec3 v3_add(lp_vec3 a, lp_vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline lp_vec3 v3_sub(lp_vec3 a, lp_vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline lp_vec3 v3_scale(lp_vec3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline lp_vec3 v3_neg(lp_vec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline double v3_dot(lp_vec3 a, lp_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline lp_vec3 v3_cross(lp_vec3 a, lp_vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double v3_len(lp_vec3 a) { return sqrt(v3_dot(a, a)); }
/* a + s*b */
static inline lp_vec3 v3_madd(lp_vec3 a, lp_vec3 b, double s)
{
    return v3(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z);
}
static inline int v3_finite(lp_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
/* fmax(a, b) exactly (a NaN gives the other argument), inline and free of
 * branches, so that loops over many rays can be vectorized. */
static inline double lp__fmax(double a, double b)
{
    double m = a > b ? a : b;
    return b != b ? a : m;
}
/* The larger of two numbers that are not NaN (inline,
 * unlike fmax, which must handle NaN). */
static inline double lp__max(double a, double b) { return a > b ? a : b; }
/* 1.0 when a is finite (as isfinite), else 0.0, without branches. */
static inline double lp__finite(double a) { return fabs(a) <= DBL_MAX ? 1.0 : 0.0; }
/* Unit vector along a; a zero or non-finite a gives (0,0,0).  Free of
 * branches (the quotients of a rejected vector are computed, then
 * dropped), so that loops over many rays can be vectorized. */
static inline lp_vec3 v3_normalize(lp_vec3 a)
{
    /* Scale by the largest component first: exact for tiny (denormal) and
     * huge vectors, whose squared length would underflow or overflow. */
    double m = lp__fmax(fabs(a.x), lp__fmax(fabs(a.y), fabs(a.z)));
    double ok = m > 0.0 ? lp__finite(m) : 0.0;
    a = v3(a.x / m, a.y / m, a.z / m); /* not * (1/m): 1/m can overflow */
    a = v3_scale(a, 1.0 / v3_len(a));
    return v3(ok != 0.0 ? a.x : 0.0, ok != 0.0 ? a.y : 0.0, ok != 0.0 ? a.z : 0.0);
}
/* Any unit vector perpendicular to the unit vector a (deterministic). */
static inline lp_vec3 v3_any_perp(lp_vec3 a)
{
    lp_vec3 h = fabs(a.x) < 0.6 ? v3(1, 0, 0) : (fabs(a.y) < 0.6 ? v3(0, 1, 0) : v3(0, 0, 1));
    return v3_normalize(v3_cross(a, h));
}

#endif
