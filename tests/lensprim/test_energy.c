/* test_energy.c -- energy bookkeeping of the forward trace on >= 1e4
 * random rays through random valid lenses of every family (catalog and
 * constant glasses, random media, placements, wavelengths, depths and
 * all three modes), lp_trace_forward_many against single calls,
 * min_weight and LP_SKIP_EXTERNAL_REFLECTION.
 *
 * Checked on every trace: in = out + skipped + absorbed_glass +
 * absorbed_rim + truncated (1e-12 relative), out = the sum of the output
 * intensities, each intensity finite and >= 0, vp unit and perpendicular
 * to dir in polarized mode, 1 <= depth <= max_depth, each output's origin
 * on the cap it names and its direction leaving the glass, the chain's
 * path bits, TIR parts 0/1 on the same ray with phases pi/2 apart
 * (ellipse axes).  A fixed-seed splitmix64 generator makes every failure
 * reproducible; messages carry the seed, lens and ray index.
 *
 * Geometry references (ref_real: binary128 where available) and the
 * Fresnel reflectances are written here; nothing expected comes from the
 * library.
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
/* Fresnel, written here (Born & Wolf), ref_real                       */
/* ------------------------------------------------------------------ */

/* Reflectances at incidence cosine ci from n1 into n2; 1, 1 under TIR. */
static void fresnel_R(ref_real ci, ref_real n1, ref_real n2, ref_real *Rs,
                      ref_real *Rp, ref_real *ct_out)
{
    ref_real st2 = (n1 / n2) * (n1 / n2) * (1 - ci) * (1 + ci);
    if (st2 >= 1) {
        *Rs = *Rp = 1;
        *ct_out = -1;
        return;
    }
    ref_real ct = ref_sqrt(1 - st2);
    ref_real rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    ref_real rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    *Rs = rs * rs;
    *Rp = rp * rp;
    *ct_out = ct;
}

/* ------------------------------------------------------------------ */

static const uint64_t SEED = 0x5eed0000c0ffeeULL;
static char ctx[256];
static long n_rays_total, n_hits_total, n_leaks, n_tir_pairs, n_rim_rays, n_truncated_rays;
static double worst_balance;

/* distance-like residual of a point from a cap surface (local) */
static ref_real cap_residual(const ref_lens *L, lv3 p, int back)
{
    ref_real c = back ? L->c2 : L->c1, z0 = back ? L->t : REF(0.0);
    ref_real Z = p.z - z0;
    ref_real G = c * (p.x * p.x + p.y * p.y + Z * Z) - 2 * Z;
    ref_real g = 2 * ref_sqrt(c * c * (p.x * p.x + p.y * p.y) + (c * Z - 1) * (c * Z - 1));
    return ref_fabs(G) / g;
}

static lv3 cap_normal(const ref_lens *L, lv3 p, int back)
{
    ref_real c = back ? L->c2 : L->c1, z0 = back ? L->t : REF(0.0);
    lv3 g = L3(c * p.x, c * p.y, c * (p.z - z0) - REF(1.0));
    return lnorm(back ? lscale(g, -REF(1.0)) : g);
}

/* expected path bits of the single chain through a lens: node 1 a
 * refraction in, nodes 2..d-1 internal reflections, node d a refraction
 * out; depth 1 is the external reflection */
static uint64_t chain_path(int d) { return d == 1 ? 1u : (((uint64_t)1 << (d - 1)) - 2); }

typedef struct {
    int robust;      /* the reference hit is far from edges and not grazing */
    int surf;        /* its surface */
    ref_real cos_i;
    lv3 n;           /* local outward normal at the hit */
} ref_entry;

