/* fuzz_agf.c -- libFuzzer target: Zemax AGF catalog text.
 *
 * The input is loaded with lp_catalog_load_agf_text into a fresh catalog;
 * when it loads, every glass is looked up, checked, and its index and
 * absorption evaluated at a few wavelengths (glass.c); the first few
 * valid glasses also make a lens that one ray is traced through.  A
 * refusal must carry a message; a crash, sanitizer report, leak or hang
 * is a bug. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "lensprim.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A biconvex lens of glass g; one ray through it at lambda_nm. */
static void trace_through(const lp_glass *g, double lambda_nm)
{
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_error err;
    lp_ray in;
    lp_result res;

    lp_lens_desc_init(&desc);
    desc.radius1 = 50.0;
    desc.radius2 = -50.0;
    desc.thickness = 5.0;
    desc.diameter = 25.0;
    desc.glass = *g;
    if (lp_lens_create(&desc, &lens, &err) != LP_OK) {
        if (err.message[0] == '\0')
            abort();
        return;
    }
    memset(&in, 0, sizeof in);
    in.origin = (lp_vec3){ 0.0, 3.0, -10.0 };
    in.dir = (lp_vec3){ 0.0, 0.0, 1.0 };
    in.vp = (lp_vec3){ 1.0, 0.0, 0.0 };
    in.lambda_nm = lambda_nm;
    in.intensity = 1.0;
    lp_result_init(&res);
    if (lp_trace_forward(lens, &in, NULL, &res, &err) == LP_OK) {
        /* energy is conserved and every output is a finite ray */
        double sum = res.out + res.skipped + res.absorbed_glass + res.absorbed_rim +
                     res.truncated;
        if (!(fabs(sum - res.in) <= 1e-9 * fmax(1.0, res.in)))
            abort();
        for (size_t i = 0; i < res.count; i++)
            if (!isfinite(res.rays[i].ray.intensity) || res.rays[i].ray.intensity < 0.0)
                abort();
    }
    lp_result_release(&res);
    lp_lens_destroy(lens);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const double lambdas[] = { 200.0, 380.0, 587.5618, 780.0, 2500.0, 1e6 };
    lp_catalog *cat = NULL;
    lp_error err;

    if (lp_catalog_create(&cat, &err) != LP_OK)
        return 0;
    if (lp_catalog_load_agf_text(cat, (const char *)data, size, &err) != LP_OK) {
        if (err.message[0] == '\0')
            abort();
    } else {
        size_t n = lp_catalog_count(cat);
        for (size_t i = 0; i < n; i++) {
            const char *name = lp_catalog_name(cat, i);
            lp_glass g;
            if (name == NULL)
                abort();
            if (lp_catalog_find(cat, name, &g, &err) != LP_OK)
                continue;
            if (lp_glass_check(&g, &err) != LP_OK)
                continue;
            for (size_t k = 0; k < sizeof lambdas / sizeof lambdas[0]; k++) {
                volatile double v = lp_glass_index(&g, lambdas[k]);
                v = lp_glass_absorption(&g, lambdas[k]);
                v = lp_glass_covers(&g, lambdas[k]);
                (void)v;
            }
            if (i < 3) {
                trace_through(&g, 587.5618);
                trace_through(&g, g.lambda_min_nm > 0.0 ? g.lambda_min_nm : 380.0);
            }
        }
    }
    lp_catalog_destroy(cat);
    return 0;
}
