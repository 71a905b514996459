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

typedef struct lp__fresnel {
    int tir;               /* 1 beyond the critical angle: no transmitted wave */
    double eta;            /* n1 / n2 */
    double cos_t;          /* cosine of the refraction angle; 0 under TIR */
    double complex rs, rp; /* amplitude reflection coefficients */
    double ts, tp;         /* power-normalized transmission amplitudes, >= 0 */
    double Rs, Rp;         /* reflectances |rs|^2, |rp|^2 */
} lp__fresnel;

/* Evaluate at incidence cosine cos_i (clamped to [0,1]) from n1 into n2. */
void lp__fresnel_eval(double cos_i, double n1, double n2, lp__fresnel *f);

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
