/* test_gather_many.c -- lp_backward_gather_many, the gathers of many
 * builders in one call, and lp_backward_gather_power_many, their power
 * alone.
 *
 * identity   For placed and tilted lenses of every kind (dispersive
 *            catalog glasses with absorption, one in a dispersive medium,
 *            a ball whose chains totally reflect inside, a flat plate seen
 *            along its axis, a conical rim, a uniaxial crystal, a lens
 *            in a denser medium), view rays
 *            of every kind (some through the front cap's centre of
 *            curvature: normal incidence at their first node; some
 *            steeply onto the front vertex), depths
 *            1, 2, 5, 12 and 16, builders of 16
 *            wavelengths (lp_backward_build_many) in the polarized mode
 *            and some in the fresnel mode: requests through every query
 *            of every builder, in builder order or interleaved, with
 *            bundles of 0 to 20 rays (random field directions and
 *            intensities, some 0), some of them failing (an intensity
 *            that is not a number, a field along the light, a query that
 *            does not exist, a NULL builder or bundle), are gathered by
 *            lp_backward_gather_many and by lp_backward_gather one by one
 *            into results already holding rays.  Every status and
 *            message ("request k: " and lp_backward_gather's), every
 *            request's start, every outgoing ray (as bytes) and every sum
 *            must be identical; after a failure both go on from the next
 *            request.  The contract is exactness, so the tolerance is 0.
 * power      lp_backward_gather_power_many of the same requests (two
 *            builds in three made with LP_BACKWARD_POWER): the same
 *            statuses and messages, and each request's power the sum of
 *            the intensities of the rays lp_backward_gather gives it,
 *            within rounding (power_from says how much); among the
 *            failing rays some within a few 1e-12 of the light's
 *            direction, where the checks' verdicts must agree.
 * errors     NULL arguments; count = 0.
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
#define NW 16
#define MAX_REQ (NW * 64)
#define MAX_RAYS 20

static uint64_t rng = 0x6a7e4e11a5ull;
static double uniform(void)
{
    return splitmix_uniform(&rng);
}

static lp_backward *bws[NW];

/* The requests of a case. */
static const lp_backward *req_bw[MAX_REQ];
static size_t req_q[MAX_REQ], req_n[MAX_REQ];
static const lp_ray *req_b[MAX_REQ];
static lp_ray rays[MAX_REQ][MAX_RAYS];

static int n_cases, n_requests, n_rays, n_failed, n_out, n_power;
static double worst_power;

/* A bundle ray arriving back along the world direction qd (lambda_nm):
 * a random field direction, or one that fails (bad 1: an intensity that
 * is not a number, 2: a field along the light, 4: an intensity negative
 * or infinite, 5: an infinite optical path or a phase not a number) or
 * may (3: a field within a few 1e-12 of the light's direction). */
static lp_ray bundle_ray(lp_vec3 qd, double lambda_nm, int bad)
{
    lp_ray r;
    r.origin = vec(0, 0, 0);
    r.dir = vec(-qd.x, -qd.y, -qd.z);
    r.lambda_nm = lambda_nm;
    double u = uniform();
    r.intensity = u < 0.1 ? 0.0 : 3.0 * uniform();
    r.vp = vec(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5);
    r.kphi = (int)(4.0 * uniform());
    r.op = 10.0 * uniform();
    r.phase = 6.0 * uniform() - 3.0;
    r.ch = (uint64_t)(1000.0 * uniform());
    if (bad == 1)
        r.intensity = NAN;
    else if (bad == 2)
        r.vp = qd;
    else if (bad == 4)
        r.intensity = uniform() < 0.5 ? -1.0 : INFINITY;
    else if (bad == 5) {
        if (uniform() < 0.5)
            r.op = INFINITY;
        else
            r.phase = NAN;
    } else if (bad == 3) { /* near the check's limit: a part across the light of
                          * 0.3e-12 .. 3e-12 of the field (it fails below 1e-12) */
        lp_vec3 a = fabs(qd.x) < 0.9 ? vec(1, 0, 0) : vec(0, 1, 0);
        lp_vec3 c = vec(qd.y * a.z - qd.z * a.y, qd.z * a.x - qd.x * a.z, qd.x * a.y - qd.y * a.x);
        double e = 1e-12 * (0.3 + 2.7 * uniform());
        r.vp = vec(qd.x + e * c.x, qd.y + e * c.y, qd.z + e * c.z);
    }
    return r;
}

