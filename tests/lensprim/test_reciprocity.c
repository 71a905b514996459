/* test_reciprocity.c -- forward/backward reciprocity on random paths.
 *
 * For a random lens and a view ray V (origin outside, direction d),
 * lp_backward_build gives the query rays.  For each query (origin Q,
 * direction u), light arriving along -u into Q with a random linear
 * payload is
 *   (a) gathered with lp_backward_gather, and
 *   (b) traced forward with lp_trace_forward from a point just outside
 *       the lens on the query ray (Q + s u, direction -u);
 * the forward ray of the same depth (path bits reversed) must leave at
 * V's entry point along -d, and both must carry the same intensity
 * (1e-10 relative) and the same complex field sum over TIR parts of
 * sqrt(I) vp exp(i Phi), Phi = 2 pi op/lambda - pi kphi + phase (1e-8).
 * Both are also compared with the exact field computed here: the view
 * chain traced in ref_real (binary128 where available), and the light
 * carried back along it by Fresnel's amplitude equations (Born & Wolf,
 * p = k x s basis, complex TIR coefficients for exp(-i w t)), with n*s
 * propagation phase and Beer-Lambert absorption of a hand-made glass
 * (tau flat in lambda).  fresnel and schlick modes compare intensities,
 * also with the node product of (Rs+Rp)/2 or Schlick's law written here.
 * The power of each gather alone (lp_backward_gather_power_many of the
 * same view ray built with LP_BACKWARD_POWER: the Jones matrices of its
 * way) is compared with the gather's rays (1e-12) and the exact chain's
 * (1e-10), TIR paths among them.
 *
 * Paths that are ill-conditioned in double precision are not compared
 * (and counted): a node within 1e-6 x size of a cap's edge circle, an
 * incidence or refraction cosine below 0.02, a refraction sine within
 * 1e-3 of 1 (near the critical angle), or an angular amplification of
 * the reverse path above 1e4 (rounding of 1e-16 then grows past 1e-12).
 * Fixed-seed splitmix64; messages name the seed, lens, view ray, depth.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include "lensprim.h"
#include "ref_real.h"

/* ------------------------------------------------------------------ */
/* small helpers                                                       */
/* ------------------------------------------------------------------ */

#include "lens_reference.h"

/* ------------------------------------------------------------------ */
/* optics written here: refraction, Fresnel amplitudes, Jones transport */
/* ------------------------------------------------------------------ */

#include <complex.h>

typedef ref_complex lcx;
typedef struct { lcx x, y, z; } cv3;

