/* test_backward_many.c -- lp_backward_build_many, the backward build of
 * one view ray at many wavelengths at once.
 *
 * identity   For placed and tilted lenses of every kind (dispersive
 *            catalog glasses with absorption, one in a dispersive medium,
 *            a ball whose chains totally reflect inside, a flat plate seen
 *            along its axis, a conical rim, a knife edge, a uniaxial
 *            crystal, a lens in a denser medium, one index-matched to
 *            its medium), every mode, depths 1, 2, 5 and 12, flags, a filter
 *            and min_weight, and view rays of every kind (from both sides,
 *            along the axis, grazing, at the rim, from points on the lens,
 *            missing it): n builders are built by lp_backward_build_many
 *            at n wavelengths (n = 1, 3, 16, 17, 40, some wavelengths
 *            repeated) and n others by lp_backward_build one by one.  The
 *            statuses, the queries (compared as bytes), the rim depths,
 *            the filter's calls (every argument, in order) and the result
 *            of gathering two bundle rays through every query (every
 *            outgoing ray as bytes and every sum, and their power alone,
 *            lp_backward_gather_power_many, of builds with and without
 *            LP_BACKWARD_POWER) must be identical.  The
 *            contract is exactness, so the tolerance is 0.  A query
 *            lp_backward_query_leaves says leaves its lens must have no
 *            hit of lp_lens_intersect, and both builds must say the same.
 * errors     NULL arguments; a NULL builder, an invalid wavelength, bad
 *            args, a view ray that is not finite or has no direction: the
 *            first failing build's status and message, prefixed with its
 *            wavelength, the builders before it built, those after it
 *            untouched; a builder given twice holds its last wavelength's
 *            build; n = 0.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "splitmix.h"
#include "same_bits.h"
#include "lensprim.h"
#include "placed_lens.h"

#define PI 3.14159265358979323846
#define MAX_WL 40

static uint64_t rng = 0xb4c3a11e5ull;
static double uniform(void)
{
    return splitmix_uniform(&rng);
}

/* The filter's calls, logged: every argument, in order. */
typedef struct call_log {
    size_t n, cap;
    lp_branch_info *calls;
} call_log;

static int log_filter(const lp_branch_info *info, void *user)
{
    call_log *log = user;
    if (log->n == log->cap) {
        log->cap = log->cap ? 2 * log->cap : 256;
        log->calls = realloc(log->calls, log->cap * sizeof *log->calls);
        if (!log->calls)
            abort();
    }
    log->calls[log->n++] = *info;
    /* keep the transmitted queries and the odd depths */
    return info->kind == LP_KIND_TRANSMIT || info->depth % 2 == 1;
}

static int same_calls(const call_log *a, const call_log *b)
{
    if (a->n != b->n)
        return 0;
    for (size_t i = 0; i < a->n; i++) {
        const lp_branch_info *x = &a->calls[i], *y = &b->calls[i];
        if (x->depth != y->depth || x->kind != y->kind || x->surface != y->surface ||
            memcmp(&x->origin, &y->origin, sizeof x->origin) != 0 ||
            memcmp(&x->dir, &y->dir, sizeof x->dir) != 0 ||
            memcmp(&x->bound, &y->bound, sizeof x->bound) != 0)
            return 0;
    }
    return 1;
}

/* The same query, field by field as bytes (no padding compared). */
static int same_query(const lp_query *a, const lp_query *b)
{
    return memcmp(&a->origin, &b->origin, sizeof a->origin) == 0 &&
           memcmp(&a->dir, &b->dir, sizeof a->dir) == 0 && a->depth == b->depth &&
           a->kind == b->kind && a->surface == b->surface && a->path == b->path &&
           memcmp(&a->op, &b->op, sizeof a->op) == 0 &&
           memcmp(&a->bound, &b->bound, sizeof a->bound) == 0 &&
           memcmp(&a->weight, &b->weight, sizeof a->weight) == 0 && a->waves == b->waves;
}

/* Do two builders hold the same build?  Queries, rim depth, and two
 * bundle rays gathered through every query. */
