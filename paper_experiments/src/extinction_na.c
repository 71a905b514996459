/* extinction_na.c -- the empty polarizing microscope's extinction against
 * its numerical aperture: a thin driver of extinction.h that writes the
 * chart's table (CSV) and picture (PNG).  scripts/extinction_na.sh runs it
 * on the shipped microscope. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "extinction.h"
#include "lpmpi/group.h"
#include "lpmpi/schedule.h"
#include "plot.h"
#include "support/image.h"

#define EXIT_USAGE 2
#define MAX_POINTS 1000

static const char usage_text[] =
"usage: extinction_na [--scene FILE] [--lambda NM] [--na-max NA] [--step D]\n"
"                     [--rings N] [--azimuths N] [--h-max MM] [--iris NA]\n"
"                     [--csv FILE] [--png FILE]\n"
"       extinction_na --help\n"
"\n"
"The leak of an empty polarizing microscope between crossed ideal\n"
"polarizers against the numerical aperture: the lenses between the two\n"
"polarizers of --scene (default scenes/microscope/microscope_empty.scene),\n"
"rays parallel to the axis in the polarizer's plane at --lambda (default\n"
"550 nm in air), for NA = step, 2 step, ... --na-max (default 0.02 to\n"
"0.54): the crossed over the parallel light of the whole aperture\n"
"(--rings x --azimuths rays, default 32 x 8) and of its rim ray at 45\n"
"degrees, each traced through the library's polarized trace and\n"
"predicted from the s and p Fresnel transmissions of the surfaces.\n"
"--h-max bounds the ray heights searched (default 6 mm); --iris marks the\n"
"instrument's own aperture on the chart (default 0.45; 0: none).\n"
"Writes --csv (default docs/extinction-na.csv) and --png (default\n"
"docs/extinction-na.png) and prints the worst relative difference.\n";

/* The NA points as independent items (lpmpi/schedule.h): one process, or
 * shared among the processes of an MPI run (mpirun -n N extinction_na),
 * gathered on rank 0. */
typedef struct na_sweep {
    const ext_system *sys;
    double step, h_max;
    int rings, azimuths;
    ext_point *pt;       /* rank 0: point k */
    int *ok;             /* rank 0: point k was computed */
    char (*why)[256];    /* rank 0: why not */
} na_sweep;

typedef struct na_result {
    ext_point pt;
    int ok;
    char why[256];
} na_result;

static int na_run(void *user, long k, void *result, size_t *used, char *msg, size_t msg_size)
{
    const na_sweep *w = user;
    na_result r;
    (void)msg;
    (void)msg_size;
    memset(&r, 0, sizeof r);
    r.ok = ext_point_compute(w->sys, w->step * (double)(k + 1), w->h_max, w->rings,
                             w->azimuths, &r.pt, r.why, sizeof r.why) == 0;
    memcpy(result, &r, sizeof r);
    *used = sizeof r;
    return 0;
}

static void na_done(void *user, long k, const void *result, size_t size)
{
    na_sweep *w = user;
    na_result r;
    (void)size;
    memcpy(&r, result, sizeof r);
    w->pt[k] = r.pt;
    w->ok[k] = r.ok;
    memcpy(w->why[k], r.why, sizeof r.why);
}

static int number(const char *opt, const char *v, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double x = strtod(v, &end);
    if (errno || end == v || *end || !(x >= lo && x <= hi)) {
        fprintf(stderr, "extinction_na: %s wants a number in [%g, %g], not '%s'\n", opt, lo, hi,
                v);
        return -1;
    }
    *out = x;
    return 0;
}

