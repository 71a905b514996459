/* test_references.c -- regression against stored renders.
 *
 * Every .scene file in scenes/ and in tests/renderer/scenes/ (scenes made
 * for this test: a lit one with shadows) is rendered through the renderer's face
 * in each light model (polarized at 80 x 60; fresnel, schlick and rgb at
 * 40 x 30, a quarter of the time) with
 * the default settings (16 wavelengths, the scene's max_trace_level and
 * adc_bailout) and compared with tests/renderer/ref/<name>.<mode>.pfm, a
 * float PFM: values above 1 are kept (highlights, a lamp's direct light),
 * nothing is clipped, and an unchanged render reads back bit for bit.
 * The metric is the PSNR over all pixels and channels with the peak the
 * larger of 1 and the reference's largest value; it must be >= 100 dB: an
 * RMS difference of 1e-5 of the peak, far above the rounding between
 * builds (the release and sanitizer builds compare at infinity, i.e.
 * bit-identical, measured) and far below any change of the physics (a
 * fix of the ring radii scored 31.8 dB against the old references).  By
 * design this is the one test whose expectation is the renderer's own
 * earlier output: it catches unintended change, not physics errors; a
 * reference is regenerated only after a change whose physics a
 * closed-form test confirms.  A scene without its references, or a
 * reference without a scene, is a failure too.
 *
 * On failure the new render (<name>.<mode>.new.pfm) and a difference
 * image (<name>.<mode>.diff.pfm: |new - ref|) go to LP_TEST_TMP.
 *
 *   test_references                  compare
 *   test_references --regenerate DIR write DIR/<name>.<mode>.pfm for every
 *                                    scene and mode
 *                                    (scripts/make_references.sh) */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "lensrender/lensrender.h"
#include "support/image.h"

#ifndef LP_SOURCE_DIR
#error "LP_SOURCE_DIR must name the source tree"
#endif
#ifndef LP_TEST_TMP
#define LP_TEST_TMP "."
#endif

#define REF_W 80
#define REF_H 60
#define PSNR_MIN 100.0
#define MAX_SCENES 256

static const char *const SCENE_DIRS[2] = {LP_SOURCE_DIR "/scenes",
                                          LP_SOURCE_DIR "/tests/renderer/scenes"};
static const char *const REF_DIR = LP_SOURCE_DIR "/tests/renderer/ref";

/* The unpolarized models at half the size: a quarter of the time. */
static const struct { lr_mode mode; const char *name; int w, h; } MODES[4] = {
    {LR_MODE_POLARIZED, "polarized", REF_W, REF_H},
    {LR_MODE_FRESNEL, "fresnel", REF_W / 2, REF_H / 2},
    {LR_MODE_SCHLICK, "schlick", REF_W / 2, REF_H / 2},
    {LR_MODE_RGB, "rgb", REF_W / 2, REF_H / 2},
};
#define N_MODES 4

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

/* Render <dir>/<name>.scene in MODES[m] as the references are made,
 * through the renderer's face (as every program renders).  0 or -1. */
static int render_scene(const char *dir, const char *name, int m, rs_image *img)
{
    const int W = MODES[m].w, H = MODES[m].h;
    char path[4096];
    lr_scene *sc = NULL;
    lr_renderer *r = NULL;
    lr_load_opts lo;
    lr_render_opts ro;
    lr_error err;
    int rc = -1;

    snprintf(path, sizeof path, "%s/%s.scene", dir, name);
    memset(img, 0, sizeof *img);
    lr_load_opts_init(&lo);
    lo.image_width = W;
    lo.image_height = H;
    lr_render_opts_init(&ro);
    ro.mode = MODES[m].mode;
    ro.width = W;
    ro.height = H;
    ro.threads = 2;
    if (lr_scene_load(path, &lo, &sc, &err) != LR_OK ||
        lr_renderer_create(sc, &ro, &r, &err) != LR_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        goto done;
    }
    if (rs_image_create(img, W, H) != 0) {
        fprintf(stderr, "%s: out of memory for the image\n", name);
        goto done;
    }
    if (lr_render_image(r, img->rgb, NULL, NULL, &err) != LR_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        goto done;
    }
    rc = 0;
done:
    if (rc != 0)
        rs_image_free(img);
    lr_renderer_free(r);
    lr_scene_free(sc);
    return rc;
}