/* The part of v across the unit d, over |v| (0 for a zero v). */
static double across(lp_vec3 v, lp_vec3 d)
{
    lp_vec3 c = vec(v.y * d.z - v.z * d.y, v.z * d.x - v.x * d.z, v.x * d.y - v.y * d.x);
    double l = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    return l > 0.0 ? sqrt(c.x * c.x + c.y * c.y + c.z * c.z) / l : 0.0;
}

/* lp_backward_gather_power_many of the requests of [from, count), whose
 * gathers one by one fail at `failed` (count: none) with sa and message
 * want: the same status and message, and each request's power before the
 * failing one the sum of the intensities of the rays its gather appends
 * (made again here), the failing one's 0.
 *
 * The tolerance: every factor of a way (Fresnel's power-normalized
 * amplitudes, the axes' cosines, the segments' attenuations) is at most
 * 1 in size, so each rounding of a ray's amplitude is at most eps
 * (2^-53) of the ray's own amplitude; a way of k <= 16 nodes takes about
 * 10 of them a node in either computation (3-vectors projected and
 * rebuilt, or 2 x 2 products), and a request adds up at most 20 rays: at
 * most 2 (10 x 16 + 20) eps = 4.0e-14 of the bundle's intensity apart.
 * A field direction v given to rounding (eps |v|) has its part across
 * the light known to eps |v| too, so a ray whose v is within a fraction f
 * of the light's direction (the rays near the check's limit, f ~ 1e-12)
 * has its direction across the light, and its power, known to about 2
 * eps / f: both computations may differ by twice that, 4 eps / f of its
 * intensity.  (Measured: the worst request is 0.04 of its tolerance --
 * 1.5e-15 of the intensity for the rays clear of the light's direction.) */
static void power_from(const char *name, size_t from, size_t count, size_t failed, lp_status sa,
                       const char *want)
{
    static lp_result d;
    static double power[MAX_REQ];
    const double tol = 2.0 * (10.0 * 16.0 + 20.0) * 0x1p-53;
    lp_error ec;
    lp_result_clear(&d);
    lp_status sc = lp_backward_gather_power_many(req_bw + from, req_q + from, req_b + from,
                                                 req_n + from, count - from, power, &ec);
    CHECK(sc == sa, "%s: power: status %d / %d (%s)", name, (int)sa, (int)sc, ec.message);
    if (sa != LP_OK)
        CHECK(strcmp(ec.message, want) == 0, "%s: power: '%s', want '%s'", name, ec.message,
              want);
    for (size_t k = from; k < failed && k < count; k++) {
        size_t start = d.count;
        lp_backward_gather(req_bw[k], req_q[k], req_b[k], req_n[k], &d, NULL);
        double want_p = 0.0, in_k = 0.0, allow = 0.0;
        for (size_t t = start; t < d.count; t++)
            want_p += d.rays[t].ray.intensity;
        int has_q = req_bw[k] && req_q[k] < lp_backward_query_count(req_bw[k]);
        lp_vec3 qd = has_q ? lp_backward_queries(req_bw[k])[req_q[k]].dir : vec(0, 0, 1);
        for (size_t i = 0; i < req_n[k] && req_b[k]; i++) {
            const lp_ray *r = &req_b[k][i];
            double I = isfinite(r->intensity) ? r->intensity : 0.0;
            in_k += I;
            if (I > 0.0)
                allow += I * (tol + 4.0 * 0x1p-53 / across(r->vp, qd));
        }
        double e = allow > 0.0 ? fabs(power[k - from] - want_p) / allow : 0.0;
        CHECK(fabs(power[k - from] - want_p) <= allow,
              "%s: request %zu: power %.17g, its rays %.17g (in %g)", name, k, power[k - from],
              want_p, in_k);
        worst_power = e > worst_power ? e : worst_power;
        n_power++;
    }
    if (failed < count)
        CHECK(power[failed - from] == 0.0, "%s: power: the failing request's is %g", name,
              power[failed - from]);
}

