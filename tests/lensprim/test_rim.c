/* test_rim.c -- the opaque rim (cylinder or cone).
 *
 * Rays aimed at the rim from outside give no output rays and
 * absorbed_rim == in; for a conical rim (D = 30, D2 = 20) the cone's
 * points, normals and containment follow the closed-form cone written
 * here; a ray entering the front cap near its edge whose refracted path
 * runs into the cone is absorbed at depth 2 with exactly the refracted
 * power (1 - R) I (Fresnel computed here) and lp_backward_rim_depth = 2;
 * on random lenses lp_backward_rim_depth equals the depth at which the
 * reference chain (traced here in ref_real) meets the rim; rays
 * through the exact cap/rim edge circle give finite results, a first hit
 * that enters the glass or is on the rim, and a balanced bookkeeping.
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

#include "lens_reference.h" /* the reference chain: ref_build_cap_chain */

/* ------------------------------------------------------------------ */

static char ctx[256];
static const uint64_t SEED = 0x7171d0e5ULL;

static lp_lens *lens_n(double R1, double R2, double t, double D, double D2, double n, const frame *f)
{
    rshape s = {R1, R2, t, D, D2, 0};
    lp_glass g;
    lp_glass_init_constant(&g, n);
    return make_lens_g(&s, &g, NULL, f);
}

static void ray_init(lp_ray *in, lp_vec3 o, lp_vec3 d, double I)
{
    memset(in, 0, sizeof *in);
    in->origin = o;
    in->dir = vnorm(d);
    in->lambda_nm = urange(380, 780);
    in->intensity = I;
    lp_vec3 vp;
    do {
        vp = rand_unit();
    } while (vlen(vcross(vp, in->dir)) < 0.1);
    in->vp = vp;
    in->ch = 42;
}

static void check_balance(const lp_result *r, const char *what)
{
    double sum = r->out + r->skipped + r->absorbed_glass + r->absorbed_rim + r->truncated;
    CHECK(isfinite(sum) && isfinite(r->in), "%s: bookkeeping not finite", what);
    if (r->in > 0)
        CHECK_REL(sum, r->in, 1e-12, "%s: in = out + skipped + glass + rim + truncated", what);
    else
        CHECK(sum == 0 && r->count == 0, "%s: nothing received but sum %g", what, sum);
    double out = 0;
    for (size_t i = 0; i < r->count; i++) {
        const lp_ray *o = &r->rays[i].ray;
        CHECK(vfinite(o->origin) && vfinite(o->dir) && vfinite(o->vp) && isfinite(o->intensity) &&
                  isfinite(o->op) && isfinite(o->phase) && o->intensity >= 0,
              "%s: output ray %zu not finite / negative", what, i);
        out += o->intensity;
    }
    if (r->count)
        CHECK_REL(out, r->out, 1e-12, "%s: out = sum of the output rays", what);
}

/* outward normal of the rim (cylinder or cone) at a local point */
static lv3 rim_normal(const ref_lens *L, lv3 p)
{
    ref_real r = L->a1 + L->k * (p.z - L->zf);
    return lnorm(L3(p.x, p.y, -r * L->k));
}

