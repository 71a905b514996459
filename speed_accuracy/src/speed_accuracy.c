/* speed_accuracy.c -- what each render setting costs and how wrong it is.
 *
 * For every scene: a converged reference (polarized, wavelengths and
 * depth doubled until a doubling changes no pixel by more than 1e-5, or
 * their caps; no cut-off), then a sweep of light model x wavelength count
 * x depth x cut-off, --mode auto at three tolerances and POV-Ray itself,
 * each render timed on one thread (CPU time, median of several runs) and
 * compared with the reference.  Writes the table (CSV), the chart (PNG)
 * and the page that explains them (Markdown).  The definitions are in the
 * usage text and in the page it writes. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <signal.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <dirent.h>
#include <unistd.h>

#include "lpmpi/group.h"
#include "lpmpi/schedule.h"
#include "support/image.h"
#include "sa_chart.h"
#include "sa_error.h"
#include "sa_point.h"
#include "sa_refine.h"
#include "sa_run.h"

#define EXIT_USAGE 2
#define PATH_MAX_LEN 4096
#define PATH_BUF (PATH_MAX_LEN + 64) /* a directory and a file name in it */

static const char *const usage_text[] = {
"usage: speed_accuracy [--bin DIR] [--scenes DIR] [--docs DIR] [--work DIR]\n"
"                      [--width W] [--height H] [--runs K] [--scene NAME]...\n"
"                      [--max-wavelengths N] [--sweep-wavelengths N]\n"
"                      [--reference-seconds S]\n"
"                      [--point-seconds S] [--auto-seconds S] [--reuse-references]\n"
"       speed_accuracy --redo-auto [--scene NAME]... [options as above]\n"
"       speed_accuracy --chart-only [--docs DIR]\n"
"       speed_accuracy --help\n"
"\n"
"Sweeps every scene of DIR (default scenes) and writes into the docs\n"
"directory (default docs): speed-accuracy.csv, speed-accuracy.png and\n"
"speed-accuracy.md.  --chart-only redraws the chart and the page from an\n"
"existing CSV.\n"
"\n",
"  --bin DIR        where lensrender and pov_compare are (default build/bin)\n"
"  --work DIR       references and renders (default build/speed-accuracy)\n"
"  --width W, --height H   image size of every render (default 128 x 96:\n"
"                   a process's fixed cost, 3 ms, is <= 25 % of the cheapest\n"
"                   render's)\n"
"  --runs K         timed runs per setting; its time is their median\n"
"                   (default 3; a setting slower than 1 s runs once)\n"
"  --scene NAME     only this scene (repeatable; default every *.scene);\n"
"                   the other scenes' rows of an existing table of the same\n"
"                   size are kept\n"
"  --max-wavelengths N   the reference's wavelength cap, <= 16384 (default 16384)\n"
"  --sweep-wavelengths N   the swept settings' largest wavelength count\n"
"                   (default 512)\n"
"  --reference-seconds S   no reference doubling predicted (2.5 x the last\n"
"                   render) to take longer than S CPU seconds (default 45)\n"
"  --point-seconds S   no swept setting predicted (from the reference's time\n"
"                   per wavelength) to take longer than S (default 10)\n"
"  --auto-seconds S    an auto render (its probe included) that takes more\n"
"                   CPU time is left out (default 300)\n"
"  --reuse-references    keep references already in the work directory\n"
"  --references-only     make the references and stop\n"
"  --redo-auto      measure the --mode auto points again (of every scene, or\n"
"                   of the --scene ones) against the references kept in the\n"
"                   work directory, and keep every other row of the\n"
"                   existing speed-accuracy.csv: after a change of auto's\n"
"                   rule, without sweeping again\n"
"\n"
"REFERENCE: polarized; at 128 wavelengths the depth doubled from 16 (to 64)\n"
"and the cut-off divided by 100 from 1e-10 (to 1e-14) while that changes\n"
"some pixel by more than 1e-5; then the wavelengths doubled from 128 until\n"
"two doublings in a row change no pixel by more than that (to the cap and\n"
"the time budget), then pixel by pixel the pixels not yet so.  Its\n"
"uncertainty U: the RMSE changes of the three last steps, summed.\n"
"ERROR: RMSE of linear RGB against it, the largest channel difference,\n"
"and the share of pixels with a channel off by more than 1/255 after the\n"
"sRGB curve.  TIME: CPU seconds of the lensrender (or povray) process,\n"
"--threads 1.\n"
"\n"
"ACROSS PROCESSES: mpirun -n N speed_accuracy ... (a build with MPI) shares\n"
"the references, then the points, among N processes (each needs the\n"
"scenes and --bin at the same paths, and a --work directory of its own or\n"
"a shared one); rank 0 writes the same table but for the times.\n",
};

typedef struct opts {
    const char *bin, *scenes, *docs, *work;
    int width, height, runs, max_wavelengths, reuse, chart_only, references_only;
    int redo_auto;         /* only the auto points; the other rows from the CSV */
    int sweep_wavelengths; /* the sweep's largest wavelength count */
    double reference_seconds; /* a reference doubling predicted slower is not run */
    double point_seconds;     /* a swept setting predicted slower is not run */
    double auto_seconds;      /* an auto point that runs longer is left out */
    int rank; /* this process's, in a run across processes (names its renders) */
    const char *only[64];
    int n_only;
} opts;

static void say(const char *fmt, const char *a, const char *b)
{
    fprintf(stderr, "speed_accuracy: ");
    fprintf(stderr, fmt, a, b);
    fputc('\n', stderr);
}

/* Make a directory whose parent exists (the script makes the docs and
 * work directories). */