static ref_entry classify(const ref_lens *L, lv3 O, lv3 d)
{
    ref_entry e;
    ref_hit h = ref_intersect(L, O, d, REF(0.0));
    e.surf = h.surf;
    e.robust = 0;
    e.cos_i = 0;
    if (h.surf < 0)
        return e;
    e.n = h.n;
    e.cos_i = -ldot(d, h.n);
    ref_real m = REF(1e-7) * L->size;
    int ok = e.cos_i > REF(1e-3);
    if (h.surf == LP_SURFACE_RIM) {
        ok = ok && h.p.z - L->zf > m && L->zb - h.p.z > m;
    } else {
        ref_real a = h.surf == LP_SURFACE_BACK ? L->a2 : L->a1;
        ok = ok && ref_sqrt(h.p.x * h.p.x + h.p.y * h.p.y) < a - m;
    }
    e.robust = ok;
    return e;
}

/* All the per-trace properties. */
static void check_trace(const ref_lens *L, const frame *f, const lp_glass *glass, const lp_ray *in,
                        const lp_trace_args *args, const lp_result *res, const ref_entry *ent)
{
    double I = in->intensity;
    double sum = res->out + res->skipped + res->absorbed_glass + res->absorbed_rim + res->truncated;
    n_rays_total++;
    if (res->warnings & LP_WARN_LEAK)
        n_leaks++;
    CHECK(isfinite(res->in) && isfinite(sum), "%s: bookkeeping not finite", ctx);
    CHECK(res->in >= 0 && res->out >= 0 && res->skipped >= 0 && res->absorbed_glass >= 0 &&
              res->absorbed_rim >= 0 && res->truncated >= 0,
          "%s: negative bookkeeping entry (in %g out %g skip %g glass %g rim %g trunc %g)", ctx,
          res->in, res->out, res->skipped, res->absorbed_glass, res->absorbed_rim, res->truncated);
    if (res->in > 0) {
        n_hits_total++;
        double e = fabs(res->in - sum) / res->in;
        if (e > worst_balance)
            worst_balance = e;
        CHECK_REL(sum, res->in, 1e-12, "%s: in = out + skipped + glass + rim + truncated", ctx);
    } else {
        CHECK(res->count == 0 && sum == 0, "%s: in = 0 but %zu rays / sum %g", ctx, res->count, sum);
    }
    if (res->truncated > 0)
        n_truncated_rays++;
    if (res->absorbed_rim > 0)
        n_rim_rays++;
    if (ent->robust) {
        CHECK_REL(res->in, I, 1e-15, "%s: in = the ray's intensity (robust hit)", ctx);
        if (ent->surf == LP_SURFACE_RIM) {
            CHECK(res->count == 0, "%s: a ray hitting the rim from outside gave %zu rays", ctx,
                  res->count);
            CHECK_REL(res->absorbed_rim, I, 1e-15, "%s: rim hit from outside: absorbed_rim = in", ctx);
        }
    }
    if (glass->n_tau == 0)
        CHECK(res->absorbed_glass <= 1e-15 * res->in, "%s: lossless glass absorbed %g", ctx,
              res->absorbed_glass);
    if (!L->rim && !(res->warnings & LP_WARN_LEAK))
        CHECK(res->absorbed_rim == 0, "%s: knife-edge lens (no rim) absorbed %g at the rim", ctx,
              res->absorbed_rim);

    /* per output ray */
    double out_sum = 0;
    int entry_surface = -1;
    for (size_t i = 0; i < res->count; i++)
        if (res->rays[i].depth == 1)
            entry_surface = res->rays[i].surface;
    if (entry_surface < 0 && ent->robust && ent->surf != LP_SURFACE_RIM)
        entry_surface = ent->surf;
    int per_depth[LP_MAX_DEPTH + 2] = {0};
    int part_mask[LP_MAX_DEPTH + 2] = {0};
    for (size_t i = 0; i < res->count; i++) {
        const lp_out_ray *o = &res->rays[i];
        const lp_ray *r = &o->ray;
        out_sum += r->intensity;
        CHECK(vfinite(r->origin) && vfinite(r->dir) && vfinite(r->vp) && isfinite(r->intensity) &&
                  isfinite(r->op) && isfinite(r->phase),
              "%s: output ray %zu not finite", ctx, i);
        CHECK(r->intensity >= 0, "%s: output ray %zu intensity %g < 0", ctx, i, r->intensity);
        CHECK(r->intensity <= I * (1 + 1e-12), "%s: output ray %zu intensity %g > input %g", ctx, i,
              r->intensity, I);
        CHECK(o->depth >= 1 && o->depth <= args->max_depth, "%s: depth %d outside 1..%d", ctx,
              o->depth, args->max_depth);
        CHECK(o->part == 0 || o->part == 1, "%s: part %d", ctx, o->part);
        CHECK(o->kind == LP_KIND_REFLECT || o->kind == LP_KIND_TRANSMIT, "%s: kind %d", ctx,
              (int)o->kind);
        CHECK(o->surface == LP_SURFACE_FRONT || o->surface == LP_SURFACE_BACK,
              "%s: output surface %d", ctx, o->surface);
        CHECK_ABS(vlen(r->dir), 1.0, 1e-12, "%s: |dir|", ctx);
        CHECK(r->lambda_nm == in->lambda_nm && r->ch == in->ch, "%s: lambda/ch not copied", ctx);
        CHECK(r->op >= in->op - 1e-12, "%s: op %g decreased below the input's %g", ctx, r->op, in->op);
        if (args->mode == LP_MODE_POLARIZED) {
            CHECK_ABS(vlen(r->vp), 1.0, 1e-9, "%s: |vp|", ctx);
            CHECK_ABS(vdot(r->vp, r->dir), 0.0, 1e-9, "%s: vp . dir", ctx);
        }
        if (o->depth >= 1 && o->depth <= LP_MAX_DEPTH) {
            per_depth[o->depth]++;
            part_mask[o->depth] |= 1 << (o->part & 1);
            CHECK(o->path == chain_path(o->depth), "%s: depth %d path %#llx, want %#llx", ctx,
                  o->depth, (unsigned long long)o->path, (unsigned long long)chain_path(o->depth));
        }
        if (o->depth == 1) {
            CHECK(o->kind == LP_KIND_REFLECT, "%s: depth-1 ray is not a reflection", ctx);
            CHECK_ABS(r->op, in->op, 1e-12, "%s: depth-1 reflection adds no optical path", ctx);
        }
        if (entry_surface >= 0 && o->depth >= 2)
            CHECK(o->kind == (o->surface == entry_surface ? LP_KIND_REFLECT : LP_KIND_TRANSMIT),
                  "%s: depth %d kind %d leaving surface %d (entered %d)", ctx, o->depth, (int)o->kind,
                  o->surface, entry_surface);
        /* the origin lies on the named cap and the ray leaves the glass */
        if (o->surface == LP_SURFACE_FRONT || o->surface == LP_SURFACE_BACK) {
            int back = o->surface == LP_SURFACE_BACK;
            lv3 p = fl_point(f, r->origin);
            ref_real a = back ? L->a2 : L->a1;
            CHECK(cap_residual(L, p, back) <= REF(1e-9) * L->size, "%s: ray %zu origin %.3g off its cap",
                  ctx, i, (double)cap_residual(L, p, back));
            CHECK(ref_sqrt(p.x * p.x + p.y * p.y) <= a * (1 + REF(1e-9)),
                  "%s: ray %zu origin outside the cap", ctx, i);
            lv3 n = cap_normal(L, p, back);
            CHECK(ldot(fl_dir(f, r->dir), n) >= -REF(1e-9), "%s: ray %zu points into the glass", ctx, i);
        }
    }
    if (res->count)
        CHECK_REL(out_sum, res->out, 1e-12, "%s: out = sum of output intensities", ctx);
    else
        CHECK(res->out == 0, "%s: out %g with no rays", ctx, res->out);
    for (int d = 1; d <= args->max_depth && d <= LP_MAX_DEPTH; d++) {
        CHECK(per_depth[d] <= 2, "%s: %d rays at depth %d (one chain, at most two TIR parts)", ctx,
              per_depth[d], d);
        if (per_depth[d] == 2)
            CHECK(part_mask[d] == 3, "%s: two rays at depth %d are not parts 0 and 1", ctx, d);
    }
    /* TIR pairs: the same ray, parts 0/1 along the ellipse axes, so
     * their total phases differ by pi/2 modulo pi */
    for (size_t i = 0; i < res->count; i++) {
        const lp_out_ray *p1 = &res->rays[i];
        if (p1->part != 1)
            continue;
        const lp_out_ray *p0 = NULL;
        for (size_t j = 0; j < res->count; j++)
            if (res->rays[j].part == 0 && res->rays[j].depth == p1->depth &&
                res->rays[j].kind == p1->kind && res->rays[j].path == p1->path)
                p0 = &res->rays[j];
        CHECK(p0 != NULL, "%s: part 1 at depth %d without its part 0", ctx, p1->depth);
        if (!p0)
            continue;
        n_tir_pairs++;
        CHECK(p0->surface == p1->surface &&
                  vlen(vsub(p0->ray.origin, p1->ray.origin)) <= 1e-12 * L->size &&
                  vlen(vsub(p0->ray.dir, p1->ray.dir)) <= 1e-12,
              "%s: TIR parts at depth %d are not the same ray", ctx, p1->depth);
        if (args->mode == LP_MODE_POLARIZED) {
            double I0 = p0->ray.intensity, I1 = p1->ray.intensity;
            if (fmin(I0, I1) > 1e-9 * (I0 + I1)) {
                double dphi = 2 * M_PI * (p1->ray.op - p0->ray.op) / in->lambda_nm * 1e6 -
                              M_PI * (p1->ray.kphi - p0->ray.kphi) + (p1->ray.phase - p0->ray.phase);
                double m = fmod(dphi, M_PI);
                if (m < 0)
                    m += M_PI;
                CHECK_ABS(m, M_PI / 2, 1e-9, "%s: TIR parts' phase difference mod pi (ellipse axes)",
                          ctx);
            }
        }
    }
}

