/* test_fresnel.c -- Fresnel's equations, as pure functions and end to end.
 *
 * Expected values are Born & Wolf, Principles of Optics, 1.5.2 (20)-(21)
 * and 1.5.3 (35)-(38), written out here from scratch:
 *
 *   Snell       n1 sin i = n2 sin t
 *   amplitudes  rs = (n1 ci - n2 ct)/(n1 ci + n2 ct)
 *               rp = (n2 ci - n1 ct)/(n2 ci + n1 ct)     (p = k x s basis)
 *               ts = 2 n1 ci/(n1 ci + n2 ct),  tp = 2 n1 ci/(n2 ci + n1 ct)
 *   powers      R = r^2,  T = (n2 ct)/(n1 ci) t^2,  R + T = 1
 *   Brewster    tan iB = n2/n1 (rp = 0),  critical  sin ic = n2/n1
 *   Schlick     R0 + (1-R0)(1-c)^5, R0 = ((n1-n2)/(n1+n2))^2, c = cos of
 *               the angle on the less dense side.
 *
 * The reference values of the pure functions are computed in ref_real
 * (binary128 where available, see ref_real.h) from the same double cos_i
 * the library receives, so the measured error is the library's own
 * rounding.  Relative tolerance 1e-12 (double math
 * of a few operations is ~1e-15; near the critical angle ct is
 * ill-conditioned in st^2, which costs up to ~1e-14).  The identities the
 * brief states at 1e-15 are checked at 1e-15.
 *
 * End to end: a flat plate (both radii 0, thickness 10, diameter 1000,
 * constant n = 1.5168) hit at its centre from z < 0 at angle theta in the
 * x-z plane; the depth-1 reflected ray must carry Rs(theta) or Rp(theta)
 * and the field r * (reflected s or p unit vector); the depth-2 ray
 * (1-R)^2 (the internal reflectance at the refraction angle is the same R,
 * Stokes).  Field of a ray: E = sqrt(I) vp exp(i Phi),
 * Phi = 2 pi op/lambda - pi kphi + phase (lensprim.h).
 */
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "fresnel.h"
#include "lensprim.h"
#include "ref_real.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static const double NGLASS = 1.5168;

/* ---------------------------------------------------------------- */
/* My closed forms (ref_real)                                        */
/* ---------------------------------------------------------------- */

typedef struct ref_fresnel {
    int tir;
    ref_real ct, rs, rp, Ts, Tp;
} ref_fresnel;

static void ref_eval(double cos_i, double n1d, double n2d, ref_fresnel *m)
{
    ref_real ci = cos_i, n1 = n1d, n2 = n2d;
    ref_real si2 = (REF(1.0) - ci) * (REF(1.0) + ci);
    ref_real st2 = (n1 / n2) * (n1 / n2) * si2;
    memset(m, 0, sizeof *m);
    if (st2 > REF(1.0)) {
        m->tir = 1;
        return;
    }
    ref_real ct = ref_sqrt(REF(1.0) - st2);
    m->ct = ct;
    m->rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    m->rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    ref_real tsa = REF(2.0) * n1 * ci / (n1 * ci + n2 * ct);
    ref_real tpa = REF(2.0) * n1 * ci / (n2 * ci + n1 * ct);
    ref_real g = (ci > REF(0.0)) ? n2 * ct / (n1 * ci) : REF(0.0);
    m->Ts = g * tsa * tsa;
    m->Tp = g * tpa * tpa;
}

static ref_real ref_schlick(double cos_i, double n1, double n2)
{
    ref_fresnel m;
    ref_eval(cos_i, n1, n2, &m);
    if (m.tir)
        return REF(1.0);
    ref_real r0 = ((ref_real)n1 - n2) / ((ref_real)n1 + n2);
    r0 *= r0;
    ref_real c = (n1 <= n2) ? (ref_real)cos_i : m.ct;
    ref_real x = REF(1.0) - c;
    return r0 + (REF(1.0) - r0) * x * x * x * x * x;
}

