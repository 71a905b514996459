/* bench_lensprim.c -- lens-tree nodes per second per core.
 *
 * A benchmark, not a test: it traces random rays through the default lens
 * (biconvex N-BK7, R 50/-50, t 8, D 25) in each mode and depth, forward
 * (one call per ray, lp_trace_forward_many, and lp_trace_forward_soa on
 * groups of 64 rays, each group at one wavelength) and backward (build +
 * gather of a one-ray bundle per query), on one thread, and prints
 * nodes/s and the time ratio of each mode to polarized measured in the
 * same run.  Times are the CPU time of the tracing thread (not wall
 * clock), so nodes/s is per core even on a machine that other programs
 * share.  Usage:
 *     bench_lensprim [RAYS] [--mode polarized|fresnel|schlick] [--depth N]
 * RAYS defaults to 200000; --mode and --depth keep one row each (for a
 * profiler); without them every mode at depths 2, 5 and 20 is printed. */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lensprim.h"

#define PI 3.14159265358979323846

/* CPU seconds of this thread: what the tracing cost one core, whatever
 * else the machine runs. */
static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static double uniform(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (z >> 11) * (1.0 / 9007199254740992.0);
}

static void random_ray(lp_ray *r)
{
    double rho = 12.0 * sqrt(uniform()), phi = 2.0 * PI * uniform();
    double tilt = 0.3 * uniform(), az = 2.0 * PI * uniform();
    r->origin = (lp_vec3){rho * cos(phi), rho * sin(phi), -20.0};
    r->dir = (lp_vec3){sin(tilt) * cos(az), sin(tilt) * sin(az), cos(tilt)};
    r->lambda_nm = 380.0 + 400.0 * uniform();
    r->intensity = 1.0;
    r->vp = (lp_vec3){cos(az + 1.0), sin(az + 1.0), 0.0};
    r->kphi = 0;
    r->op = 0.0;
    r->phase = 0.0;
    r->ch = 1;
}