static int make_dir(const char *path)
{
    return mkdir(path, 0777) == 0 || errno == EEXIST ? 0 : -1;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* ---- one render ---------------------------------------------------------- */

/* A reference's numbers: every process needs them (the points a scene
 * sweeps depend on s_per_wl), so they travel as one record. */
typedef struct sa_reference {
    int wavelengths, depth;
    double cutoff;
    /* The changes of the last doubling of the wavelengths (dn), of the
     * depth (dd) and of the cut-off divided by 100 (dc): largest pixel
     * channel and RMSE.  u, their RMSE summed, bounds the reference's own
     * error (see make_reference). */
    double dn_max, dn_rmse, dd_max, dd_rmse, dc_max, dc_rmse, u;
    double s_per_wl; /* CPU seconds per wavelength at depth 16, cut-off 1e-6 */
    int dn_cheap;    /* the wavelength doubling was measured there */
    int whole;       /* the wavelengths of the whole image (sa_refine went on
                        from there; wavelengths is the most a pixel has) */
    long refined;    /* pixel renders of sa_refine (0: none) */
    long left;       /* pixels still changing by more than REF_TOL */
} sa_reference;

typedef struct scene_ctx {
    const opts *o;
    char path[PATH_MAX_LEN]; /* the scene file */
    char name[256];      /* its base name without .scene */
    char dir[PATH_MAX_LEN]; /* its work directory */
    rs_image ref;
    sa_reference rn; /* its numbers */
} scene_ctx;

/* Render the setting p once or several times, each run with at most
 * cpu_limit CPU seconds (<= 0: no limit); fills p->seconds and, when img
 * is not NULL, reads the image into *img.  Returns 0; 1 when the render
 * ran out of its CPU time (left out); or -1 with a message on stderr. */
static int render(const scene_ctx *sc, sa_point *p, int runs, double cpu_limit, rs_image *img)
{
    char pfm[PATH_BUF], png[PATH_BUF], exe[PATH_BUF];
    char w[16], h[16], nl[16], dp[16], cut[32], tol[32], msg[512];
    char *argv[32];
    int n = 0;
    double times[16];

    snprintf(exe, sizeof exe, "%s/lensrender", sc->o->bin);
    snprintf(pfm, sizeof pfm, "%s/render-%d.pfm", sc->dir, sc->o->rank);
    snprintf(png, sizeof png, "%s/render-%d.png", sc->dir, sc->o->rank);
    snprintf(w, sizeof w, "%d", sc->o->width);
    snprintf(h, sizeof h, "%d", sc->o->height);
    argv[n++] = exe;
    argv[n++] = (char *)sc->path;
    argv[n++] = "--threads";
    argv[n++] = "1";
    argv[n++] = "--width";
    argv[n++] = w;
    argv[n++] = "--height";
    argv[n++] = h;
    argv[n++] = "-o";
    argv[n++] = png;
    argv[n++] = "--pfm";
    argv[n++] = pfm;
    argv[n++] = "--mode";
    argv[n++] = p->model;
    if (p->tolerance > 0.0) {
        snprintf(tol, sizeof tol, "%.17g", p->tolerance);
        argv[n++] = "--tolerance";
        argv[n++] = tol;
    } else {
        argv[n++] = "--quiet";
    }
    if (p->wavelengths > 0) {
        snprintf(nl, sizeof nl, "%d", p->wavelengths);
        argv[n++] = "--wavelengths";
        argv[n++] = nl;
    }
    if (p->depth > 0) {
        snprintf(dp, sizeof dp, "%d", p->depth);
        argv[n++] = "--depth";
        argv[n++] = dp;
    }
    if (p->cutoff >= 0.0) {
        snprintf(cut, sizeof cut, "%.17g", p->cutoff);
        argv[n++] = "--cutoff";
        argv[n++] = cut;
    }
    argv[n] = NULL;

    if (runs > 16)
        runs = 16;
    for (int r = 0; r < runs; r++) {
        sa_run_result res;
        if (sa_run(argv, NULL, cpu_limit, &res, msg, sizeof msg) != 0) {
            say("%s: %s", exe, msg);
            return -1;
        }
        if (cpu_limit > 0.0 && res.status == 128 + SIGXCPU) {
            fprintf(stderr, "speed_accuracy: %s: %s %d wl depth %d cut-off %g: over %g CPU s, "
                    "left out\n", sc->name, p->model, p->wavelengths, p->depth, p->cutoff,
                    cpu_limit);
            return 1;
        }
        if (res.status != 0) {
            say("%s failed: %s", sc->path, res.err);
            return -1;
        }
        times[r] = res.cpu_seconds;
        if (r == 0 && p->tolerance > 0.0) {
            /* "lensrender: auto: <choice>" is the first line. */
            const char *c = strstr(res.err, "auto: ");
            if (c) {
                size_t k = 0;
                c += strlen("auto: ");
                while (c[k] && c[k] != '\n' && k + 1 < sizeof p->note)
                    k++;
                memcpy(p->note, c, k);
                p->note[k] = '\0';
            }
        }
        if (r == 0 && runs > 1 && res.cpu_seconds > 1.0) {
            runs = 1;
            break;
        }
    }
    qsort(times, (size_t)runs, sizeof *times, cmp_double);
    p->seconds = runs % 2 ? times[runs / 2] : 0.5 * (times[runs / 2 - 1] + times[runs / 2]);
    p->runs = runs;
    if (img && rs_pfm_read(pfm, img, msg, sizeof msg) != 0) {
        say("%s: %s", pfm, msg);
        return -1;
    }
    return 0;
}

static double max_abs_diff(const rs_image *a, const rs_image *b)
{
    sa_error e;
    if (sa_error_measure(a, b, &e) != 0)
        return INFINITY;
    return e.max_abs;
}

/* ---- the converged reference -------------------------------------------- */

/* Polarized, always.  Depth and cut-off are settled at REF_WAVELENGTHS0
 * (the branch tree does not depend on the wavelength count): the depth is
 * doubled from REF_DEPTH0 while that changes some pixel by more than
 * REF_TOL (to REF_DEPTH_MAX), then the cut-off divided by 100 from
 * REF_CUTOFF0 while that does (to REF_CUTOFF_MIN).  A cut-off and not
 * none: a branch below 1e-10 of the light cannot change a pixel by more
 * than 1e-10 of the brightest radiance (2e-5 through interference, the
 * amplitude's square root times two), and without one a birefringent
 * plate's tree doubles at every bounce (conoscope at depth 16: 70 CPU s at
 * 16 x 12 and 64 wavelengths against 4 s with it).  Then the wavelengths
 * are doubled while the doubling changes some pixel by more than REF_TOL,
 * up to --max-wavelengths, or until the next doubling is predicted (2.5
 * times the last render) to take more than --reference-seconds.
 *
 * The midpoint rule over wavelength has a step wherever a pixel's path
 * changes with the wavelength (a dispersed ray crossing a checker edge or
 * a rim), so its error falls as 1/N: the last doubling's change is about
 * the coarser render's error and twice the finer one's.  rn.u, the RMSE
 * of the three last changes summed, therefore bounds the reference's own
 * RMSE from the truth; an error measured against it is known to +- rn.u
 * (the triangle inequality), and the page says a setting meets E only
 * when its error plus rn.u is at most E. */
#define REF_TOL 1e-5
#define REF_DEPTH0 16
#define REF_DEPTH_MAX 64
#define REF_WAVELENGTHS0 128
#define REF_CUTOFF0 1e-10
#define REF_CUTOFF_MIN 1e-14
#define CHEAP_DEPTH 16
#define CHEAP_CUTOFF 1e-6

static int save_reference(scene_ctx *sc)
{
    char path[PATH_BUF], msg[512];
    FILE *f;
    snprintf(path, sizeof path, "%s/reference.pfm", sc->dir);
    if (rs_pfm_write(path, &sc->ref, msg, sizeof msg) != 0) {
        say("%s: %s", path, msg);
        return -1;
    }
    snprintf(path, sizeof path, "%s/reference.txt", sc->dir);
    f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "%d %d %d %d %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %d %d %ld %ld\n",
            sc->o->width, sc->o->height, sc->rn.wavelengths, sc->rn.depth, sc->rn.cutoff,
            sc->rn.dn_max, sc->rn.dn_rmse, sc->rn.dd_max, sc->rn.dd_rmse, sc->rn.dc_max,
            sc->rn.dc_rmse, sc->rn.u, sc->rn.s_per_wl, sc->rn.dn_cheap, sc->rn.whole,
            sc->rn.refined, sc->rn.left);
    return fclose(f) == 0 ? 0 : -1;
}

