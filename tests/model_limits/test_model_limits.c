/* test_model_limits.c -- the physics behind "where the light models fail"
 * (docs/model-limits.md), checked twice: on the library directly, and on
 * the tables the model_limits command writes.
 *
 * Expected values come from formulas written here: Fresnel's equations
 * (Born & Wolf), Schlick's approximation as lensprim.h defines it
 * (R0 + (1-R0)(1-c)^5, c the cosine on the low-index side), the Schott
 * Sellmeier coefficients of N-BK7 and N-SF11 (Schott data sheets), the
 * ray chain of a flat plate, and a 2-D meridional trace of a biconvex lens
 * written from its geometry.  Glass absorption is switched off (n_tau = 0)
 * here and in the command: it scales a path's power equally in every model.
 *
 * Facts checked, natural light (two orthogonal incoherent halves):
 *   1. One interface: polarized == fresnel == (Rs+Rp)/2 (to 1e-15), both
 *      for n1 < n2 and n1 > n2, below and above the critical angle.
 *   2. Schlick is exact at normal incidence (error 0).
 *   3. Two interfaces (the direct ray through a plate):
 *        T_pol  = ((1-Rs)^2 + (1-Rp)^2)/2,  T_fres = (1 - (Rs+Rp)/2)^2,
 *        T_pol - T_fres = (Rs-Rp)^2/4 >= 0,
 *      and the k-th ray of the plate's chain, ((1-Rs)^2 Rs^(k-2) +
 *      (1-Rp)^2 Rp^(k-2))/2 against (1-R)^2 R^(k-2): the relative error
 *      of fresnel grows with k.
 *   4. Schlick's error grows towards grazing incidence (n1 < n2: too low
 *      up to ~75 deg, too high beyond, largest beyond 80 deg), and for
 *      n1 > n2 lensprim's Schlick (cosine of the transmitted angle) makes
 *      the error at glass angle g exactly the n1 < n2 error at the air
 *      angle asin(n sin g): the whole 0-90 deg curve is squeezed below the
 *      critical angle, and its maximum lies just below it.
 *   5. A meridional ray through a biconvex lens to depth 12: s and p never
 *      mix, so polarized = (S_k + P_k)/2 with S_k, P_k the products of the
 *      s and p factors along the path, fresnel the product of the
 *      averages; lensprim must give both.  For skew rays s and p mix: a
 *      complex field-vector trace written here must give lensprim's
 *      polarized powers, and on the worst ray of model_limits' sample
 *      fresnel overestimates the depth-12 power 10^5-fold (the turning
 *      planes of incidence extinguish the light like crossed polarizers).
 *   6. The command: --help documents the comparisons; bad usage exits 2
 *      with one line on stderr; a monochromatic run (--lambda) writes
 *      tables whose every plate entry equals the closed forms above, whose
 *      thresholds ("within 1 % up to X deg") are those of the closed
 *      forms, whose depth table obeys the one-interface facts; PNGs are
 *      PNGs under 100 KB; the spectral run keeps fresnel's single-
 *      interface error at 0, Schlick's normal-incidence error at 0 and
 *      polarized >= fresnel for the direct ray (true at every wavelength,
 *      hence for the weighted mean).
 */
#define _POSIX_C_SOURCE 200809L

#include <complex.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "subprocess.h"
#include "test_files.h"
#include "lensprim.h"

#ifndef LP_BIN_DIR
#error "LP_BIN_DIR must name the directory of the built programs"
#endif
#ifndef LP_TEST_TMP
#define LP_TEST_TMP "."
#endif

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define LAMBDA_D 587.5618 /* helium d line, in air */

static const char *const TOOL = LP_BIN_DIR "/model_limits";

/* ------------------------------------------------------------------ */
/* Closed forms                                                        */
/* ------------------------------------------------------------------ */

typedef struct sellmeier {
    const char *name;
    double b[3], c[3];
} sellmeier;

/* Schott data sheets (C in um^2). */
static const sellmeier GLASSES[2] = {
    {"N-BK7", {1.03961212, 0.231792344, 1.01046945}, {0.00600069867, 0.0200179144, 103.560653}},
    {"N-SF11", {1.73759695, 0.313747346, 1.89878101}, {0.013188707, 0.0623068142, 155.23629}},
};

/* The index of the glass the lens is made of.  The dispersion formula
 * itself is checked against the makers' catalog values in test_glass;
 * here the closed forms need the very double the lens uses (a one-ulp
 * difference in n moves R by ~1e-15, the size of these tolerances), so the
 * index comes from lp_glass_index on the same coefficients. */
static double sellmeier_n(const sellmeier *g, double lambda_nm)
{
    lp_glass glass;
    lp_glass_init_sellmeier(&glass, g->name, g->b, g->c);
    return lp_glass_index(&glass, lambda_nm);
}

/* Fresnel reflectances from n1 into n2 at incidence angle th (rad); 1, 1
 * under TIR.  *cos_t gets the cosine of the refraction angle (0 under TIR). */
static void fresnel(double th, double n1, double n2, double *Rs, double *Rp, double *cos_t)
{
    double ci = cos(th), si = sin(th), st = n1 / n2 * si;
    if (st >= 1.0) {
        *Rs = *Rp = 1.0;
        *cos_t = 0.0;
        return;
    }
    double ct = sqrt((1.0 - st) * (1.0 + st));
    double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    double rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    *Rs = rs * rs;
    *Rp = rp * rp;
    *cos_t = ct;
}

/* Schlick as lensprim.h defines it. */
static double schlick(double th, double n1, double n2)
{
    double r0 = (n1 - n2) / (n1 + n2), c = cos(th);
    r0 *= r0;
    if (n1 > n2) {
        double st = n1 / n2 * sin(th);
        if (st >= 1.0)
            return 1.0;
        c = sqrt((1.0 - st) * (1.0 + st));
    }
    return r0 + (1.0 - r0) * pow(1.0 - c, 5.0);
}

/* The plate's depth-1..3 powers for natural light in each model (n1 is
 * the outside, n2 the plate; by Stokes' relations the second face has the
 * same reflectances as the first). */
typedef struct plate_powers {
    double pol[4], fres[4], sch[4];
} plate_powers;

static plate_powers plate_closed_form(double th, double n1, double n2)
{
    plate_powers p;
    double Rs, Rp, ct;
    fresnel(th, n1, n2, &Rs, &Rp, &ct);
    double R = 0.5 * (Rs + Rp), S = schlick(th, n1, n2);
    p.pol[1] = R;
    p.fres[1] = R;
    p.sch[1] = S;
    p.pol[2] = 0.5 * ((1 - Rs) * (1 - Rs) + (1 - Rp) * (1 - Rp));
    p.fres[2] = (1 - R) * (1 - R);
    p.sch[2] = (1 - S) * (1 - S);
    p.pol[3] = 0.5 * ((1 - Rs) * (1 - Rs) * Rs + (1 - Rp) * (1 - Rp) * Rp);
    p.fres[3] = (1 - R) * (1 - R) * R;
    p.sch[3] = (1 - S) * (1 - S) * S;
    p.pol[0] = p.fres[0] = p.sch[0] = 0.0;
    return p;
}

