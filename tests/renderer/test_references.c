/* test_references.c -- regression against stored renders.
 *
 * Every .scene file in scenes/ is rendered through the core API at
 * 80 x 60 in the polarized mode with default settings (16 wavelengths,
 * the scene's max_trace_level and adc_bailout) and compared with
 * tests/renderer/ref/<name>.png, a 16-bit LINEAR PNG (values clipped to
 * [0, 1], stored as floor(v * 65535 + 0.5): 1/131070 at most off, so
 * an unchanged render compares at about 103-115 dB; the checkerboards'
 * 0.9 and 0.1 sit exactly half a step off).  The metric is the PSNR over
 * all pixels and channels of the two images clipped to [0, 1], peak 1;
 * it must be >= 50 dB (an RMS
 * difference of at most 0.0032, under one 8-bit step).  By design this is
 * the one test whose expectation is the renderer's own earlier output: it
 * catches unintended change, not physics errors.  A scene without a
 * reference, or a reference without a scene, is a failure too.
 *
 * On failure the new render (<name>.new.png, 16-bit linear) and a
 * difference image (<name>.diff.png: |new - ref| * 10, 16-bit linear) go
 * to LP_TEST_TMP.
 *
 *   test_references                  compare
 *   test_references --regenerate DIR write DIR/<name>.png for every scene
 *                                    (scripts/make_references.sh) */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "support/image.h"
#include "integrator.h"
#include "library_path.h"
#include "parser.h"
#include "scene.h"
#include "support/tiles.h"

#ifndef LP_SOURCE_DIR
#error "LP_SOURCE_DIR must name the source tree"
#endif
#ifndef LP_TEST_TMP
#define LP_TEST_TMP "."
#endif

#define REF_W 80
#define REF_H 60
#define PSNR_MIN 50.0
#define MAX_SCENES 256

static const char *const SCENE_DIR = LP_SOURCE_DIR "/scenes";
static const char *const REF_DIR = LP_SOURCE_DIR "/tests/renderer/ref";

/* ---- listing --------------------------------------------------------------- */

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The base names (without `ext`) of the files in dir ending in ext,
 * sorted.  Returns the count, or -1 when dir cannot be read. */
static int list_names(const char *dir, const char *ext, char **names, int max)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int n = 0;
    size_t el = strlen(ext);
    if (!d)
        return -1;
    while ((e = readdir(d)) != NULL && n < max) {
        size_t l = strlen(e->d_name);
        if (l <= el || strcmp(e->d_name + l - el, ext) != 0 || e->d_name[0] == '.')
            continue;
        names[n] = malloc(l - el + 1);
        if (!names[n])
            break;
        memcpy(names[n], e->d_name, l - el);
        names[n][l - el] = '\0';
        n++;
    }
    closedir(d);
    qsort(names, (size_t)n, sizeof *names, cmp_str);
    return n;
}

/* ---- rendering ----------------------------------------------------------------- */

typedef struct job {
    const rs_integrator *it;
    rs_image *img;
} job;

static void *job_worker_make(void *user)
{
    return rs_worker_create(((const job *)user)->it);
}

static void job_worker_free(void *w)
{
    rs_worker_destroy(w);
}

static void job_tile(void *user, void *worker, int x0, int y0, int x1, int y1)
{
    const job *jb = user;
    for (int j = y0; j < y1; j++)
        for (int i = x0; i < x1; i++) {
            rs_color c;
            float *px = jb->img->rgb + 3 * ((size_t)j * (size_t)jb->img->width + (size_t)i);
            rs_integrator_pixel(jb->it, worker, i, j, &c);
            px[0] = (float)c.r;
            px[1] = (float)c.g;
            px[2] = (float)c.b;
        }
}

/* Render scenes/<name>.scene as the references are made.  0 or -1. */
static int render_scene(const char *name, rs_image *img)
{
    char path[4096], msg[1024] = "";
    rs_scene sc;
    rs_parse_opts po;
    const char *dirs[4];
    rs_render_opts ro;
    rs_integrator *it = NULL;
    int rc = -1;

    snprintf(path, sizeof path, "%s/%s.scene", SCENE_DIR, name);
    memset(img, 0, sizeof *img);
    rs_scene_init(&sc);
    rs_parse_opts_init(&po);
    po.image_width = REF_W;
    po.image_height = REF_H;
    po.include_dirs = dirs;
    po.n_include_dirs = rs_library_path(NULL, 0, dirs, sizeof dirs / sizeof dirs[0]);
    rs_render_opts_init(&ro);
    ro.mode = RS_MODE_POLARIZED;
    ro.width = REF_W;
    ro.height = REF_H;
    if (rs_parse_file(path, &po, &sc, msg, sizeof msg) != 0 ||
        rs_scene_prepare(&sc, msg, sizeof msg) != 0 ||
        rs_integrator_create(&sc, &ro, &it, msg, sizeof msg) != 0 ||
        rs_image_create(img, REF_W, REF_H) != 0) {
        if (!msg[0])
            snprintf(msg, sizeof msg, "out of memory for the image");
        fprintf(stderr, "%s: %s\n", name, msg);
        goto done;
    }
    job jb = {it, img};
    if (rs_render_tiles(REF_W, REF_H, 16, 2, job_worker_make, job_worker_free, job_tile, &jb,
                        -1) != 0) {
        fprintf(stderr, "%s: the render failed\n", name);
        goto done;
    }
    rc = 0;
done:
    if (rc != 0)
        rs_image_free(img);
    rs_integrator_destroy(it);
    rs_scene_free(&sc);
    return rc;
}

/* ---- comparing -------------------------------------------------------------------- */

static double clip01(double v)
{
    return v > 1.0 ? 1.0 : (v >= 0.0 ? v : 0.0); /* NaN -> 0 */
}

