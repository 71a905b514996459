/* test_face.c -- the renderer's public face, used as a program outside the
 * renderer uses it (this directory sees lensrender/ only: an include of
 * any other renderer header does not compile here).
 *
 * Loading: a scene with a lens loads, its warnings and #debug text come
 * back as messages in order, it keeps the scene's rules (and a copy with a
 * broken rule is refused at the object's place); a wrong scene gives LR_ERROR_SCENE with the
 * file, line and column where the error is; a missing file gives
 * LR_ERROR_IO with its path.  Options out of range are refused.
 * Determinism: the whole image on 1 thread, the whole image on 2 and 3
 * threads, and the image put together from regions (row strips, column
 * strips, an uneven grid, single pixels) rendered with 1, 2 and 3 threads
 * are byte for byte the same.  Progress: called, increasing, the last call
 * with done == total; a callback that says stop gives LR_CANCELLED. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "lensrender/lensrender.h"

#define W 37 /* not a multiple of the tile size */
#define H 23

static const char *scene_text =
    "// a lens over a checkered floor\n"
    "global_settings { max_trace_level 6 assumed_gamma 2.2 }\n"
    "#debug \"face test\\n\"\n"
    "camera { location <0, 80, -70> look_at <0, 2, 0>\n"
    "         right x*image_width/image_height angle 44 }\n"
    "background { rgb <0.10, 0.12, 0.18> }\n"
    "light_source { <45, 90, -25> color rgb 1.6 }\n"
    "plane { y, 0 pigment { checker rgb 0.9, rgb 0.45 scale 10 } }\n"
    "sphere { <-16, 8, 12>, 8 pigment { rgb <0.8, 0.3, 0.1> } }\n"
    "lens { radius1 40 radius2 -40 thickness 6 diameter 20 glass \"N-BK7\"\n"
    "       rotate <-90, 0, 0> translate <-4, 16, -18> }\n";

/* A lens over a self-lit black-and-white checker, which it disperses into
 * coloured edges: auto refines the pixels seen through it. */
static const char *dispersed_text =
    "global_settings { max_trace_level 8 adc_bailout 0.002 }\n"
    "camera { location <0, 95, -55> look_at <0, 14, 0>\n"
    "         right x*image_width/image_height angle 36 }\n"
    "background { rgb <0.20, 0.30, 0.50> }\n"
    "lens { radius1 50 radius2 -50 thickness 8 diameter 25 glass \"N-BK7\"\n"
    "       rotate <-90, 0, 0> translate <0, 20, 0> }\n"
    "plane { y, 0 pigment { checker rgb 0.9, rgb 0.1 scale 5 }\n"
    "        finish { ambient 0 diffuse 0 emission 1 } }\n";

/* "sphere" at line 3, column 1, lacks its '{'. */
static const char *bad_text =
    "camera { location <0, 0, -5> }\n"
    "light_source { <0, 5, -5> color rgb 1 }\n"
    "sphere <0, 0, 0>, 1 }\n";

static int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fputs(text, f);
    return fclose(f);
}

typedef struct progress_log {
    int calls, increasing, stop_after;
    long long last_done, last_total;
} progress_log;

static int on_progress(void *user, long long done, long long total)
{
    progress_log *p = user;
    if (p->calls > 0 && done < p->last_done)
        p->increasing = 0;
    p->calls++;
    p->last_done = done;
    p->last_total = total;
    return p->stop_after > 0 && p->calls >= p->stop_after;
}

/* Render the image region by region (nx x ny regions, cut unevenly) with
 * the renderer's threads into img; 0 on success. */