/* The requests k of [from, count) one by one into a, the many call into
 * b; both results compared, and each request's start.  Returns the
 * request after the first that failed (count when none did). */
static size_t compare_from(const char *name, size_t from, size_t count, lp_result *a,
                           lp_result *b)
{
    size_t start_a[MAX_REQ], start_b[MAX_REQ];
    lp_error ea, eb;
    lp_status sa = LP_OK;
    size_t k = from;
    char want[400] = "";

    for (; k < count; k++) {
        start_a[k] = a->count;
        sa = lp_backward_gather(req_bw[k], req_q[k], req_b[k], req_n[k], a, &ea);
        if (sa != LP_OK) {
            snprintf(want, sizeof want, "request %zu: %s", k - from, ea.message);
            break;
        }
    }
    for (size_t i = from; i < count; i++)
        start_b[i] = SIZE_MAX;
    lp_status sb = lp_backward_gather_many(req_bw + from, req_q + from, req_b + from,
                                           req_n + from, count - from, b, start_b + from, &eb);
    CHECK(sa == sb, "%s: status %d / %d (%s)", name, (int)sa, (int)sb, eb.message);
    if (sa != LP_OK) {
        CHECK(strcmp(eb.message, want) == 0, "%s: '%s', want '%s'", name, eb.message, want);
        n_failed++;
    }
    size_t last = k < count ? k : count - 1;
    for (size_t i = from; i <= last && i < count; i++)
        CHECK(start_a[i] == start_b[i], "%s: request %zu starts at %zu / %zu", name, i,
              start_a[i], start_b[i]);
    for (size_t i = last + 1; i < count; i++)
        CHECK(start_b[i] == SIZE_MAX, "%s: request %zu after the failure is set", name, i);
    CHECK(same_books(a, b), "%s: the sums or counts differ (%zu / %zu rays)", name, a->count,
          b->count);
    power_from(name, from, count, k, sa, want);
    size_t differ = 0;
    for (size_t t = 0; t < a->count && t < b->count; t++)
        differ += !same_out_ray(&a->rays[t], &b->rays[t]);
    CHECK(differ == 0, "%s: %zu of %zu outgoing rays differ", name, differ, a->count);
    return k < count ? k + 1 : count;
}

/* The requests of the builders bws[0..nb) (their queries, in builder
 * order or interleaved query by query), bad: some fail; gathered both
 * ways. */