static cv3 cv_from(lv3 a) { cv3 r = {a.x, a.y, a.z}; return r; }
static lcx cv_dot_real(cv3 a, lv3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static cv3 cv_comb(lcx s, lv3 a, lcx p, lv3 b)
{
    cv3 r = {s * a.x + p * b.x, s * a.y + p * b.y, s * a.z + p * b.z};
    return r;
}
static cv3 cv_scale(cv3 a, lcx s) { cv3 r = {a.x * s, a.y * s, a.z * s}; return r; }
static cv3 cv_add(cv3 a, cv3 b) { cv3 r = {a.x + b.x, a.y + b.y, a.z + b.z}; return r; }
static ref_real cv_norm2(cv3 a)
{
    return ref_creal(a.x * ref_conj(a.x) + a.y * ref_conj(a.y) + a.z * ref_conj(a.z));
}

/* Snell: d hits a surface with (either-sided) normal n from index n1 into
 * n2; 0 under TIR. */

/* Born & Wolf amplitudes for the basis s, p = k x s of each wave; time
 * dependence exp(-i w t), so under TIR n2 cos_t = +i sqrt(n1^2 sin^2 - n2^2). */
typedef struct {
    int tir;
    lcx rs, rp;
    ref_real ts, tp; /* power-normalized: ts^2 = 1 - |rs|^2 */
    ref_real Rs, Rp, ct;
} fres;

static fres fresnel(ref_real ci, ref_real n1, ref_real n2)
{
    fres f;
    ref_real st2 = (n1 / n2) * (n1 / n2) * (1 - ci) * (1 + ci);
    if (st2 >= 1) {
        ref_real q = ref_sqrt(n1 * n1 * (1 - ci) * (1 + ci) - n2 * n2);
        f.tir = 1;
        f.rs = (n1 * ci - I * q) / (n1 * ci + I * q);
        f.rp = (n2 * n2 * ci - I * n1 * q) / (n2 * n2 * ci + I * n1 * q);
        f.ts = f.tp = 0;
        f.Rs = f.Rp = 1;
        f.ct = -1;
        return f;
    }
    ref_real ct = ref_sqrt(1 - st2);
    ref_real rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    ref_real rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    f.tir = 0;
    f.rs = rs;
    f.rp = rp;
    f.Rs = rs * rs;
    f.Rp = rp * rp;
    f.ts = ref_sqrt(1 - f.Rs);
    f.tp = ref_sqrt(1 - f.Rp);
    f.ct = ct;
    return f;
}

/* Reflectance of a node for a mode's unpolarized law (fresnel, schlick). */
static ref_real mode_R(lp_mode mode, ref_real ci, ref_real n1, ref_real n2)
{
    fres f = fresnel(ci, n1, n2);
    if (f.tir)
        return 1;
    if (mode == LP_MODE_SCHLICK) {
        ref_real R0 = ((n1 - n2) / (n1 + n2)) * ((n1 - n2) / (n1 + n2));
        ref_real c = n1 <= n2 ? ci : f.ct;
        return R0 + (1 - R0) * ref_pow(1 - c, 5);
    }
    return (f.Rs + f.Rp) / 2;
}

/* One node in the direction of light: field E on k_in leaves along k_out
 * (reflected or transmitted) at a surface with normal n. */
static cv3 jones_node(cv3 E, lv3 k_in, lv3 k_out, lv3 n, ref_real n1, ref_real n2, int reflect)
{
    ref_real ci = ref_fabs(ldot(k_in, n));
    lv3 s = lcross(k_in, n);
    if (llen(s) < REF(1e-12)) { /* normal incidence: any s */
        lv3 h = ref_fabs(k_in.x) < REF(0.6) ? L3(1, 0, 0) : L3(0, 1, 0);
        s = lcross(k_in, h);
    }
    s = lnorm(s);
    lv3 p_in = lcross(k_in, s), p_out = lcross(k_out, s);
    lcx Es = cv_dot_real(E, s), Ep = cv_dot_real(E, p_in);
    fres f = fresnel(ci, n1, n2);
    if (reflect)
        return cv_comb(f.rs * Es, s, f.rp * Ep, p_out);
    return cv_comb(f.ts * Es, s, f.tp * Ep, p_out);
}

/* ------------------------------------------------------------------ */
/* the view ray's chain through the lens: ref_build_cap_chain              */
/* (lens_reference.h)                                                  */
/* ------------------------------------------------------------------ */

/* Follow light along the reverse of the chain from node k to node 1,
 * starting at S along u0; 0 if it takes another route. */
static int follow(const ref_lens *L, const ref_cap_chain *c, int k, ref_real ng, ref_real nm, lv3 S,
                  lv3 u0, lv3 *exit_p, lv3 *exit_d)
{
    ref_hit h = ref_intersect(L, S, u0, REF(0.0));
    if (h.surf != c->surf[k])
        return 0;
    if (k == 1) {
        *exit_p = h.p;
        *exit_d = lreflect(u0, h.n);
        return 1;
    }
    lv3 dir;
    if (!lrefract(u0, h.n, nm, ng, &dir))
        return 0;
    lv3 p = h.p;
    for (int j = k - 1; j >= 1; j--) {
        h = ref_intersect(L, p, dir, REF(1e-9) * L->size);
        if (h.surf != c->surf[j])
            return 0;
        p = h.p;
        if (j > 1)
            dir = lreflect(dir, h.n);
        else if (!lrefract(dir, h.n, ng, nm, &dir))
            return 0;
    }
    *exit_p = p;
    *exit_d = dir;
    return 1;
}

/* optical path inside the lens along query k's path */
static ref_real chain_op(const ref_cap_chain *c, int k, ref_real ng)
{
    ref_real L = 0;
    for (int j = 2; j <= k; j++)
        L += c->seg[j];
    return ng * L;
}
static ref_real chain_len(const ref_cap_chain *c, int k)
{
    ref_real L = 0;
    for (int j = 2; j <= k; j++)
        L += c->seg[j];
    return L;
}

/* The exact field leaving at the view ray's entry point along -d for
 * light arriving along -(query k dir) with field vp (unit, real), without
 * the propagation phase and absorption. */
static cv3 chain_jones(const ref_cap_chain *c, int k, ref_real ng, ref_real nm, lv3 vp, lv3 view_d)
{
    cv3 E = cv_from(vp);
    if (k == 1)
        return jones_node(E, lscale(c->drefl[1], -1), lscale(view_d, -1), c->nrm[1], nm, ng, 1);
    /* node k: from outside into the glass */
    E = jones_node(E, lscale(c->dtran[k], -1), lscale(c->din[k], -1), c->nrm[k], nm, ng, 0);
    for (int j = k - 1; j >= 2; j--)
        E = jones_node(E, lscale(c->drefl[j], -1), lscale(c->din[j], -1), c->nrm[j], ng, nm, 1);
    return jones_node(E, lscale(c->dtran[1], -1), lscale(view_d, -1), c->nrm[1], ng, nm, 0);
}

/* unpolarized (or polarized bound) power transmittance of query k's path,
 * without absorption */
static ref_real chain_power(const ref_cap_chain *c, int k, ref_real ng, ref_real nm, lp_mode mode,
                            int bound)
{
    ref_real P = 1;
    for (int j = 1; j <= k; j++) {
        ref_real n1 = j == 1 ? nm : ng, n2 = j == 1 ? ng : nm;
        int reflect = (k == 1) || (j > 1 && j < k);
        ref_real R;
        if (bound) {
            fres f = fresnel(c->cosi[j], n1, n2);
            R = reflect ? ref_fmax(f.Rs, f.Rp) : ref_fmin(f.Rs, f.Rp);
        } else {
            R = mode_R(mode, c->cosi[j], n1, n2);
        }
        P *= reflect ? R : 1 - R;
    }
    return P;
}

static uint64_t chain_path(int d) { return d == 1 ? 1u : (((uint64_t)1 << (d - 1)) - 2); }
static uint64_t reverse_path(uint64_t p, int d)
{
    uint64_t r = 0;
    for (int j = 0; j < d; j++)
        if (p >> j & 1)
            r |= (uint64_t)1 << (d - 1 - j);
    return r;
}

/* ------------------------------------------------------------------ */

static const uint64_t SEED = 0x2ec1b0c17eULL;
static char ctx[256];

typedef struct {
    long compared, skipped_cond, skipped_sens, queries, view_rays, tir_paths;
    long power_compared, power_tir; /* lp_backward_gather_power_many's requests */
    double worst_field_fb, worst_field_ref, worst_int_fb, worst_op;
} stats;
static stats st_pol, st_unp;

static lv3 rand_perp(lv3 u)
{
    lv3 v;
    do {
        v = lfrom(rand_unit());
        v = lsub(v, lscale(u, ldot(v, u)));
    } while (llen(v) < REF(0.1));
    return lnorm(v);
}

/* field sum of a set of rays, phase relative to op_ref (mm), corrected to
 * the reference exit point E along the ray (first order, Malus-Dupin) */
static cv3 field_sum(const lp_out_ray *const *rays, int n, const frame *f, ref_real op_ref,
                     ref_real lambda_mm, ref_real nm, lv3 E_ref, ref_real *op_out)
{
    cv3 sum = {0, 0, 0};
    for (int i = 0; i < n; i++) {
        const lp_ray *r = &rays[i]->ray;
        lv3 o = fl_point(f, r->origin), d = fl_dir(f, r->dir);
        ref_real op = r->op + nm * ldot(lsub(E_ref, o), d);
        if (op_out)
            *op_out = op;
        ref_real phi = 2 * REF_PI * (op - op_ref) / lambda_mm - REF_PI * r->kphi + r->phase;
        lcx a = ref_sqrt((ref_real)r->intensity) * ref_cexp(I * phi);
        sum = cv_add(sum, cv_scale(cv_from(fl_dir(f, r->vp)), a));
    }
    return sum;
}

static ref_real cv_dist(cv3 a, cv3 b)
{
    cv3 d = {a.x - b.x, a.y - b.y, a.z - b.z};
    return ref_sqrt(cv_norm2(d));
}

/* A builder for power alone (LP_BACKWARD_POWER), beside each build. */
static lp_backward *bwp;

static void one_lens(int li, lp_backward *bw, lp_mode mode, stats *S)
{
    rng_state = SEED + (uint64_t)li * 0x9E3779B97F4A7C15ULL + (uint64_t)mode;
    rshape s;
    random_shape(&s);
    ref_real ng = urange(1.3, 2.0), nm = (sm64() & 1) ? 1.0 : urange(1.0, 1.4);
    lp_glass glass, medium;
    lp_glass_init_constant(&glass, (double)ng);
    ref_real alpha = 0;
    if (sm64() & 1) { /* absorbing: tau = 0.5..0.99 over 10 mm, flat in lambda */
        double tau = urange(0.5, 0.99);
        glass.n_tau = 2;
        glass.tau_lambda_nm[0] = 300;
        glass.tau_lambda_nm[1] = 900;
        glass.tau[0] = glass.tau[1] = tau;
        glass.tau_thickness_mm = 10;
        alpha = -ref_log(tau) / 10;
        lp_error gerr;
        CHECK(lp_glass_check(&glass, &gerr) == LP_OK, "hand-made absorbing glass: %s", gerr.message);
    }
    lp_glass_init_constant(&medium, (double)nm);
    frame f = frame_make(V(urange(-20, 20), urange(-20, 20), urange(-20, 20)), rand_unit());
    ref_lens L;
    ref_init(&L, s.R1, s.R2, s.t, s.D, s.D2);
    lp_lens *lens = make_lens_g(&s, &glass, &medium, &f);
    if (!lens)
        return;
    lp_trace_args args;
    lp_trace_args_init(&args);
    args.mode = mode;
    args.max_depth = 2 + (int)(sm64() % 5);
    lp_result g, fw;
    lp_result_init(&g);
    lp_result_init(&fw);
    for (int vi = 0; vi < 3; vi++) {
        /* a view ray entering a random cap point from outside */
        int back = (int)(sm64() & 1);
        lv3 T = random_surface_point(&L, back);
        if (ref_sqrt(T.x * T.x + T.y * T.y) > REF(0.9) * (back ? L.a2 : L.a1))
            continue;
        lv3 nT = lnorm(back ? lscale(L3(L.c2 * T.x, L.c2 * T.y, L.c2 * (T.z - L.t) - 1), -1)
                            : L3(L.c1 * T.x, L.c1 * T.y, L.c1 * T.z - 1));
        lv3 d;
        do {
            d = lfrom(rand_unit());
        } while (ldot(d, nT) > -REF(0.2));
        lp_vec3 Ow = lto(fw_point(&f, lsub(T, lscale(d, REF(2.0) * L.size))));
        lp_vec3 dw = lto(fw_dir(&f, d));
        double lambda = urange(380, 780);
        ref_real lambda_mm = lambda * REF(1e-6);
        /* the reference chain from exactly the double view ray */
        lv3 O = fl_point(&f, Ow);
        d = lnorm(fl_dir(&f, dw));
        ref_cap_chain c;
        ref_build_cap_chain(&L, ng, nm, O, d, &c);
        lp_error err;
        lp_status stt = lp_backward_build(bw, lens, Ow, dw, lambda, &args, &err);
        /* the same view ray's build for power alone: the same queries */
        lp_trace_args pargs = args;
        pargs.flags |= LP_BACKWARD_POWER;
        CHECK(bwp && lp_backward_build(bwp, lens, Ow, dw, lambda, &pargs, &err) == LP_OK,
              "power build: %s", err.message);
        CHECK(lp_backward_query_count(bwp) == lp_backward_query_count(bw) &&
                  memcmp(lp_backward_queries(bwp), lp_backward_queries(bw),
                         lp_backward_query_count(bw) * sizeof(lp_query)) == 0,
              "power build: its queries differ");
        CHECK(stt == LP_OK, "backward_build: %s", err.message);
        if (stt != LP_OK)
            continue;
        S->view_rays++;
        size_t nq = lp_backward_query_count(bw);
        const lp_query *qs = lp_backward_queries(bw);
        int kmax = c.n < args.max_depth ? c.n : args.max_depth;
        int kgood = 0;
        while (kgood < kmax && c.good[kgood + 1])
            kgood++;
        if (c.n == 0) {
            if (c.rim_depth == 1)
                CHECK(nq == 0, "view ray on the rim: %zu queries", nq);
            continue;
        }
        /* the queries up to kgood, one per depth, as the chain says */
        int want_count = 0, got_count = 0;
        for (int k = 1; k <= kgood; k++)
            want_count += (k == 1) || !c.tir[k];
        for (size_t qi = 0; qi < nq; qi++)
            got_count += qs[qi].depth >= 1 && qs[qi].depth <= kgood;
        snprintf(ctx, sizeof ctx, "[seed %#llx lens %d (%s) mode %d view %d]", (unsigned long long)SEED,
                 li, family_names[s.family], (int)mode, vi);
        CHECK(got_count == want_count, "%s: %d queries of depth <= %d, want %d", ctx, got_count, kgood,
              want_count);
        for (size_t qi = 0; qi < nq; qi++) {
            const lp_query *q = &qs[qi];
            int k = q->depth;
            S->queries++;
            if (k < 1 || k > kgood) {
                S->skipped_cond++;
                continue;
            }
            snprintf(ctx, sizeof ctx, "[seed %#llx lens %d (%s) mode %d view %d depth %d]",
                     (unsigned long long)SEED, li, family_names[s.family], (int)mode, vi, k);
            /* the query itself against the chain */
            lv3 Qref = c.p[k], uref = k == 1 ? c.drefl[1] : c.dtran[k];
            CHECK(!(k > 1 && c.tir[k]), "%s: query at a TIR node", ctx);
            if (k > 1 && c.tir[k])
                continue;
            CHECK_ABS((double)llen(lsub(fl_point(&f, q->origin), Qref)) / L.size, 0.0, 1e-9,
                      "%s: query origin vs reference chain", ctx);
            CHECK_ABS((double)llen(lsub(fl_dir(&f, q->dir), uref)), 0.0, 1e-9,
                      "%s: query dir vs reference chain", ctx);
            CHECK(q->path == chain_path(k), "%s: query path %#llx want %#llx", ctx,
                  (unsigned long long)q->path, (unsigned long long)chain_path(k));
            CHECK(q->surface == c.surf[k], "%s: query surface %d want %d", ctx, q->surface, c.surf[k]);
            CHECK(q->kind == (k == 1 || c.surf[k] == c.surf[1] ? LP_KIND_REFLECT : LP_KIND_TRANSMIT),
                  "%s: query kind %d", ctx, (int)q->kind);
            ref_real op_ref = chain_op(&c, k, ng);
            ref_real absorb = ref_exp(-alpha * chain_len(&c, k));
            double tol_op = 1e-8 * (double)lambda_mm / (2 * M_PI);
            CHECK_ABS(q->op, (double)op_ref, tol_op, "%s: query op (phase-equivalent 1e-8 rad)", ctx);
            ref_real P_bound = chain_power(&c, k, ng, nm, mode, mode == LP_MODE_POLARIZED) * absorb;
            CHECK_REL(q->bound, (double)P_bound, 1e-10, "%s: query bound vs Fresnel product", ctx);

            /* conditioning of the reverse path: angular amplification */
            ref_real s_off = REF(1e-3) * L.size;
            ref_hit back_hit = ref_intersect(&L, Qref, uref, REF(1e-9) * L.size);
            if (back_hit.surf >= 0 && back_hit.s < 4 * s_off)
                s_off = back_hit.s / 4;
            lv3 S0 = ladd(Qref, lscale(uref, s_off));
            lv3 ep, ed, ep1, ed1;
            int ok = follow(&L, &c, k, ng, nm, S0, lscale(uref, -1), &ep, &ed);
            CHECK(ok && llen(lsub(ep, c.p[1])) < REF(1e-12) * L.size &&
                      llen(lsub(ed, lscale(d, -1))) < REF(1e-12),
                  "%s: (test self-check) reverse path does not retrace the chain", ctx);
            ref_real G = 0;
            lv3 e1 = rand_perp(uref), e2 = lnorm(lcross(uref, e1));
            for (int pj = 0; pj < 2 && ok; pj++) {
                const ref_real dl = REF(1e-7);
                lv3 u1 = lnorm(ladd(lscale(uref, -1), lscale(pj ? e2 : e1, dl)));
                if (!follow(&L, &c, k, ng, nm, S0, u1, &ep1, &ed1)) {
                    G = INFINITY;
                    break;
                }
                G = ref_fmax(G, llen(lsub(ed1, ed)) / dl);
            }
            if (!ok || G > REF(1e4)) {
                S->skipped_sens++;
                continue;
            }

            /* gather two bundle rays: the brief's plain one and one with a payload */
            lp_ray bundle[2];
            memset(bundle, 0, sizeof bundle);
            lv3 vp[2];
            for (int b = 0; b < 2; b++) {
                vp[b] = rand_perp(uref);
                bundle[b].lambda_nm = lambda;
                bundle[b].vp = lto(fw_dir(&f, vp[b]));
                bundle[b].dir = lto(fw_dir(&f, lscale(uref, -1)));
                bundle[b].origin = q->origin;
                bundle[b].ch = 1000 + (uint64_t)b;
            }
            bundle[0].intensity = 1;
            bundle[1].intensity = urange(0.1, 5);
            bundle[1].op = urange(0, 3);
            bundle[1].kphi = (int)(sm64() % 4);
            bundle[1].phase = urange(-3, 3);
            lp_result_clear(&g);
            stt = lp_backward_gather(bw, qi, bundle, 2, &g, &err);
            CHECK(stt == LP_OK, "%s: gather: %s", ctx, err.message);
            if (stt != LP_OK)
                continue;
            double bsum = bundle[0].intensity + bundle[1].intensity;
            CHECK_REL(g.in, bsum, 1e-15, "%s: gather in = bundle intensity", ctx);
            CHECK_REL(g.out + g.skipped + g.absorbed_glass + g.absorbed_rim + g.truncated, g.in, 1e-12,
                      "%s: gather bookkeeping", ctx);
            double gsum = 0;
            for (size_t i = 0; i < g.count; i++)
                gsum += g.rays[i].ray.intensity;
            CHECK_REL(gsum, g.out, 1e-12, "%s: gather out = sum of its rays", ctx);
            CHECK(g.count >= 2 && g.count <= 4, "%s: gather returned %zu rays for 2 bundle rays", ctx,
                  g.count);
            /* the same request's power alone (lp_backward_gather_power_many) */
            const lp_backward *pb = bwp;
            const lp_ray *pbundle = bundle;
            size_t pq = qi, pn = 2;
            double power = -1.0;
            stt = lp_backward_gather_power_many(&pb, &pq, &pbundle, &pn, 1, &power, &err);
            CHECK(stt == LP_OK, "%s: gather_power: %s", ctx, err.message);
            /* both carry the field through k <= 6 nodes, about 10 roundings a
             * node each, every factor at most 1 in size: apart by at most
             * 2 (10 x 6 + 2) eps of the bundle's intensity = 1.4e-14
             * (measured: 1.8e-14 of the power itself, less of the bundle's) */
            CHECK_ABS(power, g.out, 2.0 * (10.0 * 6.0 + 2.0) * 0x1p-53 * bsum,
                      "%s: gather_power against the gather's rays", ctx);
            ref_real exact_sum = 0;
            int n_exact = 0, tir_here = 0;
            for (size_t i = 0; i < g.count; i++) {
                const lp_out_ray *o = &g.rays[i];
                CHECK(o->depth == k && o->kind == q->kind && o->path == q->path,
                      "%s: gathered ray depth/kind/path", ctx);
                CHECK_ABS((double)llen(lsub(fl_point(&f, o->ray.origin), c.p[1])) / L.size, 0.0, 1e-9,
                          "%s: gathered ray leaves at the view ray's entry point", ctx);
                CHECK_ABS((double)llen(lsub(fl_dir(&f, o->ray.dir), lscale(d, -1))), 0.0, 1e-12,
                          "%s: gathered ray leaves along -view dir", ctx);
                CHECK(o->ray.ch == 1000 || o->ray.ch == 1001, "%s: gathered ch not copied", ctx);
                if (mode == LP_MODE_POLARIZED) {
                    CHECK_ABS(vlen(o->ray.vp), 1.0, 1e-9, "%s: gathered |vp|", ctx);
                    CHECK_ABS(vdot(o->ray.vp, o->ray.dir), 0.0, 1e-9, "%s: gathered vp . dir", ctx);
                }
            }

            /* forward from just outside Q along -u, for each bundle ray */
            uint64_t fpath = reverse_path(q->path, k);
            for (int b = 0; b < 2; b++) {
                lp_ray in = bundle[b];
                in.origin = lto(fw_point(&f, S0));
                in.dir = bundle[b].dir;
                lp_trace_args fargs = args;
                fargs.max_depth = k;
                stt = lp_trace_forward(lens, &in, &fargs, &fw, &err);
                CHECK(stt == LP_OK, "%s: forward: %s", ctx, err.message);
                const lp_out_ray *fr[8], *gr[8];
                int nf = 0, ng_ = 0;
                for (size_t i = 0; i < fw.count && nf < 8; i++) {
                    const lp_out_ray *o = &fw.rays[i];
                    if (o->depth != k || o->path != fpath)
                        continue;
                    fr[nf++] = o;
                }
                for (size_t i = 0; i < g.count && ng_ < 8; i++)
                    if (g.rays[i].ray.ch == bundle[b].ch)
                        gr[ng_++] = &g.rays[i];
                CHECK(nf >= 1 && nf <= 2, "%s: %d forward rays of depth %d path %#llx", ctx, nf, k,
                      (unsigned long long)fpath);
                CHECK(ng_ >= 1 && ng_ <= 2, "%s: %d gathered rays for bundle ray %d", ctx, ng_, b);
                if (nf < 1 || ng_ < 1)
                    continue;
                int match = 1;
                for (int i = 0; i < nf; i++) {
                    lv3 o = fl_point(&f, fr[i]->ray.origin), dd = fl_dir(&f, fr[i]->ray.dir);
                    match &= llen(lsub(o, c.p[1])) < REF(1e-7) * L.size &&
                             llen(lsub(dd, lscale(d, -1))) < REF(1e-7);
                    CHECK(fr[i]->kind == q->kind && fr[i]->surface == c.surf[1],
                          "%s: forward ray kind %d surface %d", ctx, (int)fr[i]->kind, fr[i]->surface);
                }
                CHECK(match, "%s: the forward ray of depth %d does not leave at the view entry point "
                             "along -d", ctx, k);
                if (!match)
                    continue;
                S->compared++;
                ref_real Ib = bundle[b].intensity;
                if (mode == LP_MODE_POLARIZED) {
                    ref_real opf = 0, opg = 0;
                    ref_real op0 = op_ref + bundle[b].op;
                    cv3 Ef = field_sum(fr, nf, &f, op0, lambda_mm, nm, c.p[1], &opf);
                    cv3 Eg = field_sum(gr, ng_, &f, op0, lambda_mm, nm, c.p[1], &opg);
                    /* the exact field, written here */
                    cv3 Er = chain_jones(&c, k, ng, nm, vp[b], d);
                    lcx a = ref_sqrt(Ib) * ref_sqrt(absorb) *
                            ref_cexp(I * (-REF_PI * bundle[b].kphi + bundle[b].phase));
                    Er = cv_scale(Er, a);
                    if (nf == 2 || ng_ == 2)
                        S->tir_paths++;
                    ref_real sc = ref_sqrt(Ib);
                    double dfb = (double)(cv_dist(Ef, Eg) / sc), dref = (double)(cv_dist(Eg, Er) / sc);
                    double dfr = (double)(cv_dist(Ef, Er) / sc);
                    CHECK_ABS(dfb, 0.0, 1e-8, "%s: bundle %d: field forward vs gathered", ctx, b);
                    CHECK_ABS(dref, 0.0, 1e-8, "%s: bundle %d: gathered field vs exact Jones field", ctx, b);
                    CHECK_ABS(dfr, 0.0, 1e-8, "%s: bundle %d: forward field vs exact Jones field", ctx, b);
                    ref_real If = cv_norm2(Ef), Ig = cv_norm2(Eg), Ir = cv_norm2(Er);
                    CHECK_REL((double)Ig, (double)If, 1e-10, "%s: bundle %d: intensity gathered vs forward",
                              ctx, b);
                    CHECK_REL((double)Ig, (double)Ir, 1e-10, "%s: bundle %d: intensity vs exact", ctx, b);
                    exact_sum += Ir;
                    n_exact++;
                    tir_here |= nf == 2 || ng_ == 2;
                    CHECK(Ig <= P_bound * Ib * (1 + REF(1e-10)), "%s: gathered intensity above the bound",
                          ctx);
                    CHECK_ABS((double)opg, (double)opf, tol_op, "%s: bundle %d: gathered op = forward op",
                              ctx, b);
                    CHECK_ABS((double)opg, (double)op0, tol_op, "%s: bundle %d: gathered op = bundle op + "
                              "path op", ctx, b);
                    S->worst_field_fb = fmax(S->worst_field_fb, dfb);
                    S->worst_field_ref = fmax(S->worst_field_ref, fmax(dref, dfr));
                    S->worst_int_fb =
                        fmax(S->worst_int_fb, (double)(ref_fabs(Ig - If) / ref_fmax(If, REF(1e-300))));
                    S->worst_op = fmax(S->worst_op, (double)ref_fabs(opg - opf));
                    if (nf == 1 && ng_ == 1)
                        CHECK_REL(gr[0]->ray.intensity, fr[0]->ray.intensity, 1e-10,
                                  "%s: bundle %d: ray intensity gathered vs forward", ctx, b);
                } else {
                    double If = 0, Ig = 0;
                    for (int i = 0; i < nf; i++)
                        If += fr[i]->ray.intensity;
                    for (int i = 0; i < ng_; i++)
                        Ig += gr[i]->ray.intensity;
                    ref_real want = Ib * chain_power(&c, k, ng, nm, mode, 0) * absorb;
                    CHECK_REL(Ig, If, 1e-10, "%s: bundle %d: intensity gathered vs forward", ctx, b);
                    CHECK_REL(Ig, (double)want, 1e-10, "%s: bundle %d: intensity vs %s product", ctx, b,
                              mode == LP_MODE_FRESNEL ? "Fresnel" : "Schlick");
                    CHECK_REL(Ig, q->bound * Ib, 1e-10, "%s: bundle %d: gathered = bound x I (exact "
                              "transmittance in this mode)", ctx, b);
                    S->worst_int_fb = fmax(S->worst_int_fb, fabs(Ig - If) / fmax(If, 1e-300));
                    exact_sum += want;
                    n_exact++;
                }
            }
            if (n_exact == 2) { /* the power against the exact Jones (or Fresnel) chain's */
                /* the tolerance of the gathered intensity against the exact
                 * chain, above, which this power equals to 1.4e-14 (measured
                 * worst here 1.1e-13 relative) */
                CHECK_REL(power, (double)exact_sum, 1e-10, "%s: gather_power vs exact", ctx);
                S->power_compared++;
                S->power_tir += tir_here;
            }
        }
    }
    lp_result_release(&g);
    lp_result_release(&fw);
    lp_lens_destroy(lens);
}

int main(void)
{
    lp_backward *bw = NULL;
    lp_error err;
    CHECK(lp_backward_create(&bw, &err) == LP_OK, "lp_backward_create: %s", err.message);
    CHECK(lp_backward_create(&bwp, &err) == LP_OK, "lp_backward_create: %s", err.message);
    if (!bw)
        return check_finish("test_reciprocity");
    printf("test_reciprocity: seed %#llx\n", (unsigned long long)SEED);
    for (int li = 0; li < 240; li++)
        one_lens(li, bw, LP_MODE_POLARIZED, &st_pol);
    for (int li = 0; li < 120; li++) {
        one_lens(1000 + li, bw, LP_MODE_FRESNEL, &st_unp);
        one_lens(2000 + li, bw, LP_MODE_SCHLICK, &st_unp);
    }
    printf("test_reciprocity: polarized: %ld view rays, %ld queries, %ld bundle rays compared "
           "(%ld with TIR parts), skipped %ld ill-conditioned + %ld sensitive; worst |E_f - E_g| %.3g, "
           "worst |E - E_exact| %.3g, worst intensity f/g %.3g, worst op diff %.3g mm\n",
           st_pol.view_rays, st_pol.queries, st_pol.compared, st_pol.tir_paths, st_pol.skipped_cond,
           st_pol.skipped_sens, st_pol.worst_field_fb, st_pol.worst_field_ref, st_pol.worst_int_fb,
           st_pol.worst_op);
    printf("test_reciprocity: fresnel+schlick: %ld view rays, %ld queries, %ld compared, skipped %ld + %ld; "
           "worst intensity f/g %.3g\n",
           st_unp.view_rays, st_unp.queries, st_unp.compared, st_unp.skipped_cond, st_unp.skipped_sens,
           st_unp.worst_int_fb);
    printf("test_reciprocity: gather_power against the exact chain: polarized %ld requests (%ld "
           "with TIR parts), fresnel+schlick %ld\n",
           st_pol.power_compared, st_pol.power_tir, st_unp.power_compared);
    CHECK(st_pol.compared >= 1000, "enough polarized comparisons (%ld)", st_pol.compared);
    CHECK(st_pol.power_tir >= 10, "TIR paths among gather_power's (%ld)", st_pol.power_tir);
    CHECK(st_pol.tir_paths >= 10, "TIR paths among the comparisons (%ld)", st_pol.tir_paths);
    CHECK(st_unp.compared >= 500, "enough unpolarized comparisons (%ld)", st_unp.compared);
    lp_backward_destroy(bw);
    lp_backward_destroy(bwp);
    lp_backward_destroy(NULL);
    return check_finish("test_reciprocity");
}
