/* test_sa_refine.c -- a reference converged pixel by pixel (sa_refine).
 *
 * A flint lens over a lit checker at 12 x 9 pixels, polarized, depth 8.
 * The expectation comes from whole images rendered here at 4, 8, 16, 32
 * and 64 wavelengths (R4 ... R64) and the rule sa_refine.h states: start
 * from R8 with each pixel's change R8 - R4; a pixel is doubled again
 * until two doublings in a row are within tol in every channel (R8 -
 * R4 counting as the first).  So each pixel of the result must be, bit
 * for bit, R_L at the first L in 16, 32 where R_L - R_{L/2} and R_{L/2} -
 * R_{L/4} are both within tol, else R64; the statistics are the pixels
 * rendered per doubling (the open pixels at 8, 16 and 32), the most
 * wavelengths any pixel reached, the RMS of each pixel's last change and
 * the pixels still open.  Given the change of the doubling before
 * (R4 - R2), a pixel calm in both starts converged.  With no budget nothing is rendered; images
 * of different sizes are refused. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "lensrender/lensrender.h"
#include "sa_refine.h"
#include "support/image.h"
#include "test_files.h"

#define W 12
#define H 9
#define TOL 2e-3
#define DEPTH 8
#define CUTOFF 1e-6
#define LEVELS 5 /* 4, 8, 16, 32, 64 */

static const char *const SCENE =
    "global_settings { max_trace_level 8 adc_bailout 0.002 }\n"
    "camera { location <0, 60, -35> look_at <0, 6, 0> right x*4/3 angle 28 }\n"
    "background { rgb <0.2, 0.3, 0.5> }\n"
    "light_source { <30, 80, -20> color rgb 1 }\n"
    "lens { radius1 30 radius2 -30 thickness 9 diameter 22 glass \"N-SF11\"\n"
    "       rotate <-90, 0, 0> translate <0, 14, 0> }\n"
    "plane { y, 0 pigment { checker rgb 0.9, rgb 0.1 scale 1.5 }\n"
    "        finish { ambient 0.2 diffuse 0.8 } }\n";

static int render(lr_scene *scene, int n, float *rgb)
{
    lr_render_opts ro;
    lr_renderer *r = NULL;
    lr_error err;
    lr_render_opts_init(&ro);
    ro.mode = LR_MODE_POLARIZED;
    ro.width = W;
    ro.height = H;
    ro.depth = DEPTH;
    ro.cutoff = CUTOFF;
    ro.wavelengths = n;
    ro.threads = 1;
    if (lr_renderer_create(scene, &ro, &r, &err) != LR_OK)
        return -1;
    lr_status st = lr_render_image(r, rgb, NULL, NULL, &err);
    lr_renderer_free(r);
    return st == LR_OK ? 0 : -1;
}

/* Does pixel k change by more than TOL from image a to image b? */
static int open_between(const float *a, const float *b, int k)
{
    for (int c = 0; c < 3; c++) {
        float d = b[3 * k + c] - a[3 * k + c];
        if (!(fabs((double)d) <= TOL))
            return 1;
    }
    return 0;
}

