/* test_refine.c -- the refinement of the wavelengths per pixel
 * (rs_render_opts.refine_tol, refine_max), against plain renders.
 *
 * The rule, restated here and replayed on integrators without it: a
 * pixel whose render at N wavelengths split a spectral packet at a lens
 * (rs_worker_splits) is rendered at 2N, 4N ... until two doublings in a
 * row change no channel by more than the tolerance, or at refine_max --
 * past which it goes on doubling, up to refine_limit, while its last
 * doubling changed some channel by more than refine_outlier; it takes its
 * last render's value.  So every pixel of a refining render
 * must equal, bit for bit, the plain render at the count the replay ends
 * on, and its work must be the sum of the replay's renders' work.  A
 * scene whose lens does not disperse (and one without lenses) splits no
 * packet: its refining render is the plain render at N, pixel for pixel.
 * Checked on default.scene (a dispersive lens over a checker) in the
 * fresnel and polarized models, at a size where some pixels are refined
 * to every count and some pixels not at all. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "integrator.h"
#include "load_scene.h"
#include "scene.h"

#define W 32
#define H 24
#define N0 4
#define N_MAX 64   /* refine_max */
#define N_LIMIT 256 /* refine_limit */
#define LEVELS 7    /* 4, 8 ... 256 */

static int same(rs_color a, rs_color b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static double change_max(rs_color a, rs_color b)
{
    return fmax(fabs(a.r - b.r), fmax(fabs(a.g - b.g), fabs(a.b - b.b)));
}

/* A refining render of sc in mode against the replay; counts[l] gets the
 * pixels that ended at level l.  Returns the pixels that split. */
static int against_replay(const rs_scene *sc, rs_mode mode, double tol, double outlier,
                          int *counts)
{
    char msg[512];
    rs_integrator *plain[LEVELS], *ref;
    rs_worker *pw[LEVELS], *rw;
    rs_render_opts o;
    int n_split = 0, ok = 1;
    rs_render_opts_init(&o);
    o.mode = mode;
    o.width = W;
    o.height = H;
    o.depth = 8;
    o.cutoff = 1e-3;
    for (int l = 0; l < LEVELS; l++) {
        o.wavelengths = N0 << l;
        CHECK(rs_integrator_create(sc, &o, &plain[l], msg, sizeof msg) == 0, "plain %d: %s",
              o.wavelengths, msg);
        pw[l] = rs_worker_create(plain[l]);
        CHECK(pw[l] != NULL, "worker");
        counts[l] = 0;
    }
    o.wavelengths = N0;
    o.refine_tol = tol;
    o.refine_max = N_MAX;
    o.refine_outlier = outlier;
    o.refine_limit = N_LIMIT;
    CHECK(rs_integrator_create(sc, &o, &ref, msg, sizeof msg) == 0, "refining: %s", msg);
    rw = rs_worker_create(ref);
    CHECK(rw != NULL, "worker");
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            rs_color got, want, c;
            rs_work wb, wa, expect = {0, 0, 0, 0};
            int level = 0, calm = 0;
            rs_worker_work(rw, &wb);
            rs_integrator_pixel(ref, rw, i, j, &got);
            rs_worker_work(rw, &wa);
            for (int l = 0; l < LEVELS; l++) {
                rs_work b, a;
                unsigned long long s0 = rs_worker_splits(pw[l]);
                rs_worker_work(pw[l], &b);
                rs_integrator_pixel(plain[l], pw[l], i, j, &c);
                rs_worker_work(pw[l], &a);
                expect.rays += a.rays - b.rays;
                expect.lane_rays += a.lane_rays - b.lane_rays;
                expect.builds += a.builds - b.builds;
                expect.gathered += a.gathered - b.gathered;
                if (l == 0) {
                    want = c;
                    if (rs_worker_splits(pw[0]) == s0)
                        break;
                    n_split++;
                    continue;
                }
                double ch = change_max(c, want);
                want = c;
                level = l;
                calm = ch > tol ? 0 : calm + 1;
                if ((N0 << l) >= N_MAX ? !(ch > outlier) : calm == 2)
                    break;
            }
            counts[level]++;
            if (ok && !same(got, want)) {
                CHECK(0, "%s pixel %d %d: refined %.9g %.9g %.9g, replay (level %d) %.9g %.9g %.9g",
                      mode == RS_MODE_POLARIZED ? "polarized" : "fresnel", i, j, got.r, got.g,
                      got.b, level, want.r, want.g, want.b);
                ok = 0;
            }
            if (ok && (wa.rays - wb.rays != expect.rays ||
                       wa.lane_rays - wb.lane_rays != expect.lane_rays ||
                       wa.builds - wb.builds != expect.builds ||
                       wa.gathered - wb.gathered != expect.gathered)) {
                CHECK(0, "pixel %d %d: the refining render's work %g rays %g lanes, the "
                         "replay's %g %g",
                      i, j, wa.rays - wb.rays, wa.lane_rays - wb.lane_rays, expect.rays,
                      expect.lane_rays);
                ok = 0;
            }
        }
    rs_worker_destroy(rw);
    rs_integrator_destroy(ref);
    for (int l = 0; l < LEVELS; l++) {
        rs_worker_destroy(pw[l]);
        rs_integrator_destroy(plain[l]);
    }
    return n_split;
}