/* ------------------------------------------------------------------ */
/* Library checks                                                      */
/* ------------------------------------------------------------------ */

static lp_vec3 vec(double x, double y, double z)
{
    lp_vec3 v = {x, y, z};
    return v;
}

/* Powers by depth (1..max_depth) of natural light of power 1: two
 * orthogonal halves at an arbitrary angle psi around the ray. */
static void natural(const lp_lens *lens, lp_vec3 o, lp_vec3 d, double lambda, lp_mode mode,
                    int max_depth, double psi, double *P)
{
    /* a basis perpendicular to d (d has no large y component here) */
    lp_vec3 a = vec(0, 1, 0);
    double ad = a.x * d.x + a.y * d.y + a.z * d.z;
    lp_vec3 u = vec(a.x - ad * d.x, a.y - ad * d.y, a.z - ad * d.z);
    double un = sqrt(u.x * u.x + u.y * u.y + u.z * u.z);
    u = vec(u.x / un, u.y / un, u.z / un);
    lp_vec3 w = vec(d.y * u.z - d.z * u.y, d.z * u.x - d.x * u.z, d.x * u.y - d.y * u.x);
    lp_trace_args args;
    lp_result res;
    lp_error err;
    lp_ray in;

    lp_trace_args_init(&args);
    args.mode = mode;
    args.max_depth = max_depth;
    lp_result_init(&res);
    memset(&err, 0, sizeof err);
    memset(&in, 0, sizeof in);
    for (int k = 0; k <= max_depth; k++)
        P[k] = 0.0;
    in.origin = o;
    in.dir = d;
    in.lambda_nm = lambda;
    in.intensity = 0.5;
    for (int h = 0; h < 2; h++) {
        double c = cos(psi + h * PI / 2), s = sin(psi + h * PI / 2);
        in.vp = vec(c * u.x + s * w.x, c * u.y + s * w.y, c * u.z + s * w.z);
        lp_status st = lp_trace_forward(lens, &in, &args, &res, &err);
        CHECK(st == LP_OK, "trace: %s", err.message);
        for (size_t i = 0; i < res.count; i++)
            if (res.rays[i].depth >= 1 && res.rays[i].depth <= max_depth)
                P[res.rays[i].depth] += res.rays[i].ray.intensity;
    }
    lp_result_release(&res);
}

/* A flat plate of thickness 10: the glass in air (gap 0) or an air gap in
 * the glass (gap 1). */
static lp_lens *plate(const char *glass, int gap)
{
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_error err;
    lp_glass g;

    memset(&err, 0, sizeof err);
    lp_lens_desc_init(&desc);
    desc.radius1 = 0.0;
    desc.radius2 = 0.0;
    desc.thickness = 10.0;
    desc.diameter = 1e7;
    CHECK(lp_glass_builtin(glass, &g, &err) == LP_OK, "glass %s: %s", glass, err.message);
    g.n_tau = 0; /* lossless, as the closed forms */
    if (gap) {
        lp_glass_init_constant(&desc.glass, 1.0);
        desc.medium = g;
    } else {
        desc.glass = g;
    }
    CHECK(lp_lens_create(&desc, &lens, &err) == LP_OK, "plate: %s", err.message);
    return lens;
}

static void plate_ray(double deg, lp_vec3 *o, lp_vec3 *d)
{
    double th = deg * DEG;
    *d = vec(sin(th), 0.0, cos(th));
    *o = vec(-10.0 * d->x, 0.0, -10.0 * d->z);
}

static void check_plates(void)
{
    for (int gi = 0; gi < 2; gi++) {
        const sellmeier *g = &GLASSES[gi];
        double n = sellmeier_n(g, LAMBDA_D);
        for (int gap = 0; gap < 2; gap++) {
            lp_lens *lens = plate(g->name, gap);
            double n1 = gap ? n : 1.0, n2 = gap ? 1.0 : n;
            double crit = gap ? asin(1.0 / n) / DEG : 90.0;
            const char *sn = gap ? "glass->air" : "air->glass";
            if (!lens)
                continue;
            for (double deg = 0.0; deg < 89.95; deg += 0.5) {
                if (fabs(deg - crit) < 0.3)
                    continue; /* the gap ray would run almost along the faces */
                lp_vec3 o, d;
                double pol[4], fres[4], sch[4];
                plate_ray(deg, &o, &d);
                natural(lens, o, d, LAMBDA_D, LP_MODE_POLARIZED, 3, 0.3 + deg * 0.01, pol);
                natural(lens, o, d, LAMBDA_D, LP_MODE_FRESNEL, 3, 0.0, fres);
                natural(lens, o, d, LAMBDA_D, LP_MODE_SCHLICK, 3, 0.0, sch);
                plate_powers want = plate_closed_form(deg * DEG, n1, n2);
                /* 1: one interface */
                CHECK_ABS(fres[1] - pol[1], 0.0, 1e-15, "%s %s %.1f: R1 fresnel == polarized",
                          g->name, sn, deg);
                CHECK_ABS(pol[1], want.pol[1], 2e-15, "%s %s %.1f: R1 = (Rs+Rp)/2", g->name, sn,
                          deg);
                /* the ray's direction carries an angle error of a few eps,
                 * which near the critical angle Schlick's cos t amplifies */
                plate_powers wp = plate_closed_form(deg * DEG + 1e-7, n1, n2);
                plate_powers wm = plate_closed_form(deg * DEG - 1e-7, n1, n2);
                double slope = fabs(wp.sch[1] - wm.sch[1]) / 2e-7;
                CHECK_ABS(sch[1], want.sch[1], 2e-15 + 8 * DBL_EPSILON * slope,
                          "%s %s %.1f: R1 schlick", g->name, sn, deg);
                /* 3: two and three interfaces */
                for (int k = 2; k <= 3; k++) {
                    CHECK_ABS(pol[k], want.pol[k], 1e-14, "%s %s %.1f: polarized depth %d",
                              g->name, sn, deg, k);
                    CHECK_ABS(fres[k], want.fres[k], 1e-14, "%s %s %.1f: fresnel depth %d",
                              g->name, sn, deg, k);
                    CHECK_ABS(sch[k], want.sch[k], 1e-14, "%s %s %.1f: schlick depth %d",
                              g->name, sn, deg, k);
                }
                double Rs, Rp, ct;
                fresnel(deg * DEG, n1, n2, &Rs, &Rp, &ct);
                CHECK_ABS(pol[2] - fres[2], 0.25 * (Rs - Rp) * (Rs - Rp), 1e-14,
                          "%s %s %.1f: T_pol - T_fres = (Rs-Rp)^2/4", g->name, sn, deg);
                CHECK(pol[2] >= fres[2] - 1e-15, "%s %s %.1f: T_pol >= T_fres", g->name, sn, deg);
                if (deg > crit) {
                    /* |rs|^2 and |rp|^2 of two unit complex numbers, halved
                     * and added: a few roundings, 8 ulp */
                    CHECK_ABS(pol[1], 1.0, 8 * DBL_EPSILON, "%s %s %.1f: TIR", g->name, sn,
                              deg);
                    CHECK_ABS(pol[2] + fres[2] + sch[2], 0.0, 0.0, "%s %s %.1f: nothing through",
                              g->name, sn, deg);
                }
            }
            /* 2: Schlick exact at normal incidence */
            {
                lp_vec3 o, d;
                double pol[4], sch[4], r0 = (n - 1.0) / (n + 1.0);
                plate_ray(0.0, &o, &d);
                natural(lens, o, d, LAMBDA_D, LP_MODE_POLARIZED, 3, 0.7, pol);
                natural(lens, o, d, LAMBDA_D, LP_MODE_SCHLICK, 3, 0.0, sch);
                CHECK_ABS(sch[1] - pol[1], 0.0, 1e-16, "%s %s: schlick error at 0 deg", g->name,
                          sn);
                CHECK_REL(pol[1], r0 * r0, 1e-14, "%s %s: R0", g->name, sn);
            }
            lp_lens_destroy(lens);
        }
    }
}