static int load_reference(scene_ctx *sc)
{
    char path[PATH_BUF], msg[512];
    int w, h;
    FILE *f;
    snprintf(path, sizeof path, "%s/reference.txt", sc->dir);
    f = fopen(path, "r");
    if (!f)
        return -1;
    /* the last fields are newer: missing, they are 0 */
    sc->rn.dn_cheap = sc->rn.whole = 0;
    sc->rn.refined = sc->rn.left = 0;
    int ok = fscanf(f, "%d %d %d %d %lg %lg %lg %lg %lg %lg %lg %lg %lg %d %d %ld %ld", &w, &h,
                    &sc->rn.wavelengths, &sc->rn.depth, &sc->rn.cutoff, &sc->rn.dn_max,
                    &sc->rn.dn_rmse, &sc->rn.dd_max, &sc->rn.dd_rmse, &sc->rn.dc_max,
                    &sc->rn.dc_rmse, &sc->rn.u, &sc->rn.s_per_wl, &sc->rn.dn_cheap,
                    &sc->rn.whole, &sc->rn.refined, &sc->rn.left) >= 13;
    fclose(f);
    if (!ok || w != sc->o->width || h != sc->o->height)
        return -1;
    snprintf(path, sizeof path, "%s/reference.pfm", sc->dir);
    return rs_pfm_read(path, &sc->ref, msg, sizeof msg);
}

/* Render (n, d, c) into *next and measure its change from *base; *base
 * becomes *next.  Returns 0, or -1. */
static int ref_step(scene_ctx *sc, int n, int d, double c, rs_image *base, double *max,
                    double *rmse, double *seconds)
{
    sa_point p;
    rs_image next;
    memset(&next, 0, sizeof next);
    sa_point_init(&p, "reference", "polarized", n, d, c);
    if (render(sc, &p, 1, 0.0, &next) != 0)
        return -1;
    *max = max_abs_diff(&next, base);
    *rmse = rs_image_rmse(&next, base);
    *seconds = p.seconds;
    rs_image_free(base);
    *base = next;
    return 0;
}

/* *dst = a copy of src; 0, or -1 out of memory. */
static int image_copy(rs_image *dst, const rs_image *src)
{
    rs_image_free(dst);
    if (rs_image_create(dst, src->width, src->height) != 0)
        return -1;
    memcpy(dst->rgb, src->rgb, 3 * sizeof(float) * (size_t)src->width * (size_t)src->height);
    return 0;
}

/* *out = a - b, pixel by pixel; 0, or -1. */
static int image_diff(rs_image *out, const rs_image *a, const rs_image *b)
{
    if (!a->rgb || !b->rgb || a->width != b->width || a->height != b->height ||
        image_copy(out, a) != 0)
        return -1;
    for (size_t k = 0; k < 3 * (size_t)a->width * (size_t)a->height; k++)
        out->rgb[k] -= b->rgb[k];
    return 0;
}

/* Past the whole image's doublings: the pixels still changing, pixel by
 * pixel (sa_refine.h), from `last`, each pixel's change in the last
 * doubling measured, and `before` (NULL: not measured), its change in
 * the doubling before. */
static int refine_reference(scene_ctx *sc, int n, int d, double c, double seconds,
                            rs_image *last, const rs_image *before)
{
    sa_refine_opts ro;
    sa_refine_stats st;
    char msg[512];
    double pixels = (double)sc->o->width * sc->o->height;
    ro.scene = sc->path;
    ro.depth = d;
    ro.cutoff = c;
    ro.wavelengths = n;
    ro.wavelengths_max = sc->o->max_wavelengths;
    ro.tol = REF_TOL;
    ro.budget = sc->o->reference_seconds;
    ro.s_per_pixel_wl = seconds / (pixels * n);
    ro.before = before;
    if (sa_refine(&ro, &sc->ref, last, &st, msg, sizeof msg) != 0) {
        say("%s: %s", sc->name, msg);
        return -1;
    }
    fprintf(stderr,
            "speed_accuracy: %s: pixel by pixel from %d wavelengths: %d doublings, %ld pixel "
            "renders (%.3g s), up to %d wavelengths; last changes max %.3g, rmse %.3g; %ld "
            "pixels over %g\n",
            sc->name, n, st.levels, st.renders, st.seconds, st.wavelengths, st.max, st.rmse,
            st.left, REF_TOL);
    sc->rn.wavelengths = st.wavelengths;
    sc->rn.refined = st.renders;
    sc->rn.left = st.left;
    sc->rn.dn_max = st.max;
    sc->rn.dn_rmse = st.rmse;
    sc->rn.u = sc->rn.dn_rmse + sc->rn.dd_rmse + sc->rn.dc_rmse;
    return 0;
}