static void make_ray(lp_ray *in, lp_vec3 origin, lp_vec3 dir)
{
    memset(in, 0, sizeof *in);
    in->origin = origin;
    in->dir = dir;
    lp_vec3 vp;
    do {
        vp = rand_unit();
    } while (vlen(vcross(vp, dir)) < 0.1);
    in->vp = vp;
    in->lambda_nm = urange(380, 780);
    in->intensity = urange(0.1, 10);
    in->op = urange(0, 5);
    in->kphi = (int)(sm64() % 4);
    in->phase = urange(-3, 3);
    in->ch = sm64();
}

/* A random ray aimed near a random lens point, from outside. */
static void random_ray(const ref_lens *L, const frame *f, lp_ray *in)
{
    int which = (int)(sm64() % 10);
    lv3 T;
    if (which < 4)
        T = random_surface_point(L, 0);
    else if (which < 8)
        T = random_surface_point(L, 1);
    else
        T = random_surface_point(L, 2);
    if (sm64() % 4 == 0) /* some misses and grazing rays */
        T = ladd(T, lscale(lfrom(rand_unit()), REF(0.05) * L->size * urand()));
    lp_vec3 dir = rand_unit();
    lv3 O = lsub(T, lscale(lfrom(dir), REF(2.0) * L->size));
    make_ray(in, lto(fw_point(f, O)), lto(fw_dir(f, lfrom(dir))));
}

