/* test_paper_experiments.c -- the one command behind
 * docs/paper-experiments.md, at a tiny size.
 *
 * Renders a scene in the four light models at 16 x 12 with lensrender,
 * runs paper_experiments on the renders and the shipped scenes, and
 * checks: exit 0; the page has its three sections and links its figures,
 * which exist as PNG files; cone.csv's theta_K of the shipped flat plate
 * (newtons_rings #2: t = 5, D = 40, apex 80 mm in front) equals the
 * closed form 80 tan(th) + (dT - 1) t tan(b) = D/2, sin(th) = n sin(b),
 * for dT = 1..8, with n of N-BK7 at 587.56 nm from its Sellmeier
 * coefficients written here; and the default lens at dT = 1 the angle of
 * its front cap's edge.  A missing render fails with a message and
 * leaves an existing page alone; no --renders is a usage error (2). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "subprocess.h"
#include "test_files.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int run(const char *prog, const char *const *args, tp_result *r)
{
    char what[512];
    tp_describe(prog, args, what, sizeof what);
    if (tp_run(prog, args, NULL, r) != 0) {
        fprintf(stderr, "%s: %s\n", what, r->error);
        return 0;
    }
    if (r->status != 0)
        fprintf(stderr, "%s: status %d: %s\n", what, r->status, r->err);
    return 1;
}

/* N-BK7, Schott Sellmeier (catalog data), lambda in um */
static double n_bk7(double um)
{
    double l2 = um * um;
    return sqrt(1 + 1.03961212 * l2 / (l2 - 0.00600069867) + 0.231792344 * l2 / (l2 - 0.0200179144) +
                1.01046945 * l2 / (l2 - 103.560653));
}

static double plate_theta(double L, double t, double h, double n, int m)
{
    double lo = 0, hi = M_PI / 2 - 1e-9;
    for (int i = 0; i < 200; i++) {
        double mid = 0.5 * (lo + hi), sb = sin(mid) / n;
        if (L * tan(mid) + m * t * sb / sqrt(1 - sb * sb) <= h)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* theta_K (deg) of lens `name` at dT from cone.csv, or NAN */
static double csv_theta(const char *csv, const char *name, int dT)
{
    char key[96];
    snprintf(key, sizeof key, "\n%s,%d,all,", name, dT);
    const char *p = strstr(csv, key);
    return p ? strtod(p + strlen(key), NULL) : NAN;
}

int main(void)
{
    const char *render = LP_BIN_DIR "/lensrender", *tool = LP_BIN_DIR "/paper_experiments";
    char dir[1024], rdir[1100], out[1100], md[1100], path[1300];
    struct stat st;
    if (stat(tool, &st) != 0) {
        fprintf(stderr, "%s is not built\n", tool);
        return 1;
    }
    snprintf(dir, sizeof dir, "%s/paper_experiments_test", LP_TEST_TMP);
    snprintf(rdir, sizeof rdir, "%s/renders", dir);
    snprintf(out, sizeof out, "%s/figures", dir);
    snprintf(md, sizeof md, "%s/page.md", dir);
    mkdir(dir, 0777);
    mkdir(rdir, 0777);
    const char *modes[4] = {"rgb", "fresnel", "polarized", "schlick"};
    for (int m = 0; m < 4; m++) {
        char pfm[1200], png[1200];
        snprintf(pfm, sizeof pfm, "%s/%s.pfm", rdir, modes[m]);
        snprintf(png, sizeof png, "%s/%s.png", rdir, modes[m]);
        const char *args[] = {LP_SOURCE_DIR "/scenes/default.scene", "--mode", modes[m],
                              "--width", "16", "--height", "12", "--wavelengths", "4",
                              "--pfm", pfm, "-o", png, "--quiet", NULL};
        tp_result r;
        CHECK(run(render, args, &r) && r.status == 0, "lensrender --mode %s", modes[m]);
        tp_result_free(&r);
    }
    const char *args[] = {"--renders", rdir, "--scene-name", "default.scene", "--wavelengths",
                          "4", "--scenes", LP_SOURCE_DIR "/scenes", "--out", out, "--md", md,
                          NULL};
    tp_result r;
    CHECK(run(tool, args, &r) && r.status == 0, "paper_experiments ran");
    tp_result_free(&r);

    size_t n = 0;
    char *page = tf_read(md, &n);
    CHECK(page != NULL, "the page %s was written", md);
    if (page) {
        const char *need[] = {"## 1. The cone K", "## 2. Shares", "## 3. RGB against spectral",
                              "(figures/theta_vs_depth.png)", "(figures/cone_sections.png)",
                              "(figures/cone_off_axis.png)", "(figures/shares.png)",
                              "(figures/rgb_vs_spectral.png)", "(figures/schlick_vs_g.png)"};
        for (size_t i = 0; i < sizeof need / sizeof need[0]; i++)
            CHECK(strstr(page, need[i]) != NULL, "the page has '%s'", need[i]);
    }
    const char *figs[] = {"theta_vs_depth.png", "cone_sections.png", "cone_off_axis.png",
                          "shares.png", "rgb_vs_spectral.png", "schlick_vs_g.png"};
    for (size_t i = 0; i < sizeof figs / sizeof figs[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", out, figs[i]);
        CHECK(tf_is_png(path), "%s is a PNG", path);
    }
    snprintf(path, sizeof path, "%s/cone.csv", out);
    char *csv = tf_read(path, &n);
    CHECK(csv != NULL, "cone.csv written");
    if (csv) {
        double nd = n_bk7(0.58756);
        for (int dT = 1; dT <= 8; dT++) {
            double want = plate_theta(80, 5, 20, nd, dT - 1) * 180 / M_PI;
            /* measured: 4.6e-8 deg (the library's 1e-9 rad bisection) */
            CHECK_ABS(csv_theta(csv, "newtons_rings #2", dT), want, 1e-6,
                      "plate of newtons_rings at dT=%d", dT);
        }
        double c = 1.0 / 50, h = 12.5, sag = c * h * h / (1 + sqrt(1 - c * c * h * h));
        CHECK_ABS(csv_theta(csv, "default", 1), atan(h / (50 + sag)) * 180 / M_PI, 1e-6,
                  "default lens at dT=1: the front cap's edge");
    }
    free(csv);

    /* a missing render: failure with a message, the page left alone */
    snprintf(path, sizeof path, "%s/schlick.pfm", rdir);
    remove(path);
    CHECK(run(tool, args, &r) && r.status == 1 && strstr(r.err, "schlick.pfm"),
          "a missing render is reported: status %d '%s'", r.status, r.err ? r.err : "");
    tp_result_free(&r);
    char *page2 = tf_read(md, &n);
    CHECK(page && page2 && strcmp(page, page2) == 0, "the page is left alone on failure");
    free(page);
    free(page2);
    const char *bad[] = {"--out", out, NULL};
    CHECK(run(tool, bad, &r) && r.status == 2 && strstr(r.err, "--renders"),
          "no --renders: usage error");
    tp_result_free(&r);
    return check_finish("test_paper_experiments");
}