static int chart(const char *png, const ext_point *pt, int n, double iris, char *msg,
                 size_t msg_size)
{
    static double x[MAX_POINTS], y[4][MAX_POINTS];
    double lo = INFINITY, hi = 0;
    for (int i = 0; i < n; i++) {
        x[i] = pt[i].na;
        y[0][i] = pt[i].leak_t;
        y[1][i] = pt[i].leak_p;
        y[2][i] = pt[i].rim_t;
        y[3][i] = pt[i].rim_p;
        for (int k = 0; k < 4; k++)
            if (y[k][i] > 0) {
                lo = fmin(lo, y[k][i]);
                hi = fmax(hi, y[k][i]);
            }
    }
    if (!(hi > 0)) {
        snprintf(msg, msg_size, "nothing to plot: no leak at any point");
        return -1;
    }
    pl_series s[4] = {
        {"aperture, traced", x, y[0], (size_t)n, 0x1f77b4u, PL_SOLID, 3},
        {"aperture, predicted", x, y[1], (size_t)n, 0xff7f0eu, PL_DASHED, 2},
        {"rim ray at 45 deg, traced", x, y[2], (size_t)n, 0x2ca02cu, PL_SOLID, 3},
        {"rim ray at 45 deg, predicted", x, y[3], (size_t)n, 0xd62728u, PL_DASHED, 2},
    };
    pl_marker mk = {iris, "iris"};
    pl_chart c;
    memset(&c, 0, sizeof c);
    c.title = "Empty microscope, crossed polarizers: leak vs NA";
    c.xlabel = "numerical aperture NA = sin(theta) at the specimen";
    c.ylabel = "crossed / parallel";
    c.xmin = 0;
    c.xmax = x[n - 1] + 0.5 * (n > 1 ? x[1] - x[0] : x[0]);
    c.ymin = pow(10, floor(log10(lo)));
    c.ymax = pow(10, ceil(log10(hi)));
    if (c.ymax <= c.ymin)
        c.ymax = 10 * c.ymin;
    c.ylog = 1;
    c.legend = PL_LEGEND_BOTTOM_RIGHT;
    c.markers = iris > 0 ? &mk : NULL;
    c.n_markers = iris > 0 ? 1 : 0;
    rs_image img;
    if (rs_image_create(&img, 800, 520) != 0) {
        snprintf(msg, msg_size, "out of memory for the chart");
        return -1;
    }
    pl_fill(&img, 0xFFFFFFu);
    int rc = pl_draw(&img, 0, 0, 800, 520, &c, s, 4, msg, msg_size);
    if (rc == 0)
        rc = rs_png_write(png, &img, msg, msg_size);
    rs_image_free(&img);
    return rc;
}