/* 3 (chain): the k-th ray of a plate, k = 2..12, at 60 deg. */
static void check_plate_chain(void)
{
    double n = sellmeier_n(&GLASSES[0], LAMBDA_D), deg = 60.0;
    lp_lens *lens = plate("N-BK7", 0);
    lp_vec3 o, d;
    double pol[13], fres[13], Rs, Rp, ct, last = 0.0;
    if (!lens)
        return;
    plate_ray(deg, &o, &d);
    natural(lens, o, d, LAMBDA_D, LP_MODE_POLARIZED, 12, 1.1, pol);
    natural(lens, o, d, LAMBDA_D, LP_MODE_FRESNEL, 12, 0.0, fres);
    fresnel(deg * DEG, 1.0, n, &Rs, &Rp, &ct);
    double R = 0.5 * (Rs + Rp);
    for (int k = 2; k <= 12; k++) {
        double wp = 0.5 * ((1 - Rs) * (1 - Rs) * pow(Rs, k - 2) + (1 - Rp) * (1 - Rp) * pow(Rp, k - 2));
        double wf = (1 - R) * (1 - R) * pow(R, k - 2);
        CHECK_REL(pol[k], wp, 1e-12, "plate chain: polarized depth %d", k);
        CHECK_REL(fres[k], wf, 1e-12, "plate chain: fresnel depth %d", k);
        double rel = fabs(wf - wp) / wp;
        if (k >= 3)
            CHECK(rel > last, "plate chain: fresnel's relative error grows at depth %d", k);
        last = rel;
    }
    CHECK(last > 0.9, "plate chain: at depth 12 fresnel is off by %.3g (> 90 %%)", last);
    lp_lens_destroy(lens);
}

/* 4: Schlick's error against the angle. */
static void check_schlick_shape(void)
{
    for (int gi = 0; gi < 2; gi++) {
        const sellmeier *g = &GLASSES[gi];
        double n = sellmeier_n(g, LAMBDA_D), crit = asin(1.0 / n) / DEG;
        lp_lens *ag = plate(g->name, 0), *ga = plate(g->name, 1);
        double best = 0.0, at = 0.0, prev = -1.0;
        if (!ag || !ga) {
            lp_lens_destroy(ag);
            lp_lens_destroy(ga);
            continue;
        }
        /* n1 < n2: grows from 0 deg to 80 deg, peaks beyond 80 deg */
        for (int i = 0; i <= 899; i++) {
            double deg = 0.1 * i, pol[2], sch[2];
            lp_vec3 o, d;
            plate_ray(deg, &o, &d);
            natural(ag, o, d, LAMBDA_D, LP_MODE_POLARIZED, 1, 0.2, pol);
            natural(ag, o, d, LAMBDA_D, LP_MODE_SCHLICK, 1, 0.0, sch);
            double e = fabs(sch[1] - pol[1]);
            /* below ~75 deg Schlick reflects too little, more and more;
             * then the error changes sign and peaks near grazing */
            if (deg <= 60.0 && i % 50 == 0 && i > 0) {
                CHECK(e > prev, "%s air->glass: schlick error grows (%.1f deg: %.3g)", g->name,
                      deg, e);
                prev = e;
            }
            if (i > 0 && i % 50 == 0)
                CHECK(deg <= 70.0 ? sch[1] < pol[1] : deg >= 80.0 ? sch[1] > pol[1] : 1,
                      "%s air->glass %.1f deg: schlick %s", g->name, deg,
                      deg <= 70.0 ? "too low" : "too high");
            if (e > best) {
                best = e;
                at = deg;
            }
        }
        CHECK(at > 80.0 && at < 89.9, "%s air->glass: schlick error peaks near grazing (%.1f deg)",
              g->name, at);
        /* n1 > n2: the same curve, at the glass angle */
        double best2 = 0.0, at2 = 0.0;
        for (int i = 1; i <= 899; i++) {
            double deg = 0.1 * i, pol[2], sch[2];
            lp_vec3 o, d;
            plate_ray(deg, &o, &d);
            natural(ga, o, d, LAMBDA_D, LP_MODE_POLARIZED, 1, 0.2, pol);
            natural(ga, o, d, LAMBDA_D, LP_MODE_SCHLICK, 1, 0.0, sch);
            double e = fabs(sch[1] - pol[1]);
            if (e > best2) {
                best2 = e;
                at2 = deg;
            }
            double s_air = n * sin(deg * DEG);
            if (s_air < 0.999) {
                double air_deg = asin(s_air) / DEG, pa[2], sa[2];
                plate_ray(air_deg, &o, &d);
                natural(ag, o, d, LAMBDA_D, LP_MODE_POLARIZED, 1, 0.2, pa);
                natural(ag, o, d, LAMBDA_D, LP_MODE_SCHLICK, 1, 0.0, sa);
                CHECK_ABS(e, fabs(sa[1] - pa[1]), 1e-14,
                          "%s: schlick error glass->air at %.1f deg = air->glass at %.4f deg",
                          g->name, deg, air_deg);
            }
        }
        CHECK(at2 < crit && at2 > crit - 1.0,
              "%s glass->air: schlick error peaks just below the critical angle (%.1f, crit %.2f)",
              g->name, at2, crit);
        CHECK(fabs(best2 - best) < 0.002,
              "%s: schlick's peak error is the same both ways (%.4f vs %.4f)", g->name, best2,
              best);
        lp_lens_destroy(ag);
        lp_lens_destroy(ga);
    }
}

