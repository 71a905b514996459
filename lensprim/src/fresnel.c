/* fresnel.c -- Fresnel's equations at one interface (Born & Wolf, §1.5).
 *
 * Everything here is a pure function of the incidence cosine and the two
 * indices; see fresnel.h for the sign conventions. */
#include <math.h>

#include "fresnel.h"

double lp__refraction_cos(double cos_i, double n1, double n2)
{
    return lp__refraction_cos_eta(cos_i, n1 / n2);
}

double lp__fresnel_unpolarized(double cos_i, double n1, double n2)
{
    lp__fresnel f;
    lp__fresnel_eval(cos_i, n1, n2, &f);
    return 0.5 * (f.Rs + f.Rp);
}

double lp__schlick(double cos_i, double n1, double n2)
{
    double r0 = (n1 - n2) / (n1 + n2);
    double c = cos_i < 0.0 ? 0.0 : (cos_i > 1.0 ? 1.0 : cos_i);
    r0 *= r0;
    if (n1 > n2) {
        c = lp__refraction_cos(c, n1, n2);
        if (c < 0.0)
            return 1.0;
    }
    double m = 1.0 - c;
    double m2 = m * m;
    return r0 + (1.0 - r0) * m2 * m2 * m;
}

double lp__brewster_angle(double n1, double n2)
{
    return atan2(n2, n1);
}

double lp__critical_angle(double n1, double n2)
{
    if (!(n1 > n2))
        return NAN;
    return asin(n2 / n1);
}