/* ---- the scenes ------------------------------------------------------------------ */

typedef struct scene_list {
    char *name[MAX_SCENES];
    const char *dir[MAX_SCENES];
    int n;
} scene_list;

/* Every scene of SCENE_DIRS, sorted within each directory.  -1 when the
 * first directory cannot be read. */
static int list_scenes(scene_list *l)
{
    l->n = 0;
    for (int d = 0; d < 2; d++) {
        char *names[MAX_SCENES];
        int n = list_names(SCENE_DIRS[d], ".scene", names, MAX_SCENES - l->n);
        if (n < 0 && d == 0)
            return -1;
        for (int k = 0; k < n; k++) {
            l->name[l->n] = names[k];
            l->dir[l->n++] = SCENE_DIRS[d];
        }
    }
    return l->n;
}

static void free_scenes(scene_list *l)
{
    for (int k = 0; k < l->n; k++)
        free(l->name[k]);
    l->n = 0;
}

/* ---- comparing -------------------------------------------------------------------- */

/* PSNR (dB) of got against ref over all pixels and channels, the peak the
 * larger of 1 and ref's largest value (nothing clipped); INFINITY when
 * they agree exactly, NAN when got has a value that is not finite. */
static double psnr_float(const rs_image *got, const rs_image *ref, double *peak_out)
{
    size_t n = (size_t)3 * (size_t)ref->width * (size_t)ref->height;
    double se = 0.0, peak = 1.0;
    for (size_t k = 0; k < n; k++)
        if (isfinite(ref->rgb[k]) && ref->rgb[k] > peak)
            peak = ref->rgb[k];
    for (size_t k = 0; k < n; k++) {
        if (!isfinite(got->rgb[k]))
            return NAN;
        double d = (double)got->rgb[k] - (double)ref->rgb[k];
        se += d * d;
    }
    *peak_out = peak;
    if (se == 0.0)
        return INFINITY;
    return 10.0 * log10(peak * peak / (se / (double)n));
}

static void write_failure_images(const char *stem, const rs_image *got, const rs_image *ref)
{
    char path[4096], msg[1024] = "";
    rs_image diff;
    snprintf(path, sizeof path, "%s/%s.new.pfm", LP_TEST_TMP, stem);
    if (rs_pfm_write(path, got, msg, sizeof msg) != 0)
        fprintf(stderr, "%s\n", msg);
    else
        fprintf(stderr, "%s: the new render is %s\n", stem, path);
    if (ref->width != got->width || ref->height != got->height)
        return;
    if (rs_image_create(&diff, got->width, got->height) != 0)
        return;
    for (size_t k = 0; k < (size_t)3 * got->width * got->height; k++)
        diff.rgb[k] = (float)fabs((double)got->rgb[k] - (double)ref->rgb[k]);
    snprintf(path, sizeof path, "%s/%s.diff.pfm", LP_TEST_TMP, stem);
    if (rs_pfm_write(path, &diff, msg, sizeof msg) != 0)
        fprintf(stderr, "%s\n", msg);
    else
        fprintf(stderr, "%s: |new - reference| is %s\n", stem, path);
    rs_image_free(&diff);
}

static int regenerate(const char *dir)
{
    scene_list l;
    int status = 0;
    if (list_scenes(&l) <= 0) {
        fprintf(stderr, "test_references: no scenes in %s\n", SCENE_DIRS[0]);
        return 1;
    }
    for (int s = 0; s < l.n; s++)
        for (int m = 0; m < N_MODES; m++) {
            char path[4096], msg[1024] = "";
            rs_image img;
            snprintf(path, sizeof path, "%s/%s.%s.pfm", dir, l.name[s], MODES[m].name);
            if (render_scene(l.dir[s], l.name[s], m, &img) != 0) {
                status = 1;
                continue;
            } else if (rs_pfm_write(path, &img, msg, sizeof msg) != 0) {
                fprintf(stderr, "test_references: %s\n", msg);
                status = 1;
            } else {
                printf("wrote %s\n", path);
            }
            rs_image_free(&img);
        }
    free_scenes(&l);
    return status;
}