/* ------------------------------------------------------------------ */
/* 5: a meridional ray through a biconvex lens, in 2-D                  */
/* ------------------------------------------------------------------ */

/* The lens R1 = 30, R2 = -30, t = 10, D = 25 in the (y, z) plane: the
 * intersection of the ball about (0, 30) and the ball about (0, -20), both
 * of radius 30, and the slab |y| <= 12.5. */
static const double LR = 30.0, LT = 10.0, LD = 25.0;

typedef struct v2 {
    double y, z;
} v2;

/* Larger root t of |p + t d - c| = r (p inside the ball). */
static double ball_exit(v2 p, v2 d, v2 c, double r)
{
    double qy = p.y - c.y, qz = p.z - c.z;
    double b = qy * d.y + qz * d.z, cc = qy * qy + qz * qz - r * r;
    return -b + sqrt(b * b - cc);
}

/* Depth-k powers of a meridional ray: s, p and fresnel chains.  Returns 0,
 * or -1 when the ray does not enter through the front cap. */
static int meridional(double n, v2 o, v2 d, double S[13], double P[13], double F[13])
{
    v2 c1 = {0.0, LR}, c2 = {0.0, LT - LR};
    for (int k = 0; k <= 12; k++)
        S[k] = P[k] = F[k] = 0.0;
    /* entry on the front ball: smaller root */
    double qy = o.y - c1.y, qz = o.z - c1.z;
    double b = qy * d.y + qz * d.z, cc = qy * qy + qz * qz - LR * LR;
    double t = -b - sqrt(b * b - cc);
    v2 p = {o.y + t * d.y, o.z + t * d.z};
    if (!(b * b - cc > 0.0) || fabs(p.y) > 0.5 * LD ||
        hypot(p.y - c2.y, p.z - c2.z) > LR)
        return -1;
    v2 nrm = {(p.y - c1.y) / LR, (p.z - c1.z) / LR}; /* outward */
    double ci = -(d.y * nrm.y + d.z * nrm.z), Rs, Rp, ct;
    fresnel(acos(ci), 1.0, n, &Rs, &Rp, &ct);
    S[1] = Rs;
    P[1] = Rp;
    F[1] = 0.5 * (Rs + Rp);
    double s = 1.0 - Rs, pp = 1.0 - Rp, f = 1.0 - F[1], eta = 1.0 / n;
    /* refracted: eta d + (eta ci - ct) nrm, nrm facing the incoming light */
    d.y = eta * d.y + (eta * ci - ct) * nrm.y;
    d.z = eta * d.z + (eta * ci - ct) * nrm.z;
    for (int k = 2; k <= 12; k++) {
        double t1 = ball_exit(p, d, c1, LR), t2 = ball_exit(p, d, c2, LR);
        double tb = t1 < t2 ? t1 : t2;
        int back = t2 < t1;
        v2 q = {p.y + tb * d.y, p.z + tb * d.z};
        if (fabs(q.y) > 0.5 * LD)
            return 0; /* the rim: absorbed */
        /* the lens lies inside both balls: the outward normal of either
         * cap points away from its ball's centre */
        v2 c = back ? c2 : c1;
        nrm.y = (q.y - c.y) / LR;
        nrm.z = (q.z - c.z) / LR;
        double cosi = d.y * nrm.y + d.z * nrm.z;
        fresnel(acos(cosi > 1.0 ? 1.0 : cosi), n, 1.0, &Rs, &Rp, &ct);
        double R = 0.5 * (Rs + Rp);
        S[k] = s * (1.0 - Rs);
        P[k] = pp * (1.0 - Rp);
        F[k] = f * (1.0 - R);
        s *= Rs;
        pp *= Rp;
        f *= R;
        d.y -= 2.0 * cosi * nrm.y;
        d.z -= 2.0 * cosi * nrm.z;
        p = q;
    }
    return 0;
}

static void check_meridional(void)
{
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_error err;
    memset(&err, 0, sizeof err);
    lp_lens_desc_init(&desc);
    desc.radius1 = LR;
    desc.radius2 = -LR;
    desc.thickness = LT;
    desc.diameter = LD;
    CHECK(lp_glass_builtin("N-BK7", &desc.glass, &err) == LP_OK, "N-BK7: %s", err.message);
    desc.glass.n_tau = 0; /* lossless */
    CHECK(lp_lens_create(&desc, &lens, &err) == LP_OK, "biconvex: %s", err.message);
    if (!lens)
        return;
    double n = sellmeier_n(&GLASSES[0], LAMBDA_D);
    static const double rays[][2] = {
        /* entry height, angle to the axis (deg) */
        {5.0, 0.0}, {8.0, 25.0}, {-3.0, 40.0}, {11.0, -30.0}, {2.0, 60.0}, {12.0, 10.0},
    };
    int compared = 0, grew = 0;
    for (size_t r = 0; r < sizeof rays / sizeof rays[0]; r++) {
        double a = rays[r][1] * DEG;
        v2 d = {sin(a), cos(a)};
        /* aim at the front cap point at height rays[r][0] */
        double h = rays[r][0], zc = LR - sqrt(LR * LR - h * h);
        v2 o = {h - 50.0 * d.y, zc - 50.0 * d.z};
        double S[13], P[13], F[13], pol[13], fres[13];
        CHECK(meridional(n, o, d, S, P, F) == 0, "meridional ray %zu enters the front cap", r);
        natural(lens, vec(0.0, o.y, o.z), vec(0.0, d.y, d.z), LAMBDA_D, LP_MODE_POLARIZED, 12,
                0.4, pol);
        natural(lens, vec(0.0, o.y, o.z), vec(0.0, d.y, d.z), LAMBDA_D, LP_MODE_FRESNEL, 12, 0.0,
                fres);
        double rel_first = -1.0, rel_last = -1.0;
        for (int k = 1; k <= 12; k++) {
            double wp = 0.5 * (S[k] + P[k]);
            CHECK_ABS(pol[k], wp, 1e-12 * (wp > 1e-3 ? wp : 1e-3) + 1e-300,
                      "meridional ray %zu: polarized depth %d", r, k);
            CHECK_ABS(fres[k], F[k], 1e-12 * (F[k] > 1e-3 ? F[k] : 1e-3) + 1e-300,
                      "meridional ray %zu: fresnel depth %d", r, k);
            if (wp > 0.0) {
                compared++;
                double rel = fabs(F[k] - wp) / wp;
                if (k == 1)
                    CHECK_ABS(rel, 0.0, 1e-14, "meridional ray %zu: one interface", r);
                if (k == 3)
                    rel_first = rel;
                rel_last = rel;
            }
        }
        if (rel_first > 0.0 && rel_last > rel_first)
            grew++;
    }
    CHECK(compared >= 30, "meridional rays: %d depths compared", compared);
    CHECK(grew >= 3, "meridional rays: fresnel's relative error grows with depth on %d rays", grew);
    lp_lens_destroy(lens);
}