static void test_random_bookkeeping(void)
{
    const int n_lenses = 200, rays_per_lens = 60;
    int fam_count[13] = {0};
    long mode_count[3] = {0};
    lp_result res;
    lp_result_init(&res);
    printf("test_energy: seed %#llx, %d lenses x %d rays\n", (unsigned long long)SEED, n_lenses,
           rays_per_lens);
    for (int li = 0; li < n_lenses; li++) {
        rng_state = SEED + (uint64_t)li * 0x2545F4914F6CDD1DULL;
        rshape s;
        random_shape(&s);
        fam_count[s.family]++;
        lp_glass glass, medium;
        random_glass(&glass);
        random_medium(&medium);
        frame f = frame_make(V(urange(-100, 100), urange(-100, 100), urange(-100, 100)), rand_unit());
        ref_lens L;
        ref_init(&L, s.R1, s.R2, s.t, s.D, s.D2);
        lp_lens *lens = make_lens_g(&s, &glass, &medium, &f);
        if (!lens)
            continue;
        for (int ri = 0; ri < rays_per_lens; ri++) {
            snprintf(ctx, sizeof ctx, "[seed %#llx lens %d (%s, %s in n=%g) ray %d]",
                     (unsigned long long)SEED, li, family_names[s.family], glass.name,
                     lp_glass_index(&medium, 550), ri);
            lp_ray in;
            random_ray(&L, &f, &in);
            lp_trace_args args;
            lp_trace_args_init(&args);
            args.mode = (lp_mode)(sm64() % 3);
            args.max_depth = 1 + (int)(sm64() % 20);
            mode_count[args.mode]++;
            lv3 Ol = fl_point(&f, in.origin), dl = lnorm(fl_dir(&f, in.dir));
            ref_entry ent = classify(&L, Ol, dl);
            lp_error err;
            lp_status st = lp_trace_forward(lens, &in, &args, &res, &err);
            CHECK(st == LP_OK, "%s: trace status %d: %s", ctx, (int)st, err.message);
            if (st != LP_OK)
                continue;
            check_trace(&L, &f, &glass, &in, &args, &res, &ent);
        }
        lp_lens_destroy(lens);
    }
    lp_result_release(&res);
    printf("test_energy: %ld rays, %ld hit the lens, %ld reached the rim, %ld truncated, %ld TIR part "
           "pairs, %ld with LP_WARN_LEAK; worst balance %.3g\n",
           n_rays_total, n_hits_total, n_rim_rays, n_truncated_rays, n_tir_pairs, n_leaks,
           worst_balance);
    printf("test_energy: modes polarized %ld fresnel %ld schlick %ld; families:", mode_count[0],
           mode_count[1], mode_count[2]);
    for (int i = 0; i < 13; i++)
        printf(" %s=%d", family_names[i], fam_count[i]);
    printf("\n");
    CHECK(n_rays_total >= 10000, "at least 1e4 rays traced (%ld)", n_rays_total);
    CHECK(n_hits_total >= 5000, "enough rays hit a lens (%ld)", n_hits_total);
    CHECK(n_rim_rays > 100 && n_truncated_rays > 100 && n_tir_pairs > 10,
          "the sample reaches the rim, truncation and TIR");
}