/* PSNR (dB, peak 1) of the two images clipped to [0, 1]; INFINITY when
 * they agree exactly. */
static double psnr_clipped(const rs_image *a, const rs_image *b)
{
    size_t n = (size_t)3 * (size_t)a->width * (size_t)a->height;
    double se = 0.0;
    for (size_t k = 0; k < n; k++) {
        double d = clip01(a->rgb[k]) - clip01(b->rgb[k]);
        se += d * d;
    }
    if (se == 0.0)
        return INFINITY;
    return -10.0 * log10(se / (double)n);
}

static void write_failure_images(const char *name, const rs_image *got, const rs_image *ref)
{
    char path[4096], msg[1024] = "";
    rs_image diff;
    snprintf(path, sizeof path, "%s/%s.new.png", LP_TEST_TMP, name);
    if (rs_png_write16_linear(path, got, msg, sizeof msg) != 0)
        fprintf(stderr, "%s\n", msg);
    else
        fprintf(stderr, "%s: the new render is %s\n", name, path);
    if (ref->width != got->width || ref->height != got->height)
        return;
    if (rs_image_create(&diff, got->width, got->height) != 0)
        return;
    for (size_t k = 0; k < (size_t)3 * got->width * got->height; k++)
        diff.rgb[k] = (float)(10.0 * fabs(clip01(got->rgb[k]) - clip01(ref->rgb[k])));
    snprintf(path, sizeof path, "%s/%s.diff.png", LP_TEST_TMP, name);
    if (rs_png_write16_linear(path, &diff, msg, sizeof msg) != 0)
        fprintf(stderr, "%s\n", msg);
    else
        fprintf(stderr, "%s: |new - reference| x 10 is %s\n", name, path);
    rs_image_free(&diff);
}

static int regenerate(const char *dir)
{
    char *scenes[MAX_SCENES];
    int n = list_names(SCENE_DIR, ".scene", scenes, MAX_SCENES), status = 0;
    if (n <= 0) {
        fprintf(stderr, "test_references: no scenes in %s\n", SCENE_DIR);
        return 1;
    }
    for (int s = 0; s < n; s++) {
        char path[4096], msg[1024] = "";
        rs_image img;
        snprintf(path, sizeof path, "%s/%s.png", dir, scenes[s]);
        if (render_scene(scenes[s], &img) != 0) {
            status = 1;
        } else if (rs_png_write16_linear(path, &img, msg, sizeof msg) != 0) {
            fprintf(stderr, "test_references: %s\n", msg);
            status = 1;
        } else {
            printf("wrote %s\n", path);
        }
        rs_image_free(&img);
        free(scenes[s]);
    }
    return status;
}

int main(int argc, char **argv)
{
    char *scenes[MAX_SCENES], *refs[MAX_SCENES];
    int ns, nr;

    if (argc == 3 && strcmp(argv[1], "--regenerate") == 0)
        return regenerate(argv[2]);
    if (argc != 1) {
        fprintf(stderr, "usage: test_references [--regenerate DIR]\n");
        return 2;
    }

    ns = list_names(SCENE_DIR, ".scene", scenes, MAX_SCENES);
    nr = list_names(REF_DIR, ".png", refs, MAX_SCENES);
    CHECK(ns > 0, "scenes found in %s", SCENE_DIR);
    CHECK(nr >= 0, "reference directory %s readable", REF_DIR);

    for (int s = 0; s < ns; s++) {
        char path[4096], msg[1024] = "";
        rs_image got, ref;
        int depth = 0;
        struct timespec t0, t1;

        memset(&ref, 0, sizeof ref);
        snprintf(path, sizeof path, "%s/%s.png", REF_DIR, scenes[s]);
        clock_gettime(CLOCK_MONOTONIC, &t0);
        int ok = render_scene(scenes[s], &got) == 0;
        clock_gettime(CLOCK_MONOTONIC, &t1);
        CHECK(ok, "%s renders", scenes[s]);
        if (!ok)
            continue;
        if (rs_png_read(path, &ref, &depth, msg, sizeof msg) != 0) {
            CHECK(0, "%s: no reference (%s); run scripts/make_references.sh", scenes[s], msg);
            write_failure_images(scenes[s], &got, &ref);
            rs_image_free(&got);
            continue;
        }
        CHECK(depth == 16, "%s: the reference is 16-bit (%d)", scenes[s], depth);
        CHECK(ref.width == REF_W && ref.height == REF_H, "%s: the reference is %dx%d, want %dx%d",
              scenes[s], ref.width, ref.height, REF_W, REF_H);
        if (ref.width == REF_W && ref.height == REF_H) {
            double p = psnr_clipped(&got, &ref);
            printf("%-20s PSNR %s%6.1f dB  (%.2f s)\n", scenes[s], isinf(p) ? ">" : " ",
                   isinf(p) ? 999.0 : p,
                   (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
            CHECK(p >= PSNR_MIN, "%s: PSNR %.2f dB against the reference, want >= %.0f",
                  scenes[s], p, PSNR_MIN);
            if (!(p >= PSNR_MIN))
                write_failure_images(scenes[s], &got, &ref);
        }
        rs_image_free(&got);
        rs_image_free(&ref);
    }
    /* every reference belongs to a scene */
    for (int r = 0; r < nr; r++) {
        int found = 0;
        for (int s = 0; s < ns; s++)
            found |= strcmp(refs[r], scenes[s]) == 0;
        CHECK(found, "reference %s.png has no scene (stale: delete it or run "
              "scripts/make_references.sh)", refs[r]);
    }
    for (int s = 0; s < ns; s++)
        free(scenes[s]);
    for (int r = 0; r < nr; r++)
        free(refs[r]);
    return check_finish("test_references");
}
