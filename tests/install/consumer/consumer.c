/* consumer.c -- a program of a library user, built against an installed
 * lensprim (by find_package and by pkg-config).  Traces one ray straight
 * through a glass plate and checks the outcome against Fresnel's normal
 * incidence formula; argv[1] is the version it must report. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lensprim.h"

int main(int argc, char **argv)
{
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_trace_args args;
    lp_result res;
    lp_error err;
    lp_ray in;
    double r, want, got = -1.0;

    if (argc != 2 || strcmp(lp_version_string(), argv[1]) != 0 ||
        lp_version_number() != LP_VERSION_NUMBER) {
        fprintf(stderr, "consumer: version %s (%d), want %s\n",
                lp_version_string(), lp_version_number(), argc > 1 ? argv[1] : "?");
        return 1;
    }
    lp_lens_desc_init(&desc);
    desc.radius1 = 0.0;
    desc.radius2 = 0.0;
    desc.thickness = 2.0;
    desc.diameter = 10.0;
    lp_glass_init_constant(&desc.glass, 1.5);
    if (lp_lens_create(&desc, &lens, &err) != LP_OK) {
        fprintf(stderr, "consumer: %s\n", err.message);
        return 1;
    }
    memset(&in, 0, sizeof in);
    in.origin.z = -5.0;
    in.dir.z = 1.0;
    in.vp.x = 1.0;
    in.lambda_nm = 587.56;
    in.intensity = 1.0;
    lp_trace_args_init(&args);
    args.max_depth = 2;
    lp_result_init(&res);
    if (lp_trace_forward(lens, &in, &args, &res, &err) != LP_OK) {
        fprintf(stderr, "consumer: %s\n", err.message);
        return 1;
    }
    for (size_t i = 0; i < res.count; i++)
        if (res.rays[i].depth == 2 && res.rays[i].kind == LP_KIND_TRANSMIT)
            got = res.rays[i].ray.intensity;
    r = (1.5 - 1.0) / (1.5 + 1.0);
    r *= r;
    want = (1.0 - r) * (1.0 - r);
    lp_result_release(&res);
    lp_lens_destroy(lens);
    if (!(fabs(got - want) <= 1e-12)) {
        fprintf(stderr, "consumer: transmitted %.17g, want (1-R)^2 = %.17g\n", got, want);
        return 1;
    }
    printf("consumer: lensprim %s, T = %.6f as Fresnel says\n", lp_version_string(), got);
    return 0;
}