static int make_reference(scene_ctx *sc)
{
    sa_point p;
    rs_image base, prev = {0, 0, NULL}, last = {0, 0, NULL};
    rs_image prev2 = {0, 0, NULL}, before = {0, 0, NULL}; /* the doubling before */
    double before_max = INFINITY;
    int n = REF_WAVELENGTHS0, d = REF_DEPTH0, settled = 0; /* two calm doublings */
    double c = REF_CUTOFF0, seconds;

    if (sc->o->reuse && load_reference(sc) == 0) {
        fprintf(stderr, "speed_accuracy: %s: reference reused (%d wavelengths, depth %d)\n",
                sc->name, sc->rn.wavelengths, sc->rn.depth);
        if (!sc->o->redo_auto && sc->rn.refined == 0 && !(sc->rn.dn_max <= REF_TOL) &&
            sc->rn.wavelengths >= 2 && 2 * sc->rn.wavelengths <= sc->o->max_wavelengths) {
            /* made before the pixel by pixel doublings: each pixel's last
             * change from a render at half its wavelengths, then on */
            rs_image half = {0, 0, NULL}, last = {0, 0, NULL};
            int rc;
            sc->rn.whole = sc->rn.wavelengths;
            sa_point_init(&p, "reference", "polarized", sc->rn.wavelengths / 2, sc->rn.depth,
                          sc->rn.cutoff);
            rc = render(sc, &p, 1, 0.0, &half) != 0 || image_diff(&last, &sc->ref, &half) != 0
                     ? -1
                     : refine_reference(sc, sc->rn.wavelengths, sc->rn.depth, sc->rn.cutoff,
                                        2.0 * p.seconds, &last, NULL);
            rs_image_free(&half);
            rs_image_free(&last);
            if (rc != 0)
                return -1;
        }
        return 0;
    }
    if (sc->o->redo_auto) {
        /* the kept rows were measured against the kept reference */
        say("%s: no reference of this size in the work directory: run the whole sweep%s",
            sc->name, "");
        return -1;
    }
    if (2 * n > sc->o->max_wavelengths) /* room for one doubling */
        n = sc->o->max_wavelengths > 1 ? sc->o->max_wavelengths / 2 : 1;
    memset(&base, 0, sizeof base);
    sa_point_init(&p, "reference", "polarized", n, d, c);
    if (render(sc, &p, 1, 0.0, &base) != 0)
        return -1;
    seconds = p.seconds;
    do {
        if (ref_step(sc, n, 2 * d, c, &base, &sc->rn.dd_max, &sc->rn.dd_rmse, &seconds) != 0)
            return -1;
        fprintf(stderr, "speed_accuracy: %s: depth %d -> %d: max change %.3g, rmse %.3g\n",
                sc->name, d, 2 * d, sc->rn.dd_max, sc->rn.dd_rmse);
        d *= 2;
    } while (sc->rn.dd_max > REF_TOL && 2 * d <= REF_DEPTH_MAX);
    do {
        if (ref_step(sc, n, d, c / 100.0, &base, &sc->rn.dc_max, &sc->rn.dc_rmse, &seconds) !=
            0)
            return -1;
        fprintf(stderr, "speed_accuracy: %s: cut-off %.3g -> %.3g: max change %.3g, rmse %.3g\n",
                sc->name, c, c / 100.0, sc->rn.dc_max, sc->rn.dc_rmse);
        c /= 100.0;
    } while (sc->rn.dc_max > REF_TOL && c / 100.0 > 0.5 * REF_CUTOFF_MIN);
    /* The sweep's dearest polarized setting per wavelength (depth 16,
     * cut-off 1e-6): what predicts the points' times (list_points). */
    {
        rs_image cheap;
        double cheap_s, dmax, drmse;
        memset(&cheap, 0, sizeof cheap);
        sa_point_init(&p, "reference", "polarized", n, CHEAP_DEPTH, CHEAP_CUTOFF);
        if (render(sc, &p, 1, 0.0, &cheap) != 0)
            return -1;
        cheap_s = p.seconds;
        sc->rn.s_per_wl = cheap_s / n;
        sc->rn.dn_max = sc->rn.dn_rmse = INFINITY;
        sc->rn.dn_cheap = 0;
        if (2 * n <= sc->o->max_wavelengths && 2.5 * seconds > sc->o->reference_seconds &&
            2.5 * cheap_s <= sc->o->reference_seconds) {
            /* No doubling of the reference itself fits the budget: the
             * doubling of the wavelengths at depth 16 and cut-off 1e-6
             * gives its wavelength error instead (the quadrature's error
             * is the main paths'; the deep, faint branches the reference
             * adds change no pixel's topology). */
            if (image_copy(&prev, &cheap) != 0 ||
                ref_step(sc, 2 * n, CHEAP_DEPTH, CHEAP_CUTOFF, &cheap, &dmax, &drmse, &cheap_s) != 0)
                return -1;
            /* each pixel's change, there: where the pixel by pixel
             * doublings start */
            if (image_diff(&last, &cheap, &prev) != 0)
                return -1;
            rs_image_free(&prev);
            sc->rn.dn_max = dmax;
            sc->rn.dn_rmse = drmse;
            sc->rn.dn_cheap = 1;
            fprintf(stderr,
                    "speed_accuracy: %s: wavelengths %d -> %d at depth %d, cut-off %g: max change "
                    "%.3g, rmse %.3g\n",
                    sc->name, n, 2 * n, CHEAP_DEPTH, CHEAP_CUTOFF, dmax, drmse);
        }
        rs_image_free(&cheap);
    }
    while (!sc->rn.dn_cheap && 2 * n <= sc->o->max_wavelengths &&
           2.5 * seconds <= sc->o->reference_seconds) {
        if ((prev.rgb && image_copy(&prev2, &prev) != 0) || image_copy(&prev, &base) != 0 ||
            ref_step(sc, 2 * n, d, c, &base, &sc->rn.dn_max, &sc->rn.dn_rmse, &seconds) != 0)
            return -1;
        fprintf(stderr,
                "speed_accuracy: %s: wavelengths %d -> %d: max change %.3g, rmse %.3g (%.3g s)\n",
                sc->name, n, 2 * n, sc->rn.dn_max, sc->rn.dn_rmse, seconds);
        n *= 2;
        /* two doublings in a row within the tolerance (sa_refine.h) */
        settled = sc->rn.dn_max <= REF_TOL && before_max <= REF_TOL;
        if (settled)
            break;
        before_max = sc->rn.dn_max;
    }
    sc->ref = base;
    sc->rn.wavelengths = n;
    sc->rn.whole = n;
    sc->rn.depth = d;
    sc->rn.cutoff = c;
    sc->rn.refined = sc->rn.left = 0;
    if (!sc->rn.dn_cheap && prev.rgb && image_diff(&last, &base, &prev) != 0)
        return -1;
    if (!sc->rn.dn_cheap && prev2.rgb && image_diff(&before, &prev, &prev2) != 0)
        return -1;
    rs_image_free(&prev);
    rs_image_free(&prev2);
    if (!settled && last.rgb &&
        2 * n <= sc->o->max_wavelengths &&
        refine_reference(sc, n, d, c, seconds, &last, before.rgb ? &before : NULL) != 0) {
        rs_image_free(&last);
        rs_image_free(&before);
        return -1;
    }
    rs_image_free(&last);
    rs_image_free(&before);
    sc->rn.u = sc->rn.dn_rmse + sc->rn.dd_rmse + sc->rn.dc_rmse;
    return 0; /* saved by the process that gathers (reference_done) */
}

/* ---- POV-Ray's own point ------------------------------------------------ */

/* pov_compare writes the POV-Ray scene (glass a constant index n_d, no
 * dispersion, adc_bailout 0, the scene's depth); then povray renders it
 * on one thread, timed like every other point. */
static int povray_point(const scene_ctx *sc, sa_point *p, rs_image *img)
{
    char exe[PATH_BUF], out[PATH_BUF], w[16], h[16], msg[512];
    char a_w[24], a_h[24];
    sa_run_result res;
    int bits;
    double times[16];
    int runs = sc->o->runs > 16 ? 16 : sc->o->runs;

    sa_point_init(p, "povray", "povray", 0, 0, 0.0);
    snprintf(exe, sizeof exe, "%s/pov_compare", sc->o->bin);
    snprintf(out, sizeof out, "%s/pov", sc->dir);
    snprintf(w, sizeof w, "%d", sc->o->width);
    snprintf(h, sizeof h, "%d", sc->o->height);
    {
        char *argv[] = {exe, (char *)sc->path, "--out", out, "--width", w, "--height", h,
                        "--threads", "1", "--quiet", NULL};
        if (sa_run(argv, NULL, 0.0, &res, msg, sizeof msg) != 0 || res.status != 0) {
            say("%s: pov_compare failed: %s", sc->name, res.err);
            return -1;
        }
    }
    snprintf(a_w, sizeof a_w, "+W%d", sc->o->width);
    snprintf(a_h, sizeof a_h, "+H%d", sc->o->height);
    char *argv[] = {"povray", "-D", "-V", "-GS", "-GR", "+Iscene.pov", "+Opoint.png", a_w, a_h,
                    "-A", "+Q9", "-UA", "+FN16", "File_Gamma=1.0", "Dither=off", "+WT1", NULL};
    for (int r = 0; r < runs; r++) {
        if (sa_run(argv, out, 0.0, &res, msg, sizeof msg) != 0 || res.status != 0) {
            say("%s: povray failed: %s", sc->name, res.err);
            return -1;
        }
        times[r] = res.cpu_seconds;
    }
    qsort(times, (size_t)runs, sizeof *times, cmp_double);
    p->seconds = runs % 2 ? times[runs / 2] : 0.5 * (times[runs / 2 - 1] + times[runs / 2]);
    p->runs = runs;
    snprintf(out, sizeof out, "%s/pov/point.png", sc->dir);
    if (rs_png_read(out, img, &bits, msg, sizeof msg) != 0) {
        say("%s: %s", out, msg);
        return -1;
    }
    snprintf(p->note, sizeof p->note, "POV-Ray 3.7, glass at n_d, no dispersion");
    return 0;
}