int main(void)
{
    char path[1024], msg[512];
    lr_scene *scene = NULL;
    lr_load_opts lo;
    lr_error err;
    static float R[LEVELS][3 * W * H];
    rs_image img = {0, 0, NULL}, last = {0, 0, NULL};
    sa_refine_opts o;
    sa_refine_stats st;

    snprintf(path, sizeof path, "%s/sa_refine.scene", LP_TEST_TMP);
    CHECK(tf_write(path, SCENE, strlen(SCENE)) == 0, "cannot write %s", path);
    lr_load_opts_init(&lo);
    lo.image_width = W;
    lo.image_height = H;
    CHECK(lr_scene_load(path, &lo, &scene, &err) == LR_OK, "load: %s", err.message);
    if (!scene)
        return check_finish("test_sa_refine");
    for (int l = 0; l < LEVELS; l++)
        CHECK(render(scene, 4 << l, R[l]) == 0, "render at %d wavelengths", 4 << l);

    /* the expectation, from the whole images */
    int want_level[W * H], open_at[LEVELS] = {0}, most = 1, left = 0;
    double sum = 0.0;
    for (int k = 0; k < W * H; k++) {
        int l = 1, calm = !open_between(R[0], R[1], k);
        while (l < LEVELS - 1 && calm < 2) {
            open_at[l]++;
            l++;
            calm = open_between(R[l - 1], R[l], k) ? 0 : calm + 1;
        }
        want_level[k] = l;
        most = l > most ? l : most;
        left += calm < 2;
        for (int c = 0; c < 3; c++) {
            double d = (double)(R[l][3 * k + c] - R[l - 1][3 * k + c]);
            sum += d * d;
        }
    }
    long renders = (long)open_at[1] + open_at[2] + open_at[3];
    printf("open at 8, 16, 32: %d %d %d of %d; up to %d wavelengths\n", open_at[1], open_at[2],
           open_at[3], W * H, 4 << most);
    CHECK(open_at[2] > 0 && open_at[2] < W * H && open_at[3] > 0,
          "the scene has pixels that settle and pixels that do not (open at 16: %d, at 32: %d "
          "of %d)", open_at[2], open_at[3], W * H);

    CHECK(rs_image_create(&img, W, H) == 0 && rs_image_create(&last, W, H) == 0, "images");
    memcpy(img.rgb, R[1], sizeof R[1]);
    for (int k = 0; k < 3 * W * H; k++)
        last.rgb[k] = R[1][k] - R[0][k];
    memset(&o, 0, sizeof o);
    o.scene = path;
    o.depth = DEPTH;
    o.cutoff = CUTOFF;
    o.wavelengths = 8;
    o.wavelengths_max = 64;
    o.tol = TOL;
    o.budget = 1e9;
    o.s_per_pixel_wl = 1e-6;
    CHECK(sa_refine(&o, &img, &last, &st, msg, sizeof msg) == 0, "sa_refine: %s", msg);
    int same = 1;
    for (int k = 0; k < W * H; k++)
        if (memcmp(&img.rgb[3 * k], &R[want_level[k]][3 * k], 3 * sizeof(float)) != 0) {
            CHECK(0, "pixel %d: not R%d", k, 4 << want_level[k]);
            same = 0;
            break;
        }
    CHECK(same, "every pixel is the whole image's at its own wavelength count");
    CHECK(st.renders == renders && st.wavelengths == 4 << most && st.left == left,
          "stats: %ld renders (want %ld), up to %d wavelengths (want %d), %ld open (want %d)",
          st.renders, renders, st.wavelengths, 4 << most, st.left, left);
    /* the same float changes summed in the same order: 0 difference measured */
    CHECK_REL(st.rmse, sqrt(sum / (3.0 * W * H)), 1e-12, "the RMS of each pixel's last change");

    /* with the change before (R4 - R2) given: a pixel calm in both
     * starts converged, one calm in R8 - R4 alone starts with one */
    {
        static float R2[3 * W * H];
        rs_image before = {0, 0, NULL};
        int want2[W * H];
        long renders2 = 0;
        CHECK(render(scene, 2, R2) == 0 && rs_image_create(&before, W, H) == 0,
              "render at 2 wavelengths");
        for (int k = 0; before.rgb && k < 3 * W * H; k++)
            before.rgb[k] = R[0][k] - R2[k];
        for (int k = 0; k < W * H; k++) {
            int l = 1, calm = open_between(R[0], R[1], k) ? 0 : 1 + !open_between(R2, R[0], k);
            while (l < LEVELS - 1 && calm < 2) {
                renders2++;
                l++;
                calm = open_between(R[l - 1], R[l], k) ? 0 : calm + 1;
            }
            want2[k] = l;
        }
        memcpy(img.rgb, R[1], sizeof R[1]);
        for (int k = 0; k < 3 * W * H; k++)
            last.rgb[k] = R[1][k] - R[0][k];
        o.before = &before;
        CHECK(sa_refine(&o, &img, &last, &st, msg, sizeof msg) == 0, "sa_refine: %s", msg);
        int same2 = 1;
        for (int k = 0; same2 && k < W * H; k++)
            same2 = memcmp(&img.rgb[3 * k], &R[want2[k]][3 * k], 3 * sizeof(float)) == 0;
        CHECK(same2 && st.renders == renders2 && renders2 < renders,
              "with the doubling before: every pixel at its count, %ld renders (want %ld, "
              "fewer than %ld)", st.renders, renders2, renders);
        o.before = NULL;
        rs_image_free(&before);
    }

    /* no budget: nothing rendered, nothing changed */
    memcpy(img.rgb, R[1], sizeof R[1]);
    for (int k = 0; k < 3 * W * H; k++)
        last.rgb[k] = R[1][k] - R[0][k];
    o.budget = 1e-12;
    CHECK(sa_refine(&o, &img, &last, &st, msg, sizeof msg) == 0 && st.levels == 0 &&
              st.renders == 0 && memcmp(img.rgb, R[1], sizeof R[1]) == 0,
          "no budget: no doubling (%d levels, %ld renders)", st.levels, st.renders);

    rs_image small = {0, 0, NULL};
    CHECK(rs_image_create(&small, W - 1, H) == 0 &&
              sa_refine(&o, &img, &small, &st, msg, sizeof msg) == -1 && msg[0],
          "images of different sizes are refused: %s", msg);
    rs_image_free(&small);
    rs_image_free(&img);
    rs_image_free(&last);
    lr_scene_free(scene);
    return check_finish("test_sa_refine");
}
