/* air.c -- the refractive index of standard air.
 *
 * Edlen (1966), "The refractive index of air", Metrologia 2, 71: dry air
 * at 15 degC, 101 325 Pa, 0.03 % CO2:
 *   (n - 1) 1e8 = 8342.13 + 2406030/(130 - s^2) + 15997/(38.9 - s^2),
 * s the vacuum wavenumber in 1/um. */
#include <math.h>

#include "lensprim.h"

double lp_air_index(double lambda_vacuum_nm)
{
    if (!(lambda_vacuum_nm > 0.0) || !isfinite(lambda_vacuum_nm))
        return NAN;
    double s = 1000.0 / lambda_vacuum_nm;
    double s2 = s * s;
    if (s2 >= 38.9)
        return NAN; /* below 160 nm: outside the formula */
    return 1.0 + 1e-8 * (8342.13 + 2406030.0 / (130.0 - s2) + 15997.0 / (38.9 - s2));
}