/* ---------------------------------------------------------------- */
/* Pure functions                                                    */
/* ---------------------------------------------------------------- */

static void check_below_critical(double theta_deg, double n1, double n2)
{
    double ci = cos(theta_deg * DEG);
    ref_fresnel m;
    lp__fresnel f;
    ref_eval(ci, n1, n2, &m);
    lp__fresnel_eval(ci, n1, n2, &f);
    CHECK(!m.tir, "my formula: no TIR expected at %g deg %g->%g", theta_deg, n1, n2);
    CHECK(f.tir == 0, "tir flag at %g deg %g->%g", theta_deg, n1, n2);

    /* my own derivation: R + T = 1 (checks the test, not the library) */
    CHECK_ABS((double)(m.rs * m.rs + m.Ts), 1.0, 1e-15, "my Rs+Ts at %g deg", theta_deg);
    CHECK_ABS((double)(m.rp * m.rp + m.Tp), 1.0, 1e-15, "my Rp+Tp at %g deg", theta_deg);

    CHECK_REL(f.cos_t, (double)m.ct, 1e-12, "cos_t %g deg %g->%g", theta_deg, n1, n2);
    CHECK_REL(lp__refraction_cos(ci, n1, n2), (double)m.ct, 1e-12,
              "refraction_cos %g deg %g->%g", theta_deg, n1, n2);
    CHECK_REL(creal(f.rs), (double)m.rs, 1e-12, "rs %g deg %g->%g", theta_deg, n1, n2);
    CHECK_REL(creal(f.rp), (double)m.rp, 1e-12, "rp %g deg %g->%g", theta_deg, n1, n2);
    CHECK_ABS(cimag(f.rs), 0.0, 1e-15, "Im rs %g deg %g->%g", theta_deg, n1, n2);
    CHECK_ABS(cimag(f.rp), 0.0, 1e-15, "Im rp %g deg %g->%g", theta_deg, n1, n2);
    CHECK_REL(f.Rs, (double)(m.rs * m.rs), 1e-12, "Rs %g deg %g->%g", theta_deg, n1, n2);
    CHECK_REL(f.Rp, (double)(m.rp * m.rp), 1e-12, "Rp %g deg %g->%g", theta_deg, n1, n2);
    CHECK(f.ts >= 0.0 && f.tp >= 0.0, "ts, tp >= 0 at %g deg", theta_deg);
    CHECK_REL(f.ts * f.ts, (double)m.Ts, 1e-12, "Ts %g deg %g->%g", theta_deg, n1, n2);
    CHECK_REL(f.tp * f.tp, (double)m.Tp, 1e-12, "Tp %g deg %g->%g", theta_deg, n1, n2);
    /* energy: R + T = 1 */
    CHECK_ABS(f.Rs + f.ts * f.ts, 1.0, 1e-15, "Rs+ts^2 %g deg %g->%g", theta_deg, n1, n2);
    CHECK_ABS(f.Rp + f.tp * f.tp, 1.0, 1e-15, "Rp+tp^2 %g deg %g->%g", theta_deg, n1, n2);
    CHECK_REL(lp__fresnel_unpolarized(ci, n1, n2), (double)((m.rs * m.rs + m.rp * m.rp) / REF(2.0)),
              1e-12, "unpolarized %g deg %g->%g", theta_deg, n1, n2);
    CHECK_REL(lp__schlick(ci, n1, n2), (double)ref_schlick(ci, n1, n2), 1e-12,
              "schlick %g deg %g->%g", theta_deg, n1, n2);
}