/* ---- the sweep ------------------------------------------------------------ */

static const char *const MODELS[] = {"polarized", "fresnel", "schlick", "rgb"};
static const int WAVELENGTHS[] = {4, 8, 16, 32, 64, 128, 256, 512};
static const int DEPTHS[] = {4, 8, 16, 32};
/* --mode auto's grid (renderer/src/auto_settings.c): cut-offs 1e-2 ...
 * 1e-6 at every depth, 1e-8 ... 1e-12 (coherent scenes' floors) from
 * depth 16 on; and the scene's own (-1: its adc_bailout) at depth 16, the
 * default's. */
static const double CUTOFFS[] = {1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12, -1.0};
static const double TOLERANCES[] = {1e-2, 1e-3, 1e-4};

#define N_OF(a) (sizeof(a) / sizeof *(a))

/* Is the setting in the sweep?  The grid auto chooses from, pruned where
 * a setting cannot be on the front: cut-offs below 1e-6 only from depth
 * 16 on (auto uses them only there), the scene's own only at depth 16;
 * from 64 wavelengths on, where the wavelength error is below 1e-3, only
 * the trees whose own error can be too (depth 8 and deeper, cut-off 1e-3
 * and below); rgb has no wavelength count. */
static int in_sweep(int m, int wl, int d, int c)
{
    double cut = CUTOFFS[c];
    if (m == 3 && wl != 0)
        return 0;
    if ((cut < 0.0 && DEPTHS[d] != 16) || (cut >= 0.0 && cut < 1e-6 && DEPTHS[d] < 16))
        return 0;
    if (m != 3 && WAVELENGTHS[wl] >= 64 && (DEPTHS[d] < 8 || cut > 1e-3 || cut < 0.0))
        return 0;
    return 1;
}

/* ---- the runs, spread over the processes of the run -------------------
 *
 * Two rounds of independent items (lpmpi/schedule.h: one process alone,
 * or every process of an MPI run): first each scene's reference, then
 * every point of every scene.  An item's result is its numbers and its
 * image; the process that gathers (rank 0) measures each point against
 * its scene's reference and writes the table in the order of the points,
 * so the table is the same however many processes ran it (but for the
 * times). */

typedef struct job_point {
    int scene;     /* index into the scenes */
    sa_point p;    /* the setting; rank 0: measured */
    int measured;  /* rank 0: arrived (a POV-Ray point that could not run
                      does not) */
} job_point;

typedef struct sweep {
    const opts *o;
    scene_ctx *sc;
    int n_sc;
    job_point *pts;
    long n_pts, cap;
    long mismatch; /* rank 0: the first point that came back as another, or -1 */
    const sa_points *old; /* rank 0, --redo-auto: the existing table */
} sweep;

/* What an item's result starts with; the image's floats follow. */
typedef struct item_head {
    int width, height; /* 0 x 0: no image (a point that could not run) */
    sa_point p;        /* a point's numbers */
    sa_reference rn;   /* a reference's numbers (not its image) */
} item_head;

static int add_point(sweep *w, int scene, const sa_point *p)
{
    if (w->n_pts == w->cap) {
        long cap = w->cap ? 2 * w->cap : 256;
        job_point *q = realloc(w->pts, (size_t)cap * sizeof *q);
        if (!q)
            return -1;
        w->pts = q;
        w->cap = cap;
    }
    memset(&w->pts[w->n_pts], 0, sizeof *w->pts);
    w->pts[w->n_pts].scene = scene;
    w->pts[w->n_pts].p = *p;
    snprintf(w->pts[w->n_pts].p.scene, sizeof p->scene, "%.63s", w->sc[scene].name);
    w->n_pts++;
    return 0;
}

/* Every point of scene k, in the table's order (after its reference). */
static int list_points(sweep *w, int k)
{
    sa_point p;
    sa_point_init(&p, "povray", "povray", 0, 0, 0.0);
    if (!w->o->redo_auto && add_point(w, k, &p) != 0)
        return -1;
    for (size_t t = 0; t < N_OF(TOLERANCES); t++) {
        sa_point_init(&p, "auto", "auto", 0, 0, -1.0);
        p.tolerance = TOLERANCES[t];
        if (add_point(w, k, &p) != 0)
            return -1;
    }
    if (w->o->redo_auto)
        return 0;
    for (size_t m = 0; m < N_OF(MODELS); m++)
        for (size_t wl = 0; wl < N_OF(WAVELENGTHS); wl++)
            for (size_t d = 0; d < N_OF(DEPTHS); d++)
                for (size_t c = 0; c < N_OF(CUTOFFS); c++) {
                    if (!in_sweep((int)m, (int)wl, (int)d, (int)c))
                        continue;
                    /* Predicted from the reference's time per wavelength
                     * (deeper, a lower cut-off, polarized: an upper bound). */
                    if (m != 3 && (WAVELENGTHS[wl] * w->sc[k].rn.s_per_wl > w->o->point_seconds ||
                                   WAVELENGTHS[wl] > w->o->sweep_wavelengths))
                        continue;
                    sa_point_init(&p, "sweep", MODELS[m], m == 3 ? 0 : WAVELENGTHS[wl],
                                  DEPTHS[d], CUTOFFS[c]);
                    if (add_point(w, k, &p) != 0)
                        return -1;
                }
    /* The default polarized render, for the ratio the page reports. */
    sa_point_init(&p, "default", "polarized", 0, 0, -1.0);
    return add_point(w, k, &p);
}

static size_t item_bytes(const opts *o)
{
    return sizeof(item_head) + 3 * sizeof(float) * (size_t)o->width * (size_t)o->height;
}

/* The head and the image into an item's result. */
static void pack(item_head *h, const rs_image *img, void *result, size_t *used,
                 const opts *o)
{
    size_t n = 0;
    if (img && img->rgb && img->width == o->width && img->height == o->height) {
        h->width = img->width;
        h->height = img->height;
        n = 3 * sizeof(float) * (size_t)img->width * (size_t)img->height;
        memcpy((char *)result + sizeof *h, img->rgb, n);
    }
    memcpy(result, h, sizeof *h);
    *used = sizeof *h + n;
}

/* The image of a result (not copied: it points into the result). */
static rs_image unpack(const void *result, item_head *h)
{
    rs_image img = {0, 0, NULL};
    memcpy(h, result, sizeof *h);
    if (h->width > 0) {
        img.width = h->width;
        img.height = h->height;
        img.rgb = (float *)((char *)result + sizeof *h);
    }
    return img;
}

static int reference_run(void *user, long k, void *result, size_t *used, char *msg,
                         size_t msg_size)
{
    sweep *w = user;
    scene_ctx *sc = &w->sc[k];
    item_head h;
    (void)msg_size;
    msg[0] = '\0'; /* make_reference says what failed */
    fprintf(stderr, "speed_accuracy: %s\n", sc->name);
    if (make_reference(sc) != 0)
        return 1;
    memset(&h, 0, sizeof h);
    h.rn = sc->rn;
    pack(&h, &sc->ref, result, used, w->o);
    rs_image_free(&sc->ref); /* rank 0 gets it back in reference_done */
    return 0;
}

