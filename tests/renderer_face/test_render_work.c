/* test_render_work.c -- lr_render_region_work: what a render did.
 *
 * Counts from the definitions: a scene with nothing in it traces exactly
 * one ray per camera ray (aa x aa per pixel), each carrying every lane
 * (3 in rgb, N wavelengths in the spectral modes), with no lens builds and
 * nothing gathered.  A lens scene in every mode: more rays than camera
 * rays, lens builds, a positive price, no rays gathered but in the
 * polarized mode -- and there none either, the dispersive lens's every
 * hit being the camera ray's own, where each wavelength's power alone is
 * gathered, but some without dispersion; the counts are whole numbers and the same on 1, 2 and 3 threads,
 * and the counts of regions that cut the image add up to the whole
 * image's.  A bad argument gives zero counts. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "lensrender/lensrender.h"

#define W 37 /* not a multiple of the tile size */
#define H 23

static const char *empty_text =
    "camera { location <0, 0, -5> look_at <0, 0, 0> }\n"
    "background { rgb <0.2, 0.3, 0.4> }\n"
    "light_source { <0, 5, -5> color rgb 1 }\n";

static const char *lens_text =
    "global_settings { max_trace_level 6 }\n"
    "camera { location <0, 80, -70> look_at <0, 2, 0>\n"
    "         right x*image_width/image_height angle 44 }\n"
    "background { rgb <0.10, 0.12, 0.18> }\n"
    "light_source { <45, 90, -25> color rgb 1.6 }\n"
    "plane { y, 0 pigment { checker rgb 0.9, rgb 0.45 scale 10 } }\n"
    "sphere { <-16, 8, 12>, 8 pigment { rgb <0.8, 0.3, 0.1> } }\n"
    "lens { radius1 40 radius2 -40 thickness 6 diameter 20 glass \"N-BK7\"\n"
    "       rotate <-90, 0, 0> translate <-4, 16, -18> }\n";

static lr_scene *load(const char *text)
{
    lr_load_opts lo;
    lr_scene *s = NULL;
    lr_error err;
    lr_load_opts_init(&lo);
    lo.image_width = W;
    lo.image_height = H;
    if (lr_scene_load_string(text, "work.scene", &lo, &s, &err) != LR_OK) {
        fprintf(stderr, "load: %s\n", err.message);
        lr_scene_free(s);
        return NULL;
    }
    return s;
}

/* Dispersion off in the renders of work_of (lr_render_opts.no_dispersion). */
static int no_dispersion;

/* Render region [x0,x1) x [y0,y1) of scene s; 0, or -1 on failure. */
static int work_of(lr_scene *s, lr_mode mode, int wavelengths, int aa, int threads, int x0,
                   int y0, int x1, int y1, lr_work *wk)
{
    lr_render_opts o;
    lr_renderer *r = NULL;
    lr_error err;
    float *rgb = malloc(sizeof *rgb * 3 * W * H);
    int rc = -1;
    lr_render_opts_init(&o);
    o.no_dispersion = no_dispersion;
    o.mode = mode;
    o.width = W;
    o.height = H;
    o.wavelengths = wavelengths;
    o.aa = aa;
    o.threads = threads;
    if (rgb && lr_renderer_create(s, &o, &r, &err) == LR_OK &&
        lr_render_region_work(r, x0, y0, x1, y1, rgb, NULL, NULL, wk, &err) == LR_OK)
        rc = 0;
    else
        fprintf(stderr, "render: %s\n", err.message);
    lr_renderer_free(r);
    free(rgb);
    return rc;
}

static int same(const lr_work *a, const lr_work *b)
{
    return a->pixels == b->pixels && a->rays == b->rays && a->lane_rays == b->lane_rays &&
           a->builds == b->builds && a->gathered == b->gathered && a->cost == b->cost;
}

static int whole(const lr_work *a)
{
    return a->pixels == floor(a->pixels) && a->rays == floor(a->rays) &&
           a->lane_rays == floor(a->lane_rays) && a->builds == floor(a->builds) &&
           a->gathered == floor(a->gathered);
}

static void empty_scene(void)
{
    static const struct { lr_mode mode; int wl, aa, lanes; } cases[] = {
        {LR_MODE_RGB, 0, 1, 3},        {LR_MODE_RGB, 0, 2, 3},
        {LR_MODE_FRESNEL, 7, 1, 7},    {LR_MODE_SCHLICK, 16, 1, 16},
        {LR_MODE_POLARIZED, 5, 1, 5},  {LR_MODE_POLARIZED, 12, 3, 12},
    };
    lr_scene *s = load(empty_text);
    CHECK(s != NULL, "the empty scene loads");
    if (!s)
        return;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        lr_work wk;
        double camera_rays = (double)W * H * cases[c].aa * cases[c].aa;
        if (work_of(s, cases[c].mode, cases[c].wl, cases[c].aa, 2, 0, 0, W, H, &wk) != 0) {
            CHECK(0, "empty scene, %s: renders", lr_mode_name(cases[c].mode));
            continue;
        }
        CHECK(wk.pixels == (double)W * H, "empty %s: pixels %g, want %d",
              lr_mode_name(cases[c].mode), wk.pixels, W * H);
        CHECK(wk.rays == camera_rays, "empty %s aa %d: rays %g, want %g (one per camera ray)",
              lr_mode_name(cases[c].mode), cases[c].aa, wk.rays, camera_rays);
        CHECK(wk.lane_rays == camera_rays * cases[c].lanes,
              "empty %s: lane_rays %g, want %g (%d lanes each)", lr_mode_name(cases[c].mode),
              wk.lane_rays, camera_rays * cases[c].lanes, cases[c].lanes);
        CHECK(wk.builds == 0.0 && wk.gathered == 0.0, "empty %s: builds %g gathered %g, want 0",
              lr_mode_name(cases[c].mode), wk.builds, wk.gathered);
        CHECK(wk.cost > 0.0, "empty %s: cost %g > 0", lr_mode_name(cases[c].mode), wk.cost);
    }
    lr_scene_free(s);
}

