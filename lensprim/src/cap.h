/* cap.h -- a ray meets a spherical or flat cap in the Spencer & Murty form
 * (internal; inline, since every node meets one or two caps).
 *
 * With the ray p + s d (|d| = 1) relative to the vertex, the surface
 * c|x|^2 - 2z = 0 gives  c s^2 + 2 b s + g = 0  with
 *     b = c (p.d) - d_z,   g = c |p|^2 - 2 p_z.
 * The roots are taken as g/q and q/c with q = -(b + sign(b) sqrt(b^2 - c g)),
 * which has no cancellation for large radii and reduces to the plane root
 * -g/(2b) at c = 0 (Spencer & Murty, JOSA 52, 1962; Welford, "Aberrations
 * of Optical Systems", ch. 4).  The ray is first moved to its point of
 * closest approach to the vertex so that |p| is as small as it can be. */
#ifndef LP_CAP_H
#define LP_CAP_H

#include <math.h>

#include "lens_internal.h"
#include "vec3.h"

/* Is the point x (relative to the vertex) on the patch of the cap? */
static inline int lp__cap_on_patch(const lp__cap *cap, lp_vec3 x)
{
    double r2 = x.x * x.x + x.y * x.y;
    if (r2 > cap->h * cap->h * (1.0 + 1e-12))
        return 0;
    /* the branch next to the vertex: c z <= 1 (the sphere's near half) */
    return cap->c * x.z <= 1.0;
}

/* Smallest t in (t_min, t_max) where p + t d meets the cap patch.  When
 * on_surface is set, p lies on this cap and the root t = 0 is removed
 * exactly (the remaining root is -2b/c), so a ray never re-hits the point
 * it leaves.  Returns 1 on a hit. */
static inline int lp__cap_intersect(const lp__cap *cap, lp_vec3 p, lp_vec3 d, int on_surface,
                                    double t_min, double t_max, double *t)
{
    double c = cap->c;
    lp_vec3 q0 = v3(p.x, p.y, p.z - cap->z0);
    double roots[2];
    int nroots = 0;

    if (on_surface) {
        /* g = 0 exactly: roots 0 and -2b/c */
        if (c == 0.0)
            return 0;
        double b = c * v3_dot(q0, d) - d.z;
        roots[nroots++] = -2.0 * b / c;
        for (int i = 0; i < nroots; i++) {
            double s = roots[i];
            if (s > t_min && s < t_max && lp__cap_on_patch(cap, v3_madd(q0, d, s))) {
                *t = s;
                return 1;
            }
        }
        return 0;
    }

    double s0 = -v3_dot(q0, d); /* closest approach to the vertex */
    lp_vec3 q = v3_madd(q0, d, s0);
    double b = c * v3_dot(q, d) - d.z;
    double g = c * v3_dot(q, q) - 2.0 * q.z;
    double disc = b * b - c * g;
    if (disc < 0.0)
        return 0;
    double qq = -(b + copysign(sqrt(disc), b));
    if (qq != 0.0)
        roots[nroots++] = g / qq;
    if (c != 0.0)
        roots[nroots++] = qq / c;
    if (nroots == 2 && roots[1] < roots[0]) {
        double tmp = roots[0];
        roots[0] = roots[1];
        roots[1] = tmp;
    }
    for (int i = 0; i < nroots; i++) {
        double s = s0 + roots[i];
        if (s > t_min && s < t_max && lp__cap_on_patch(cap, v3_madd(q0, d, s))) {
            *t = s;
            return 1;
        }
    }
    return 0;
}

#endif