static int same_build(const lp_backward *a, const lp_backward *b, double lambda_nm)
{
    static lp_result ra, rb;
    size_t n = lp_backward_query_count(a);
    if (n != lp_backward_query_count(b) || lp_backward_rim_depth(a) != lp_backward_rim_depth(b))
        return 0;
    const lp_query *qa = lp_backward_queries(a), *qb = lp_backward_queries(b);
    for (size_t q = 0; q < n; q++) {
        if (!same_query(&qa[q], &qb[q]))
            return 0;
        lp_ray bundle[2];
        for (int i = 0; i < 2; i++) {
            lp_vec3 d = qa[q].dir;
            /* a field direction off the query's axis */
            lp_vec3 h = fabs(d.x) < 0.6 ? vec(1, 0, 0) : vec(0, 1, 0);
            bundle[i].origin = vec(0, 0, 0);
            bundle[i].dir = vec(-d.x, -d.y, -d.z);
            bundle[i].lambda_nm = lambda_nm;
            bundle[i].intensity = 0.5 + i;
            bundle[i].vp = i == 0 ? h : vec(h.y + 0.3, h.z + 0.2, h.x + 0.1);
            bundle[i].kphi = i;
            bundle[i].op = 3.0 * i;
            bundle[i].phase = 0.7 - 2.0 * i;
            bundle[i].ch = 9u + (uint64_t)i;
        }
        lp_result_clear(&ra);
        lp_result_clear(&rb);
        lp_status sa = lp_backward_gather(a, q, bundle, 2, &ra, NULL);
        lp_status sb = lp_backward_gather(b, q, bundle, 2, &rb, NULL);
        if (sa != sb || !same_books(&ra, &rb))
            return 0;
        for (size_t k = 0; k < ra.count; k++)
            if (!same_out_ray(&ra.rays[k], &rb.rays[k]))
                return 0;
        /* and their power alone (a power build's forms), bit for bit */
        const lp_ray *pb = bundle;
        size_t two = 2;
        double pa = -1.0, pbw = -2.0;
        sa = lp_backward_gather_power_many(&a, &q, &pb, &two, 1, &pa, NULL);
        sb = lp_backward_gather_power_many(&b, &q, &pb, &two, 1, &pbw, NULL);
        if (sa != sb || memcmp(&pa, &pbw, sizeof pa) != 0)
            return 0;
    }
    return 1;
}

static lp_backward *one[MAX_WL], *many[MAX_WL];
static int n_cases, n_builds, n_queries, n_rim, n_leaves;

/* One view ray at wavelengths lambda[0..n): many vs one by one. */
static void identity_case(const char *name, const lp_lens *lens, lp_vec3 o, lp_vec3 d,
                          const double *lambda, size_t n, const lp_trace_args *args)
{
    static call_log log_one, log_many;
    lp_trace_args a = *args;
    lp_error err;
    lp_status st1 = LP_OK, stm;

    log_one.n = log_many.n = 0;
    if (a.filter)
        a.user = &log_one;
    for (size_t k = 0; k < n && st1 == LP_OK; k++)
        st1 = lp_backward_build(one[k], lens, o, d, lambda[k], &a, &err);
    if (a.filter)
        a.user = &log_many;
    stm = lp_backward_build_many(many, n, lens, o, d, lambda, &a, &err);
    CHECK(st1 == LP_OK && stm == LP_OK, "%s: builds %d / %d: %s", name, (int)st1, (int)stm,
          err.message);
    CHECK(same_calls(&log_one, &log_many), "%s: the filter's calls (%zu / %zu)", name,
          log_one.n, log_many.n);
    size_t differ = 0, wrong = 0;
    for (size_t k = 0; k < n; k++) {
        differ += !same_build(one[k], many[k], lambda[k]);
        /* lp_backward_query_leaves: the same for both builds, and where it
         * says so, the lens really has no hit along the query ray */
        const lp_query *q = lp_backward_queries(many[k]);
        for (size_t j = 0; j < lp_backward_query_count(many[k]); j++) {
            int leaves = lp_backward_query_leaves(many[k], j);
            lp_hit h;
            differ += leaves != lp_backward_query_leaves(one[k], j);
            wrong += leaves && lp_lens_intersect(lens, q[j].origin, q[j].dir, 0.0, INFINITY, &h);
            n_leaves += leaves;
        }
        n_queries += (int)lp_backward_query_count(many[k]);
        n_rim += lp_backward_rim_depth(many[k]) > 0;
    }
    CHECK(differ == 0, "%s mode %d depth %d: %zu of %zu wavelengths differ", name,
          (int)args->mode, args->max_depth, differ, n);
    CHECK(wrong == 0, "%s mode %d depth %d: %zu queries said to leave the lens meet it", name,
          (int)args->mode, args->max_depth, wrong);
    n_cases++;
    n_builds += (int)n;
}