/* 1. rays from outside onto the rim: no output, all absorbed at the rim */
static void test_rim_from_outside(void)
{
    const struct { double R1, R2, t, D, D2; } shapes[] = {
        {50, -50, 8, 25, 0},   {25.8, INFINITY, 5.3, 25.4, 0}, {-40, 40, 2, 25, 0},
        {30, 60, 5, 25, 0},    {0, INFINITY, 3, 20, 0},        {50, -50, 8, 30, 20},
        {50, -50, 8, 20, 30},
    };
    for (size_t si = 0; si < sizeof shapes / sizeof shapes[0]; si++) {
        frame f = si % 2 ? frame_make(V(urange(-20, 20), urange(-20, 20), urange(-20, 20)), rand_unit())
                         : frame_identity();
        ref_lens L;
        ref_init(&L, shapes[si].R1, shapes[si].R2, shapes[si].t, shapes[si].D, shapes[si].D2);
        lp_lens *lens = lens_n(shapes[si].R1, shapes[si].R2, shapes[si].t, shapes[si].D, shapes[si].D2,
                               1.5, &f);
        if (!lens)
            continue;
        CHECK(L.rim, "shape %zu has a rim", si);
        lp_result res;
        lp_result_init(&res);
        int n_done = 0;
        for (int k = 0; k < 200; k++) {
            ref_real u = urange(0.02, 0.98), phi = urange(0, 2 * M_PI);
            ref_real z = L.zf + u * (L.zb - L.zf), r = L.a1 + u * (L.a2 - L.a1);
            lv3 P = L3(r * ref_cos(phi), r * ref_sin(phi), z);
            lv3 n = rim_normal(&L, P);
            lv3 d;
            do {
                d = lfrom(rand_unit());
            } while (ldot(d, n) > -REF(0.1));
            lv3 O = lsub(P, lscale(d, REF(3.0) * L.size));
            ref_hit h = ref_intersect(&L, O, d, REF(0.0));
            if (h.surf != LP_SURFACE_RIM || llen(lsub(h.p, P)) > REF(1e-9) * L.size)
                continue; /* a concave cap's lip is in the way */
            snprintf(ctx, sizeof ctx, "[rim from outside: shape %zu ray %d]", si, k);
            lp_vec3 Ow = lto(fw_point(&f, O)), dw = lto(fw_dir(&f, d));
            lp_hit hit;
            int got = lp_lens_intersect(lens, Ow, dw, 0.0, INFINITY, &hit);
            CHECK(got && hit.surface == LP_SURFACE_RIM, "%s: intersect surface %d, want rim", ctx,
                  got ? hit.surface : -9);
            if (got) {
                CHECK_ABS((double)llen(lsub(fl_point(&f, hit.point), P)) / L.size, 0.0, 1e-12,
                          "%s: rim hit point", ctx);
                CHECK_ABS((double)llen(lsub(fl_dir(&f, hit.normal), n)), 0.0, 1e-10,
                          "%s: rim normal (cylinder/cone, outward)", ctx);
            }
            lp_ray in;
            ray_init(&in, Ow, dw, urange(0.5, 2));
            lp_trace_args args;
            lp_trace_args_init(&args);
            args.mode = (lp_mode)(k % 3);
            args.max_depth = 1 + k % 10;
            lp_status st = lp_trace_forward(lens, &in, &args, &res, NULL);
            CHECK(st == LP_OK, "%s: status %d", ctx, (int)st);
            CHECK(res.count == 0, "%s: %zu output rays from a rim hit", ctx, res.count);
            CHECK_REL(res.in, in.intensity, 1e-15, "%s: in", ctx);
            CHECK_REL(res.absorbed_rim, res.in, 1e-15, "%s: absorbed_rim = in", ctx);
            check_balance(&res, ctx);
            /* backward: a view ray on the rim has rim depth 1 and no queries */
            lp_backward *bw = NULL;
            lp_backward_create(&bw, NULL);
            if (bw) {
                st = lp_backward_build(bw, lens, Ow, dw, 550, &args, NULL);
                CHECK(st == LP_OK, "%s: backward build", ctx);
                CHECK(lp_backward_rim_depth(bw) == 1, "%s: rim depth %d, want 1", ctx,
                      lp_backward_rim_depth(bw));
                CHECK(lp_backward_query_count(bw) == 0, "%s: %zu queries", ctx,
                      lp_backward_query_count(bw));
                lp_backward_destroy(bw);
            }
            n_done++;
        }
        CHECK(n_done > 50, "shape %zu: %d rim rays tested", si, n_done);
        lp_result_release(&res);
        lp_lens_destroy(lens);
    }
}