static void reference_done(void *user, long k, const void *result, size_t size)
{
    sweep *w = user;
    scene_ctx *sc = &w->sc[k];
    item_head h;
    rs_image img = unpack(result, &h);
    (void)size;
    sc->rn = h.rn;
    rs_image_free(&sc->ref);
    if (!img.rgb || rs_image_create(&sc->ref, img.width, img.height) != 0) {
        say("%s: the reference is lost (out of memory)%s", sc->name, "");
        return;
    }
    memcpy(sc->ref.rgb, img.rgb, 3 * sizeof(float) * (size_t)img.width * (size_t)img.height);
    if (save_reference(sc) != 0)
        say("%s: the reference could not be saved%s", sc->name, "");
}

static int point_run(void *user, long k, void *result, size_t *used, char *msg,
                     size_t msg_size)
{
    sweep *w = user;
    job_point *jp = &w->pts[k];
    item_head h;
    rs_image img = {0, 0, NULL};
    int rc;
    (void)msg_size;
    msg[0] = '\0'; /* render says what failed */
    memset(&h, 0, sizeof h);
    h.p = jp->p;
    if (strcmp(h.p.kind, "povray") == 0) {
        /* Without POV-Ray the point is left out (no image), as before. */
        povray_point(&w->sc[jp->scene], &h.p, &img);
        snprintf(h.p.scene, sizeof h.p.scene, "%s", jp->p.scene);
        rc = 0;
    } else {
        /* A swept point that runs out of 4 x --point-seconds is left out (no
         * image): the time predicted from the cheap render does not know
         * a scene's own cut-off of 0 on a birefringent tree.  An auto
         * point that runs out of --auto-seconds too (thousands of
         * wavelengths through dispersive glass at E = 1e-4). */
        double limit = strcmp(h.p.kind, "sweep") == 0  ? 4.0 * w->o->point_seconds
                       : strcmp(h.p.kind, "auto") == 0 ? w->o->auto_seconds
                                                       : 0.0;
        rc = render(&w->sc[jp->scene], &h.p, w->o->runs, limit, &img);
        if (rc == 1) {
            memset(&h.p.err, 0, sizeof h.p.err);
            rc = 0;
            rs_image_free(&img);
            img.rgb = NULL;
        }
    }
    if (rc == 0)
        pack(&h, &img, result, used, w->o);
    rs_image_free(&img);
    return rc == 0 ? 0 : 1;
}

/* Is a point that came back the one listed (the same setting)? */
static int same_setting(const sa_point *a, const sa_point *b)
{
    return strcmp(a->scene, b->scene) == 0 && strcmp(a->kind, b->kind) == 0 &&
           strcmp(a->model, b->model) == 0 && a->wavelengths == b->wavelengths &&
           a->depth == b->depth && a->cutoff == b->cutoff && a->tolerance == b->tolerance;
}

static void point_done(void *user, long k, const void *result, size_t size)
{
    sweep *w = user;
    job_point *jp = &w->pts[k];
    item_head h;
    rs_image img = unpack(result, &h);
    (void)size;
    if (!same_setting(&h.p, &jp->p)) {
        if (w->mismatch < 0)
            w->mismatch = k;
        return;
    }
    if (!img.rgb)
        return;
    jp->p = h.p;
    sa_error_measure(&img, &w->sc[jp->scene].ref, &jp->p.err);
    jp->measured = 1;
    if (strcmp(jp->p.kind, "auto") == 0)
        fprintf(stderr, "speed_accuracy: %s: auto %g: %.3g s, rmse %.3g (%s)\n", jp->p.scene,
                jp->p.tolerance, jp->p.seconds, jp->p.err.rmse, jp->p.note);
}

/* Rank 0: the table, each scene's reference first, then its points. */
static int write_scene(const sweep *w, int s, FILE *csv, sa_points *all)
{
    const scene_ctx *sc = &w->sc[s];
    sa_point p;
    char refined[160] = "last doubling of the wavelengths";
    if (sc->rn.refined > 0)
        snprintf(refined, sizeof refined,
                 "%d wavelengths then pixel by pixel (%ld pixel renders; %ld pixels not "
                 "within 1e-5 in two doublings); each pixel's last doubling",
                 sc->rn.whole, sc->rn.refined, sc->rn.left);
    sa_point_init(&p, "reference", "polarized", sc->rn.wavelengths, sc->rn.depth,
                  sc->rn.cutoff);
    snprintf(p.scene, sizeof p.scene, "%.63s", sc->name);
    snprintf(p.note, sizeof p.note,
             "%d x %d pixels; %s%s: max %.2g rmse %.2g; of "
             "the depth: max %.2g rmse %.2g; cut-off / 100: max %.2g rmse %.2g",
             w->o->width, w->o->height, refined,
             sc->rn.dn_cheap ? " (at depth 16 and cut-off 1e-6)" : "", sc->rn.dn_max, sc->rn.dn_rmse, sc->rn.dd_max, sc->rn.dd_rmse,
             sc->rn.dc_max, sc->rn.dc_rmse);
    /* A reference's error columns: its own uncertainty (rmse: rn.u;
     * max_abs: the last wavelength doubling's largest change). */
    p.err.rmse = sc->rn.u;
    p.err.max_abs = sc->rn.dn_max;
    p.err.share_visible = NAN;
    p.seconds = NAN;
    if (sa_points_add(all, &p) != 0 || sa_point_write_csv(csv, &p) != 0)
        return -1;
    for (long k = 0; k < w->n_pts; k++)
        if (w->pts[k].scene == s && w->pts[k].measured &&
            (sa_points_add(all, &w->pts[k].p) != 0 ||
             sa_point_write_csv(csv, &w->pts[k].p) != 0))
            return -1;
    return 0;
}

static int write_table(const sweep *w, FILE *csv, sa_points *all)
{
    for (int s = 0; s < w->n_sc; s++)
        if (write_scene(w, s, csv, all) != 0)
            return -1;
    return 0;
}

static int put_row(sa_points *all, FILE *csv, const sa_point *p)
{
    return sa_points_add(all, p) != 0 || sa_point_write_csv(csv, p) != 0 ? -1 : 0;
}

static int scene_index(const sweep *w, const char *name)
{
    for (int s = 0; s < w->n_sc; s++)
        if (strcmp(w->sc[s].name, name) == 0)
            return s;
    return -1;
}

/* Has the table an auto row of this scene and tolerance? */
static int old_has_auto(const sa_points *old, const sa_point *p)
{
    for (size_t i = 0; i < old->n; i++)
        if (strcmp(old->p[i].kind, "auto") == 0 && strcmp(old->p[i].scene, p->scene) == 0 &&
            old->p[i].tolerance == p->tolerance)
            return 1;
    return 0;
}

/* Rank 0, --redo-auto: the existing table's rows in their order, each
 * auto row of a scene run again replaced by its new measurement (left out
 * where that could not run), and a new auto point without a row of its
 * own after its scene's last row. */