static void test_identity(void)
{
    const placed_shape shapes[] = {
        {"biconvex N-BK7", 50, -50, 8, 25, 0, "N-BK7", 0, NULL, 0, 0},
        {"ball N-SF11", 10, -10, 19, 19.9, 0, "N-SF11", 0, NULL, 0, 0},
        {"meniscus F2 in CaF2", 20, 40, 4, 20, 0, "F2", 0, "CAF2", 0, 0},
        {"flat plate N-SF6", 0, 0, 3, 20, 0, "N-SF6", 0, NULL, 0, 0},
        {"conical rim n=1.6", 60, -30, 6, 24, 18, NULL, 1.6, NULL, 0, 0},
        {"knife edge n=1.5", 20, -20, 2 * (20 - sqrt(400 - 100)), 20, 0, NULL, 1.5, NULL, 0, 0},
        {"crystal plate", 0, 0, 3, 20, 0, NULL, 0, NULL, 1, 0},
        /* in a denser medium: total internal reflection off the outside */
        {"biconvex n=1.3 in N-SF11", 40, -40, 6, 24, 0, NULL, 1.3, "N-SF11", 0, 0},
        /* index-matched: no interface at the caps (fresnel.h's n1 == n2) */
        {"N-BK7 in N-BK7", 30, -40, 5, 20, 0, "N-BK7", 0, "N-BK7", 0, 0},
    };
    const size_t counts[] = {1, 3, 16, 17, 40};
    const int depths[] = {1, 2, 5, 12};

    for (size_t si = 0; si < sizeof shapes / sizeof shapes[0]; si++) {
        lp_lens_desc desc;
        lp_lens *lens;
        lp_vec3 u, v, w;
        if (placed_lens(&shapes[si], si, &lens, &desc, &u, &v, &w) != 0)
            continue;
        double h = 0.5 * desc.diameter, t = desc.thickness;
        for (int ri = 0; ri < 36; ri++) {
            lp_vec3 o, d;
            int kind = ri % 6;
            if (kind == 0) { /* along the axis, from the front */
                o = place(desc.position, u, v, w, 0, 0, -3.0 * h);
                d = w;
            } else if (kind == 1) { /* at the rim, from the side */
                o = place(desc.position, u, v, w, 2.0 * h, 0.3, 0.5 * t);
                d = place(vec(0, 0, 0), u, v, w, -1.0, 0.05 * uniform(), 0.02);
            } else if (kind == 2) { /* from a point on the front cap */
                lp_hit hit;
                lp_vec3 o0 = place(desc.position, u, v, w, 0.3 * h, 0.2 * h, -3.0 * h);
                if (lp_lens_intersect(lens, o0, w, 0.0, INFINITY, &hit))
                    o = hit.point;
                else
                    o = o0;
                d = place(vec(0, 0, 0), u, v, w, -0.2, 0.1, 1.0);
            } else { /* from either side, steep or grazing */
                double rho = 1.2 * h * sqrt(uniform()), phi = 2.0 * PI * uniform();
                double tilt = (kind == 5 ? 1.4 : 0.7) * uniform(), az = 2.0 * PI * uniform();
                double side = kind == 4 ? t + 3.0 * h : -3.0 * h;
                o = place(desc.position, u, v, w, rho * cos(phi), rho * sin(phi), side);
                d = place(vec(0, 0, 0), u, v, w, sin(tilt) * cos(az), sin(tilt) * sin(az),
                          (side < 0.0 ? 1.0 : -1.0) * cos(tilt));
            }
            size_t n = counts[ri % 5];
            double lambda[MAX_WL];
            for (size_t k = 0; k < n; k++)
                lambda[k] = k % 7 == 6 ? lambda[k - 2] : 400.0 + 300.0 * uniform();
            lp_trace_args a;
            lp_trace_args_init(&a);
            a.mode = (lp_mode)(ri % 3);
            a.max_depth = shapes[si].crystal ? 1 + ri % 4 : depths[ri % 4];
            char name[128];
            snprintf(name, sizeof name, "%s, view ray %d", shapes[si].name, ri);
            identity_case(name, lens, o, d, lambda, n, &a);
            /* for power alone (the queries' power forms) */
            a.flags = LP_BACKWARD_POWER;
            identity_case(name, lens, o, d, lambda, n, &a);
            /* flags, the filter and a weight cut */
            a.flags = ri % 2 ? LP_SKIP_EXTERNAL_REFLECTION : LP_SKIP_REFLECTED;
            a.flags |= ri % 4 < 2 ? LP_BACKWARD_POWER : 0u;
            a.filter = log_filter;
            a.min_weight = ri % 3 ? 1e-3 : 0.0;
            identity_case(name, lens, o, d, lambda, n, &a);
        }
        lp_lens_destroy(lens);
    }
    printf("identity: %d calls, %d builds, %d queries (%d with a rim depth), every query, "
           "filter call and gather identical to lp_backward_build's; %d queries leave "
           "their lens, none of them meets it\n",
           n_cases, n_builds, n_queries, n_rim, n_leaves);
    CHECK(n_leaves > 0, "some query leaves its lens");
}