static void check_beyond_critical(double theta_deg, double n1, double n2)
{
    double ci = cos(theta_deg * DEG);
    ref_fresnel m;
    lp__fresnel f;
    ref_eval(ci, n1, n2, &m);
    lp__fresnel_eval(ci, n1, n2, &f);
    CHECK(m.tir, "my formula: TIR expected at %g deg %g->%g", theta_deg, n1, n2);
    CHECK(f.tir == 1, "tir flag at %g deg %g->%g", theta_deg, n1, n2);
    CHECK_ABS(cabs(f.rs), 1.0, 1e-15, "|rs| under TIR at %g deg", theta_deg);
    CHECK_ABS(cabs(f.rp), 1.0, 1e-15, "|rp| under TIR at %g deg", theta_deg);
    CHECK_ABS(f.Rs, 1.0, 1e-15, "Rs under TIR at %g deg", theta_deg);
    CHECK_ABS(f.Rp, 1.0, 1e-15, "Rp under TIR at %g deg", theta_deg);
    CHECK(f.ts == 0.0 && f.tp == 0.0, "ts = tp = 0 under TIR at %g deg (got %g %g)",
          theta_deg, f.ts, f.tp);
    CHECK(f.cos_t == 0.0, "cos_t = 0 under TIR at %g deg (got %g)", theta_deg, f.cos_t);
    CHECK(lp__refraction_cos(ci, n1, n2) == -1.0, "refraction_cos = -1 under TIR at %g deg",
          theta_deg);
    CHECK_ABS(lp__fresnel_unpolarized(ci, n1, n2), 1.0, 1e-15, "unpolarized under TIR %g deg",
              theta_deg);
    CHECK_ABS(lp__schlick(ci, n1, n2), 1.0, 1e-15, "schlick under TIR %g deg", theta_deg);
}

