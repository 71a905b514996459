/* test_speed_accuracy.c -- the speed-accuracy sweep, end to end, small.
 *
 * speed_accuracy on two scenes of its own at 4 x 3 pixels, one run per
 * point, the reference capped at 256 wavelengths, the sweep at 4 (its
 * grid of trees makes some 90 points a scene):
 *   - "emitters": a checker of self-lit RGB emitters seen directly, no
 *     glass.  Every spectral render of an RGB emitter is exactly its RGB
 *     (the colour correction of the wavelength quadrature), so every point
 *     of every model, the reference's uncertainty U included, is 0 to the
 *     PFM's float precision (bound 1e-6 on values <= 0.9; float rounding
 *     is 6e-8).  A point compared with the wrong image, or an image read
 *     at the wrong size, is off by the checker's contrast, 0.8.
 *   - "lens": a BK7 lens over the checker.  Its points have an error: at
 *     4 wavelengths the polarized render misses the dispersion the
 *     reference resolves (rmse above U, so the sweep measures it), the
 *     rgb render too; and for every point rmse <= largest error (an RMSE
 *     cannot exceed the largest difference) and the share of visibly
 *     different pixels in [0, 1].
 * And the files: the CSV (a reference row per scene with its U), the
 * chart (a PNG), the page with one row per scene and E. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "subprocess.h"
#include "test_files.h"

static const char *const EMITTERS =
    "global_settings { max_trace_level 4 adc_bailout 0.002 }\n"
    "camera { location <0, 10, 0> look_at <0, 0, 0> right x*4/3 angle 60 }\n"
    "background { rgb <0.2, 0.3, 0.5> }\n"
    "plane { y, 0 pigment { checker rgb 0.9, rgb 0.1 scale 2 }\n"
    "        finish { ambient 0 diffuse 0 emission 1 } }\n";

static const char *const LENS =
    "global_settings { max_trace_level 8 adc_bailout 0.002 }\n"
    "camera { location <0, 95, -55> look_at <0, 14, 0> right x*4/3 angle 20 }\n"
    "background { rgb <0.2, 0.3, 0.5> }\n"
    "lens { radius1 50 radius2 -50 thickness 8 diameter 25 glass \"N-BK7\"\n"
    "       rotate <-90, 0, 0> translate <0, 20, 0> }\n"
    "plane { y, 0 pigment { checker rgb 0.9, rgb 0.1 scale 1 }\n"
    "        finish { ambient 0 diffuse 0 emission 1 } }\n";

#define FLOAT_TOL 1e-6

/* One CSV row, the columns the test reads. */
typedef struct row {
    char scene[64], kind[16], model[16];
    int wavelengths, depth;
    double cutoff, rmse, max_abs, share;
} row;

static int parse_row(const char *line, row *r)
{
    char f[13][128];
    int n = 0;
    size_t k = 0;
    memset(r, 0, sizeof *r);
    for (const char *p = line;; p++) {
        if (*p == ',' || *p == '\n' || *p == '\0') {
            if (n < 13)
                f[n][k < 127 ? k : 127] = '\0';
            n++;
            k = 0;
            if (*p != ',')
                break;
        } else if (n < 13 && k < 127) {
            f[n][k++] = *p;
        }
    }
    if (n < 13)
        return -1;
    snprintf(r->scene, sizeof r->scene, "%.63s", f[0]);
    snprintf(r->kind, sizeof r->kind, "%.15s", f[1]);
    snprintf(r->model, sizeof r->model, "%.15s", f[2]);
    r->wavelengths = atoi(f[3]);
    r->depth = atoi(f[4]);
    r->cutoff = strtod(f[5], NULL);
    r->rmse = strtod(f[9], NULL);
    r->max_abs = strtod(f[10], NULL);
    r->share = strtod(f[11], NULL);
    return 0;
}