/* lp_trace_forward_many == single calls */
static void test_many(void)
{
    rng_state = SEED ^ 0x77;
    for (int rep = 0; rep < 4; rep++) {
        rshape s;
        random_shape(&s);
        lp_glass glass, medium;
        random_glass(&glass);
        random_medium(&medium);
        frame f = frame_make(V(urange(-10, 10), urange(-10, 10), urange(-10, 10)), rand_unit());
        ref_lens L;
        ref_init(&L, s.R1, s.R2, s.t, s.D, s.D2);
        lp_lens *lens = make_lens_g(&s, &glass, &medium, &f);
        if (!lens)
            continue;
        enum { N = 1000 };
        static lp_ray rays[N];
        static size_t offsets[N + 1];
        for (int i = 0; i < N; i++)
            random_ray(&L, &f, &rays[i]);
        lp_trace_args args;
        lp_trace_args_init(&args);
        args.mode = (lp_mode)(rep % 3);
        args.max_depth = 4 + 3 * rep;
        lp_result many, one;
        lp_result_init(&many);
        lp_result_init(&one);
        lp_error err;
        lp_status st = lp_trace_forward_many(lens, rays, N, &args, &many, offsets, &err);
        CHECK(st == LP_OK, "forward_many status %d: %s", (int)st, err.message);
        if (st != LP_OK) {
            lp_lens_destroy(lens);
            continue;
        }
        double in = 0, out = 0, skipped = 0, ag = 0, ar = 0, tr = 0, worst = 0;
        int mismatches = 0;
        CHECK(offsets[0] == 0 && offsets[N] == many.count, "forward_many offsets span the rays");
        for (int i = 0; i < N; i++) {
            lp_trace_forward(lens, &rays[i], &args, &one, NULL);
            in += one.in;
            out += one.out;
            skipped += one.skipped;
            ag += one.absorbed_glass;
            ar += one.absorbed_rim;
            tr += one.truncated;
            size_t n = offsets[i + 1] - offsets[i];
            if (n != one.count) {
                mismatches++;
                continue;
            }
            for (size_t k = 0; k < n; k++) {
                const lp_out_ray *a = &many.rays[offsets[i] + k], *b = &one.rays[k];
                if (a->depth != b->depth || a->kind != b->kind || a->surface != b->surface ||
                    a->part != b->part || a->path != b->path || a->ray.kphi != b->ray.kphi ||
                    a->ray.ch != b->ray.ch) {
                    mismatches++;
                    continue;
                }
                double e = fabs(a->ray.intensity - b->ray.intensity) / fmax(b->ray.intensity, 1e-300);
                e = fmax(e, vlen(vsub(a->ray.origin, b->ray.origin)) / L.size);
                e = fmax(e, vlen(vsub(a->ray.dir, b->ray.dir)));
                e = fmax(e, vlen(vsub(a->ray.vp, b->ray.vp)));
                e = fmax(e, fabs(a->ray.op - b->ray.op) / fmax(1, fabs(b->ray.op)));
                e = fmax(e, fabs(a->ray.phase - b->ray.phase));
                if (e > worst)
                    worst = e;
            }
        }
        CHECK(mismatches == 0, "forward_many rep %d: %d rays differ from single calls", rep, mismatches);
        CHECK_ABS(worst, 0.0, 1e-14, "forward_many rep %d: ray fields vs single calls", rep);
        CHECK_REL(many.in, in, 1e-12, "forward_many: in = sum of single calls");
        CHECK_REL(many.out, out, 1e-12, "forward_many: out = sum of single calls");
        CHECK_ABS(many.skipped - skipped, 0.0, 1e-12 * in, "forward_many: skipped");
        CHECK_ABS(many.absorbed_glass - ag, 0.0, 1e-12 * in, "forward_many: absorbed_glass");
        CHECK_ABS(many.absorbed_rim - ar, 0.0, 1e-12 * in, "forward_many: absorbed_rim");
        CHECK_ABS(many.truncated - tr, 0.0, 1e-12 * in, "forward_many: truncated");
        CHECK_REL(many.out + many.skipped + many.absorbed_glass + many.absorbed_rim + many.truncated,
                  many.in, 1e-12, "forward_many: summed bookkeeping balances");
        /* an invalid ray (vp parallel to dir) is reported by index */
        rays[5].vp = rays[5].dir;
        memset(&err, 0, sizeof err);
        st = lp_trace_forward_many(lens, rays, N, &args, &many, offsets, &err);
        CHECK(st != LP_OK, "forward_many with vp parallel to dir at ray 5 accepted");
        CHECK(has_word(err.message, "5"), "forward_many error message \"%s\" names ray 5", err.message);
        lp_result_release(&many);
        lp_result_release(&one);
        lp_lens_destroy(lens);
    }
}