/* ------------------------------------------------------------------ */
/* 5b: a skew ray through the same lens, with complex field vectors    */
/* ------------------------------------------------------------------ */

/* Skew rays turn the plane of incidence from node to node, so s and p mix
 * and only a vector trace gives the polarized powers.  Field E (complex
 * 3-vector); at a node with unit normal nv facing the incoming light,
 * s = d x nv normalized, the p vector of each wave is k x s (Born & Wolf
 * amplitudes, transmission power-normalized), under TIR cos_t = i kappa.
 * Powers only, so the common propagation phase is left out. */
typedef struct cv3 {
    double complex x, y, z;
} cv3;

static lp_vec3 v_add(lp_vec3 a, lp_vec3 b) { return vec(a.x + b.x, a.y + b.y, a.z + b.z); }
static lp_vec3 v_scale(double k, lp_vec3 a) { return vec(k * a.x, k * a.y, k * a.z); }
static double v_dot(lp_vec3 a, lp_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static lp_vec3 v_cross(lp_vec3 a, lp_vec3 b)
{
    return vec(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static lp_vec3 v_unit(lp_vec3 a) { return v_scale(1.0 / sqrt(v_dot(a, a)), a); }
static double complex c_dot(cv3 e, lp_vec3 v) { return e.x * v.x + e.y * v.y + e.z * v.z; }
static cv3 c_comb(double complex a, lp_vec3 u, double complex b, lp_vec3 v)
{
    cv3 e = {a * u.x + b * v.x, a * u.y + b * v.y, a * u.z + b * v.z};
    return e;
}
static double c_power(cv3 e)
{
    return creal(e.x * conj(e.x) + e.y * conj(e.y) + e.z * conj(e.z));
}

/* One node: reflected field and direction; transmitted ones unless TIR. */
static int vector_node(cv3 E, lp_vec3 d, lp_vec3 nv, double n1, double n2, cv3 *Er, lp_vec3 *dr,
                       cv3 *Et, lp_vec3 *dt)
{
    double ci = -v_dot(d, nv), eta = n1 / n2, st2 = eta * eta * (1.0 - ci * ci);
    lp_vec3 sv = v_unit(v_cross(d, nv));
    double complex Es = c_dot(E, sv), Ep = c_dot(E, v_cross(d, sv)), ct, rs, rp;
    *dr = v_add(d, v_scale(2.0 * ci, nv));
    int tir = st2 >= 1.0;
    ct = tir ? I * sqrt(st2 - 1.0) : sqrt(1.0 - st2);
    rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    *Er = c_comb(rs * Es, sv, rp * Ep, v_cross(*dr, sv));
    if (tir)
        return 0;
    double ctr = creal(ct);
    *dt = v_add(v_scale(eta, d), v_scale(eta * ci - ctr, nv));
    *Et = c_comb(sqrt(1.0 - creal(rs * conj(rs))) * Es, sv,
                 sqrt(1.0 - creal(rp * conj(rp))) * Ep, v_cross(*dt, sv));
    return 1;
}

/* Larger (exit) or smaller (entry) root of |p + t d - c| = LR. */
static double ball_root(lp_vec3 p, lp_vec3 d, lp_vec3 c, int exit_root)
{
    lp_vec3 q = v_add(p, v_scale(-1.0, c));
    double b = v_dot(q, d), cc = v_dot(q, q) - LR * LR, disc = b * b - cc;
    if (disc < 0.0)
        return NAN;
    return exit_root ? -b + sqrt(disc) : -b - sqrt(disc);
}

/* Depth-k powers of one linearly polarized ray of power |E|^2. */
static void vector_trace(double n, lp_vec3 o, lp_vec3 d, cv3 E, double P[13])
{
    lp_vec3 c1 = vec(0, 0, LR), c2 = vec(0, 0, LT - LR), p, nv, dr, dt;
    cv3 Er, Et;
    for (int k = 0; k <= 12; k++)
        P[k] = 0.0;
    double t = ball_root(o, d, c1, 0);
    p = v_add(o, v_scale(t, d));
    nv = v_scale(1.0 / LR, v_add(p, v_scale(-1.0, c1)));
    vector_node(E, d, nv, 1.0, n, &Er, &dr, &Et, &dt);
    P[1] = c_power(Er);
    E = Et;
    d = dt;
    for (int k = 2; k <= 12; k++) {
        double t1 = ball_root(p, d, c1, 1), t2 = ball_root(p, d, c2, 1);
        double a = d.x * d.x + d.y * d.y, b = p.x * d.x + p.y * d.y;
        double cc = p.x * p.x + p.y * p.y - 0.25 * LD * LD;
        double t3 = a > 0.0 ? (-b + sqrt(b * b - a * cc)) / a : INFINITY;
        double tm = fmin(t1, t2);
        if (t3 < tm)
            return; /* the rim */
        lp_vec3 c = t1 < t2 ? c1 : c2;
        p = v_add(p, v_scale(tm, d));
        nv = v_scale(-1.0 / LR, v_add(p, v_scale(-1.0, c))); /* facing the light */
        if (vector_node(E, d, nv, n, 1.0, &Er, &dr, &Et, &dt))
            P[k] = c_power(Et);
        E = Er;
        d = dr;
    }
}

static void check_skew(void)
{
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_error err;
    memset(&err, 0, sizeof err);
    lp_lens_desc_init(&desc);
    desc.radius1 = LR;
    desc.radius2 = -LR;
    desc.thickness = LT;
    desc.diameter = LD;
    CHECK(lp_glass_builtin("N-BK7", &desc.glass, &err) == LP_OK, "N-BK7: %s", err.message);
    desc.glass.n_tau = 0;
    CHECK(lp_lens_create(&desc, &lens, &err) == LP_OK, "biconvex: %s", err.message);
    if (!lens)
        return;
    double n = sellmeier_n(&GLASSES[0], LAMBDA_D);
    /* the ray of model_limits' sample whose depth-12 power fresnel gets
     * most wrong, and a second, milder one */
    static const double rays[2][6] = {
        {16.740061848363588, -89.418761706621481, -42.723268630200891, -0.22911003369551841,
         0.87101238155349636, 0.43456417666501795},
        {-60.0, 20.0, -60.0, 0.6, -0.2, 0.7745966692414834},
    };
    for (int r = 0; r < 2; r++) {
        lp_vec3 o = vec(rays[r][0], rays[r][1], rays[r][2]);
        lp_vec3 d = v_unit(vec(rays[r][3], rays[r][4], rays[r][5]));
        lp_vec3 u = v_unit(v_cross(d, vec(0, 0, 1))), w = v_cross(d, u);
        double Pa[13], Pb[13], pol[13], fres[13];
        cv3 Eu = c_comb(sqrt(0.5), u, 0.0, u), Ew = c_comb(sqrt(0.5), w, 0.0, w);
        vector_trace(n, o, d, Eu, Pa);
        vector_trace(n, o, d, Ew, Pb);
        natural(lens, o, d, LAMBDA_D, LP_MODE_POLARIZED, 12, 0.9, pol);
        natural(lens, o, d, LAMBDA_D, LP_MODE_FRESNEL, 12, 0.0, fres);
        int deep = 0;
        for (int k = 1; k <= 12; k++) {
            double want = Pa[k] + Pb[k];
            CHECK_ABS(pol[k], want, 1e-10 * want + 1e-300, "skew ray %d: polarized depth %d", r,
                      k);
            deep += want > 0.0;
        }
        CHECK(deep >= 6, "skew ray %d: %d depths reached", r, deep);
        if (r == 0)
            CHECK(fres[12] > 1e5 * pol[12],
                  "skew ray 0: at depth 12 fresnel gives %.3g, %.3g times the polarized power",
                  fres[12], fres[12] / pol[12]);
    }
    lp_lens_destroy(lens);
}

/* ------------------------------------------------------------------ */
/* 6: the command                                                      */
/* ------------------------------------------------------------------ */

/* Run the tool with argv[1..] = args (NULL-terminated).  When it cannot
 * be run: status -1, out and err NULL. */
static tp_result run_tool(const char *const *args)
{
    tp_result r;
    tp_run(TOOL, args, NULL, &r);
    return r;
}

/* A CSV table: the header's column names and the rows' fields. */
typedef struct table {
    char *text;
    int ncol, nrow;
    char **cell; /* nrow * ncol, row-major; header is row -1 (names) */
    char **name;
} table;

static int table_read(const char *path, table *t)
{
    memset(t, 0, sizeof *t);
    t->text = tf_read(path, NULL);
    if (!t->text)
        return -1;
    int lines = 0;
    for (char *p = t->text; *p; p++)
        lines += *p == '\n';
    char *line = t->text;
    char *nl = strchr(line, '\n');
    if (!nl)
        return -1;
    *nl = '\0';
    t->ncol = 1;
    for (char *p = line; *p; p++)
        t->ncol += *p == ',';
    t->name = calloc((size_t)t->ncol, sizeof *t->name);
    t->cell = calloc((size_t)lines * (size_t)t->ncol, sizeof *t->cell);
    if (!t->name || !t->cell)
        return -1;
    char *f = line;
    for (int c = 0; c < t->ncol; c++) {
        char *comma = strchr(f, ',');
        if (comma)
            *comma = '\0';
        t->name[c] = f;
        f = comma ? comma + 1 : f + strlen(f);
    }
    line = nl + 1;
    while (*line) {
        nl = strchr(line, '\n');
        if (nl)
            *nl = '\0';
        int c = 0;
        f = line;
        for (; c < t->ncol; c++) {
            char *comma = strchr(f, ',');
            if (comma)
                *comma = '\0';
            t->cell[(size_t)t->nrow * (size_t)t->ncol + (size_t)c] = f;
            if (!comma) {
                c++;
                break;
            }
            f = comma + 1;
        }
        if (c != t->ncol)
            return -1; /* a row with too few fields */
        t->nrow++;
        if (!nl)
            break;
        line = nl + 1;
    }
    return 0;
}

static void table_free(table *t)
{
    free(t->text);
    free(t->cell);
    free(t->name);
}

static int col(const table *t, const char *name)
{
    for (int c = 0; c < t->ncol; c++)
        if (strcmp(t->name[c], name) == 0)
            return c;
    CHECK(0, "table has no column '%s'", name);
    return 0;
}

static const char *cell(const table *t, int r, int c) { return t->cell[(size_t)r * (size_t)t->ncol + (size_t)c]; }

/* A number, or NaN for an empty field. */
static double num(const table *t, int r, int c)
{
    const char *s = cell(t, r, c);
    char *end;
    if (*s == '\0')
        return NAN;
    if (strcmp(s, "inf") == 0)
        return INFINITY;
    double v = strtod(s, &end);
    return *end ? NAN : v;
}

static void check_png(const char *dir, const char *name)
{
    char path[512];
    size_t len = 0;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    char *s = tf_read(path, &len);
    long size = (long)len;
    CHECK(s != NULL, "%s exists", path);
    if (!s)
        return;
    CHECK(size > 8 && memcmp(s, "\x89PNG\r\n\x1a\n", 8) == 0, "%s is a PNG", name);
    CHECK(size < 100 * 1024, "%s is under 100 KB (%ld bytes)", name, size);
    free(s);
}

/* Thresholds of the closed forms on the tool's 0.1 deg grid: the largest
 * angle up to which |rel| < 1 % at every angle. */
static double closed_threshold(double n1, double n2, int depth, int model /* 1 fres, 2 sch */)
{
    double ok = -1.0;
    for (int i = 0; i < 900; i++) {
        plate_powers p = plate_closed_form(0.1 * i * DEG, n1, n2);
        double ref = p.pol[depth], got = model == 1 ? p.fres[depth] : p.sch[depth];
        double rel = got == ref ? 0.0 : ref != 0.0 ? fabs(got - ref) / ref : INFINITY;
        if (!(rel < 0.01))
            break;
        ok = 0.1 * i;
    }
    return ok;
}

static void check_command_usage(void)
{
    const char *help[] = {"--help", NULL};
    tp_result r = run_tool(help);
    CHECK(r.status == 0, "--help exits 0 (got %d)", r.status);
    if (r.out) {
        CHECK(strstr(r.out, "usage: model_limits") != NULL, "--help: usage line");
        CHECK(strstr(r.out, "(Rs-Rp)^2/4") != NULL, "--help: states the two-interface gap");
        CHECK(strstr(r.out, "air gap") != NULL, "--help: explains the glass->air setup");
        CHECK(strstr(r.out, "642.4") != NULL, "--help: defines the rgb model");
        CHECK(strstr(r.out, "ybar") != NULL, "--help: defines the spectral weighting");
    }
    tp_result_free(&r);
    const char *bad[] = {"--no-such-option", NULL};
    r = run_tool(bad);
    CHECK(r.status == 2, "bad option exits 2 (got %d)", r.status);
    if (r.out && r.err) {
        CHECK(r.out[0] == '\0', "bad option: nothing on stdout");
        char *nl = strchr(r.err, '\n');
        CHECK(nl && nl[1] == '\0' && strncmp(r.err, "model_limits: ", 14) == 0,
              "bad option: one line on stderr: %s", r.err);
    }
    tp_result_free(&r);
    const char *bad2[] = {"--rays", "0", NULL};
    r = run_tool(bad2);
    CHECK(r.status == 2, "--rays 0 exits 2 (got %d)", r.status);
    tp_result_free(&r);
}

static void check_command_mono(void)
{
    char dir[512], path[600];
    snprintf(dir, sizeof dir, "%s/model_limits_mono", LP_TEST_TMP);
    const char *args[] = {"--out", dir, "--lambda", "587.5618", "--rays", "40", NULL};
    tp_result r = run_tool(args);
    CHECK(r.status == 0, "monochromatic run exits 0 (got %d): %s", r.status, r.err ? r.err : "");
    CHECK(r.out && strstr(r.out, "up to") != NULL, "monochromatic run prints the summary");
    tp_result_free(&r);
    if (r.status != 0)
        return;
    static const char *const pngs[] = {"angle_air_glass.png", "angle_glass_air.png", "depth.png",
                                       "glass.png"};
    for (int i = 0; i < 4; i++)
        check_png(dir, pngs[i]);

    /* angle.csv against the closed forms */
    table t;
    snprintf(path, sizeof path, "%s/angle.csv", dir);
    CHECK(table_read(path, &t) == 0, "%s: readable CSV", path);
    if (t.nrow > 0) {
        int cg = col(&t, "glass"), cs = col(&t, "setup"), ca = col(&t, "angle_deg");
        int cd = col(&t, "depth"), cp = col(&t, "polarized"), cf = col(&t, "fresnel");
        int csch = col(&t, "schlick"), crgb = col(&t, "rgb"), cef = col(&t, "err_fresnel");
        int ces = col(&t, "err_schlick"), crf = col(&t, "rel_fresnel");
        int rows = 0;
        CHECK(t.nrow == 2 * 2 * 92 * 3, "angle.csv: %d rows, want 2 glasses x 2 setups x 92 "
              "angles x 3 depths", t.nrow);
        for (int i = 0; i < t.nrow; i++) {
            int gi = strcmp(cell(&t, i, cg), "N-SF11") == 0;
            int gap = strcmp(cell(&t, i, cs), "glass_air") == 0;
            double n = sellmeier_n(&GLASSES[gi], LAMBDA_D);
            double deg = num(&t, i, ca);
            int k = (int)num(&t, i, cd);
            if (k < 1 || k > 3 || !isfinite(deg))
                continue;
            plate_powers w = plate_closed_form(deg * DEG, gap ? n : 1.0, gap ? 1.0 : n);
            double pol = num(&t, i, cp), fres = num(&t, i, cf), sch = num(&t, i, csch);
            const char *what = cell(&t, i, cs);
            CHECK_ABS(pol, w.pol[k], 1e-13 + 1e-12 * w.pol[k], "angle.csv %s %s %.1f depth %d: "
                      "polarized", GLASSES[gi].name, what, deg, k);
            CHECK_ABS(fres, w.fres[k], 1e-13 + 1e-12 * w.fres[k], "angle.csv %s %s %.1f depth "
                      "%d: fresnel", GLASSES[gi].name, what, deg, k);
            CHECK_ABS(sch, w.sch[k], 1e-13 + 1e-12 * w.sch[k], "angle.csv %s %s %.1f depth %d: "
                      "schlick", GLASSES[gi].name, what, deg, k);
            CHECK(isnan(num(&t, i, crgb)), "angle.csv: rgb is empty in a monochromatic run");
            double ef = num(&t, i, cef), es = num(&t, i, ces);
            CHECK_ABS(ef, fres - pol, 1e-6 * fabs(fres - pol) + 1e-15,
                      "angle.csv row %d: err_fresnel = fresnel - polarized", i);
            CHECK_ABS(es, sch - pol, 1e-6 * fabs(sch - pol) + 1e-15,
                      "angle.csv row %d: err_schlick = schlick - polarized", i);
            if (k == 1) {
                CHECK_ABS(ef, 0.0, 1e-15, "angle.csv %s %s %.1f: fresnel's one-interface error",
                          GLASSES[gi].name, what, deg);
                if (deg == 0.0)
                    CHECK_ABS(es, 0.0, 1e-15, "angle.csv %s %s: schlick error at 0 deg",
                              GLASSES[gi].name, what);
            }
            if (k == 2 && pol > 0.0) {
                double rf = num(&t, i, crf);
                CHECK_ABS(rf, (fres - pol) / pol, 1e-6 * fabs((fres - pol) / pol) + 1e-15,
                          "angle.csv row %d: rel_fresnel", i);
                CHECK(ef <= 1e-15, "angle.csv %s %s %.1f: fresnel under-transmits two interfaces",
                      GLASSES[gi].name, what, deg);
            }
            rows++;
        }
        CHECK(rows == t.nrow, "angle.csv: %d of %d rows understood", rows, t.nrow);
    }
    table_free(&t);

    /* glass.csv: maxima and thresholds of the closed forms */
    snprintf(path, sizeof path, "%s/glass.csv", dir);
    CHECK(table_read(path, &t) == 0, "%s: readable CSV", path);
    if (t.nrow > 0) {
        int cg = col(&t, "glass"), cc = col(&t, "comparison"), cq = col(&t, "quantity");
        int cm = col(&t, "model"), cmax = col(&t, "max_abs_err"), cok = col(&t, "ok_1pct_up_to");
        int cnd = col(&t, "n_d");
        double fres_t2_max[2] = {0, 0};
        int seen = 0;
        for (int i = 0; i < t.nrow; i++) {
            int gi = strcmp(cell(&t, i, cg), "N-SF11") == 0;
            double n = sellmeier_n(&GLASSES[gi], LAMBDA_D);
            const char *cmp = cell(&t, i, cc), *q = cell(&t, i, cq), *m = cell(&t, i, cm);
            CHECK_ABS(num(&t, i, cnd), n, 6e-6, "glass.csv: n_d of %s", GLASSES[gi].name);
            if (strcmp(cmp, "biconvex") == 0)
                continue;
            int gap = strcmp(cmp, "glass_air") == 0;
            int k = q[0] == 'R' && q[1] == '1' ? 1 : q[1] == '2' ? 2 : 3;
            int model = strcmp(m, "fresnel") == 0 ? 1 : strcmp(m, "schlick") == 0 ? 2 : 0;
            if (!model)
                continue;
            double n1 = gap ? n : 1.0, n2 = gap ? 1.0 : n;
            double want_ok = closed_threshold(n1, n2, k, model);
            double want_max = 0.0;
            for (int a = 0; a < 900; a++) {
                plate_powers p = plate_closed_form(0.1 * a * DEG, n1, n2);
                double e = fabs((model == 1 ? p.fres[k] : p.sch[k]) - p.pol[k]);
                if (e > want_max)
                    want_max = e;
            }
            double got_ok = num(&t, i, cok);
            if (want_ok >= 89.85)
                CHECK(got_ok >= 89.85, "glass.csv %s %s %s %s: within 1 %% everywhere",
                      GLASSES[gi].name, cmp, q, m);
            else
                CHECK_ABS(got_ok, want_ok, 0.101, "glass.csv %s %s %s %s: 1 %% threshold",
                          GLASSES[gi].name, cmp, q, m);
            if (model == 1 && k == 1)
                CHECK_ABS(num(&t, i, cmax), 0.0, 1e-15, "glass.csv %s %s: fresnel R1 exact",
                          GLASSES[gi].name, cmp);
            else
                CHECK_ABS(num(&t, i, cmax), want_max, 1e-9 + 1e-6 * want_max,
                          "glass.csv %s %s %s %s: max |err|", GLASSES[gi].name, cmp, q, m);
            if (model == 1 && k == 2 && !gap)
                fres_t2_max[gi] = num(&t, i, cmax);
            seen++;
        }
        CHECK(seen == 2 * 2 * 3 * 2, "glass.csv: %d plate rows for fresnel/schlick", seen);
        CHECK(fres_t2_max[1] > fres_t2_max[0],
              "glass.csv: the higher index (N-SF11) has the larger two-interface fresnel error "
              "(%.4f vs %.4f)", fres_t2_max[1], fres_t2_max[0]);
    }
    table_free(&t);

    /* depth.csv: the one-interface facts over random rays */
    snprintf(path, sizeof path, "%s/depth.csv", dir);
    CHECK(table_read(path, &t) == 0, "%s: readable CSV", path);
    if (t.nrow > 0) {
        int cg = col(&t, "glass"), cd = col(&t, "depth"), cm = col(&t, "model");
        int cmaxa = col(&t, "max_abs_err"), cmean = col(&t, "mean_rel_err");
        int cmed = col(&t, "median_rel_err"), cmax = col(&t, "max_rel_err");
        int crays = col(&t, "rays"), cwith = col(&t, "rays_with_output");
        CHECK(t.nrow == 2 * 12 * 3, "depth.csv: %d rows, want 2 glasses x 12 depths x 3 models",
              t.nrow);
        for (int i = 0; i < t.nrow; i++) {
            int gi = strcmp(cell(&t, i, cg), "N-SF11") == 0;
            int k = (int)num(&t, i, cd);
            const char *m = cell(&t, i, cm);
            double n = sellmeier_n(&GLASSES[gi], LAMBDA_D);
            CHECK(num(&t, i, crays) == 40.0, "depth.csv: 40 rays");
            if (strcmp(m, "rgb") == 0)
                continue;
            if (num(&t, i, cwith) > 0) {
                CHECK(num(&t, i, cmed) <= num(&t, i, cmax) && num(&t, i, cmean) <= num(&t, i, cmax),
                      "depth.csv row %d: median and mean <= max", i);
            }
            if (k != 1)
                continue;
            CHECK(num(&t, i, cwith) == 40.0, "depth.csv: every ray has an external reflection");
            if (strcmp(m, "fresnel") == 0) {
                CHECK_ABS(num(&t, i, cmaxa), 0.0, 1e-15, "depth.csv %s: fresnel's depth-1 error",
                          GLASSES[gi].name);
            } else {
                /* schlick's depth-1 error of any ray is one interface's */
                double bound = 0.0;
                for (int a = 0; a < 9000; a++) {
                    plate_powers p = plate_closed_form(0.01 * a * DEG, 1.0, n);
                    double rel = fabs(p.sch[1] - p.pol[1]) / p.pol[1];
                    if (rel > bound)
                        bound = rel;
                }
                CHECK(num(&t, i, cmax) <= bound * (1.0 + 1e-6),
                      "depth.csv %s: schlick depth-1 error %.6g within one interface's max %.6g",
                      GLASSES[gi].name, num(&t, i, cmax), bound);
            }
        }
    }
    table_free(&t);
}

static void check_command_spectral(void)
{
    char dir[512], path[600];
    snprintf(dir, sizeof dir, "%s/model_limits_spectral", LP_TEST_TMP);
    const char *args[] = {"--out", dir, "--rays", "20", NULL};
    tp_result r = run_tool(args);
    CHECK(r.status == 0, "spectral run exits 0 (got %d): %s", r.status, r.err ? r.err : "");
    tp_result_free(&r);
    if (r.status != 0)
        return;
    table t;
    snprintf(path, sizeof path, "%s/angle.csv", dir);
    CHECK(table_read(path, &t) == 0, "%s: readable CSV", path);
    if (t.nrow > 0) {
        int ca = col(&t, "angle_deg"), cd = col(&t, "depth"), cp = col(&t, "polarized");
        int cf = col(&t, "fresnel"), crgb = col(&t, "rgb"), cef = col(&t, "err_fresnel");
        int ces = col(&t, "err_schlick"), cer = col(&t, "err_rgb");
        for (int i = 0; i < t.nrow; i++) {
            int k = (int)num(&t, i, cd);
            double deg = num(&t, i, ca);
            CHECK(isfinite(num(&t, i, crgb)), "spectral angle.csv row %d: rgb present", i);
            if (k == 1) {
                /* a weighted sum of 80 equal terms: rounding only */
                CHECK_ABS(num(&t, i, cef), 0.0, 4e-15, "spectral row %d: fresnel R1 exact", i);
                if (deg == 0.0) {
                    CHECK_ABS(num(&t, i, ces), 0.0, 1e-15, "spectral row %d: schlick at 0 deg", i);
                    /* rgb at normal incidence: only the 3-wavelength sampling */
                    CHECK(fabs(num(&t, i, cer)) > 0.0 && fabs(num(&t, i, cer)) < 1e-3,
                          "spectral row %d: rgb's normal-incidence error is small, not 0 (%g)",
                          i, num(&t, i, cer));
                }
            }
            if (k == 2)
                CHECK(num(&t, i, cp) >= num(&t, i, cf) - 1e-15,
                      "spectral row %d: polarized transmits at least fresnel", i);
        }
    }
    table_free(&t);
    static const char *const pngs[] = {"angle_air_glass.png", "angle_glass_air.png", "depth.png",
                                       "glass.png"};
    for (int i = 0; i < 4; i++)
        check_png(dir, pngs[i]);
}

int main(void)
{
    check_plates();
    check_plate_chain();
    check_schlick_shape();
    check_meridional();
    check_skew();
    check_command_usage();
    check_command_mono();
    check_command_spectral();
    return check_finish("test_model_limits");
}
