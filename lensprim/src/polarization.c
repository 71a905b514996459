/* polarization.c -- the axes of the polarization ellipse of a field.
 *
 * For E = exp(i psi)(A + i B) with real A perpendicular to B, the
 * bilinear square E.E = exp(2 i psi)(|A|^2 - |B|^2) fixes psi, and A, B
 * are the real and imaginary parts of E exp(-i psi).  A linear field is
 * real up to a common phase, so B vanishes and one ray carries it. */
#include <math.h>

#include "polarization.h"

int lp__field_split_elliptic(const lp__cvec3 *E, double total, lp_vec3 dir,
                             lp__linear_part part[2])
{
    double complex q = E->x * E->x + E->y * E->y + E->z * E->z;
    double psi = lp__ellipse_psi(q);
    lp__cvec3 F = psi == 0.0 ? *E : cv3_scale(*E, lp__phasor_minus(psi));
    lp_vec3 a = cv3_re(F), b = cv3_im(F);
    double ia = v3_dot(a, a), ib = v3_dot(b, b);

    if (ib <= 1e-20 * total) {
        part[0].intensity = total;
        part[0].vp = lp__unit_perp(a, dir);
        part[0].phase = psi;
        return 1;
    }
    part[0].intensity = ia;
    part[0].vp = lp__unit_perp(a, dir);
    part[0].phase = psi;
    part[1].intensity = ib;
    part[1].vp = lp__unit_perp(b, dir);
    part[1].phase = psi + 0.5 * LP_PI;
    return 2;
}