int main(void)
{
    char scenes[2048], docs[2048], work[2048], path[4200];
    tp_result r;
    snprintf(scenes, sizeof scenes, "%s/sa_scenes", LP_TEST_TMP);
    snprintf(docs, sizeof docs, "%s/sa_docs", LP_TEST_TMP);
    snprintf(work, sizeof work, "%s/sa_work", LP_TEST_TMP);
    mkdir(scenes, 0777);
    mkdir(docs, 0777);
    mkdir(work, 0777);
    snprintf(path, sizeof path, "%s/emitters.scene", scenes);
    CHECK(tf_write(path, EMITTERS, strlen(EMITTERS)) == 0, "cannot write %s", path);
    snprintf(path, sizeof path, "%s/lens.scene", scenes);
    CHECK(tf_write(path, LENS, strlen(LENS)) == 0, "cannot write %s", path);
    snprintf(path, sizeof path, "%s/speed-accuracy.csv", docs);
    remove(path);

    const char *args[] = {"--bin", LP_BIN_DIR, "--scenes", scenes, "--docs", docs, "--work", work,
                          "--width", "4", "--height", "3", "--runs", "1", "--max-wavelengths",
                          "256", "--sweep-wavelengths", "4", NULL};
    int rc = tp_run(LP_BIN_DIR "/speed_accuracy", args, NULL, &r);
    CHECK(rc == 0 && r.status == 0, "speed_accuracy: status %d: %s", r.status,
          r.err ? r.err : r.error);
    printf("speed_accuracy: %.2f s\n", r.seconds);
    tp_result_free(&r);

    size_t len = 0;
    char *csv = tf_read(path, &len);
    CHECK(csv != NULL, "%s was not written", path);
    int n_ref = 0, n_emit = 0, n_lens = 0, coarse_seen = 0, rgb_seen = 0;
    double lens_u = NAN;
    for (char *line = csv; csv && line && *line;) {
        char *next = strchr(line, '\n');
        row w;
        if (next)
            *next++ = '\0';
        if (strncmp(line, "scene,", 6) != 0 && parse_row(line, &w) == 0) {
            int emit = strcmp(w.scene, "emitters") == 0;
            if (strcmp(w.kind, "reference") == 0) {
                n_ref++;
                CHECK(w.wavelengths == 256 && w.rmse >= 0.0 && isfinite(w.rmse),
                      "%s: reference at %d wavelengths, U %g", w.scene, w.wavelengths, w.rmse);
                if (emit)
                    CHECK(w.rmse <= FLOAT_TOL, "emitters: the reference's U is %g", w.rmse);
                else
                    lens_u = w.rmse;
            } else if (strcmp(w.kind, "povray") != 0) {
                n_emit += emit;
                n_lens += !emit;
                if (emit)
                    CHECK(w.max_abs <= FLOAT_TOL, "emitters: %s %s %d wl depth %d: error %g",
                          w.kind, w.model, w.wavelengths, w.depth, w.max_abs);
                CHECK(w.rmse <= w.max_abs * (1 + 1e-6) + 1e-12 && w.share >= 0.0 &&
                          w.share <= 1.0,
                      "%s %s %s: rmse %g, largest %g, share %g", w.scene, w.kind, w.model, w.rmse,
                      w.max_abs, w.share);
                if (!emit && strcmp(w.kind, "sweep") == 0 &&
                    strcmp(w.model, "polarized") == 0 && w.wavelengths == 4 && w.depth == 16 &&
                    w.cutoff == 1e-6) {
                    coarse_seen = 1;
                    CHECK(w.rmse > 3.0 * lens_u && w.rmse > 1e-4,
                          "lens: polarized at 4 wavelengths: rmse %g, not above U %g", w.rmse,
                          lens_u);
                }
                if (!emit && strcmp(w.model, "rgb") == 0 && w.depth == 16 && w.cutoff == 1e-6) {
                    rgb_seen = 1;
                    CHECK(w.rmse > 1e-4, "lens: rgb: rmse %g", w.rmse);
                }
            }
        }
        line = next;
    }
    CHECK(n_ref == 2, "%d reference rows", n_ref);
    /* auto x 3, the default and the sweep: more than 90 points a scene */
    CHECK(n_emit > 90 && n_lens > 90, "points: emitters %d, lens %d", n_emit, n_lens);
    CHECK(coarse_seen && rgb_seen, "the lens's coarse points are missing");
    free(csv);

    snprintf(path, sizeof path, "%s/speed-accuracy.png", docs);
    CHECK(tf_is_png(path), "%s is not a PNG", path);
    snprintf(path, sizeof path, "%s/speed-accuracy.md", docs);
    char *md = tf_read(path, &len);
    CHECK(md != NULL, "%s was not written", path);
    int rows = 0;
    for (const char *p = md; md && (p = strstr(p, "\n| lens | ")) != NULL; p++)
        rows++;
    /* three E in the table against the front, one row among the references */
    CHECK(rows == 4, "the page has %d rows for the lens", rows);
    free(md);
    return check_finish("test_speed_accuracy");
}