static void test_pure(void)
{
    const double n_air = 1.0, n_g = NGLASS;

    /* air -> glass, 0..89 deg */
    for (int d = 0; d <= 89; d++)
        check_below_critical((double)d, n_air, n_g);

    /* glass -> air below the critical angle (41.25 deg), beyond it TIR */
    double ic = asin(n_air / n_g) / DEG;
    for (int d = 0; d <= 89; d++) {
        if (d < ic)
            check_below_critical((double)d, n_g, n_air);
        else
            check_beyond_critical((double)d, n_g, n_air);
    }

    /* critical and Brewster angles */
    CHECK_REL(lp__critical_angle(n_g, n_air), asin(n_air / n_g), 1e-15, "critical angle");
    CHECK_REL(lp__critical_angle(1.51, 1.0), asin(1.0 / 1.51), 1e-15, "critical angle 1.51");
    CHECK_REL(lp__critical_angle(1.7, 1.33), asin(1.33 / 1.7), 1e-15, "critical angle 1.7->1.33");
    CHECK(isnan(lp__critical_angle(n_air, n_g)), "critical angle NaN for n1 < n2");
    CHECK(isnan(lp__critical_angle(1.5, 1.5)), "critical angle NaN for n1 == n2");
    CHECK_REL(lp__brewster_angle(n_air, n_g), atan(n_g / n_air), 1e-15, "Brewster air->glass");
    CHECK_REL(lp__brewster_angle(n_g, n_air), atan(n_air / n_g), 1e-15, "Brewster glass->air");

    /* rp vanishes at Brewster's angle, both ways; rs does not */
    {
        lp__fresnel f;
        double ib = atan(n_g / n_air);
        lp__fresnel_eval(cos(ib), n_air, n_g, &f);
        CHECK(cabs(f.rp) < 1e-15, "|rp| at Brewster air->glass = %g", cabs(f.rp));
        CHECK_ABS(f.Rp, 0.0, 1e-15, "Rp at Brewster air->glass");
        /* Rs at Brewster: rs = -cos(2 iB) ... = (n1^2 - n2^2)/(n1^2 + n2^2) */
        double rsb = (n_air * n_air - n_g * n_g) / (n_air * n_air + n_g * n_g);
        CHECK_REL(creal(f.rs), rsb, 1e-12, "rs at Brewster air->glass");
        ib = atan(n_air / n_g);
        lp__fresnel_eval(cos(ib), n_g, n_air, &f);
        CHECK(cabs(f.rp) < 1e-15, "|rp| at Brewster glass->air = %g", cabs(f.rp));
        CHECK_REL(creal(f.rs), -rsb, 1e-12, "rs at Brewster glass->air");
    }

    /* normal incidence: rs = (n1-n2)/(n1+n2), rp = -rs (basis p = k x s) */
    {
        lp__fresnel f;
        lp__fresnel_eval(1.0, n_air, n_g, &f);
        double r0 = (n_air - n_g) / (n_air + n_g);
        CHECK_REL(creal(f.rs), r0, 1e-15, "rs at normal incidence");
        CHECK_REL(creal(f.rp), -r0, 1e-15, "rp at normal incidence");
        CHECK_REL(f.cos_t, 1.0, 1e-15, "cos_t at normal incidence");
        CHECK_REL(lp__schlick(1.0, n_air, n_g), r0 * r0, 1e-15, "schlick R0");
    }

    /* grazing incidence: everything is reflected, rs = rp = -1 */
    {
        lp__fresnel f;
        lp__fresnel_eval(0.0, n_air, n_g, &f);
        CHECK_ABS(creal(f.rs), -1.0, 1e-15, "rs at grazing incidence");
        CHECK_ABS(creal(f.rp), -1.0, 1e-15, "rp at grazing incidence");
        CHECK_ABS(f.Rs + f.ts * f.ts, 1.0, 1e-15, "Rs+Ts at grazing");
        CHECK_ABS(f.Rp + f.tp * f.tp, 1.0, 1e-15, "Rp+Tp at grazing");
    }

    /* cos_i is clamped to [0, 1] */
    {
        lp__fresnel a, b;
        lp__fresnel_eval(1.0 + 1e-9, n_air, n_g, &a);
        lp__fresnel_eval(1.0, n_air, n_g, &b);
        CHECK(a.Rs == b.Rs && a.Rp == b.Rp && a.cos_t == b.cos_t, "cos_i > 1 clamped to 1");
        lp__fresnel_eval(-1e-9, n_air, n_g, &a);
        lp__fresnel_eval(0.0, n_air, n_g, &b);
        CHECK(a.Rs == b.Rs && a.Rp == b.Rp, "cos_i < 0 clamped to 0");
    }
}

/* ---------------------------------------------------------------- */
/* End to end through a flat plate                                   */
/* ---------------------------------------------------------------- */

static lp_vec3 vec(double x, double y, double z)
{
    lp_vec3 v = {x, y, z};
    return v;
}

static double ray_phi(const lp_ray *r)
{
    return 2.0 * PI * (r->op / (r->lambda_nm * 1e-6)) - PI * r->kphi + r->phase;
}

static lp_lens *make_plate(void)
{
    lp_lens_desc d;
    lp_lens *lens = NULL;
    lp_error err;
    memset(&err, 0, sizeof err);
    lp_lens_desc_init(&d);
    d.radius1 = 0.0;
    d.radius2 = 0.0;
    d.thickness = 10.0;
    d.diameter = 1000.0;
    lp_glass_init_constant(&d.glass, NGLASS);
    lp_status st = lp_lens_create(&d, &lens, &err);
    CHECK(st == LP_OK && lens != NULL, "flat plate creation: %s", err.message);
    return st == LP_OK ? lens : NULL;
}

/* Find the only output ray of a given depth; NULL (and a failed check) if
 * there is not exactly one. */
static const lp_out_ray *only_ray(const lp_result *res, int depth, const char *what)
{
    const lp_out_ray *found = NULL;
    int n = 0;
    for (size_t i = 0; i < res->count; i++)
        if (res->rays[i].depth == depth) {
            found = &res->rays[i];
            n++;
        }
    CHECK(n == 1, "%s: %d rays at depth %d, want 1", what, n, depth);
    return n == 1 ? found : NULL;
}

