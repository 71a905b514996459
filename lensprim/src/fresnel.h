/* fresnel.h -- Fresnel's equations at one interface, as pure functions
 * (internal; tests include it directly).
 *
 * Conventions (Born & Wolf): a wave meets the boundary from index n1 to
 * index n2 at incidence cosine cos_i in [0, 1].  s is perpendicular to
 * the plane of incidence, and the p unit vector of each wave is k x s for
 * its own direction k.  With that basis
 *     rs = (n1 ci - n2 ct)/(n1 ci + n2 ct),
 *     rp = (n2 ci - n1 ct)/(n2 ci + n1 ct),
 * so at normal incidence rp = -rs: the p vector of the reflected wave is
 * minus the mirror image of the incident one.  Transmission amplitudes are
 * POWER-normalized (ts^2 = Ts = 1 - Rs), which is what a ray carrying
 * power needs.  Beyond the critical angle rs and rp are unit complex
 * numbers, exp(i*delta), for time dependence exp(-i*omega*t).
 */
#ifndef LP_FRESNEL_H
#define LP_FRESNEL_H

#include <complex.h>
#include <math.h>

typedef struct lp__fresnel {
    int tir;               /* 1 beyond the critical angle: no transmitted wave */
    double eta;            /* n1 / n2 */
    double cos_t;          /* cosine of the refraction angle; 0 under TIR */
    double complex rs, rp; /* amplitude reflection coefficients */
    double ts, tp;         /* power-normalized transmission amplitudes, >= 0 */
    double Rs, Rp;         /* reflectances |rs|^2, |rp|^2 */
} lp__fresnel;

/* The cosine of refraction for the relative index eta = n1/n2, or -1. */
static inline double lp__refraction_cos_eta(double cos_i, double eta)
{
    /* sin^2 i written as (1-c)(1+c): no cancellation at grazing incidence */
    double sin2_i = (1.0 - cos_i) * (1.0 + cos_i);
    double cos2_t = 1.0 - eta * eta * sin2_i;
    if (cos2_t < 0.0)
        return -1.0;
    return sqrt(cos2_t);
}

/* Evaluate at incidence cosine cos_i (clamped to [0,1]) from n1 into n2
 * (inline: every node evaluates it). */
static inline void lp__fresnel_eval(double cos_i, double n1, double n2, lp__fresnel *f)
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

    double ct = lp__refraction_cos_eta(ci, f->eta);
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

/* Cosine of the refraction angle from n1 into n2, or -1 under TIR.
 * Accurate at grazing incidence (uses sin^2 = (1-c)(1+c)). */
double lp__refraction_cos(double cos_i, double n1, double n2);

/* Unpolarized reflectance (Rs + Rp)/2; 1 under TIR. */
double lp__fresnel_unpolarized(double cos_i, double n1, double n2);

/* Schlick's approximation R0 + (1 - R0)(1 - c)^5, R0 = ((n1-n2)/(n1+n2))^2,
 * with c = cos_i when n1 <= n2 and c = cos_t when n1 > n2; 1 under TIR. */
double lp__schlick(double cos_i, double n1, double n2);

/* Brewster's angle atan(n2/n1) and the critical angle asin(n2/n1)
 * (NaN when n1 <= n2), radians. */
double lp__brewster_angle(double n1, double n2);
double lp__critical_angle(double n1, double n2);

#endif
