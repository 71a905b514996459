/* test_threads.c -- one const lens shared by several threads.
 *
 * Four threads trace the same rays (forward and backward) through one
 * lens at once; every thread must get bit-identical results to a
 * single-threaded reference run, which shows the lens is immutable and
 * the library keeps no hidden shared state. */
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "lensprim.h"

#define NRAYS 2000
#define NTHREADS 4

typedef struct job {
    const lp_lens *lens;
    const lp_ray *rays;
    double *out; /* per ray: sum of I*depth over forward rays, then backward gathered sum */
    int failed;
} job;

static void run(job *j)
{
    lp_result res, g;
    lp_backward *bw = NULL;
    lp_trace_args a;
    lp_result_init(&res);
    lp_result_init(&g);
    lp_trace_args_init(&a);
    a.max_depth = 8;
    if (lp_backward_create(&bw, NULL) != LP_OK) {
        j->failed = 1;
        return;
    }
    for (int i = 0; i < NRAYS; i++) {
        double s = 0.0;
        if (lp_trace_forward(j->lens, &j->rays[i], &a, &res, NULL) != LP_OK)
            j->failed = 1;
        for (size_t k = 0; k < res.count; k++)
            s += res.rays[k].ray.intensity * res.rays[k].depth + res.rays[k].ray.op +
                 res.rays[k].ray.vp.x;
        j->out[2 * i] = s;
        if (lp_backward_build(bw, j->lens, j->rays[i].origin, j->rays[i].dir,
                              j->rays[i].lambda_nm, &a, NULL) != LP_OK)
            j->failed = 1;
        lp_result_clear(&g);
        const lp_query *q = lp_backward_queries(bw);
        for (size_t k = 0; k < lp_backward_query_count(bw); k++) {
            lp_ray b = j->rays[i];
            b.vp = q[k].dir.z > 0.5 || q[k].dir.z < -0.5 ? (lp_vec3){1, 0, 0} : (lp_vec3){0, 0, 1};
            if (lp_backward_gather(bw, k, &b, 1, &g, NULL) != LP_OK)
                j->failed = 1;
        }
        j->out[2 * i + 1] = g.out + g.absorbed_glass;
    }
    lp_backward_destroy(bw);
    lp_result_release(&res);
    lp_result_release(&g);
}

static void *thread_main(void *arg)
{
    run(arg);
    return NULL;
}

int main(void)
{
    lp_lens_desc d;
    lp_lens *lens;
    lp_error err;
    static lp_ray rays[NRAYS];
    static double ref[2 * NRAYS], got[NTHREADS][2 * NRAYS];

    lp_lens_desc_init(&d);
    d.radius1 = 20;
    d.radius2 = -35;
    d.thickness = 9;
    d.diameter = 24;
    d.diameter2 = 20;
    CHECK(lp_glass_builtin("N-SF11", &d.glass, &err) == LP_OK, "N-SF11: %s", err.message);
    CHECK(lp_lens_create(&d, &lens, &err) == LP_OK, "lens: %s", err.message);
    for (int i = 0; i < NRAYS; i++) {
        double u = (i % 97) / 97.0 - 0.5, v = (i % 89) / 89.0 - 0.5;
        rays[i] = (lp_ray){{26 * u, 26 * v, -15}, {0.2 * v, -0.2 * u, 1}, 400 + (i % 380), 1,
                           {1, 0, 0.2 * v}, 0, 0, 0, (uint64_t)i};
    }
    job reference = {lens, rays, ref, 0};
    run(&reference);
    CHECK(!reference.failed, "reference run failed");

    pthread_t th[NTHREADS];
    job jobs[NTHREADS];
    for (int t = 0; t < NTHREADS; t++) {
        jobs[t] = (job){lens, rays, got[t], 0};
        CHECK(pthread_create(&th[t], NULL, thread_main, &jobs[t]) == 0, "pthread_create");
    }
    for (int t = 0; t < NTHREADS; t++) {
        pthread_join(th[t], NULL);
        CHECK(!jobs[t].failed, "thread %d failed", t);
        CHECK(memcmp(got[t], ref, sizeof ref) == 0, "thread %d differs from the reference", t);
    }
    lp_lens_destroy(lens);
    return check_finish("threads");
}
