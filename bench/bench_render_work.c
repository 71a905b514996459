/* bench_render_work.c -- the work counters of renders of one scene.
 *
 * A benchmark, not a test: it loads SCENE once and renders it at W x H on
 * one thread once per SETTING (MODE:WAVELENGTHS:DEPTH:CUTOFF, e.g.
 * polarized:16:5:1e-3; MODE polarized, fresnel, schlick or rgb), in the
 * order given, each with lr_render_region_work, and prints one line per
 * render:
 *     SCENE MODE WAVELENGTHS DEPTH CUTOFF pixels rays lane_rays builds
 *     gathered cost
 * (lensrender.h's lr_work; cost is the automatic mode's price of the
 * counts).  Under callgrind with --dump-after=lr_render_region_work each
 * render is one dump, in the same order (bench/work_cost_fit.sh).  Usage:
 *     bench_render_work SCENE W H SETTING...
 * Exit status 0, 1 a failed render, 2 bad input. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lensrender/lensrender.h"

static int parse_setting(const char *s, lr_render_opts *o)
{
    char mode[16];
    int wl, depth, used = 0;
    double cut;
    if (sscanf(s, "%15[a-z]:%d:%d:%lf%n", mode, &wl, &depth, &cut, &used) != 4 ||
        s[used] != '\0')
        return -1;
    if (strcmp(mode, "polarized") == 0)
        o->mode = LR_MODE_POLARIZED;
    else if (strcmp(mode, "fresnel") == 0)
        o->mode = LR_MODE_FRESNEL;
    else if (strcmp(mode, "schlick") == 0)
        o->mode = LR_MODE_SCHLICK;
    else if (strcmp(mode, "rgb") == 0)
        o->mode = LR_MODE_RGB;
    else
        return -1;
    o->wavelengths = wl;
    o->depth = depth;
    o->cutoff = cut;
    return 0;
}

int main(int argc, char **argv)
{
    lr_load_opts lo;
    lr_scene *scene = NULL;
    lr_error err;
    float *rgb;
    int w, h;
    const char *name;

    if (argc < 5) {
        fprintf(stderr, "usage: bench_render_work SCENE W H MODE:WAVELENGTHS:DEPTH:CUTOFF...\n");
        return 2;
    }
    w = atoi(argv[2]);
    h = atoi(argv[3]);
    if (w < 1 || h < 1 || w > LR_SIZE_MAX || h > LR_SIZE_MAX) {
        fprintf(stderr, "bench_render_work: W and H must be 1..%d\n", LR_SIZE_MAX);
        return 2;
    }
    name = strrchr(argv[1], '/') ? strrchr(argv[1], '/') + 1 : argv[1];
    lr_load_opts_init(&lo);
    lo.image_width = w;
    lo.image_height = h;
    if (lr_scene_load(argv[1], &lo, &scene, &err) != LR_OK) {
        fprintf(stderr, "bench_render_work: %s\n", err.message);
        lr_scene_free(scene);
        return 2;
    }
    rgb = malloc(sizeof *rgb * 3 * (size_t)w * (size_t)h);
    if (!rgb) {
        lr_scene_free(scene);
        return 1;
    }
    for (int k = 4; k < argc; k++) {
        lr_render_opts o;
        lr_renderer *r;
        lr_work wk;
        lr_render_opts_init(&o);
        o.width = w;
        o.height = h;
        o.threads = 1;
        if (parse_setting(argv[k], &o) != 0) {
            fprintf(stderr, "bench_render_work: bad setting '%s'\n", argv[k]);
            free(rgb);
            lr_scene_free(scene);
            return 2;
        }
        if (lr_renderer_create(scene, &o, &r, &err) != LR_OK ||
            lr_render_region_work(r, 0, 0, w, h, rgb, NULL, NULL, &wk, &err) != LR_OK) {
            fprintf(stderr, "bench_render_work: %s\n", err.message);
            lr_renderer_free(r);
            free(rgb);
            lr_scene_free(scene);
            return 1;
        }
        printf("%s %s %d %d %g %.0f %.0f %.0f %.0f %.0f %.0f\n", name, lr_mode_name(o.mode),
               o.wavelengths, o.depth, o.cutoff, wk.pixels, wk.rays, wk.lane_rays, wk.builds,
               wk.gathered, wk.cost);
        fflush(stdout);
        lr_renderer_free(r);
    }
    free(rgb);
    lr_scene_free(scene);
    return 0;
}