static void test_errors(void)
{
    lp_lens_desc desc;
    lp_lens *lens;
    lp_error err, e1;
    lp_vec3 o = vec(1, 0.5, -20), d = vec(0, 0, 1);
    double lambda[6] = {450, 500, 550, 600, 650, 700};
    lp_backward *bw[6];

    lp_lens_desc_init(&desc);
    desc.radius1 = 40;
    desc.radius2 = -40;
    desc.thickness = 5;
    desc.diameter = 20;
    CHECK(lp_glass_builtin("N-BK7", &desc.glass, &err) == LP_OK, "%s", err.message);
    CHECK(lp_lens_create(&desc, &lens, &err) == LP_OK, "%s", err.message);
    for (int k = 0; k < 6; k++)
        bw[k] = many[k];

    CHECK(lp_backward_build_many(bw, 6, NULL, o, d, lambda, NULL, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL lens");
    CHECK(lp_backward_build_many(NULL, 6, lens, o, d, lambda, NULL, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL builders");
    CHECK(lp_backward_build_many(bw, 6, lens, o, d, NULL, NULL, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL wavelengths");
    CHECK(lp_backward_build_many(NULL, 0, lens, o, d, NULL, NULL, &err) == LP_OK,
          "n = 0: nothing to do");

    /* the first failing build stops the call: its wavelength, the builds
     * before it made, those after it untouched (still the marker build) */
    lp_vec3 marker_o = vec(-3, 1, -20);
    for (int c = 0; c < 6; c++) {
        double lam[6];
        lp_backward *b[6];
        lp_trace_args a, *ap = NULL;
        lp_vec3 oo = o, dd = d;
        size_t k = 2;
        memcpy(lam, lambda, sizeof lam);
        memcpy(b, bw, sizeof b);
        for (int i = 0; i < 6; i++)
            CHECK(lp_backward_build(bw[i], lens, marker_o, d, 555.0, NULL, NULL) == LP_OK,
                  "marker");
        lp_trace_args_init(&a);
        switch (c) {
        case 0: b[2] = NULL; break;
        case 1: lam[2] = NAN; break;
        case 2: lam[2] = -5.0; break;
        case 3: a.max_depth = 0, ap = &a, k = 0; break;
        case 4: oo.x = INFINITY, k = 0; break;
        case 5: dd = vec(0, 0, 0), k = 0; break;
        }
        lp_status st = lp_backward_build_many(b, 6, lens, oo, dd, lam, ap, &err);
        /* what lp_backward_build says of the failing build */
        lp_status s1 = b[k] ? lp_backward_build(one[0], lens, oo, dd, lam[k], ap, &e1)
                            : LP_ERROR_INVALID_ARGUMENT;
        char want[300];
        snprintf(want, sizeof want, "wavelength %zu: %s", k,
                 b[k] ? e1.message : "NULL lp_backward");
        CHECK(st != LP_OK && st == s1 && strcmp(err.message, want) == 0,
              "case %d: '%s', want '%s'", c, err.message, want);
        for (size_t i = 0; i < k; i++) {
            lp_backward_build(one[0], lens, oo, dd, lam[i], ap, NULL);
            CHECK(same_build(one[0], b[i], lam[i]), "case %d: build %zu made", c, i);
        }
        lp_backward_build(one[0], lens, marker_o, d, 555.0, NULL, NULL);
        for (size_t i = k + 1; i < 6; i++)
            CHECK(same_build(one[0], b[i], 555.0), "case %d: build %zu untouched", c, i);
        if (b[k]) {
            CHECK(lp_backward_query_count(b[k]) == 0, "case %d: the failed build is empty", c);
        }
    }

    /* a builder twice: it holds the later wavelength's build */
    lp_backward *twice[3] = {bw[0], bw[1], bw[0]};
    CHECK(lp_backward_build_many(twice, 3, lens, o, d, lambda, NULL, &err) == LP_OK, "%s",
          err.message);
    lp_backward_build(one[0], lens, o, d, lambda[2], NULL, NULL);
    lp_backward_build(one[1], lens, o, d, lambda[1], NULL, NULL);
    CHECK(same_build(one[0], bw[0], lambda[2]) && same_build(one[1], bw[1], lambda[1]),
          "a builder twice holds its last build");
    lp_lens_destroy(lens);
}

int main(void)
{
    lp_error err;
    for (int k = 0; k < MAX_WL; k++)
        if (lp_backward_create(&one[k], &err) != LP_OK ||
            lp_backward_create(&many[k], &err) != LP_OK)
            return 1;
    test_identity();
    test_errors();
    for (int k = 0; k < MAX_WL; k++) {
        lp_backward_destroy(one[k]);
        lp_backward_destroy(many[k]);
    }
    return check_finish("test_backward_many");
}