static void gather_case(const char *name, size_t nb, const double *lambda, int interleave,
                        int bad)
{
    static lp_result a, b;
    size_t count = 0, nq_max = 0;
    for (size_t s = 0; s < nb; s++)
        if (lp_backward_query_count(bws[s]) > nq_max)
            nq_max = lp_backward_query_count(bws[s]);
    for (size_t o = 0; o < nb * (nq_max + 1); o++) {
        size_t s = interleave ? o % nb : o / (nq_max + 1);
        size_t j = interleave ? o / nb : o % (nq_max + 1);
        size_t nq = lp_backward_query_count(bws[s]);
        if (j > nq || (j == nq && !(bad && uniform() < 0.05)) || count == MAX_REQ)
            continue; /* j == nq: a query that does not exist */
        const lp_query *qs = lp_backward_queries(bws[s]);
        lp_vec3 qd = j < nq ? qs[j].dir : vec(0, 0, 1);
        double u = uniform();
        size_t n = u < 0.05 ? 0 : u < 0.6 ? 2 : u < 0.8 ? 1 : (size_t)(MAX_RAYS * uniform());
        for (size_t i = 0; i < n; i++)
            rays[count][i] = bundle_ray(qd, lambda[s], bad && uniform() < 0.02 ? 1 + (int)(5.0 * uniform()) : 0);
        req_bw[count] = bws[s];
        req_q[count] = j;
        req_n[count] = n;
        req_b[count] = rays[count];
        if (bad && uniform() < 0.01)
            req_bw[count] = NULL;
        if (bad && n > 0 && uniform() < 0.01)
            req_b[count] = NULL;
        if (n == 0 && uniform() < 0.5)
            req_b[count] = NULL; /* no rays: NULL is fine */
        n_rays += (int)n;
        count++;
    }
    /* both results hold the same rays already: the calls append */
    lp_result_clear(&a);
    lp_result_clear(&b);
    if (count > 0 && req_bw[0] && req_b[0]) {
        lp_backward_gather(req_bw[0], req_q[0], req_b[0], req_n[0], &a, NULL);
        lp_backward_gather(req_bw[0], req_q[0], req_b[0], req_n[0], &b, NULL);
    }
    for (size_t from = 0; from < count;)
        from = compare_from(name, from, count, &a, &b);
    n_out += (int)a.count;
    n_requests += (int)count;
    n_cases++;
}