/* min_weight stops the chain early; the bookkeeping still balances. */
static void test_min_weight(void)
{
    lp_lens_desc desc;
    lp_lens_desc_init(&desc);
    desc.radius1 = 50;
    desc.radius2 = -50;
    desc.thickness = 8;
    desc.diameter = 25;
    lp_glass_init_constant(&desc.glass, 1.5);
    lp_lens *lens = NULL;
    CHECK(lp_lens_create(&desc, &lens, NULL) == LP_OK, "min_weight lens");
    if (!lens)
        return;
    for (int k = 0; k < 20; k++) {
        lp_ray in;
        lp_vec3 d = vnorm(V(urange(-0.05, 0.05), urange(-0.05, 0.05), 1));
        make_ray(&in, V(urange(-3, 3), urange(-3, 3), -20), d);
        in.op = 0;
        lp_trace_args args;
        lp_trace_args_init(&args);
        args.mode = (lp_mode)(k % 3);
        args.max_depth = 20;
        lp_result full, cut;
        lp_result_init(&full);
        lp_result_init(&cut);
        lp_trace_forward(lens, &in, &args, &full, NULL);
        args.min_weight = 1e-3;
        lp_trace_forward(lens, &in, &args, &cut, NULL);
        int dfull = 0, dcut = 0;
        for (size_t i = 0; i < full.count; i++)
            dfull = full.rays[i].depth > dfull ? full.rays[i].depth : dfull;
        for (size_t i = 0; i < cut.count; i++)
            dcut = cut.rays[i].depth > dcut ? cut.rays[i].depth : dcut;
        /* near-normal: internal power after j internal reflections is
         * ~ 0.96 * 0.04^j, below 1e-3 from j = 3 on: the chain ends by
         * depth 5, while without a cut it runs to depth 20 */
        CHECK(dfull == 20, "min_weight 0: chain reaches max_depth 20 (got %d)", dfull);
        CHECK(dcut >= 2 && dcut <= 6, "min_weight 1e-3: chain stops early (depth %d)", dcut);
        CHECK(cut.count < full.count, "min_weight 1e-3: fewer rays (%zu vs %zu)", cut.count, full.count);
        CHECK_REL(cut.out + cut.skipped + cut.absorbed_glass + cut.absorbed_rim + cut.truncated, cut.in,
                  1e-12, "min_weight 1e-3: bookkeeping");
        CHECK_REL(cut.in, in.intensity, 1e-15, "min_weight: in");
        CHECK(cut.truncated > 0 && cut.truncated < 2e-3 * cut.in,
              "min_weight 1e-3: truncated %g is the cut branch (< 2e-3 in)", cut.truncated / cut.in);
        /* every ray of the cut trace is a ray of the full trace */
        int missing = 0;
        for (size_t i = 0; i < cut.count; i++) {
            int found = 0;
            for (size_t j = 0; j < full.count && !found; j++)
                found = full.rays[j].depth == cut.rays[i].depth &&
                        full.rays[j].part == cut.rays[i].part &&
                        fabs(full.rays[j].ray.intensity - cut.rays[i].ray.intensity) <=
                            1e-12 * full.rays[j].ray.intensity;
            missing += !found;
        }
        CHECK(missing == 0, "min_weight: %d rays of the cut trace are not in the full trace", missing);
        lp_result_release(&full);
        lp_result_release(&cut);
    }
    lp_lens_destroy(lens);
}