/* 2. the conical rim: containment near the cone */
static void test_cone_contains(void)
{
    ref_lens L;
    ref_init(&L, 50, -50, 8, 30, 20);
    frame f = frame_identity();
    lp_lens *lens = lens_n(50, -50, 8, 30, 20, 1.5, &f);
    if (!lens)
        return;
    /* closed form: zf = 50 - sqrt(2500 - 225), zb = 8 - (50 - sqrt(2500 - 100)) */
    CHECK_ABS((double)L.zf, 50 - sqrt(2275.0), 1e-13, "cone lens: front edge z");
    CHECK_ABS((double)L.zb, 8 - 50 + sqrt(2400.0), 1e-13, "cone lens: back edge z");
    for (int k = 0; k < 300; k++) {
        ref_real u = urange(0.02, 0.98), phi = urange(0, 2 * M_PI);
        ref_real z = L.zf + u * (L.zb - L.zf), r = L.a1 + u * (L.a2 - L.a1);
        lv3 P = L3(r * ref_cos(phi), r * ref_sin(phi), z);
        lv3 n = rim_normal(&L, P);
        for (int j = 1; j <= 3; j++) {
            ref_real e = ref_pow(10, -2 * j); /* 1e-2, 1e-4, 1e-6 mm */
            CHECK(lp_lens_contains(lens, lto(ladd(P, lscale(n, -e)))), "cone: %g inside is inside",
                  (double)e);
            CHECK(!lp_lens_contains(lens, lto(ladd(P, lscale(n, e)))), "cone: %g outside is outside",
                  (double)e);
        }
        /* points inside the old cylinder r < 15 but outside the cone */
        ref_real rc = r + REF(0.5) * (L.a1 - r);
        if (rc > r + REF(0.05))
            CHECK(!lp_lens_contains(lens, lto(L3(rc * ref_cos(phi), rc * ref_sin(phi), z))),
                  "cone: r=%g at z=%g (cone radius %g) is outside", (double)rc, (double)z, (double)r);
    }
    lp_lens_destroy(lens);
}

/* 3. entering the front cap near the edge, refracted into the rim:
 * absorbed at depth 2 */