static void test_identity(void)
{
    const placed_shape shapes[] = {
        {"biconvex N-BK7", 50, -50, 8, 25, 0, "N-BK7", 0, NULL, 0, 0},
        {"ball N-SF11", 10, -10, 19, 19.9, 0, "N-SF11", 0, NULL, 0, 0},
        /* absorbing where total internal reflection makes the field complex */
        {"absorbing ball n=1.8", 10, -10, 19, 19.9, 0, NULL, 1.8, NULL, 0, 0.3},
        {"meniscus F2 in CaF2", 20, 40, 4, 20, 0, "F2", 0, "CAF2", 0, 0},
        {"flat plate N-SF6", 0, 0, 3, 20, 0, "N-SF6", 0, NULL, 0, 0},
        {"conical rim n=1.6", 60, -30, 6, 24, 18, NULL, 1.6, NULL, 0, 0},
        {"biconcave SF11", -30, 30, 3, 22, 0, "N-SF11", 0, NULL, 0, 0},
        {"crystal plate", 0, 0, 3, 20, 0, NULL, 0, NULL, 1, 0},
        /* in a denser medium: total internal reflection off the outside */
        {"biconvex n=1.3 in N-SF11", 40, -40, 6, 24, 0, NULL, 1.3, "N-SF11", 0, 0},
    };
    const int depths[] = {1, 2, 5, 12, 16};
    lp_error err;

    for (size_t si = 0; si < sizeof shapes / sizeof shapes[0]; si++) {
        lp_lens_desc desc;
        lp_lens *lens;
        lp_vec3 u, v, w;
        if (placed_lens(&shapes[si], si, &lens, &desc, &u, &v, &w) != 0)
            continue;
        double h = 0.5 * desc.diameter, t = desc.thickness;
        for (int ri = 0; ri < 30; ri++) {
            if (ri >= 24 && ri < 28 && shapes[si].r1 == 0.0)
                continue; /* a flat cap has no centre */
            lp_vec3 o, d;
            int kind = ri % 4;
            if (kind == 0) { /* along the axis, from the front */
                o = place(desc.position, u, v, w, 0, 0, -3.0 * h);
                d = w;
            } else { /* from either side, steep or grazing */
                double rho = 1.1 * h * sqrt(uniform()), phi = 2.0 * PI * uniform();
                double tilt = (kind == 3 ? 1.4 : 0.7) * uniform(), az = 2.0 * PI * uniform();
                double side = kind == 2 ? t + 3.0 * h : -3.0 * h;
                o = place(desc.position, u, v, w, rho * cos(phi), rho * sin(phi), side);
                d = place(vec(0, 0, 0), u, v, w, sin(tilt) * cos(az), sin(tilt) * sin(az),
                          (side < 0.0 ? 1.0 : -1.0) * cos(tilt));
            }
            if (ri >= 28) { /* steeply onto the front vertex: past the critical angle
                             * of a lens in a denser medium */
                double th = 1.0 + 0.4 * uniform();
                d = place(vec(0, 0, 0), u, v, w, 0, sin(th), cos(th));
                lp_vec3 X = desc.position;
                o = vec(X.x - 3.0 * h * d.x, X.y - 3.0 * h * d.y, X.z - 3.0 * h * d.z);
            } else if (ri >= 24) { /* through the front cap's centre: normal incidence there */
                lp_vec3 C = place(desc.position, u, v, w, 0, 0, desc.radius1);
                d = place(vec(0, 0, 0), u, v, w, 0.3 * (2.0 * uniform() - 1.0),
                          0.3 * (2.0 * uniform() - 1.0), 1.0);
                double dl = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
                d = vec(d.x / dl, d.y / dl, d.z / dl);
                double back = (desc.radius1 > 0.0 ? desc.radius1 : 0.0) + 3.0 * h;
                o = vec(C.x - back * d.x, C.y - back * d.y, C.z - back * d.z);
            }
            double lambda[NW];
            for (size_t k = 0; k < NW; k++)
                lambda[k] = 400.0 + 300.0 * uniform();
            lp_trace_args a;
            lp_trace_args_init(&a);
            a.mode = ri % 6 == 5 ? LP_MODE_FRESNEL : LP_MODE_POLARIZED;
            if (ri % 3 != 1) /* the builds for power alone (ignored by fresnel's) */
                a.flags |= LP_BACKWARD_POWER;
            if (ri >= 24) { /* the special view rays: for power alone */
                a.mode = LP_MODE_POLARIZED;
                a.flags |= LP_BACKWARD_POWER;
            }
            a.max_depth = depths[ri % 5];
            size_t nb = ri % 5 == 4 ? 3 : NW;
            CHECK(lp_backward_build_many(bws, nb, lens, o, d, lambda, &a, &err) == LP_OK,
                  "%s: build: %s", shapes[si].name, err.message);
            char name[160];
            for (int c = 0; c < 4; c++) {
                snprintf(name, sizeof name, "%s, view ray %d, depth %d, %s%s", shapes[si].name,
                         ri, a.max_depth, c & 1 ? "interleaved" : "builder by builder",
                         c & 2 ? ", failing" : "");
                gather_case(name, nb, lambda, c & 1, c >> 1);
            }
        }
        lp_lens_destroy(lens);
    }
    printf("identity: %d cases, %d requests, %d bundle rays, %d outgoing rays, %d failures: "
           "every status, message, start, ray and sum identical to lp_backward_gather's\n",
           n_cases, n_requests, n_rays, n_out, n_failed);
    CHECK(n_failed > 0 && n_out > 0, "failures and outgoing rays were exercised");
    printf("power: %d requests, worst |power - sum of rays| %.3g of the tolerance\n", n_power,
           worst_power);
}