static int write_table_redo(const sweep *w, FILE *csv, sa_points *all)
{
    const sa_points *old = w->old;
    for (size_t i = 0; i < old->n; i++) {
        const sa_point *q = &old->p[i];
        int s = scene_index(w, q->scene);
        if (s < 0 || strcmp(q->kind, "auto") != 0) {
            if (put_row(all, csv, q) != 0)
                return -1;
        } else {
            for (long k = 0; k < w->n_pts; k++)
                if (w->pts[k].scene == s && w->pts[k].measured &&
                    w->pts[k].p.tolerance == q->tolerance && put_row(all, csv, &w->pts[k].p) != 0)
                    return -1;
        }
        if (s >= 0 && (i + 1 == old->n || strcmp(old->p[i + 1].scene, q->scene) != 0))
            for (long k = 0; k < w->n_pts; k++)
                if (w->pts[k].scene == s && w->pts[k].measured && !old_has_auto(old, &w->pts[k].p) &&
                    put_row(all, csv, &w->pts[k].p) != 0)
                    return -1;
    }
    return 0;
}

/* Rank 0, --scene over an existing table of the same size: the table's
 * rows in their order, each scene run again replaced by its new rows
 * where its first row was (a scene new to the table at the end). */
static int write_table_merge(const sweep *w, FILE *csv, sa_points *all)
{
    const sa_points *old = w->old;
    unsigned char *done = calloc((size_t)w->n_sc + 1, 1);
    int rc = done ? 0 : -1;
    for (size_t i = 0; rc == 0 && i < old->n; i++) {
        int s = scene_index(w, old->p[i].scene);
        if (s < 0)
            rc = put_row(all, csv, &old->p[i]);
        else if (!done[s]) {
            rc = write_scene(w, s, csv, all);
            done[s] = 1;
        }
    }
    for (int s = 0; rc == 0 && s < w->n_sc; s++)
        if (!done[s])
            rc = write_scene(w, s, csv, all);
    free(done);
    return rc;
}

/* Is every reference row of the table of this run's size? */
static int old_size_ok(const sa_points *old, const opts *o)
{
    char size[64];
    int any = 0;
    snprintf(size, sizeof size, "%d x %d pixels", o->width, o->height);
    for (size_t i = 0; i < old->n; i++)
        if (strcmp(old->p[i].kind, "reference") == 0) {
            if (strncmp(old->p[i].note, size, strlen(size)) != 0)
                return 0;
            any = 1;
        }
    return any;
}

/* Does the existing table hold every scene to run, at this size?  0, or
 * -1 after saying why. */
static int redo_check(const sweep *w)
{
    if (!old_size_ok(w->old, w->o)) {
        char size[64];
        snprintf(size, sizeof size, "%d x %d pixels", w->o->width, w->o->height);
        say("the table's rows are not of %s: give the --width and --height of its run%s", size,
            "");
        return -1;
    }
    for (int s = 0; s < w->n_sc; s++) {
        int found = 0;
        for (size_t i = 0; i < w->old->n && !found; i++)
            found = strcmp(w->old->p[i].scene, w->sc[s].name) == 0 &&
                    strcmp(w->old->p[i].kind, "reference") == 0;
        if (!found) {
            say("%s: not in the existing table: run the whole sweep%s", w->sc[s].name, "");
            return -1;
        }
    }
    return 0;
}

/* Both rounds; rank 0 writes the table into csv.  Returns 0, or 1 after
 * the message (on whichever process saw the failure; rank 0 prints a
 * message of the run's own). */
static int run_sweep(mw_group *g, sweep *w, FILE *csv, sa_points *all)
{
    char msg[1024] = "";
    mw_job job;
    int rc;
    memset(&job, 0, sizeof job);
    job.n_items = w->n_sc;
    job.result_size = item_bytes(w->o);
    job.run = reference_run;
    job.done = reference_done;
    job.user = w;
    rc = mw_run(g, &job, msg, sizeof msg);
    if (rc == 0 && !w->o->references_only) {
        /* Only rank 0 and the process that made a reference know its
         * numbers, and the points listed depend on them: every process
         * takes rank 0's, so that item k is the same point everywhere. */
        sa_reference *rn = calloc((size_t)w->n_sc + 1, sizeof *rn);
        for (int s = 0; rn && s < w->n_sc; s++)
            rn[s] = w->sc[s].rn;
        rc = rn ? 0 : -1;
        if (rc != 0)
            snprintf(msg, sizeof msg, "out of memory");
        rc = mw_agree(g, rc, NULL, msg, sizeof msg);
        if (rc == 0)
            rc = mw_share(g, rn, (size_t)w->n_sc * sizeof *rn, msg, sizeof msg);
        for (int s = 0; rc == 0 && s < w->n_sc; s++)
            w->sc[s].rn = rn[s];
        free(rn);
    }
    if (rc == 0 && !w->o->references_only) {
        for (int s = 0; s < w->n_sc; s++)
            if (list_points(w, s) != 0) {
                snprintf(msg, sizeof msg, "out of memory");
                rc = -1;
            }
        rc = mw_agree(g, rc, NULL, msg, sizeof msg);
        job.n_items = w->n_pts;
        job.run = point_run;
        job.done = point_done;
        if (rc == 0)
            rc = mw_run(g, &job, msg, sizeof msg);
        if (rc == 0 && w->mismatch >= 0) {
            snprintf(msg, sizeof msg, "point %ld came back as another setting: the processes "
                     "listed different points", w->mismatch);
            rc = 1;
        }
    }
    if (rc != 0) {
        if (msg[0] && w->o->rank == 0)
            say("%s%s", msg, "");
        return 1;
    }
    if (w->o->rank == 0 && !w->o->references_only &&
        (w->o->redo_auto ? write_table_redo(w, csv, all)
         : w->old        ? write_table_merge(w, csv, all)
                         : write_table(w, csv, all)) != 0) {
        say("cannot write the table%s%s", "", "");
        return 1;
    }
    return 0;
}

/* ---- options ---------------------------------------------------------- */

static int int_arg(const char *s, int lo, int hi, int *out)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (end == s || *end || v < lo || v > hi)
        return -1;
    *out = (int)v;
    return 0;
}