int main(int argc, char **argv)
{
    const char *scene = "scenes/microscope/microscope_empty.scene";
    const char *csv = "docs/extinction-na.csv", *png = "docs/extinction-na.png";
    double lambda = 550, na_max = 0.54, step = 0.02, h_max = 6, iris = 0.45, v;
    int rings = 32, azimuths = 8;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage_text, stdout);
            return 0;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "extinction_na: %s needs a value (try --help)\n", a);
            return EXIT_USAGE;
        }
        const char *val = argv[++i];
        int bad = 0;
        if (strcmp(a, "--scene") == 0)
            scene = val;
        else if (strcmp(a, "--csv") == 0)
            csv = val;
        else if (strcmp(a, "--png") == 0)
            png = val;
        else if (strcmp(a, "--lambda") == 0)
            bad = number(a, val, 380, 780, &lambda);
        else if (strcmp(a, "--na-max") == 0)
            bad = number(a, val, 1e-3, 0.99, &na_max);
        else if (strcmp(a, "--step") == 0)
            bad = number(a, val, 1e-3, 0.99, &step);
        else if (strcmp(a, "--h-max") == 0)
            bad = number(a, val, 1e-3, 1e4, &h_max);
        else if (strcmp(a, "--iris") == 0)
            bad = number(a, val, 0, 0.99, &iris);
        else if (strcmp(a, "--rings") == 0 && !(bad = number(a, val, 1, 100000, &v)))
            rings = (int)v;
        else if (strcmp(a, "--azimuths") == 0 && !(bad = number(a, val, 5, 100000, &v)))
            azimuths = (int)v;
        else if (strcmp(a, "--rings") != 0 && strcmp(a, "--azimuths") != 0) {
            fprintf(stderr, "extinction_na: unknown option '%s' (try --help)\n", a);
            return EXIT_USAGE;
        }
        if (bad)
            return EXIT_USAGE;
    }
    int n = (int)floor(na_max / step + 1e-9);
    if (n < 2 || n > MAX_POINTS) {
        fprintf(stderr, "extinction_na: --na-max / --step gives %d points (2..%d)\n", n,
                MAX_POINTS);
        return EXIT_USAGE;
    }

    char msg[512] = "";
    ext_system sys;
    mw_group *g;
    if (mw_group_start(&argc, &argv, &g, msg, sizeof msg) != 0) {
        fprintf(stderr, "extinction_na: %s\n", msg);
        return 1;
    }
    int st = ext_system_from_scene(scene, lambda, &sys, msg, sizeof msg) != 0;
    if (mw_agree(g, st, NULL, msg, sizeof msg) != 0) {
        if (mw_group_rank(g) == 0)
            fprintf(stderr, "extinction_na: %s\n", msg);
        if (!st)
            ext_system_free(&sys);
        mw_group_end(g);
        return 1;
    }
    static ext_point pt[MAX_POINTS];
    static int ok[MAX_POINTS];
    static char why[MAX_POINTS][256];
    na_sweep w = {&sys, step, h_max, rings, azimuths, pt, ok, why};
    mw_job job = {n, sizeof(na_result), na_run, na_done, &w};
    int m = 0, rc = mw_run(g, &job, msg, sizeof msg);
    ext_system_free(&sys);
    if (mw_group_rank(g) != 0 || rc != 0) {
        if (rc != 0 && mw_group_rank(g) == 0)
            fprintf(stderr, "extinction_na: %s\n", msg);
        mw_group_end(g);
        return rc != 0;
    }
    mw_group_end(g);
    while (m < n && ok[m]) /* up to the first NA the lenses pass no ray at */
        m++;
    if (m < n)
        snprintf(msg, sizeof msg, "%s", why[m]);
    if (m < 2) {
        fprintf(stderr, "extinction_na: fewer than two points (%s)\n", msg);
        return 1;
    }
    FILE *f = fopen(csv, "w");
    if (!f) {
        fprintf(stderr, "extinction_na: cannot write %s: %s\n", csv, strerror(errno));
        return 1;
    }
    fprintf(f, "na,h_mm,leak_traced,leak_predicted,rim45_traced,rim45_predicted\n");
    double worst = 0;
    for (int i = 0; i < m; i++) {
        fprintf(f, "%.4f,%.12f,%.15e,%.15e,%.15e,%.15e\n", pt[i].na, pt[i].h, pt[i].leak_t,
                pt[i].leak_p, pt[i].rim_t, pt[i].rim_p);
        worst = fmax(worst, fabs(pt[i].leak_t - pt[i].leak_p) / pt[i].leak_p);
        worst = fmax(worst, fabs(pt[i].rim_t - pt[i].rim_p) / pt[i].rim_p);
    }
    if (fclose(f) != 0) {
        fprintf(stderr, "extinction_na: writing %s failed\n", csv);
        return 1;
    }
    if (chart(png, pt, m, iris, msg, sizeof msg) != 0) {
        fprintf(stderr, "extinction_na: %s: %s\n", png, msg);
        rc = 1;
    }
    printf("extinction_na: %d points, NA %.2f..%.2f at %g nm; leak at NA %.2f: %.4g "
           "(predicted %.4g); worst relative difference traced/predicted %.3g\n",
           m, pt[0].na, pt[m - 1].na, lambda, pt[m - 1].na, pt[m - 1].leak_t, pt[m - 1].leak_p,
           worst);
    return rc;
}