static int render_by_regions(const lr_renderer *r, int nx, int ny, float *img)
{
    for (int by = 0; by < ny; by++)
        for (int bx = 0; bx < nx; bx++) {
            /* uneven cuts: region k ends at k^2-ish fractions */
            int x0 = W * bx * bx / (nx * nx), x1 = W * (bx + 1) * (bx + 1) / (nx * nx);
            int y0 = H * by / ny, y1 = H * (by + 1) / ny;
            if (x1 <= x0 || y1 <= y0)
                continue;
            float *buf = malloc(sizeof(float) * 3 * (size_t)(x1 - x0) * (size_t)(y1 - y0));
            lr_error err;
            if (!buf || lr_render_region(r, x0, y0, x1, y1, buf, NULL, NULL, &err) != LR_OK) {
                free(buf);
                return -1;
            }
            for (int j = y0; j < y1; j++)
                memcpy(img + 3 * ((size_t)j * W + (size_t)x0),
                       buf + 3 * ((size_t)(j - y0) * (size_t)(x1 - x0)),
                       sizeof(float) * 3 * (size_t)(x1 - x0));
            free(buf);
        }
    return 0;
}

int main(void)
{
    char path[1024], bad[1024], missing[1024];
    lr_error err;
    lr_scene *scene = NULL, *bs = NULL, *ms = NULL;
    lr_load_opts lo;
    lr_render_opts ro;
    lr_renderer *r = NULL;
    static float ref[3 * W * H], img[3 * W * H];

    snprintf(path, sizeof path, "%s/face_scene.scene", LP_TEST_TMP);
    snprintf(bad, sizeof bad, "%s/face_bad.scene", LP_TEST_TMP);
    snprintf(missing, sizeof missing, "%s/face_no_such.scene", LP_TEST_TMP);
    remove(missing);
    CHECK(write_file(path, scene_text) == 0 && write_file(bad, bad_text) == 0,
          "cannot write the scenes into %s", LP_TEST_TMP);

    /* ---- loading ---- */
    lr_load_opts_init(&lo);
    lo.image_width = W;
    lo.image_height = H;
    CHECK(lr_scene_load(path, &lo, &scene, &err) == LR_OK, "load: %s", err.message);
    CHECK(scene && lr_scene_description(scene) &&
              lr_scene_description(scene)->n_objects == 3 &&
              lr_scene_description(scene)->n_lights == 1,
          "the description has the plane, sphere and lens and the light");
    {
        lr_message_kind k0 = LR_MESSAGE_WARNING, k1 = LR_MESSAGE_WARNING;
        size_t n = lr_scene_message_count(scene);
        const char *m0 = lr_scene_message(scene, 0, &k0), *m1 = lr_scene_message(scene, 1, &k1);
        CHECK(n == 2, "two messages (the gamma warning, the #debug), got %zu", n);
        CHECK(m0 && k0 == LR_MESSAGE_WARNING && strstr(m0, "face_scene.scene:2:") &&
                  strstr(m0, "warning"),
              "message 0 is the assumed_gamma warning with its place: '%s'", m0 ? m0 : "");
        CHECK(m1 && k1 == LR_MESSAGE_DEBUG && strcmp(m1, "face test\n") == 0,
              "message 1 is the #debug text as written: '%s'", m1 ? m1 : "");
        CHECK(lr_scene_message(scene, 2, NULL) == NULL, "no message past the end");
    }

    CHECK(lr_scene_load(bad, &lo, &bs, &err) == LR_ERROR_SCENE, "a bad scene: LR_ERROR_SCENE");
    CHECK(err.status == LR_ERROR_SCENE && strcmp(err.file, bad) == 0 && err.line == 3 &&
              err.column == 8,
          "the error's place: '%s' %d:%d (want %s 3:8): %s", err.file, err.line, err.column,
          bad, err.message);
    CHECK(strncmp(err.message, bad, strlen(bad)) == 0 && strstr(err.message, ":3:8: "),
          "the message starts FILE:3:8: '%s'", err.message);
    CHECK(bs != NULL && lr_scene_description(bs) == NULL,
          "a failed scene is kept for its messages but has no description");
    lr_render_opts_init(&ro);
    CHECK(lr_renderer_create(bs, &ro, &r, &err) == LR_ERROR_INVALID_ARGUMENT && r == NULL,
          "a failed scene cannot be rendered");
    lr_scene_free(bs);

    CHECK(lr_scene_load(missing, &lo, &ms, &err) == LR_ERROR_IO && strcmp(err.file, missing) == 0 &&
              err.line == 0,
          "a missing file: LR_ERROR_IO naming it: %d '%s' %d", err.status, err.file, err.line);
    lr_scene_free(ms);

    CHECK(lr_scene_load_string("sphere { <0,0,0>, 1 }\n#include \"x.inc\"\n", "<text>",
                               &(lr_load_opts){.no_include = 1}, &ms, &err) == LR_ERROR_SCENE &&
              strcmp(err.file, "<text>") == 0 && err.line == 2,
          "no_include: #include refused at <text>:2: '%s'", err.message);
    lr_scene_free(ms);

    /* ---- the scene's rules, checked by one function ---- */
    CHECK(lr_scene_check(lr_scene_description(scene), &err) == LR_OK,
          "a loaded scene keeps the rules: %s", err.message);
    {
        const rs_scene *d = lr_scene_description(scene);
        rs_scene copy = *d;
        rs_object objs[3];
        memcpy(objs, d->objects, sizeof objs);
        copy.objects = objs;
        objs[1].u.sphere.radius = -1.0; /* the sphere, written at line 9 */
        CHECK(lr_scene_check(&copy, &err) == LR_ERROR_SCENE && strcmp(err.file, path) == 0 &&
                  err.line == 9 && err.column == 1 && strstr(err.message, "radius"),
              "a sphere of radius -1 breaks a rule at its place: %s", err.message);
        objs[1].u.sphere.radius = 8.0;
        objs[0].finish.roughness = NAN;
        CHECK(lr_scene_check(&copy, &err) == LR_ERROR_SCENE && err.line == 8,
              "a NaN roughness breaks a rule at the plane's line 8: %s", err.message);
        objs[0].finish.roughness = d->objects[0].finish.roughness;
        copy.camera.location.x = INFINITY;
        CHECK(lr_scene_check(&copy, &err) == LR_ERROR_SCENE && strstr(err.message, "camera"),
              "an infinite camera location breaks a rule: %s", err.message);
    }

    /* ---- options ---- */
    lr_render_opts_init(&ro);
    ro.width = 0;
    CHECK(lr_renderer_create(scene, &ro, &r, &err) == LR_ERROR_INVALID_ARGUMENT && !r,
          "width 0 refused");
    lr_render_opts_init(&ro);
    ro.aa = 17;
    CHECK(lr_renderer_create(scene, &ro, &r, &err) == LR_ERROR_INVALID_ARGUMENT && !r,
          "aa 17 refused");

    /* ---- determinism: regions and threads ---- */
    lr_render_opts_init(&ro);
    ro.mode = LR_MODE_FRESNEL;
    ro.width = W;
    ro.height = H;
    ro.wavelengths = 4;
    ro.threads = 1;
    CHECK(lr_renderer_create(scene, &ro, &r, &err) == LR_OK, "renderer: %s", err.message);
    if (!r)
        return check_finish("test_face");
    {
        lr_render_opts used;
        lr_renderer_settings(r, &used);
        CHECK(used.mode == LR_MODE_FRESNEL && used.wavelengths == 4 && used.depth == 6,
              "settings: fresnel, 4 wavelengths, the scene's depth 6 (got %s %d %d)",
              lr_mode_name(used.mode), used.wavelengths, used.depth);
        CHECK(strcmp(lr_renderer_explanation(r), "") == 0, "no explanation outside auto");
        CHECK(strcmp(lr_renderer_description(r), "fresnel, 4 wavelengths, depth 6") == 0,
              "description: %s", lr_renderer_description(r));
    }
    {
        lr_renderer *rr = NULL;
        lr_render_opts rgb = ro;
        rgb.mode = LR_MODE_RGB;
        rgb.depth = 3;
        CHECK(lr_renderer_create(scene, &rgb, &rr, &err) == LR_OK && rr &&
                  strcmp(lr_renderer_description(rr), "rgb, depth 3") == 0,
              "an rgb renderer says no wavelengths: %s", rr ? lr_renderer_description(rr) : "");
        lr_renderer_free(rr);
    }
    progress_log pl = {0, 1, 0, 0, 0};
    CHECK(lr_render_image(r, ref, on_progress, &pl, &err) == LR_OK, "render: %s", err.message);
    CHECK(pl.calls >= 1 && pl.increasing && pl.last_done == (long long)W * H &&
              pl.last_total == (long long)W * H,
          "progress: %d calls, last %lld of %lld", pl.calls, pl.last_done, pl.last_total);
    {
        double sum = 0.0;
        for (size_t k = 0; k < 3 * (size_t)W * H; k++)
            sum += ref[k];
        CHECK(sum > 0.1 * W * H, "the image is not black (sum %g)", sum);
    }
    const int splits[][2] = {{1, 1}, {1, 7}, {5, 1}, {3, 4}, {W, H}};
    for (int threads = 1; threads <= 3; threads++) {
        lr_renderer *rt = NULL;
        ro.threads = threads;
        CHECK(lr_renderer_create(scene, &ro, &rt, &err) == LR_OK, "renderer: %s", err.message);
        if (!rt)
            continue;
        memset(img, 0xff, sizeof img);
        CHECK(lr_render_image(rt, img, NULL, NULL, &err) == LR_OK &&
                  memcmp(img, ref, sizeof img) == 0,
              "the whole image on %d threads is the 1-thread image", threads);
        for (size_t s = 0; s < sizeof splits / sizeof splits[0]; s++) {
            memset(img, 0xff, sizeof img);
            CHECK(render_by_regions(rt, splits[s][0], splits[s][1], img) == 0 &&
                      memcmp(img, ref, sizeof img) == 0,
                  "%d x %d regions on %d threads give the image byte for byte", splits[s][0],
                  splits[s][1], threads);
        }
        {
            /* every pixel as a list, scrambled and with repeats: each value
             * the whole image's */
            static int xy[2 * (W * H + 5)];
            static float got[3 * (W * H + 5)];
            size_t n = 0;
            for (int k = 0; k < W * H; k++, n++) {
                int m = (int)(((long)k * 29 + 11) % (W * H)); /* 29 is prime to W * H */
                xy[2 * n] = m % W;
                xy[2 * n + 1] = m / W;
            }
            for (int k = 0; k < 5; k++, n++) {
                xy[2 * n] = xy[2 * k];
                xy[2 * n + 1] = xy[2 * k + 1];
            }
            int same = lr_render_pixels(rt, xy, n, got, NULL, NULL, &err) == LR_OK;
            for (size_t k = 0; same && k < n; k++)
                same = memcmp(&got[3 * k], &ref[3 * ((size_t)xy[2 * k + 1] * W + xy[2 * k])],
                              3 * sizeof(float)) == 0;
            CHECK(same, "a scrambled list of every pixel (and 5 again) on %d threads gives each "
                  "pixel byte for byte", threads);
        }
        lr_renderer_free(rt);
    }
    {
        /* auto, where it refines pixels (more wavelengths for the pixels
         * the lens disperses): the image still the same whatever the
         * regions, the threads and the order */
        static float aref[3 * W * H], aimg[3 * W * H];
        static int xy[2 * W * H];
        static float got[3 * W * H];
        static const double tols[] = {1e-2, 1e-3};
        int refined = 0;
        lr_scene *ds = NULL;
        lr_load_opts lo;
        lr_load_opts_init(&lo);
        lo.image_width = W;
        lo.image_height = H;
        CHECK(lr_scene_load_string(dispersed_text, "dispersed.scene", &lo, &ds, &err) == LR_OK,
              "the dispersed scene loads: %s", err.message);
        for (size_t t = 0; ds && t < sizeof tols / sizeof *tols; t++) {
            lr_renderer *ra = NULL, *rb = NULL;
            lr_render_opts ao;
            lr_render_opts_init(&ao);
            ao.mode = LR_MODE_AUTO;
            ao.tolerance = tols[t];
            ao.width = W;
            ao.height = H;
            ao.threads = 1;
            CHECK(lr_renderer_create(ds, &ao, &ra, &err) == LR_OK, "auto: %s", err.message);
            ao.threads = 3;
            CHECK(lr_renderer_create(ds, &ao, &rb, &err) == LR_OK, "auto: %s", err.message);
            if (!ra || !rb) {
                lr_renderer_free(ra);
                lr_renderer_free(rb);
                continue;
            }
            refined += strstr(lr_renderer_explanation(ra), "refined") != NULL;
            CHECK((strstr(lr_renderer_explanation(ra), "refined") != NULL) ==
                      (strstr(lr_renderer_description(ra), "refined per pixel up to") != NULL),
                  "the description says where auto refines: %s | %s",
                  lr_renderer_description(ra), lr_renderer_explanation(ra));
            CHECK(strcmp(lr_renderer_explanation(ra), lr_renderer_explanation(rb)) == 0,
                  "auto chooses the same whatever the threads");
            CHECK(lr_render_image(ra, aref, NULL, NULL, &err) == LR_OK &&
                      lr_render_image(rb, aimg, NULL, NULL, &err) == LR_OK &&
                      memcmp(aimg, aref, sizeof aimg) == 0,
                  "auto at E = %g: 3 threads give the 1-thread image", tols[t]);
            memset(aimg, 0xff, sizeof aimg);
            CHECK(render_by_regions(rb, 3, 4, aimg) == 0 && memcmp(aimg, aref, sizeof aimg) == 0,
                  "auto at E = %g: 3 x 4 regions give the image byte for byte", tols[t]);
            for (int k = 0; k < W * H; k++) {
                int m = (int)(((long)k * 29 + 11) % (W * H));
                xy[2 * k] = m % W;
                xy[2 * k + 1] = m / W;
            }
            int same = lr_render_pixels(rb, xy, (size_t)W * H, got, NULL, NULL, &err) == LR_OK;
            for (int k = 0; same && k < W * H; k++)
                same = memcmp(&got[3 * k], &aref[3 * (xy[2 * k + 1] * W + xy[2 * k])],
                              3 * sizeof(float)) == 0;
            CHECK(same, "auto at E = %g: a scrambled list gives each pixel byte for byte",
                  tols[t]);
            lr_renderer_free(ra);
            lr_renderer_free(rb);
        }
        CHECK(refined > 0, "auto refines pixels at one of the tolerances at least");
        lr_scene_free(ds);
    }
    {
        float one[3];
        int outside[4] = {1, 1, 2, H};
        progress_log pl2 = {0, 1, 0, 0, 0};
        CHECK(lr_render_pixels(r, outside, 2, img, NULL, NULL, &err) == LR_ERROR_INVALID_ARGUMENT,
              "a list with a pixel outside the image is refused");
        CHECK(lr_render_pixels(r, NULL, 0, NULL, NULL, NULL, &err) == LR_OK,
              "an empty list renders nothing");
        CHECK(lr_render_pixels(r, outside, 1, one, on_progress, &pl2, &err) == LR_OK &&
                  pl2.last_done == 1 && pl2.last_total == 1,
              "a list's progress counts its pixels (%lld of %lld)", pl2.last_done, pl2.last_total);
        CHECK(lr_render_region(r, W, 0, W + 1, 1, one, NULL, NULL, &err) ==
                  LR_ERROR_INVALID_ARGUMENT,
              "a region outside the image is refused");
        CHECK(lr_render_region(r, 3, 3, 3, 4, one, NULL, NULL, &err) == LR_ERROR_INVALID_ARGUMENT,
              "an empty region is refused");
    }

    /* ---- cancel ---- */
    {
        progress_log stop = {0, 1, 1, 0, 0};
        CHECK(lr_render_image(r, img, on_progress, &stop, &err) == LR_CANCELLED &&
                  err.status == LR_CANCELLED && stop.calls == 1,
              "a callback that says stop cancels (status %d, %d calls)", err.status, stop.calls);
    }

    lr_renderer_free(r);
    lr_scene_free(scene);
    remove(path);
    remove(bad);
    return check_finish("test_face");
}
