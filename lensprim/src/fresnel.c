/* fresnel.c -- Fresnel's equations at one interface (Born & Wolf, §1.5).
 *
 * Everything here is a pure function of the incidence cosine and the two
 * indices; see fresnel.h for the sign conventions. */
#include <math.h>

#include "fresnel.h"

/* The cosine of refraction for the relative index eta = n1/n2, or -1. */
static double refraction_cos(double cos_i, double eta)
{
    /* sin^2 i written as (1-c)(1+c): no cancellation at grazing incidence */
    double sin2_i = (1.0 - cos_i) * (1.0 + cos_i);
    double cos2_t = 1.0 - eta * eta * sin2_i;
    if (cos2_t < 0.0)
        return -1.0;
    return sqrt(cos2_t);
}

double lp__refraction_cos(double cos_i, double n1, double n2)
{
    return refraction_cos(cos_i, n1 / n2);
}

void lp__fresnel_eval(double cos_i, double n1, double n2, lp__fresnel *f)
{
    double ci = cos_i < 0.0 ? 0.0 : (cos_i > 1.0 ? 1.0 : cos_i);

    f->eta = n1 / n2;
    if (n1 == n2) { /* no interface at all */
        f->tir = 0;
        f->cos_t = ci;
        f->rs = f->rp = 0.0;
        f->ts = f->tp = 1.0;
        f->Rs = f->Rp = 0.0;
        return;
    }

    double ct = refraction_cos(ci, f->eta);
    if (ct < 0.0) {
        /* Total internal reflection.  The transmitted wave is evanescent:
         * n2*cos_t = i*q with q = sqrt(n1^2 sin^2 i - n2^2) > 0, the sign
         * that decays away from the boundary for exp(-i*omega*t). */
        double sin_i = sqrt((1.0 - ci) * (1.0 + ci));
        double q2 = (n1 * sin_i - n2) * (n1 * sin_i + n2);
        double q = sqrt(q2 > 0.0 ? q2 : 0.0);
        double complex a = n1 * ci, b = I * q;
        double complex ap = n2 * n2 * ci, bp = I * n1 * q;
        f->tir = 1;
        f->cos_t = 0.0;
        f->rs = (a - b) / (a + b);
        f->rp = (ap - bp) / (ap + bp);
        f->ts = f->tp = 0.0;
        f->Rs = f->Rp = 1.0;
        return;
    }

    double a = n1 * ci, b = n2 * ct; /* s: n1 cos i, n2 cos t */
    double c = n2 * ci, d = n1 * ct; /* p: n2 cos i, n1 cos t */
    double is = 1.0 / (a + b), ip = 1.0 / (c + d); /* shared by r and t */
    double rs = (a - b) * is;
    double rp = (c - d) * ip;
    double g = 2.0 * sqrt(a * b); /* 2 sqrt(n1 ci n2 ct) */
    f->tir = 0;
    f->cos_t = ct;
    f->rs = rs;
    f->rp = rp;
    f->ts = g * is;
    f->tp = g * ip;
    f->Rs = rs * rs;
    f->Rp = rp * rp;
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
