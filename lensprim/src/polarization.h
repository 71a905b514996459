/* polarization.h -- a complex field as linearly polarized rays (internal). */
#ifndef LP_POLARIZATION_H
#define LP_POLARIZATION_H

#include "cvec3.h"

typedef struct lp__linear_part {
    double intensity;
    lp_vec3 vp;     /* unit, perpendicular to dir */
    double phase;   /* radians */
} lp__linear_part;

/* The unit vector along the part of v perpendicular to the unit dir. */
static inline lp_vec3 lp__unit_perp(lp_vec3 v, lp_vec3 dir)
{
    return v3_normalize(v3_sub(v, v3_scale(dir, v3_dot(v, dir))));
}

/* The phase psi of the ellipse of a field whose bilinear square E.E is
 * q: arg(q)/2, and 0 for a q real and not negative (lp__field_split). */
static inline double lp__ellipse_psi(double complex q)
{
    return (cimag(q) == 0.0 && creal(q) >= 0.0) ? 0.0 : 0.5 * carg(q);
}

/* exp(-i psi), exactly as cexp(-I * psi) gives it, without the general
 * complex exponential for a finite psi: exp(-0 or +0) = 1 times the
 * cosine and sine of -psi (sine -psi and cosine 1 for |psi| <= DBL_MIN). */
static inline double complex lp__phasor_minus(double psi)
{
    double t = -psi;
    if (fabs(t) > DBL_MIN && fabs(t) <= DBL_MAX)
        return CMPLX(cos(t), sin(t));
    if (fabs(t) <= DBL_MIN)
        return CMPLX(1.0, t);
    return cexp(-I * psi);
}

/* The split of a field with an imaginary part and power total > 0. */
int lp__field_split_elliptic(const lp__cvec3 *E, double total, lp_vec3 dir,
                             lp__linear_part part[2]);

/* Write E (perpendicular to the unit dir) as the sum of at most two
 * linear waves sqrt(I_k) vp_k exp(i phase_k) along the axes of its
 * polarization ellipse: E = exp(i psi) (A + i B), A . B = 0, |A| >= |B|,
 * psi = arg(E . E)/2.  A linear field (B = 0 to 1e-10 relative amplitude)
 * gives one part carrying all the power.  A zero field gives 0 parts.
 * Returns the number of parts.  total is the field's power cv3_norm2(*E),
 * which the caller has; inline, since a real field (every field before a
 * total internal reflection) is one part at once: lp__field_split_real,
 * for a field held as a real vector e (power total = v3_dot(e, e), the
 * bits of cv3_norm2 of its complex form). */
static inline int lp__field_split_real(lp_vec3 e, double total, lp_vec3 dir,
                                       lp__linear_part part[2])
{
    if (!(total > 0.0))
        return 0;
    part[0].intensity = total; /* linear already: psi = 0, A = e, B = 0 */
    part[0].vp = lp__unit_perp(e, dir);
    part[0].phase = 0.0;
    return 1;
}

static inline int lp__field_split(const lp__cvec3 *E, double total, lp_vec3 dir,
                                  lp__linear_part part[2])
{
    if (cv3_is_real(*E))
        return lp__field_split_real(cv3_re(*E), total, dir, part);
    if (!(total > 0.0))
        return 0;
    return lp__field_split_elliptic(E, total, dir, part);
}

#endif