int main(int argc, char **argv)
{
    char *refs[MAX_SCENES * N_MODES];
    scene_list l;
    int nr;
    double worst = INFINITY, above1 = 0.0;

    if (argc == 3 && strcmp(argv[1], "--regenerate") == 0)
        return regenerate(argv[2]);
    if (argc != 1) {
        fprintf(stderr, "usage: test_references [--regenerate DIR]\n");
        return 2;
    }

    int ns = list_scenes(&l);
    nr = list_names(REF_DIR, ".pfm", refs, MAX_SCENES * N_MODES);
    CHECK(ns > 0, "scenes found in %s", SCENE_DIRS[0]);
    CHECK(nr >= 0, "reference directory %s readable", REF_DIR);

    for (int s = 0; s < ns; s++)
        for (int m = 0; m < N_MODES; m++) {
            char path[4096], stem[512], msg[1024] = "";
            rs_image got, ref;
            struct timespec t0, t1;

            memset(&ref, 0, sizeof ref);
            snprintf(stem, sizeof stem, "%s.%s", l.name[s], MODES[m].name);
            snprintf(path, sizeof path, "%s/%s.pfm", REF_DIR, stem);
            clock_gettime(CLOCK_MONOTONIC, &t0);
            int ok = render_scene(l.dir[s], l.name[s], m, &got) == 0;
            clock_gettime(CLOCK_MONOTONIC, &t1);
            CHECK(ok, "%s renders", stem);
            if (!ok)
                continue;
            if (rs_pfm_read(path, &ref, msg, sizeof msg) != 0) {
                CHECK(0, "%s: no reference (%s); run scripts/make_references.sh", stem, msg);
                write_failure_images(stem, &got, &ref);
                rs_image_free(&got);
                continue;
            }
            const int W = MODES[m].w, H = MODES[m].h;
            CHECK(ref.width == W && ref.height == H, "%s: the reference is %dx%d, want %dx%d",
                  stem, ref.width, ref.height, W, H);
            if (ref.width == W && ref.height == H) {
                double peak = 1.0, p = psnr_float(&got, &ref, &peak);
                size_t over = 0;
                for (size_t k = 0; k < (size_t)3 * W * H; k++)
                    over += ref.rgb[k] > 1.0f;
                above1 = fmax(above1, (double)over / (3.0 * W * H));
                printf("%-30s PSNR %s%6.1f dB  peak %.3f, %5.1f %% above 1  (%.2f s)\n", stem,
                       isinf(p) ? ">" : " ", isinf(p) ? 999.0 : p, peak,
                       100.0 * (double)over / (3.0 * W * H),
                       (double)(t1.tv_sec - t0.tv_sec) +
                           1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
                CHECK(p >= PSNR_MIN, "%s: PSNR %.2f dB against the reference, want >= %.0f", stem,
                      p, PSNR_MIN);
                if (!(p >= PSNR_MIN))
                    write_failure_images(stem, &got, &ref);
                if (!(p >= worst))
                    worst = p;
            }
            rs_image_free(&got);
            rs_image_free(&ref);
        }
    /* every reference belongs to a scene and a mode */
    for (int r = 0; r < nr; r++) {
        int found = 0;
        for (int s = 0; s < ns; s++)
            for (int m = 0; m < N_MODES; m++) {
                char stem[512];
                snprintf(stem, sizeof stem, "%s.%s", l.name[s], MODES[m].name);
                found |= strcmp(refs[r], stem) == 0;
            }
        CHECK(found, "reference %s.pfm has no scene and mode (stale: delete it or run "
              "scripts/make_references.sh)", refs[r]);
        free(refs[r]);
    }
    free_scenes(&l);
    printf("references: worst PSNR %.1f dB; up to %.1f %% of a reference's values above 1\n",
           isinf(worst) ? 999.0 : worst, 100.0 * above1);
    return check_finish("test_references");
}