static void test_refracted_into_rim(void)
{
    const double n = 1.5;
    ref_lens L;
    ref_init(&L, 50, -50, 8, 30, 20);
    frame f = frame_make(V(3, -4, 12), V(0.2, 0.1, 1));
    lp_lens *lens = lens_n(50, -50, 8, 30, 20, n, &f);
    if (!lens)
        return;
    lp_result res;
    lp_result_init(&res);
    lp_backward *bw = NULL;
    lp_backward_create(&bw, NULL);
    int found = 0;
    for (int k = 0; k < 4000 && found < 60; k++) {
        ref_real r = urange(12.5, 14.8), phi = urange(0, 2 * M_PI);
        lv3 P = L3(r * ref_cos(phi), r * ref_sin(phi), rsag(L.c1, r));
        lv3 nP = lnorm(L3(L.c1 * P.x, L.c1 * P.y, L.c1 * P.z - 1)); /* outward front normal */
        /* incoming from the front, tilted outward */
        lv3 d = lnorm(L3(urange(0, 1.2) * ref_cos(phi), urange(0, 1.2) * ref_sin(phi) + urange(-0.2, 0.2),
                         1));
        ref_real ci = -ldot(d, nP);
        if (ci < REF(0.1))
            continue;
        lv3 dt;
        if (!lrefract(d, nP, REF(1.0), n, &dt))
            continue;
        lv3 O = lsub(P, lscale(d, REF(3.0) * L.size));
        ref_hit h0 = ref_intersect(&L, O, d, REF(0.0));
        if (h0.surf != LP_SURFACE_FRONT || llen(lsub(h0.p, P)) > REF(1e-9) * L.size)
            continue;
        ref_hit h = ref_intersect(&L, P, dt, REF(1e-9) * L.size);
        if (h.surf != LP_SURFACE_RIM || h.p.z - L.zf < REF(0.05) || L.zb - h.p.z < REF(0.05))
            continue;
        found++;
        snprintf(ctx, sizeof ctx, "[refracted into the rim, case %d]", found);
        lp_ray in;
        ray_init(&in, lto(fw_point(&f, O)), lto(fw_dir(&f, d)), urange(0.5, 2));
        lp_trace_args args;
        lp_trace_args_init(&args);
        args.mode = (lp_mode)(found % 3);
        args.max_depth = 2 + found % 8;
        lp_status st = lp_trace_forward(lens, &in, &args, &res, NULL);
        CHECK(st == LP_OK, "%s: status", ctx);
        check_balance(&res, ctx);
        /* the external reflectance at the entry, computed here */
        ref_real Rs, Rp;
        {
            ref_real ct = ref_sqrt(1 - (1 - ci * ci) / (n * n));
            ref_real rs = (ci - n * ct) / (ci + n * ct), rp = (n * ci - ct) / (n * ci + ct);
            Rs = rs * rs;
            Rp = rp * rp;
            ref_real R;
            if (args.mode == LP_MODE_POLARIZED) {
                lv3 v = fl_dir(&f, vnorm(in.vp));
                v = lnorm(lsub(v, lscale(d, ldot(v, d))));
                lv3 sx = lnorm(lcross(d, nP));
                ref_real as2 = ldot(v, sx) * ldot(v, sx);
                R = Rs * as2 + Rp * (1 - as2);
            } else if (args.mode == LP_MODE_FRESNEL) {
                R = (Rs + Rp) / 2;
            } else {
                ref_real R0 = ref_pow((1 - n) / (1 + n), 2);
                R = R0 + (1 - R0) * ref_pow(1 - ci, 5);
            }
            CHECK_REL(res.absorbed_rim, (double)((1 - R) * in.intensity), 1e-10,
                      "%s: absorbed_rim = the refracted power (1 - R) I", ctx);
            CHECK_REL(res.out, (double)(R * in.intensity), 1e-10, "%s: out = the external reflection", ctx);
        }
        CHECK(res.absorbed_rim > 0, "%s: absorbed_rim > 0", ctx);
        for (size_t i = 0; i < res.count; i++)
            CHECK(res.rays[i].depth == 1, "%s: output at depth %d (only the reflection expected)", ctx,
                  res.rays[i].depth);
        CHECK_ABS(res.truncated, 0.0, 0.0, "%s: nothing truncated", ctx);
        if (bw) {
            st = lp_backward_build(bw, lens, in.origin, in.dir, in.lambda_nm, &args, NULL);
            CHECK(st == LP_OK, "%s: backward build", ctx);
            CHECK(lp_backward_rim_depth(bw) == 2, "%s: rim depth %d, want 2", ctx,
                  lp_backward_rim_depth(bw));
            size_t nq = lp_backward_query_count(bw);
            const lp_query *q = lp_backward_queries(bw);
            CHECK(nq == 1 && q[0].depth == 1, "%s: %zu queries (want only the depth-1 reflection)", ctx,
                  nq);
        }
    }
    CHECK(found >= 30, "found %d rays refracted into the rim", found);
    lp_backward_destroy(bw);
    lp_result_release(&res);
    lp_lens_destroy(lens);
}