static void test_end_to_end(void)
{
    lp_lens *lens = make_plate();
    if (!lens)
        return;
    const double lambda_nm = 500.0;
    /* the ray starts 1 mm (= 2000 wavelengths) before the hit point, so
     * the field phase is the same whether or not op counts that path */
    const double L = 1.0;
    const double ib = atan(NGLASS);
    lp_result res;
    lp_result_init(&res);
    lp_trace_args args;
    lp_trace_args_init(&args);
    args.max_depth = 2;

    for (int deg = 0; deg <= 89; deg++) {
        double th = deg * DEG, c = cos(th), s = sin(th);
        ref_fresnel m;
        ref_eval(c, 1.0, NGLASS, &m);
        double rs = (double)m.rs, rp = (double)m.rp;
        lp_vec3 k = vec(s, 0.0, c);
        lp_vec3 kr = vec(s, 0.0, -c);
        lp_vec3 sv = vec(0.0, 1.0, 0.0);
        lp_vec3 pin = vec(-c, 0.0, s);  /* k x s */
        lp_vec3 pout = vec(c, 0.0, s);  /* kr x s */
        lp_vec3 pmirror = vec(-c, 0.0, -s); /* mirror image of pin in z = 0 */

        for (int pol = 0; pol < 2; pol++) {
            const char *pn = pol ? "p" : "s";
            lp_ray in;
            memset(&in, 0, sizeof in);
            in.origin = vec(-L * s, 0.0, -L * c);
            in.dir = k;
            in.lambda_nm = lambda_nm;
            in.intensity = 1.0;
            in.vp = pol ? pin : sv;
            in.ch = 42;
            lp_error err;
            memset(&err, 0, sizeof err);
            lp_status st = lp_trace_forward(lens, &in, &args, &res, &err);
            CHECK(st == LP_OK, "trace %s %d deg: %s", pn, deg, err.message);
            if (st != LP_OK)
                continue;
            const lp_out_ray *r1 = only_ray(&res, 1, "depth-1 reflection");
            if (r1) {
                double R = pol ? rp * rp : rs * rs;
                CHECK_REL(r1->ray.intensity, R, 1e-12, "R%s(%d deg) end to end", pn, deg);
                CHECK(r1->kind == LP_KIND_REFLECT && r1->surface == LP_SURFACE_FRONT,
                      "depth-1 ray kind/surface at %d deg", deg);
                CHECK_ABS(r1->ray.origin.x, 0.0, 1e-12, "reflection point x %d deg", deg);
                CHECK_ABS(r1->ray.origin.y, 0.0, 1e-12, "reflection point y %d deg", deg);
                CHECK_ABS(r1->ray.origin.z, 0.0, 1e-12, "reflection point z %d deg", deg);
                CHECK_ABS(r1->ray.dir.x, kr.x, 1e-15, "reflected dir x %d deg", deg);
                CHECK_ABS(r1->ray.dir.z, kr.z, 1e-15, "reflected dir z %d deg", deg);
                CHECK(r1->ray.ch == 42 && r1->ray.lambda_nm == lambda_nm,
                      "ch and lambda copied at %d deg", deg);
                /* the field: r * (s or p_out); Phi up to 2 pi * 2000 */
                double complex a = sqrt(r1->ray.intensity) * cexp(I * ray_phi(&r1->ray));
                lp_vec3 e = pol ? pout : sv;
                double r = pol ? rp : rs;
                CHECK_ABS(creal(a * r1->ray.vp.x), r * e.x, 1e-11, "Re Ex %s %d deg", pn, deg);
                CHECK_ABS(creal(a * r1->ray.vp.y), r * e.y, 1e-11, "Re Ey %s %d deg", pn, deg);
                CHECK_ABS(creal(a * r1->ray.vp.z), r * e.z, 1e-11, "Re Ez %s %d deg", pn, deg);
                CHECK_ABS(cimag(a * r1->ray.vp.x), 0.0, 1e-11, "Im Ex %s %d deg", pn, deg);
                CHECK_ABS(cimag(a * r1->ray.vp.y), 0.0, 1e-11, "Im Ey %s %d deg", pn, deg);
                CHECK_ABS(cimag(a * r1->ray.vp.z), 0.0, 1e-11, "Im Ez %s %d deg", pn, deg);
                /* the documented representation: vp is the mirror image of
                 * the incident field, kphi counts a sign flip */
                int want_k = pol ? (th < ib ? 1 : 0) : 1;
                lp_vec3 want_vp = pol ? pmirror : sv;
                CHECK(r1->ray.kphi == want_k, "convention: kphi of the %s reflection at %d deg = %d, want %d",
                      pn, deg, r1->ray.kphi, want_k);
                CHECK_ABS(r1->ray.phase, 0.0, 1e-15, "convention: phase of %s reflection %d deg", pn, deg);
                CHECK_ABS(r1->ray.vp.x, want_vp.x, 1e-12, "convention: vp.x %s reflection %d deg", pn, deg);
                CHECK_ABS(r1->ray.vp.y, want_vp.y, 1e-12, "convention: vp.y %s reflection %d deg", pn, deg);
                CHECK_ABS(r1->ray.vp.z, want_vp.z, 1e-12, "convention: vp.z %s reflection %d deg", pn, deg);
            }
            const lp_out_ray *r2 = only_ray(&res, 2, "depth-2 transmission");
            if (r2) {
                double T = pol ? (double)m.Tp : (double)m.Ts;
                CHECK_REL(r2->ray.intensity, T * T, 1e-12, "T%s^2 (%d deg) end to end", pn, deg);
                CHECK(r2->kind == LP_KIND_TRANSMIT && r2->surface == LP_SURFACE_BACK,
                      "depth-2 ray kind/surface at %d deg", deg);
            }
        }

        /* unpolarized modes: fresnel (Rs+Rp)/2 per node, schlick */
        for (int mode = 0; mode < 2; mode++) {
            lp_ray in;
            memset(&in, 0, sizeof in);
            in.origin = vec(-L * s, 0.0, -L * c);
            in.dir = k;
            in.lambda_nm = lambda_nm;
            in.intensity = 1.0;
            in.vp = sv;
            lp_trace_args a2 = args;
            a2.mode = mode ? LP_MODE_SCHLICK : LP_MODE_FRESNEL;
            lp_status st = lp_trace_forward(lens, &in, &a2, &res, NULL);
            CHECK(st == LP_OK, "trace unpolarized mode %d at %d deg", mode, deg);
            if (st != LP_OK)
                continue;
            /* external: cos_i = cos th; internal exit at the refraction
             * angle, n1 > n2: Schlick uses cos of the transmitted angle,
             * which is cos th again; Fresnel's R is the same both ways. */
            double R = mode ? (double)ref_schlick(c, 1.0, NGLASS)
                            : (double)((m.rs * m.rs + m.rp * m.rp) / REF(2.0));
            const lp_out_ray *r1 = only_ray(&res, 1, "unpolarized depth 1");
            if (r1)
                CHECK_REL(r1->ray.intensity, R, 1e-12, "%s R at %d deg",
                          mode ? "schlick" : "fresnel", deg);
            const lp_out_ray *r2 = only_ray(&res, 2, "unpolarized depth 2");
            if (r2)
                CHECK_REL(r2->ray.intensity, (1.0 - R) * (1.0 - R), 1e-12,
                          "%s (1-R)^2 at %d deg", mode ? "schlick" : "fresnel", deg);
        }
    }
    lp_result_release(&res);
    lp_lens_destroy(lens);
}

int main(void)
{
    test_pure();
    test_end_to_end();
    return check_finish("test_fresnel");
}