static void lens_scene(void)
{
    static const lr_mode modes[] = {LR_MODE_POLARIZED, LR_MODE_FRESNEL, LR_MODE_SCHLICK,
                                    LR_MODE_RGB};
    /* row strips, column strips and an uneven grid */
    static const int cuts[][4] = {{0, 0, W, 9},   {0, 9, W, 10},  {0, 10, W, H},
                                  {0, 0, 5, H},   {5, 0, 31, H},  {31, 0, W, H},
                                  {0, 0, 17, 4},  {17, 0, W, 4},  {0, 4, 17, H}, {17, 4, W, H}};
    lr_scene *s = load(lens_text);
    CHECK(s != NULL, "the lens scene loads");
    if (!s)
        return;
    for (size_t m = 0; m < sizeof modes / sizeof modes[0]; m++) {
        const char *name = lr_mode_name(modes[m]);
        lr_work one, two, three;
        if (work_of(s, modes[m], 8, 1, 1, 0, 0, W, H, &one) != 0 ||
            work_of(s, modes[m], 8, 1, 2, 0, 0, W, H, &two) != 0 ||
            work_of(s, modes[m], 8, 1, 3, 0, 0, W, H, &three) != 0) {
            CHECK(0, "lens scene, %s: renders", name);
            continue;
        }
        CHECK(whole(&one), "%s: whole-number counts", name);
        CHECK(one.pixels == (double)W * H, "%s: pixels %g", name, one.pixels);
        CHECK(one.rays > one.pixels, "%s: rays %g > camera rays %g (the lens, reflections)",
              name, one.rays, one.pixels);
        CHECK(one.lane_rays >= one.rays, "%s: lane_rays %g >= rays %g", name, one.lane_rays,
              one.rays);
        CHECK(one.builds > 0.0, "%s: lens builds %g > 0", name, one.builds);
        if (modes[m] == LR_MODE_POLARIZED) /* every lens hit the camera ray's own, each
                                              wavelength alone: their power alone */
            CHECK(one.gathered == 0.0, "%s: gathered %g == 0 (power alone)", name,
                  one.gathered);
        else
            CHECK(one.gathered == 0.0, "%s: gathered %g == 0 (polarized only)", name,
                  one.gathered);
        CHECK(one.cost > 0.0, "%s: cost %g > 0", name, one.cost);
        CHECK(same(&one, &two) && same(&one, &three),
              "%s: the same counts on 1, 2 and 3 threads (rays %g %g %g)", name, one.rays,
              two.rays, three.rays);
        for (int g = 0; g < 3; g++) { /* each group of cuts covers the image */
            static const int from[] = {0, 3, 6}, to[] = {3, 6, 10};
            lr_work sum = {0, 0, 0, 0, 0, 0}, part;
            for (int k = from[g]; k < to[g]; k++) {
                if (work_of(s, modes[m], 8, 1, 2, cuts[k][0], cuts[k][1], cuts[k][2],
                            cuts[k][3], &part) != 0)
                    break;
                sum.pixels += part.pixels;
                sum.rays += part.rays;
                sum.lane_rays += part.lane_rays;
                sum.builds += part.builds;
                sum.gathered += part.gathered;
            }
            CHECK(sum.pixels == one.pixels && sum.rays == one.rays &&
                      sum.lane_rays == one.lane_rays && sum.builds == one.builds &&
                      sum.gathered == one.gathered,
                  "%s: regions (cut %d) add up to the image (rays %g, want %g)", name, g,
                  sum.rays, one.rays);
        }
    }
    lr_scene_free(s);
}

/* Without dispersion the lens keeps the packet whole, and its rays are
 * gathered, not their power alone: counted in the polarized mode. */
static void lens_scene_no_dispersion(void)
{
    lr_scene *s = load(lens_text); /* its own: no_dispersion changes it for good */
    lr_work one;
    CHECK(s != NULL, "the lens scene loads");
    if (!s)
        return;
    no_dispersion = 1;
    if (work_of(s, LR_MODE_POLARIZED, 8, 1, 1, 0, 0, W, H, &one) == 0)
        CHECK(one.gathered > 0.0, "no dispersion, polarized: gathered %g > 0", one.gathered);
    else
        CHECK(0, "no dispersion, polarized: renders");
    no_dispersion = 0;
    lr_scene_free(s);
}

static void bad_argument(void)
{
    lr_work wk;
    float px[3];
    lr_error err;
    memset(&wk, 0xff, sizeof wk);
    CHECK(lr_render_region_work(NULL, 0, 0, 1, 1, px, NULL, NULL, &wk, &err) ==
              LR_ERROR_INVALID_ARGUMENT,
          "a NULL renderer is refused");
    CHECK(wk.pixels == 0.0 && wk.rays == 0.0 && wk.cost == 0.0, "and its counts are zero");
}

int main(void)
{
    empty_scene();
    lens_scene();
    lens_scene_no_dispersion();
    bad_argument();
    return check_finish("test_render_work");
}