/* LP_SKIP_EXTERNAL_REFLECTION: the depth-1 ray goes to `skipped`; its
 * intensity follows Fresnel's equations (computed here). */
static void test_skip_external(void)
{
    rng_state = SEED ^ 0x5151;
    int checked_fresnel = 0;
    for (int rep = 0; rep < 40; rep++) {
        rshape s;
        random_shape(&s);
        lp_glass glass, medium;
        double ng = urange(1.3, 2.0), nm = (rep & 1) ? 1.0 : urange(1.0, 1.4);
        lp_glass_init_constant(&glass, ng);
        lp_glass_init_constant(&medium, nm);
        frame f = frame_make(V(urange(-10, 10), urange(-10, 10), urange(-10, 10)), rand_unit());
        ref_lens L;
        ref_init(&L, s.R1, s.R2, s.t, s.D, s.D2);
        lp_lens *lens = make_lens_g(&s, &glass, &medium, &f);
        if (!lens)
            continue;
        for (int ri = 0; ri < 30; ri++) {
            snprintf(ctx, sizeof ctx, "[skip-external rep %d ray %d, %s]", rep, ri,
                     family_names[s.family]);
            lp_ray in;
            random_ray(&L, &f, &in);
            lp_trace_args args;
            lp_trace_args_init(&args);
            args.mode = (lp_mode)(ri % 3);
            args.max_depth = 6;
            lp_result a, b;
            lp_result_init(&a);
            lp_result_init(&b);
            lp_trace_forward(lens, &in, &args, &a, NULL);
            args.flags = LP_SKIP_EXTERNAL_REFLECTION;
            lp_trace_forward(lens, &in, &args, &b, NULL);
            double r1 = 0;
            size_t n1 = 0;
            const lp_out_ray *refl = NULL;
            for (size_t i = 0; i < a.count; i++)
                if (a.rays[i].depth == 1) {
                    r1 += a.rays[i].ray.intensity;
                    n1++;
                    refl = &a.rays[i];
                }
            for (size_t i = 0; i < b.count; i++)
                CHECK(b.rays[i].depth != 1, "%s: depth-1 ray present despite the flag", ctx);
            CHECK(b.count + n1 == a.count, "%s: flag removed %zu rays, want %zu", ctx,
                  a.count - b.count, n1);
            CHECK_ABS(b.skipped - a.skipped, r1, 1e-12 * fmax(a.in, 1e-300),
                      "%s: skipped = the depth-1 intensity", ctx);
            CHECK_REL(b.in, a.in, 1e-15, "%s: in unchanged by the flag", ctx);
            if (b.in > 0)
                CHECK_REL(b.out + b.skipped + b.absorbed_glass + b.absorbed_rim + b.truncated, b.in,
                          1e-12, "%s: bookkeeping with the flag", ctx);
            /* Fresnel at the entry node, computed here */
            lv3 Ol = fl_point(&f, in.origin), dl = lnorm(fl_dir(&f, in.dir));
            ref_entry ent = classify(&L, Ol, dl);
            if (refl && ent.robust && ent.surf != LP_SURFACE_RIM && ent.cos_i > REF(0.01)) {
                ref_real Rs, Rp, ct;
                fresnel_R(ent.cos_i, nm, ng, &Rs, &Rp, &ct);
                ref_real R;
                if (args.mode == LP_MODE_POLARIZED) {
                    lv3 v = fl_dir(&f, in.vp);
                    v = lnorm(lsub(v, lscale(dl, ldot(v, dl))));
                    lv3 sx = L3(dl.y * ent.n.z - dl.z * ent.n.y, dl.z * ent.n.x - dl.x * ent.n.z,
                                dl.x * ent.n.y - dl.y * ent.n.x);
                    ref_real as2 = llen(sx) > REF(1e-9) ? ref_pow(ldot(v, lnorm(sx)), 2) : REF(1.0);
                    R = Rs * as2 + Rp * (1 - as2);
                } else if (args.mode == LP_MODE_FRESNEL) {
                    R = (Rs + Rp) / 2;
                } else {
                    ref_real R0 = ref_pow((nm - ng) / (nm + ng), 2);
                    ref_real c = nm <= ng ? ent.cos_i : ct;
                    R = ct < 0 ? REF(1.0) : R0 + (1 - R0) * ref_pow(1 - c, 5);
                }
                CHECK_ABS(r1 / in.intensity, (double)R, 1e-12 + 1e-10 * (double)R,
                          "%s: depth-1 reflectance vs Fresnel (mode %d)", ctx, (int)args.mode);
                lv3 dr = ladd(dl, lscale(ent.n, 2 * ent.cos_i));
                CHECK_ABS((double)llen(lsub(fl_dir(&f, refl->ray.dir), dr)), 0.0, 1e-12,
                          "%s: depth-1 direction = mirror of the incident", ctx);
                checked_fresnel++;
            }
            lp_result_release(&a);
            lp_result_release(&b);
        }
        lp_lens_destroy(lens);
    }
    CHECK(checked_fresnel > 200, "depth-1 Fresnel checked on %d rays", checked_fresnel);
}

int main(void)
{
    test_random_bookkeeping();
    test_many();
    test_min_weight();
    test_skip_external();
    return check_finish("test_energy");
}