static int parse(opts *o, int argc, char **argv)
{
    o->bin = "build/bin";
    o->scenes = "scenes";
    o->docs = "docs";
    o->work = "build/speed-accuracy";
    o->width = 128;
    o->height = 96;
    o->runs = 3;
    o->max_wavelengths = 16384;
    o->sweep_wavelengths = 512;
    o->reference_seconds = 45.0;
    o->point_seconds = 10.0;
    o->auto_seconds = 300.0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            for (size_t k = 0; k < N_OF(usage_text); k++)
                fputs(usage_text[k], stdout);
            exit(0);
        } else if (strcmp(a, "--reuse-references") == 0) {
            o->reuse = 1;
        } else if (strcmp(a, "--references-only") == 0) {
            o->references_only = 1;
        } else if (strcmp(a, "--redo-auto") == 0) {
            o->redo_auto = 1;
            o->reuse = 1;
        } else if (strcmp(a, "--chart-only") == 0) {
            o->chart_only = 1;
        } else if (!v) {
            say("%s%s: unknown option or missing value (see --help)", a, "");
            return -1;
        } else if (strcmp(a, "--bin") == 0) {
            o->bin = v, i++;
        } else if (strcmp(a, "--scenes") == 0) {
            o->scenes = v, i++;
        } else if (strcmp(a, "--docs") == 0) {
            o->docs = v, i++;
        } else if (strcmp(a, "--work") == 0) {
            o->work = v, i++;
        } else if (strcmp(a, "--reference-seconds") == 0 || strcmp(a, "--point-seconds") == 0 ||
                   strcmp(a, "--auto-seconds") == 0) {
            char *end;
            double x = strtod(v, &end);
            if (end == v || *end || !(x > 0.0 && x <= 1e6)) {
                say("%s: '%s' is out of range", a, v);
                return -1;
            }
            *(a[2] == 'r' ? &o->reference_seconds
              : a[2] == 'p' ? &o->point_seconds : &o->auto_seconds) = x;
            i++;
        } else if (strcmp(a, "--scene") == 0) {
            if (o->n_only == (int)N_OF(o->only)) {
                say("too many --scene%s%s", "", "");
                return -1;
            }
            o->only[o->n_only++] = v, i++;
        } else if (strcmp(a, "--width") == 0 || strcmp(a, "--height") == 0 ||
                   strcmp(a, "--runs") == 0 || strcmp(a, "--max-wavelengths") == 0 ||
                   strcmp(a, "--sweep-wavelengths") == 0) {
            int *dst = a[2] == 'w' ? &o->width : a[2] == 'h' ? &o->height
                       : a[2] == 'r' ? &o->runs : a[2] == 'm' ? &o->max_wavelengths
                                                 : &o->sweep_wavelengths;
            if (int_arg(v, 1, a[2] == 'r' ? 15 : 16384, dst) != 0) {
                say("%s: '%s' is out of range", a, v);
                return -1;
            }
            i++;
        } else {
            say("unknown option '%s'%s (see --help)", a, "");
            return -1;
        }
    }
    return 0;
}

static int wanted(const opts *o, const char *name)
{
    if (o->n_only == 0)
        return 1;
    for (int k = 0; k < o->n_only; k++)
        if (strcmp(o->only[k], name) == 0)
            return 1;
    return 0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

int main(int argc, char **argv)
{
    opts o;
    sa_points all, old;
    char csv_path[PATH_BUF], msg[512];
    mw_group *g;
    int rc = 0;
    memset(&o, 0, sizeof o);
    if (parse(&o, argc, argv) != 0)
        return EXIT_USAGE;
    if (mw_group_start(&argc, &argv, &g, msg, sizeof msg) != 0) {
        say("%s%s", msg, "");
        return 1;
    }
    o.rank = mw_group_rank(g);
    sa_points_init(&all);
    sa_points_init(&old);
    snprintf(csv_path, sizeof csv_path, "%.4000s/speed-accuracy.csv", o.docs);
    if (o.rank == 0 && make_dir(o.docs) != 0) {
        say("%s: cannot create: %s", o.docs, strerror(errno));
        rc = 1;
    }

    if (rc == 0 && o.chart_only) {
        if (o.rank == 0 && sa_points_read_csv(csv_path, &all, msg, sizeof msg) != 0) {
            say("%s: %s", csv_path, msg);
            rc = 1;
        }
    } else if (rc == 0) {
        char *names[256];
        int n_names = 0;
        FILE *csv = NULL;
        char tmp[PATH_BUF + 8];
        sweep w;
        DIR *dir = opendir(o.scenes);
        struct dirent *de;
        memset(&w, 0, sizeof w);
        w.o = &o;
        w.mismatch = -1;
        if (!dir) {
            say("%s: cannot list: %s", o.scenes, strerror(errno));
            rc = 1;
        }
        while (dir && (de = readdir(dir)) != NULL && n_names < 256) {
            size_t n = strlen(de->d_name);
            if (n > 6 && strcmp(de->d_name + n - 6, ".scene") == 0)
                names[n_names++] = strdup(de->d_name);
        }
        if (dir)
            closedir(dir);
        qsort(names, (size_t)n_names, sizeof *names, cmp_str);
        w.sc = calloc((size_t)n_names + 1, sizeof *w.sc);
        for (int k = 0; rc == 0 && w.sc && k < n_names; k++) {
            scene_ctx *sc = &w.sc[w.n_sc];
            sc->o = &o;
            snprintf(sc->name, sizeof sc->name, "%.*s", (int)(strlen(names[k]) - 6), names[k]);
            if (!wanted(&o, sc->name))
                continue;
            snprintf(sc->path, sizeof sc->path, "%.3800s/%.255s", o.scenes, names[k]);
            snprintf(sc->dir, sizeof sc->dir, "%.3800s/%.255s", o.work, sc->name);
            if (make_dir(sc->dir) != 0) {
                say("%s: cannot create%s", sc->dir, "");
                rc = 1;
            }
            w.n_sc++;
        }
        if (o.rank == 0 && rc == 0 && o.redo_auto) {
            if (sa_points_read_csv(csv_path, &old, msg, sizeof msg) != 0) {
                say("%s: %s", csv_path, msg);
                rc = 1;
            } else {
                w.old = &old;
                rc = redo_check(&w) != 0;
            }
        } else if (o.rank == 0 && rc == 0 && o.n_only > 0 && !o.references_only) {
            /* some scenes: the others' rows of the table are kept */
            if (sa_points_read_csv(csv_path, &old, msg, sizeof msg) == 0 &&
                old_size_ok(&old, &o))
                w.old = &old;
            else if (old.n > 0)
                say("%s: of another size or unreadable: it keeps only the scenes of this "
                    "run%s", csv_path, "");
        }
        if (o.rank == 0 && rc == 0) {
            snprintf(tmp, sizeof tmp, "%s.tmp", csv_path);
            csv = fopen(tmp, "w");
            if (!csv || sa_point_write_csv_header(csv) != 0) {
                say("%s: cannot write%s", tmp, "");
                rc = 1;
            }
        }
        /* Every process must see the scenes and its directories. */
        if (mw_agree(g, rc, NULL, msg, sizeof msg) != 0)
            rc = 1;
        if (rc == 0)
            rc = run_sweep(g, &w, csv, &all);
        if (csv && (fclose(csv) != 0 || (rc == 0 && !o.references_only &&
                                          rename(tmp, csv_path) != 0))) {
            say("%s: cannot write%s", csv_path, "");
            rc = 1;
        }
        for (int k = 0; k < n_names; k++)
            free(names[k]);
        for (int k = 0; w.sc && k < w.n_sc; k++)
            rs_image_free(&w.sc[k].ref);
        free(w.sc);
        free(w.pts);
    }
    if (rc == 0 && o.rank == 0 && !o.references_only &&
        sa_chart_write(&all, o.docs, msg, sizeof msg) != 0) {
        say("chart: %s%s", msg, "");
        rc = 1;
    }
    sa_points_free(&all);
    sa_points_free(&old);
    rc = mw_agree(g, rc, NULL, msg, sizeof msg) != 0 ? 1 : 0;
    mw_group_end(g);
    return rc;
}