/* 4. lp_backward_rim_depth against the reference chain on random lenses */
static void test_rim_depth_random(void)
{
    lp_backward *bw = NULL;
    CHECK(lp_backward_create(&bw, NULL) == LP_OK, "backward create");
    if (!bw)
        return;
    lp_result res;
    lp_result_init(&res);
    long hist[REF_CHAIN_MAX + 2] = {0};
    long compared = 0, skipped = 0;
    for (int li = 0; li < 300; li++) {
        rng_state = SEED + (uint64_t)li * 0x9E3779B97F4A7C15ULL;
        rshape s;
        random_shape(&s);
        ref_real ng = urange(1.3, 2.0), nm = (sm64() & 1) ? 1.0 : urange(1.0, 1.25);
        lp_glass glass, medium;
        lp_glass_init_constant(&glass, (double)ng);
        lp_glass_init_constant(&medium, (double)nm);
        frame f = frame_make(V(urange(-20, 20), urange(-20, 20), urange(-20, 20)), rand_unit());
        ref_lens L;
        ref_init(&L, s.R1, s.R2, s.t, s.D, s.D2);
        lp_lens *lens = make_lens_g(&s, &glass, &medium, &f);
        if (!lens)
            continue;
        for (int vi = 0; vi < 20; vi++) {
            int which = (int)(sm64() % 5);
            lv3 T = random_surface_point(&L, which < 2 ? 0 : (which < 4 ? 1 : 2));
            lv3 d = lfrom(rand_unit());
            lv3 O = lsub(T, lscale(d, REF(2.0) * L.size));
            lp_vec3 Ow = lto(fw_point(&f, O)), dw = lto(fw_dir(&f, d));
            O = fl_point(&f, Ow);
            d = lnorm(fl_dir(&f, dw));
            lp_trace_args args;
            lp_trace_args_init(&args);
            args.max_depth = 1 + (int)(sm64() % 12);
            args.mode = (lp_mode)(sm64() % 3);
            ref_cap_chain c;
            ref_build_cap_chain(&L, ng, nm, O, d, &c);
            /* expected rim depth, and whether the chain is unambiguous */
            int want = c.rim_depth;
            int good = !c.leak;
            int last = c.rim_depth ? c.rim_depth - 1 : c.n;
            if (last > args.max_depth)
                last = args.max_depth;
            for (int k = 1; k <= last; k++)
                good = good && c.good[k];
            if (c.rim_depth && c.rim_depth <= args.max_depth) {
                ref_real m = REF(1e-6) * L.size;
                good = good && c.rim_p.z - L.zf > m && L.zb - c.rim_p.z > m && c.rim_cos > REF(0.02);
            }
            if (c.rim_depth == args.max_depth + 1)
                good = 0; /* the rim just past the depth limit: not specified */
            if (!c.rim_depth && c.n <= args.max_depth)
                good = 0; /* chain ended (TIR at entry / miss): nothing to compare */
            if (c.n == 0 && c.rim_depth == 0)
                good = 0;
            if (want > args.max_depth)
                want = 0;
            if (!good) {
                skipped++;
                continue;
            }
            snprintf(ctx, sizeof ctx, "[rim depth: seed %#llx lens %d (%s) view %d, max_depth %d]",
                     (unsigned long long)SEED, li, family_names[s.family], vi, args.max_depth);
            lp_status st = lp_backward_build(bw, lens, Ow, dw, 550, &args, NULL);
            CHECK(st == LP_OK, "%s: build", ctx);
            CHECK(lp_backward_rim_depth(bw) == want, "%s: rim depth %d, want %d", ctx,
                  lp_backward_rim_depth(bw), want);
            /* the same ray as light: rim absorption iff the chain meets the rim */
            lp_ray in;
            ray_init(&in, Ow, dw, 1.0);
            in.lambda_nm = 550;
            st = lp_trace_forward(lens, &in, &args, &res, NULL);
            CHECK(st == LP_OK, "%s: forward", ctx);
            check_balance(&res, ctx);
            if (want)
                CHECK(res.absorbed_rim > 0, "%s: forward absorbed nothing at the rim", ctx);
            else if (!(res.warnings & LP_WARN_LEAK))
                CHECK(res.absorbed_rim == 0, "%s: forward absorbed %g at the rim, chain does not meet it",
                      ctx, res.absorbed_rim);
            hist[want]++;
            compared++;
        }
        lp_lens_destroy(lens);
    }
    printf("test_rim: rim depth compared on %ld view rays (%ld skipped as ambiguous); by depth:", compared,
           skipped);
    for (int k = 0; k <= 12; k++)
        printf(" %d:%ld", k, hist[k]);
    printf("\n");
    CHECK(compared > 3000 && hist[1] > 100 && hist[2] > 100 && hist[3] > 20,
          "rim depths sampled broadly");
    lp_result_release(&res);
    lp_backward_destroy(bw);
}

