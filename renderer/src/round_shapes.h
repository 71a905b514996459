/* round_shapes.h -- ray intersection with POV-Ray's cylinder, cone and
 * torus in their object space (renderer-internal).
 *
 * Each function takes the ray o + t d (d need not be unit: t is the ray's
 * own parameter), returns 1 with the nearest t in (t0, t1) and the
 * outward surface normal there (not normalized), or 0. */
#ifndef RS_ROUND_SHAPES_H
#define RS_ROUND_SHAPES_H

#include "lensprim.h"

/* A cone from base (radius r1) to cap (radius r2), r1, r2 >= 0; a cylinder
 * is r1 = r2.  Closed by flat end discs unless open. */
int rs_cone_hit(lp_vec3 base, double r1, lp_vec3 cap, double r2, int open, lp_vec3 o,
                lp_vec3 d, double t0, double t1, double *t, lp_vec3 *n);

/* The torus about the y axis through the origin: the circle of radius
 * major in the xz plane swept by a circle of radius minor.  The roots of
 * its quartic along the ray are isolated between the roots of its
 * derivatives and refined by bisection, so a ray that only grazes the
 * tube is found however short its chord; a ray exactly along a tangent
 * (a double root) meets nothing there. */
int rs_torus_hit(double major, double minor, lp_vec3 o, lp_vec3 d, double t0, double t1,
                 double *t, lp_vec3 *n);

#endif