static void test_errors(void)
{
    lp_result r;
    lp_error err;
    size_t q = 0, n = 0, start = 7;
    const lp_backward *b = bws[0];
    const lp_ray *bundle = NULL;
    lp_result_init(&r);
    CHECK(lp_backward_gather_many(&b, &q, &bundle, &n, 1, NULL, &start, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL out");
    CHECK(lp_backward_gather_many(NULL, &q, &bundle, &n, 1, &r, &start, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL builders");
    CHECK(lp_backward_gather_many(&b, NULL, &bundle, &n, 1, &r, &start, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL queries");
    CHECK(lp_backward_gather_many(&b, &q, NULL, &n, 1, &r, &start, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL bundles");
    CHECK(lp_backward_gather_many(&b, &q, &bundle, NULL, 1, &r, &start, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "NULL counts");
    CHECK(start == 7 && r.count == 0, "nothing done before the arguments check out");
    CHECK(lp_backward_gather_many(NULL, NULL, NULL, NULL, 0, &r, NULL, &err) == LP_OK,
          "count = 0: nothing to do");
    CHECK(r.count == 0 && r.in == 0.0, "count = 0 leaves out as it is");
    double power = 7.0;
    CHECK(lp_backward_gather_power_many(&b, &q, &bundle, &n, 1, NULL, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "power: NULL power");
    CHECK(lp_backward_gather_power_many(NULL, &q, &bundle, &n, 1, &power, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "power: NULL builders");
    CHECK(power == 7.0, "power: nothing done before the arguments check out");
    CHECK(lp_backward_gather_power_many(NULL, NULL, NULL, NULL, 0, NULL, &err) == LP_OK &&
              err.status == LP_OK && err.message[0] == '\0',
          "power: count = 0: nothing to do, err cleared");
    lp_result_release(&r);
}

/* Calls longer than the lanes' window of requests (256 at a time): many
 * one-ray and two-ray requests of 16 wavelengths' builds, in builder order
 * and interleaved, with a bundle of 300 rays (more than a window holds:
 * gathered one by one) among them; the same comparison as above. */
static void test_windows(void)
{
    static lp_ray big[300];
    const placed_shape ball = {"ball N-SF11", 10, -10, 19, 19.9, 0, "N-SF11", 0, NULL, 0, 0.5};
    lp_lens_desc desc;
    lp_lens *lens;
    lp_vec3 u, v, w;
    lp_error err;
    static lp_result a, b;
    if (placed_lens(&ball, 1, &lens, &desc, &u, &v, &w) != 0)
        return;
    double lambda[NW];
    for (size_t k = 0; k < NW; k++)
        lambda[k] = 400.0 + 20.0 * (double)k;
    lp_trace_args args;
    lp_trace_args_init(&args);
    args.max_depth = 8;
    lp_vec3 o = place(desc.position, u, v, w, 0.3 * desc.diameter, 0.1, -30.0);
    CHECK(lp_backward_build_many(bws, NW, lens, o, w, lambda, &args, &err) == LP_OK,
          "windows: build: %s", err.message);
    size_t nq = lp_backward_query_count(bws[0]);
    CHECK(nq > 0, "windows: the view ray has queries");
    for (int pass = 0; pass < 2 && nq > 0; pass++) {
        size_t count = 0;
        for (size_t r = 0; count < MAX_REQ; r++) {
            size_t s = pass ? r % NW : (r / nq) % NW, j = pass ? (r / NW) % nq : r % nq;
            if (j >= lp_backward_query_count(bws[s]))
                continue;
            lp_vec3 qd = lp_backward_queries(bws[s])[j].dir;
            size_t n = r % 3; /* none (one by one), one or two rays */
            req_bw[count] = bws[s];
            req_q[count] = j;
            req_n[count] = n;
            req_b[count] = rays[count];
            for (size_t i = 0; i < n; i++)
                rays[count][i] = bundle_ray(qd, lambda[s], 0);
            if (count == 300) { /* past the first window: a bundle longer than one */
                for (size_t i = 0; i < sizeof big / sizeof big[0]; i++)
                    big[i] = bundle_ray(qd, lambda[s], 0);
                req_b[count] = big;
                req_n[count] = sizeof big / sizeof big[0];
            }
            count++;
        }
        lp_result_clear(&a);
        lp_result_clear(&b);
        CHECK(compare_from(pass ? "windows, interleaved" : "windows, builder by builder", 0,
                           count, &a, &b) == count,
              "windows: no request fails");
        CHECK(a.count > 2 * MAX_REQ / 2, "windows: %zu outgoing rays", a.count);
    }
    lp_lens_destroy(lens);
}

int main(void)
{
    lp_error err;
    for (int k = 0; k < NW; k++)
        if (lp_backward_create(&bws[k], &err) != LP_OK)
            return 1;
    test_identity();
    test_windows();
    test_errors();
    for (int k = 0; k < NW; k++)
        lp_backward_destroy(bws[k]);
    return check_finish("test_gather_many");
}