static void dispersive_scene(void)
{
    char path[1024];
    rs_scene sc;
    int counts[LEVELS];
    snprintf(path, sizeof path, "%s/scenes/default.scene", LP_SOURCE_DIR);
    rs_scene_init(&sc);
    CHECK(load_scene(&sc, path, NULL, NULL, W, H) == 0, "default.scene loads");
    for (int m = 0; m < 2; m++) {
        rs_mode mode = m ? RS_MODE_POLARIZED : RS_MODE_FRESNEL;
        int n_split = against_replay(&sc, mode, 1e-3, 0.003, counts);
        printf("%s: %d of %d pixels split; ended at 4..256 wavelengths: %d %d %d %d %d %d %d\n",
               m ? "polarized" : "fresnel", n_split, W * H, counts[0], counts[1], counts[2],
               counts[3], counts[4], counts[5], counts[6]);
        /* the test means something only if every way a pixel can end is
         * taken: unsplit, calm after two doublings, calm later, at the top,
         * past the top */
        CHECK(n_split > 0 && n_split < W * H / 2, "some pixels split, most not (%d)", n_split);
        CHECK(counts[0] == W * H - n_split, "the unsplit pixels end at the first count");
        CHECK(counts[1] == 0, "no pixel ends after one doubling");
        CHECK(counts[2] > 0 && counts[3] > 0 && counts[4] > 0,
              "pixels end at 16, 32 and 64 wavelengths (%d %d %d)", counts[2], counts[3],
              counts[4]);
        CHECK(counts[5] + counts[6] > 0, "pixels go on past the top (%d %d)", counts[5],
              counts[6]);
    }
    rs_scene_free(&sc);
}

/* The same scene's lens made of a glass without dispersion: nothing splits. */
static void clear_scene(void)
{
    static const char text[] =
        "camera { location <0, 95, -55> look_at <0, 14, 0> right x*image_width/image_height "
        "angle 36 }\n"
        "background { rgb <0.20, 0.30, 0.50> }\n"
        "lens { radius1 50 radius2 -50 thickness 8 diameter 25 ior 1.5 "
        "rotate <-90, 0, 0> translate <0, 20, 0> }\n"
        "plane { y, 0 pigment { checker rgb <0.9, 0.2, 0.1>, rgb <0.1, 0.3, 0.9> scale 5 } "
        "finish { ambient 0 diffuse 0 emission 1 } }\n";
    rs_scene sc;
    int counts[LEVELS];
    rs_scene_init(&sc);
    CHECK(load_scene(&sc, NULL, text, "clear.scene", W, H) == 0, "the clear scene loads");
    CHECK(against_replay(&sc, RS_MODE_FRESNEL, 1e-3, 0.003, counts) == 0,
          "a lens without dispersion splits no packet");
    CHECK(counts[0] == W * H, "every pixel is the plain render's");
    rs_scene_free(&sc);
}

int main(void)
{
    dispersive_scene();
    clear_scene();
    return check_finish("test_refine");
}
