/* test_airy.c -- coherence: the plate's rays, added as complex amplitudes,
 * give Airy's formulae (Born & Wolf 7.6.1 (13)-(16)).
 *
 * Plate n = 1.5168, thickness t = 10, in air, lossless, wide (rim never
 * reached), depth limit 60.  Each output ray is the plane wave
 *     E(P) = sqrt(I) vp exp(i (Phi + k0 n_med dir.(P - origin))),
 *     Phi = 2 pi op/lambda - pi kphi + phase,   k0 = 2 pi/lambda
 * (lensprim.h, exp(-i w t)).  All transmitted rays share one direction,
 * so on any plane perpendicular to it the sum is the same; evaluate it at
 * the point P_ref = (0, 0, t) (any point would do): add
 * k0 n_med dir.(P_ref - origin) to each ray's phase.  Consecutive rays
 * differ by 2 n t/cos r of optical path inside and by 2 t tan r along x
 * at exit, i.e. by -2 t tan r sin i = -2 n t sin^2 r/cos r of external
 * path to the plane: in all 2 n t cos r, delta = 4 pi n t cos r/lambda.
 * With the amplitudes r (outside), r' = -r (inside, Stokes) and
 * t t' = 1 - r^2:
 *   transmitted  E_T = t t' / (1 - r'^2 e^{i delta})
 *                |E_T|^2 = 1/(1 + F sin^2(delta/2)),  F = 4R/(1-R)^2
 *   reflected    E_R = r + t t' r' e^{i delta}/(1 - r'^2 e^{i delta})
 *                    = r (1 - e^{i delta})/(1 - R e^{i delta})
 *                |E_R|^2 = F sin^2(delta/2)/(1 + F sin^2(delta/2))
 * (the reflected side vanishes at the transmission maxima only when r'
 * = -r: that is the Stokes relation being checked).
 *
 * Wavelengths: m = floor(2 n t cos r/550 nm); delta = 2 pi m (maximum,
 * sin^2 = 0), (2m + 1) pi (minimum, sin^2 = 1) and 2 pi m + pi/2
 * (sin^2 = 1/2), i.e. lambda = 4 n t cos r/(2m), /(2m+1), /(2m+1/2).
 *
 * Tolerance 1e-7 on the intensities (input power 1).  The first rays
 * have op ~ 15-50 mm, Phi ~ 2e5-6e5 rad; double rounding of op
 * (~1e-15 relative) makes ~1e-9 rad of phase error per ray, ~1e-9 of
 * intensity; 1e-7 leaves a factor 100.  The truncated tail (rays past
 * depth 60) has amplitude below R^29 and is added to the tolerance.
 */
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "lensprim.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static const double NG = 1.5168, TH = 10.0;
enum { DEPTH = 60 };

