/* emitter.c -- the spectra of the scene's emitters: RGB colours as D65
 * times Smits' shape, black bodies, spectral lines (see emitter.h). */
#include <math.h>

#include "emitter.h"

/* Integral over 380-780 nm of planck(T) ȳ: Simpson's rule on each 1 nm
 * interval (ȳ is linear there; the black body is smooth). */
static double blackbody_ybar_integral(double temperature_k)
{
    double sum = 0.0, cmf[3];
    int a = (int)RS_LAMBDA_MIN, b = (int)RS_LAMBDA_MAX;
    double prev;

    rs_cmf(a, cmf);
    prev = rs_planck(temperature_k, a) * cmf[1];
    for (int n = a; n < b; n++) {
        double mid, next;
        rs_cmf(n + 0.5, cmf);
        mid = rs_planck(temperature_k, n + 0.5) * cmf[1];
        rs_cmf(n + 1, cmf);
        next = rs_planck(temperature_k, n + 1) * cmf[1];
        sum += (prev + 4.0 * mid + next) / 6.0;
        prev = next;
    }
    return sum;
}

/* ---- Emitters ---------------------------------------------------------- */

double rs_spectrum_line_power(const rs_spectrum *s)
{
    double cmf[3], ybar;

    if (s->type != RS_SPECTRUM_LINE)
        return 0.0;
    if (!(s->line_nm >= RS_CMF_MIN_NM && s->line_nm <= RS_CMF_MAX_NM))
        return 0.0;
    rs_cmf(s->line_nm, cmf);
    ybar = cmf[1] > RS_LINE_YBAR_MIN ? cmf[1] : RS_LINE_YBAR_MIN;
    return rs_luminance(s->rgb) / ybar;
}

void rs_spectrum_line_xyz(const rs_spectrum *s, double xyz[3])
{
    double p = rs_spectrum_line_power(s);

    rs_cmf(s->type == RS_SPECTRUM_LINE ? s->line_nm : -1.0, xyz);
    for (int k = 0; k < 3; k++)
        xyz[k] *= p;
}

double rs_spectrum_norm(const rs_spectrum *s)
{
    switch (s->type) {
    case RS_SPECTRUM_RGB:
        return rs_spectral_normalization();
    case RS_SPECTRUM_BLACKBODY: {
        double integral = blackbody_ybar_integral(s->temperature_k);
        double norm;
        if (!(integral > 0.0))
            return 0.0;
        norm = rs_luminance(s->rgb) / integral;
        return isfinite(norm) ? norm : 0.0;
    }
    case RS_SPECTRUM_LINE:
        return rs_spectrum_line_power(s);
    }
    return 0.0;
}

double rs_spectrum_emission_norm(const rs_spectrum *s, double norm,
                                 double lambda_nm)
{
    switch (s->type) {
    case RS_SPECTRUM_RGB:
        return norm * rs_d65(lambda_nm) * rs_emission_shape(s->rgb, lambda_nm);
    case RS_SPECTRUM_BLACKBODY:
        return norm * rs_planck(s->temperature_k, lambda_nm);
    case RS_SPECTRUM_LINE:
        return 0.0;
    }
    return 0.0;
}

double rs_spectrum_emission(const rs_spectrum *s, double lambda_nm)
{
    return rs_spectrum_emission_norm(s, rs_spectrum_norm(s), lambda_nm);
}
