/* polarization.h -- a complex field as linearly polarized rays (internal). */
#ifndef LP_POLARIZATION_H
#define LP_POLARIZATION_H

#include "cvec3.h"

typedef struct lp__linear_part {
    double intensity;
    lp_vec3 vp;     /* unit, perpendicular to dir */
    double phase;   /* radians */
} lp__linear_part;

/* Write E (perpendicular to the unit dir) as the sum of at most two
 * linear waves sqrt(I_k) vp_k exp(i phase_k) along the axes of its
 * polarization ellipse: E = exp(i psi) (A + i B), A . B = 0, |A| >= |B|,
 * psi = arg(E . E)/2.  A linear field (B = 0 to 1e-10 relative amplitude)
 * gives one part carrying all the power.  A zero field gives 0 parts.
 * Returns the number of parts. */
int lp__field_split(const lp__cvec3 *E, lp_vec3 dir, lp__linear_part part[2]);
/* The same for a field whose power cv3_norm2(*E) the caller has already. */
int lp__field_split_power(const lp__cvec3 *E, double total, lp_vec3 dir,
                          lp__linear_part part[2]);

#endif