static lp_vec3 vec(double x, double y, double z)
{
    lp_vec3 v = {x, y, z};
    return v;
}
static double dot(lp_vec3 a, lp_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static void airy_case(const lp_lens *lens, double deg, int pol, int which)
{
    const char *pn = pol ? "p" : "s";
    const char *wn[3] = {"maximum", "minimum", "quarter"};
    double th = deg * DEG, ci = cos(th), si = sin(th);
    double sr = si / NG, cr = sqrt(1.0 - sr * sr);
    double rs = (ci - NG * cr) / (ci + NG * cr);
    double rp = (NG * ci - cr) / (NG * ci + cr);
    double R = pol ? rp * rp : rs * rs;
    double F = 4.0 * R / ((1.0 - R) * (1.0 - R));

    double path = 2.0 * NG * TH * cr; /* mm, one round trip's difference */
    double m = floor(path / 550e-6);
    double denom = which == 0 ? 2.0 * m : (which == 1 ? 2.0 * m + 1.0 : 2.0 * m + 0.5);
    double lambda_mm = 2.0 * path / denom;
    double sin2 = which == 0 ? 0.0 : (which == 1 ? 1.0 : 0.5);
    double want_t = 1.0 / (1.0 + F * sin2);
    double want_r = F * sin2 / (1.0 + F * sin2);
    CHECK_ABS(want_t + want_r, 1.0, 1e-15, "my Airy T + R = 1");

    lp_ray in;
    memset(&in, 0, sizeof in);
    lp_vec3 d = vec(si, 0.0, ci);
    in.origin = vec(-3.0 * si, 0.0, -3.0 * ci);
    in.dir = d;
    in.lambda_nm = lambda_mm * 1e6;
    in.intensity = 1.0;
    in.vp = pol ? vec(-ci, 0.0, si) : vec(0.0, 1.0, 0.0);
    in.ch = 1;
    lp_trace_args args;
    lp_trace_args_init(&args);
    args.max_depth = DEPTH;
    lp_result res;
    lp_result_init(&res);
    lp_error err;
    memset(&err, 0, sizeof err);
    lp_status st = lp_trace_forward(lens, &in, &args, &res, &err);
    CHECK(st == LP_OK, "%s %g deg %s: trace: %s", pn, deg, wn[which], err.message);
    if (st != LP_OK) {
        lp_result_release(&res);
        return;
    }
    CHECK(res.count == DEPTH, "%s %g deg: %zu rays, want %d", pn, deg, res.count, DEPTH);

    const double k0 = 2.0 * PI / lambda_mm, n_med = 1.0;
    const lp_vec3 pref_t = vec(0.0, 0.0, TH), pref_r = vec(0.0, 0.0, 0.0);
    double complex et[3] = {0, 0, 0}, er[3] = {0, 0, 0};
    for (size_t i = 0; i < res.count; i++) {
        const lp_out_ray *o = &res.rays[i];
        const lp_ray *r = &o->ray;
        CHECK(r->ch == 1 && r->lambda_nm == in.lambda_nm, "ch and lambda copied");
        int tr = o->kind == LP_KIND_TRANSMIT;
        lp_vec3 pref = tr ? pref_t : pref_r;
        lp_vec3 rel = vec(pref.x - r->origin.x, pref.y - r->origin.y, pref.z - r->origin.z);
        double phi = 2.0 * PI * (r->op / lambda_mm) - PI * r->kphi + r->phase +
                     k0 * n_med * dot(r->dir, rel);
        double complex a = sqrt(r->intensity) * cexp(I * phi);
        double complex *e = tr ? et : er;
        e[0] += a * r->vp.x;
        e[1] += a * r->vp.y;
        e[2] += a * r->vp.z;
    }
    double it = creal(et[0] * conj(et[0]) + et[1] * conj(et[1]) + et[2] * conj(et[2]));
    double ir = creal(er[0] * conj(er[0]) + er[1] * conj(er[1]) + er[2] * conj(er[2]));
    /* the tail past depth 60: amplitude < sum_{k>=29} (1-R) R^k */
    double tail = 2.0 * pow(R, 29) / (1.0 - R);
    CHECK_ABS(it, want_t, 1e-7 + tail, "%s %g deg %s: Airy transmittance", pn, deg, wn[which]);
    CHECK_ABS(ir, want_r, 1e-7 + tail, "%s %g deg %s: Airy reflectance", pn, deg, wn[which]);
    printf("%s %5.1f deg %-8s lambda %.9f nm: T %.12f (Airy %.12f)  R %.12f (Airy %.12f)\n", pn,
           deg, wn[which], lambda_mm * 1e6, it, want_t, ir, want_r);
    lp_result_release(&res);
}

int main(void)
{
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_error err;
    memset(&err, 0, sizeof err);
    lp_lens_desc_init(&desc);
    desc.radius1 = 0.0;
    desc.radius2 = 0.0;
    desc.thickness = TH;
    desc.diameter = 1e4;
    lp_glass_init_constant(&desc.glass, NG);
    lp_status st = lp_lens_create(&desc, &lens, &err);
    CHECK(st == LP_OK, "plate creation: %s", err.message);
    if (st == LP_OK) {
        const double angles[3] = {0.0, 30.0, 60.0};
        for (int a = 0; a < 3; a++)
            for (int pol = 0; pol < 2; pol++)
                for (int w = 0; w < 3; w++)
                    airy_case(lens, angles[a], pol, w);
    }
    lp_lens_destroy(lens);
    return check_finish("test_airy");
}