int main(int argc, char **argv)
{
    size_t n = 200000;
    int only_mode = -1, only_depth = 0;
    const char *only_column = NULL;
    lp_lens_desc desc;
    lp_lens *lens;
    lp_error err;
    const char *mode_name[] = {"polarized", "fresnel", "schlick"};
    const int depths[] = {2, 5, 20};

    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--mode") == 0 && i + 1 < argc) {
            i++;
            for (int m = 0; m < 3; m++)
                if (strcmp(argv[i], mode_name[m]) == 0)
                    only_mode = m;
            if (only_mode < 0) {
                fprintf(stderr, "bench: unknown mode %s\n", argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--depth") == 0 && i + 1 < argc) {
            only_depth = atoi(argv[++i]);
            if (only_depth < 1 || only_depth > LP_MAX_DEPTH) {
                fprintf(stderr, "bench: depth must be in 1..%d\n", LP_MAX_DEPTH);
                return 2;
            }
        } else if (strcmp(argv[i], "--column") == 0 && i + 1 < argc) {
            only_column = argv[++i];
        } else if (argv[i][0] != '-' && strtoul(argv[i], NULL, 10) > 0) {
            n = strtoul(argv[i], NULL, 10);
        } else {
            fprintf(stderr, "usage: bench_lensprim [RAYS] [--mode M] [--depth N]\n"
                            "  prints lens-tree nodes per second of this thread's CPU time\n"
                            "  (per core), forward, batch, arrays and backward\n");
            return 2;
        }
    }
    int n_depths = only_depth ? 1 : (int)(sizeof depths / sizeof depths[0]);

    lp_lens_desc_init(&desc);
    desc.radius1 = 50;
    desc.radius2 = -50;
    desc.thickness = 8;
    desc.diameter = 25;
    if (lp_glass_builtin("N-BK7", &desc.glass, &err) != LP_OK ||
        lp_lens_create(&desc, &lens, &err) != LP_OK) {
        fprintf(stderr, "bench: %s\n", err.message);
        return 1;
    }
    lp_ray *rays = malloc(n * sizeof *rays);
    size_t *offsets = malloc((n + 1) * sizeof *offsets);
    if (!rays || !offsets)
        return 1;
    for (size_t i = 0; i < n; i++)
        random_ray(&rays[i]);
    /* the same rays as arrays for lp_trace_forward_soa */
    const size_t soa_group = 64;
    double *soa = malloc(10 * n * sizeof *soa);
    if (!soa)
        return 1;
    double *sox = soa, *soy = soa + n, *soz = soa + 2 * n, *sdx = soa + 3 * n,
           *sdy = soa + 4 * n, *sdz = soa + 5 * n, *svx = soa + 6 * n, *svy = soa + 7 * n,
           *svz = soa + 8 * n, *sin_ = soa + 9 * n;
    for (size_t i = 0; i < n; i++) {
        sox[i] = rays[i].origin.x, soy[i] = rays[i].origin.y, soz[i] = rays[i].origin.z;
        sdx[i] = rays[i].dir.x, sdy[i] = rays[i].dir.y, sdz[i] = rays[i].dir.z;
        svx[i] = rays[i].vp.x, svy[i] = rays[i].vp.y, svz[i] = rays[i].vp.z;
        sin_[i] = rays[i].intensity;
    }

    lp_result res;
    lp_result_init(&res);
    lp_backward *bw;
    lp_backward_create(&bw, &err);

    printf("%zu rays, one thread, nodes per CPU second of the thread\n", n);
    printf("%-10s %5s %14s %14s %14s %14s %10s\n", "mode", "depth", "fwd nodes/s",
           "batch nodes/s", "soa nodes/s", "bwd nodes/s", "fwd t/pol");
    for (int di = 0; di < n_depths; di++) {
        double t_pol = 0.0;
        for (int m = 0; m < 3; m++) {
            if (only_mode >= 0 && m != only_mode)
                continue;
            lp_trace_args a;
            lp_trace_args_init(&a);
            a.mode = (lp_mode)m;
            a.max_depth = only_depth ? only_depth : depths[di];

#define RUN(name) (!only_column || strcmp(only_column, name) == 0)
            size_t nodes = 0;
            double t0 = now();
            for (size_t i = 0; i < n && RUN("fwd"); i++) {
                lp_trace_forward(lens, &rays[i], &a, &res, NULL);
                nodes += res.nodes;
            }
            double t_fwd = now() - t0;

            t0 = now();
            if (RUN("batch"))
                lp_trace_forward_many(lens, rays, n, &a, &res, offsets, NULL);
            double t_batch = now() - t0;
            size_t batch_nodes = res.nodes;

            /* the arrays entry point, one wavelength per call: the rays in
             * groups of soa_group, each group at its first ray's lambda */
            size_t soa_nodes = 0;
            t0 = now();
            for (size_t i = 0; i < n && RUN("soa"); i += soa_group) {
                size_t m = n - i < soa_group ? n - i : soa_group;
                lp_ray_soa s = {sox + i, soy + i, soz + i, sdx + i, sdy + i, sdz + i, svx + i,
                                svy + i, svz + i, sin_ + i, NULL, NULL, NULL, NULL};
                lp_trace_forward_soa(lens, rays[i].lambda_nm, &s, m, &a, &res, offsets, NULL);
                soa_nodes += res.nodes;
            }
            double t_soa = now() - t0;

            size_t bnodes = 0;
            t0 = now();
            for (size_t i = 0; i < n && RUN("bwd"); i++) {
                lp_backward_build(bw, lens, rays[i].origin, rays[i].dir, rays[i].lambda_nm, &a,
                                  NULL);
                size_t nq = lp_backward_query_count(bw);
                const lp_query *q = lp_backward_queries(bw);
                lp_result_clear(&res);
                for (size_t k = 0; k < nq; k++) {
                    lp_ray b = rays[i];
                    b.vp = fabs(q[k].dir.z) < 0.9 ? (lp_vec3){0, 0, 1} : (lp_vec3){1, 0, 0};
                    lp_backward_gather(bw, k, &b, 1, &res, NULL);
                }
                bnodes += res.nodes;
            }
            double t_bwd = now() - t0;
            if (m == 0)
                t_pol = t_fwd;
            printf("%-10s %5d %14.3e %14.3e %14.3e %14.3e %10.3f\n", mode_name[m], a.max_depth,
                   nodes / t_fwd, batch_nodes / t_batch, soa_nodes / t_soa, bnodes / t_bwd,
                   t_pol > 0.0 ? t_fwd / t_pol : 1.0);
            if (only_column)
                printf("nodes: fwd %zu batch %zu soa %zu bwd %zu\n", nodes, batch_nodes, soa_nodes,
                       bnodes);
            /* one view ray at 16 wavelengths: 16 builds, or one call */
            if (RUN("build16") || RUN("build16many")) {
                enum { NW = 16 };
                lp_backward *bws[NW];
                double lam[NW];
                for (int k = 0; k < NW; k++) {
                    lp_backward_create(&bws[k], &err);
                    lam[k] = 400.0 + 20.0 * k;
                }
                size_t views = n / 4;
                t0 = now();
                for (size_t i = 0; i < views && RUN("build16"); i++)
                    for (int k = 0; k < NW; k++)
                        lp_backward_build(bws[k], lens, rays[i].origin, rays[i].dir, lam[k], &a,
                                          NULL);
                double t_one = now() - t0;
                t0 = now();
                for (size_t i = 0; i < views; i++)
                    lp_backward_build_many(bws, NW, lens, rays[i].origin, rays[i].dir, lam, &a,
                                           NULL);
                double t_many = now() - t0;
                printf("build16: one view ray at 16 wavelengths: 16 builds %.3f us, "
                       "lp_backward_build_many %.3f us (%.2fx)\n",
                       1e6 * t_one / (double)views, 1e6 * t_many / (double)views,
                       t_one / t_many);
                for (int k = 0; k < NW; k++)
                    lp_backward_destroy(bws[k]);
            }
        }
    }
    lp_backward_destroy(bw);
    lp_result_release(&res);
    free(rays);
    free(offsets);
    free(soa);
    lp_lens_destroy(lens);
    return 0;
}