/* 5. rays through the exact cap/rim edge circle */
static void test_edge_circle(void)
{
    const struct { double R1, R2, t, D, D2; } shapes[] = {
        {50, -50, 8, 25, 0}, {50, -50, 8, 30, 20}, {-40, 40, 2, 25, 0}, {5, -5, 2, 6, 0},
        {25.8, INFINITY, 5.3, 25.4, 0}, {0, INFINITY, 3, 20, 0},
    };
    lp_result res;
    lp_result_init(&res);
    for (size_t si = 0; si < sizeof shapes / sizeof shapes[0]; si++) {
        frame f = si % 2 ? frame_make(V(1, 2, 3), rand_unit()) : frame_identity();
        ref_lens L;
        ref_init(&L, shapes[si].R1, shapes[si].R2, shapes[si].t, shapes[si].D, shapes[si].D2);
        lp_lens *lens = lens_n(shapes[si].R1, shapes[si].R2, shapes[si].t, shapes[si].D, shapes[si].D2,
                               1.5, &f);
        if (!lens)
            continue;
        for (int k = 0; k < 400; k++) {
            int back = k & 1;
            double phi = (k % 8 == 0) ? 0.0 : urange(0, 2 * M_PI);
            ref_real a = back ? L.a2 : L.a1;
            lv3 P = L3(a * ref_cos(phi), a * ref_sin(phi), back ? L.zb : L.zf);
            if (k % 8 == 0)
                P.y = 0; /* exactly on the x axis */
            lv3 d = lfrom(rand_unit());
            lv3 O = lsub(P, lscale(d, REF(3.0) * L.size));
            lp_vec3 Ow = lto(fw_point(&f, O)), dw = lto(fw_dir(&f, d));
            snprintf(ctx, sizeof ctx, "[edge circle: shape %zu ray %d]", si, k);
            lp_hit h;
            memset(&h, 0, sizeof h);
            if (lp_lens_intersect(lens, Ow, dw, 0.0, INFINITY, &h)) {
                CHECK(isfinite(h.t) && vfinite(h.point) && vfinite(h.normal) &&
                          fabs(vlen(h.normal) - 1) < 1e-9,
                      "%s: non-finite hit", ctx);
                /* The ray starts outside, so its first hit enters the
                 * glass or is on the opaque rim: a cap that it would
                 * leave there is not the first thing it meets (the edge
                 * circle belongs to the rim).  A knife edge (edge
                 * thickness 0, no rim) is left out: there the two caps
                 * tie and either may come first. */
                double dn = dw.x * h.normal.x + dw.y * h.normal.y + dw.z * h.normal.z;
                if (lp_lens_edge_thickness(lens) > 0.0)
                    CHECK(h.surface == LP_SURFACE_RIM || dn <= 0.0,
                          "%s: first hit on cap %d leaves the glass (d.n = %.3g)", ctx, h.surface,
                          dn);
            }
            lp_ray in;
            ray_init(&in, Ow, dw, 1.0);
            lp_trace_args args;
            lp_trace_args_init(&args);
            args.mode = (lp_mode)(k % 3);
            args.max_depth = 1 + k % 15;
            lp_status st = lp_trace_forward(lens, &in, &args, &res, NULL);
            CHECK(st == LP_OK, "%s: status %d", ctx, (int)st);
            check_balance(&res, ctx);
            for (size_t i = 0; i < res.count; i++)
                CHECK(res.rays[i].depth >= 1 && res.rays[i].depth <= args.max_depth, "%s: depth %d",
                      ctx, res.rays[i].depth);
            lp_backward *bw = NULL;
            lp_backward_create(&bw, NULL);
            if (bw) {
                st = lp_backward_build(bw, lens, Ow, dw, 550, &args, NULL);
                CHECK(st == LP_OK, "%s: backward build at the edge", ctx);
                size_t nq = lp_backward_query_count(bw);
                const lp_query *q = lp_backward_queries(bw);
                for (size_t i = 0; i < nq; i++)
                    CHECK(vfinite(q[i].origin) && vfinite(q[i].dir) && isfinite(q[i].op) &&
                              isfinite(q[i].bound) && q[i].bound >= 0,
                          "%s: query %zu not finite", ctx, i);
                lp_backward_destroy(bw);
            }
        }
        lp_lens_destroy(lens);
    }
    lp_result_release(&res);
}

int main(void)
{
    rng_state = SEED;
    test_rim_from_outside();
    test_cone_contains();
    test_refracted_into_rim();
    test_rim_depth_random();
    test_edge_circle();
    return check_finish("test_rim");
}
