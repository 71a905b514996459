/* sa_chart.c -- the chart and the page (see sa_chart.h). */
#include "sa_chart.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/image.h"
#include "plot.h"

#define PANEL_W 560
#define PANEL_H 420
#define COLUMNS 3
#define MAX_SCENES 32
#define MAX_SERIES 2048
#define Y_FLOOR 1e-7 /* an error of 0 is drawn here */

static const double TOLS[3] = {1e-2, 1e-3, 1e-4};
static const unsigned TOL_COLOR[3] = {0x1f77b4u, 0x2ca02cu, 0x9467bdu};
#define FRONT_COLOR 0xff7f0eu
#define POV_COLOR 0xd62728u
#define SWEEP_COLOR 0x9a9a9au
#define UNCERTAIN_COLOR 0x404040u

static int is(const sa_point *p, const char *kind)
{
    return strcmp(p->kind, kind) == 0;
}

static double err_y(double e)
{
    return e > Y_FLOOR ? e : Y_FLOOR;
}

/* The scenes in order of first appearance. */
static size_t scene_list(const sa_points *ps, const char **names)
{
    size_t n = 0;
    for (size_t i = 0; i < ps->n; i++) {
        size_t k;
        for (k = 0; k < n; k++)
            if (strcmp(names[k], ps->p[i].scene) == 0)
                break;
        if (k == n && n < MAX_SCENES)
            names[n++] = ps->p[i].scene;
    }
    return n;
}

static int timed(const sa_point *p)
{
    return isfinite(p->seconds) && p->seconds > 0.0 && isfinite(p->err.rmse);
}

/* Storage for the little line pieces a panel is drawn with. */
typedef struct pieces {
    double xy[MAX_SERIES][2][4];
    pl_series s[MAX_SERIES];
    size_t n;
} pieces;

static void add_line(pieces *pc, const double *x, const double *y, size_t n, unsigned color,
                     pl_dash dash, double width, const char *label)
{
    if (pc->n >= MAX_SERIES || n > 4)
        return;
    for (size_t k = 0; k < n; k++) {
        pc->xy[pc->n][0][k] = x[k];
        pc->xy[pc->n][1][k] = y[k];
    }
    pc->s[pc->n] = (pl_series){label, pc->xy[pc->n][0], pc->xy[pc->n][1], n, color, dash, width};
    pc->n++;
}

/* A marker at (x, y): shape 0 '+', 1 'x', 2 diamond.  sx in data x units,
 * fy a factor of y. */
static void add_marker(pieces *pc, double x, double y, double sx, double fy, int shape,
                       unsigned color, double width)
{
    if (shape == 0) {
        double hx[2] = {x - sx, x + sx}, hy[2] = {y, y};
        double vx[2] = {x, x}, vy[2] = {y / fy, y * fy};
        add_line(pc, hx, hy, 2, color, PL_SOLID, width, NULL);
        add_line(pc, vx, vy, 2, color, PL_SOLID, width, NULL);
    } else if (shape == 1) {
        double ax[2] = {x - sx, x + sx}, ay[2] = {y / fy, y * fy};
        double bx[2] = {x - sx, x + sx}, by[2] = {y * fy, y / fy};
        add_line(pc, ax, ay, 2, color, PL_SOLID, width, NULL);
        add_line(pc, bx, by, 2, color, PL_SOLID, width, NULL);
    } else {
        double dx[4] = {x - sx, x, x + sx, x}, dy[4] = {y, y * fy, y, y / fy};
        double ex[2] = {x, x - sx}, ey[2] = {y / fy, y};
        add_line(pc, dx, dy, 4, color, PL_SOLID, width, NULL);
        add_line(pc, ex, ey, 2, color, PL_SOLID, width, NULL);
    }
}

static int cmp_time(const void *a, const void *b)
{
    const sa_point *p = *(const sa_point *const *)a, *q = *(const sa_point *const *)b;
    if (p->seconds != q->seconds)
        return (p->seconds > q->seconds) - (p->seconds < q->seconds);
    return (p->err.rmse > q->err.rmse) - (p->err.rmse < q->err.rmse);
}

/* The swept points of a scene sorted by time; returns the count. */
static size_t swept(const sa_points *ps, const char *scene, const sa_point **out, size_t max)
{
    size_t n = 0;
    for (size_t i = 0; i < ps->n && n < max; i++)
        if (strcmp(ps->p[i].scene, scene) == 0 && (is(&ps->p[i], "sweep")) && timed(&ps->p[i]))
            out[n++] = &ps->p[i];
    qsort(out, n, sizeof *out, cmp_time);
    return n;
}

static const sa_point *find(const sa_points *ps, const char *scene, const char *kind, double tol);

/* The reference's own uncertainty U (an RMSE): a measured error e means
 * a true error within e +- U.  Infinite when not known. */
static double uncertainty(const sa_points *ps, const char *scene)
{
    const sa_point *r = find(ps, scene, "reference", 0.0);
    return r && isfinite(r->err.rmse) ? r->err.rmse : INFINITY;
}

/* A measured error e meets E when even e + U does. */
static int meets(double e, double u, double tol)
{
    return e + u <= tol;
}

static int draw_panel(rs_image *img, int x0, int y0, const sa_points *ps, const char *scene,
                      pieces *pc, char *msg, size_t msg_size)
{
    const sa_point *sw[1024];
    size_t n = swept(ps, scene, sw, 1024);
    double tmin = INFINITY, tmax = 0.0, emin = INFINITY, emax = 0.0;
    pl_chart ch;

    pc->n = 0;
    for (size_t i = 0; i < ps->n; i++) {
        const sa_point *p = &ps->p[i];
        if (strcmp(p->scene, scene) != 0 || !timed(p))
            continue;
        tmin = fmin(tmin, p->seconds);
        tmax = fmax(tmax, p->seconds);
        emin = fmin(emin, err_y(p->err.rmse));
        emax = fmax(emax, err_y(p->err.rmse));
    }
    if (!(tmax > 0.0))
        return 0;
    memset(&ch, 0, sizeof ch);
    ch.title = scene;
    ch.xlabel = "CPU seconds, one thread (log10)";
    ch.ylabel = "RMSE vs reference";
    ch.xmin = floor(log10(tmin) * 2.0) / 2.0 - 0.1;
    ch.xmax = ceil(log10(tmax) * 2.0) / 2.0 + 0.1;
    ch.ylog = 1;
    ch.ymin = pow(10.0, floor(log10(fmin(emin, 1e-4))));
    ch.ymax = pow(10.0, ceil(log10(fmax(emax, 1e-2)) + 0.01));
    ch.legend = PL_LEGEND_NONE;
    ch.xstep = 0.5;
    ch.text_scale = 2;
    double sx = 0.012 * (ch.xmax - ch.xmin);
    double fy = pow(ch.ymax / ch.ymin, 0.016);

    for (int t = 0; t < 3; t++) {
        double x[2] = {ch.xmin, ch.xmax}, y[2] = {TOLS[t], TOLS[t]};
        add_line(pc, x, y, 2, TOL_COLOR[t], PL_DOTTED, 1.5, NULL);
    }
    double u = uncertainty(ps, scene);
    if (isfinite(u) && u > ch.ymin) {
        double x[2] = {ch.xmin, ch.xmax}, y[2] = {u, u};
        add_line(pc, x, y, 2, UNCERTAIN_COLOR, PL_DASHED, 2.0, NULL);
    }
    for (size_t k = 0; k < n; k++)
        add_marker(pc, log10(sw[k]->seconds), err_y(sw[k]->err.rmse), sx, fy, 0, SWEEP_COLOR, 1.2);
    /* The Pareto front: each point faster than all that are more accurate.
     * Errors below U cannot be told apart: the front ends at the first
     * point that reaches U. */
    {
        double best = INFINITY, px = NAN, py = NAN;
        for (size_t k = 0; k < n; k++) {
            double e = err_y(fmax(sw[k]->err.rmse, isfinite(u) ? u : 0.0));
            if (!(e < best))
                continue;
            double x = log10(sw[k]->seconds);
            if (isfinite(px)) {
                double lx[3] = {px, x, x}, ly[3] = {py, py, e};
                add_line(pc, lx, ly, 3, FRONT_COLOR, PL_SOLID, 2.0, NULL);
            }
            best = e;
            px = x;
            py = e;
        }
    }
    for (size_t i = 0; i < ps->n; i++) {
        const sa_point *p = &ps->p[i];
        if (strcmp(p->scene, scene) != 0 || !timed(p))
            continue;
        if (is(p, "povray"))
            add_marker(pc, log10(p->seconds), err_y(p->err.rmse), 1.6 * sx, pow(fy, 1.6), 1,
                       POV_COLOR, 2.5);
        if (is(p, "auto"))
            for (int t = 0; t < 3; t++)
                if (fabs(p->tolerance / TOLS[t] - 1.0) < 1e-6)
                    add_marker(pc, log10(p->seconds), err_y(p->err.rmse), 1.6 * sx, pow(fy, 1.6), 2,
                               TOL_COLOR[t], 2.5);
    }
    return pl_draw(img, x0, y0, PANEL_W, PANEL_H, &ch, pc->s, pc->n, msg, msg_size);
}

static int write_png(const sa_points *ps, const char **names, size_t ns, const char *dir,
                     char *msg, size_t msg_size)
{
    rs_image img;
    char path[4096];
    int rows = (int)((ns + COLUMNS - 1) / COLUMNS);
    int key_h = 70;
    pieces *pc = malloc(sizeof *pc);
    int rc = 0;
    if (!pc || rs_image_create(&img, COLUMNS * PANEL_W, rows * PANEL_H + key_h) != 0) {
        free(pc);
        snprintf(msg, msg_size, "out of memory for the chart");
        return -1;
    }
    pl_fill(&img, 0xffffffu);
    for (size_t k = 0; k < ns && rc == 0; k++)
        rc = draw_panel(&img, (int)(k % COLUMNS) * PANEL_W, (int)(k / COLUMNS) * PANEL_H, ps,
                        names[k], pc, msg, msg_size);
    if (rc == 0) {
        int y = rows * PANEL_H + 10, x = 20;
        pl_text(&img, x, y, 2, SWEEP_COLOR, "+ swept setting");
        pl_text(&img, x + 260, y, 2, FRONT_COLOR, "-- Pareto front");
        pl_text(&img, x + 520, y, 2, POV_COLOR, "x POV-Ray (no dispersion)");
        pl_text(&img, x, y + 30, 2, TOL_COLOR[0], "<> auto, E = 1e-2");
        pl_text(&img, x + 260, y + 30, 2, TOL_COLOR[1], "<> auto, E = 1e-3");
        pl_text(&img, x + 520, y + 30, 2, TOL_COLOR[2], "<> auto, E = 1e-4");
        pl_text(&img, x + 820, y + 30, 2, 0x606060u, "dotted: the three E");
        pl_text(&img, x + 1100, y, 2, UNCERTAIN_COLOR, "dashed: the reference's U");
        snprintf(path, sizeof path, "%s/speed-accuracy.png", dir);
        rc = rs_png_write(path, &img, msg, msg_size);
    }
    rs_image_free(&img);
    free(pc);
    return rc;
}

static const sa_point *find(const sa_points *ps, const char *scene, const char *kind, double tol)
{
    for (size_t i = 0; i < ps->n; i++)
        if (strcmp(ps->p[i].scene, scene) == 0 && is(&ps->p[i], kind) &&
            (tol <= 0.0 || fabs(ps->p[i].tolerance / tol - 1.0) < 1e-6))
            return &ps->p[i];
    return NULL;
}

static void setting(char *out, size_t size, const sa_point *p)
{
    char cut[32];
    if (p->cutoff < 0.0)
        snprintf(cut, sizeof cut, "scene's");
    else
        snprintf(cut, sizeof cut, "%g", p->cutoff);
    if (strcmp(p->model, "rgb") == 0)
        snprintf(out, size, "rgb, depth %d, cut-off %s", p->depth, cut);
    else
        snprintf(out, size, "%s, %d wl, depth %d, cut-off %s", p->model, p->wavelengths,
                 p->depth, cut);
}

static const char *const PAGE_TEXT =
"# Speed against accuracy\n"
"\n"
"![speed against accuracy](speed-accuracy.png)\n"
"\n"
"Every panel is one scene of `scenes/`.  Each grey cross is one render\n"
"setting — light model × wavelength count × depth × branch cut-off — at\n"
"its cost (x: CPU seconds of the `lensrender` process on one thread,\n"
"logarithmic) and its error (y: RMSE of linear RGB against the scene's\n"
"reference, logarithmic).  The dashed dark line is the reference's own\n"
"uncertainty U (below): an error under it is not a measurement, only a\n"
"bound (the true error is at most the measured one plus U).  The orange\n"
"line is the Pareto front: the settings that no other swept setting\n"
"beats in both time and error, errors under U counted as U (they cannot\n"
"be told apart), so the front ends where it first reaches U.  The red ×\n"
"is POV-Ray 3.7 rendering the same scene (translated by `pov_compare`:\n"
"glass a constant index n_d, no dispersion, no polarizers, one thread),\n"
"against the same reference — its error is what leaving out dispersion\n"
"and polarization costs.  The diamonds are `--mode auto --tolerance E`\n"
"for E = 1e-2 (blue), 1e-3 (green), 1e-4 (purple), and the dotted lines\n"
"the three E: a diamond should lie below its own line and near the\n"
"front's left end below that line.\n"
"\n"
"**Reading it.** Move left along the front to see how much accuracy a\n"
"faster setting gives up; a setting far right of the front at the same\n"
"height wastes time.  Wavelengths are the main cost and, through\n"
"dispersion, the main error: where a pixel's path changes with the\n"
"wavelength (a dispersed ray crossing a checker edge or a rim, TIR\n"
"setting in) the integrand over wavelength has a step, so the midpoint\n"
"rule's error falls only as 1/N.  Depth and cut-off matter less once the\n"
"tree is deep enough; the light model matters where polarization does\n"
"(the polarizer and crystal scenes, strong ghosts in dense glass).\n"
"\n"
"**The reference.** Polarized.  At 128 wavelengths the depth is doubled\n"
"from 16 (to 64) and the cut-off divided by 100 from 1e-10 (to 1e-14)\n"
"while that changes some pixel by more than 1e-5; then the wavelength\n"
"count is doubled from 128 until two doublings in a row change no pixel\n"
"by more than 1e-5, up to 16384 or until the next doubling is predicted to take\n"
"more CPU time than the budget (`--reference-seconds`); where not even one\n"
"doubling fits (the note says so), the doubling is measured at depth 16 and\n"
"cut-off 1e-6 instead: the quadrature's error is the main paths', whose\n"
"topology the deep, faint branches do not change.  Then, pixel by pixel:\n"
"the pixels not yet within 1e-5 in two doublings in a row are doubled\n"
"again (one such doubling let a bright light seen through\n"
"crossed_polarizers' lens stop at 4096 wavelengths, 0.016 off:\n"
"it changed by 1e-5 from 2048 to 4096 and by 0.016 from 4096 to 8192)\n"
"(`lr_render_pixels`, each pixel what a whole render at\n"
"its count gives), and again, to 16384 wavelengths or the budget -- a\n"
"few hundred pixels of a dispersed edge or rim instead of the image\n"
"(meniscus at 128 × 96: U 1.2e-4 at 1024 wavelengths for the whole image,\n"
"4.3e-6 with 1080 pixel renders up to 16384).  The reference's wavelength\n"
"count is then the most a pixel has, its note says how many pixel\n"
"renders it took and how many pixels still change by more than 1e-5,\n"
"and its wavelength part of U is the RMS of each pixel's own last\n"
"change.  A cut-off, not\n"
"none: a branch below 1e-10 of the light changes a pixel by at most 1e-10\n"
"of the brightest radiance (2e-5 through interference), while without one\n"
"a birefringent plate's tree doubles at every bounce.  The midpoint rule's\n"
"1/N error means the last doubling's change is about the coarser render's\n"
"error, twice the finer one's; U, the RMSE changes of the last wavelength\n"
"doubling (each pixel's own), depth doubling and cut-off step summed, bounds the reference's\n"
"RMSE from the converged image.  Where the table below shows a last\n"
"doubling's largest pixel change above 1e-5, the reference did NOT\n"
"converge to 1e-5 per pixel within its budget, and the figures are what\n"
"it reaches.\n"
"\n"
"**How it is measured.** `sh scripts/speed_accuracy.sh` builds the\n"
"project and runs `build/bin/speed_accuracy`, which for every scene\n"
"renders the reference, then every swept setting, auto at the three E,\n"
"the renderer's default (polarized, 16 wavelengths, the scene's depth and\n"
"`adc_bailout`) and POV-Ray, each `--runs` times (default 3; a setting\n"
"slower than 1 s once), and takes the median CPU time (user + system of\n"
"the child process, from `wait4`): the machine is shared, and CPU time\n"
"does not count the time other work held the cores, wall time would.\n"
"A swept setting whose time, predicted from the time per wavelength of a\n"
"polarized render at depth 16 and cut-off 1e-6, exceeds `--point-seconds`\n"
"is not run (the expensive scenes' highest wavelength counts), and one\n"
"that runs out of 4 × that much CPU time is left out (a low cut-off at\n"
"depth 16 on a birefringent plate: michel_levy, conoscope); so is an auto\n"
"render that runs out of `--auto-seconds` (thousands of wavelengths\n"
"through dispersive glass at E = 1e-4): its row shows a dash.\n"
"\n"
"**The grid** is the one `--mode auto` chooses from: rgb, schlick,\n"
"fresnel and polarized; 4, 8 … 512 wavelengths; depth 4, 8, 16, 32;\n"
"cut-off 1e-2, 1e-3, 1e-4, 1e-6 at every depth and 1e-8, 1e-10, 1e-12\n"
"(the floors auto uses under coherent light) from depth 16 on, plus the scene's own\n"
"`adc_bailout` at depth 16 (the default render's).  Pruned, as settings\n"
"that cannot be on the front: from 64 wavelengths on (wavelength errors\n"
"near 1e-3 and below) only the trees that can be as accurate, depth 8\n"
"and deeper with a cut-off of 1e-3 or less; auto's own choices beyond 512\n"
"wavelengths have no swept point.  It writes `speed-accuracy.csv`\n"
"(every point: scene, kind, model, wavelengths, depth, cut-off, tolerance,\n"
"seconds, runs, rmse, largest channel error, share of pixels off by more\n"
"than 1/255 after the sRGB curve, note; a reference's rmse column is its\n"
"U and its largest error the last wavelength doubling's largest change),\n"
"this chart and this page.\n"
"\n"
"**Auto** estimates each candidate's error on its probe from three\n"
"measured parts -- the wavelengths' (its count against the top of a\n"
"ladder 4, 8, 16 …, plus the top's last change) and the model's (against\n"
"polarized), which add in quadrature (a wavelength grid's error changes\n"
"sign from one count to the next, the model's does not), plus the tree's\n"
"(its depth and cut-off against the deepest tree, plus 0.1 E for what\n"
"that one drops) -- and prices it by the work its probe renders counted\n"
"(rays, lanes, lens builds, gathers), not by time, so the choice is the\n"
"same on any machine; it takes the cheapest whose estimate is within E.\n"
"Its note in the table gives the parts.\n"
"\n"
"**Per pixel, where it helps**, auto also refines the wavelengths: a\n"
"pixel whose spectral packet split at a dispersive lens (its wavelengths\n"
"went different ways, so its spectrum has steps and its error falls only\n"
"as 1/N) is rendered again at 2N, 4N … until two doublings in a row change\n"
"no channel by more than a tolerance τ, or at the ladder's top count\n"
"(past which only a pixel that alone would take 1/16 of the image's\n"
"squared error goes on, up to 16384: a light seen through the lens);\n"
"the other pixels, whose spectra are smooth, keep the first count.  Each\n"
"candidate count is tried with τ from E / 8 to 8 E, each replayed on the\n"
"probe's rungs for its error and its cost, and τ at most E / √s (s the\n"
"share of the image that split: a pixel is left within about τ of its\n"
"converged value, so that bounds what they add whatever the probe saw).\n"
"A refined pixel is bit for bit what a render at its last count gives it,\n"
"so an image cut into regions still renders identically.  Such a point\n"
"has no swept twin: the grid is uniform.\n"
"\n"
"**The size**, 128 × 96 pixels (the references' table says what it\n"
"was), is chosen so that what every process pays whatever the image --\n"
"start-up, the scene's parse, the output -- is a small share of a render,\n"
"as it is at the sizes people render: a 1 × 1 render costs 3 ms of CPU,\n"
"the cheapest render of a scene at 128 × 96 (rgb) 11-14 ms and a 4-wavelength\n"
"fresnel render 23 ms, so the fixed cost is at most 13-27 % of the\n"
"cheapest points and about 1 % of the default polarized render; at the\n"
"16 × 12 of earlier runs it was 75-100 % of every cheap render, and each\n"
"scene had 20-40 pixels through its lens, too few to weigh a dispersed\n"
"edge (at 128 × 96 the fresnel render of default.scene at 4 wavelengths\n"
"is 1.5e-2 off, at 16 × 12 it measured 2.2e-3).  Auto's probe is about\n"
"one in 32 of the pixels seen through a lens and one in 256 of the\n"
"rest; at 128 × 96 its cost is a tenth to a half of the chosen render's\n"
"(its line in the table says how much), less at larger sizes.\n"
"\n";

static int write_md(const sa_points *ps, const char **names, size_t ns, const char *dir,
                    char *msg, size_t msg_size)
{
    char path[4096], tmp[4200];
    FILE *f;
    snprintf(path, sizeof path, "%s/speed-accuracy.md", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    f = fopen(tmp, "w");
    if (!f) {
        snprintf(msg, msg_size, "%s: cannot write", tmp);
        return -1;
    }
    fputs(PAGE_TEXT, f);
    fputs("## Auto against the front\n\n"
          "Per scene and E: auto's choice, its error and time, and whether it meets\n"
          "E: *yes* when its error + U ≤ E, *no* when its error − U > E, *unresolved*\n"
          "between (the reference cannot tell); the cheapest swept setting that meets\n"
          "E the same way (error + U ≤ E; none when U ≥ E: E is below what the\n"
          "reference resolves); auto's time over that one's (the goal is ≤ 1.25) and\n"
          "over the default polarized render's; and whether auto sits on the front\n"
          "at its own error: its time over that of the cheapest swept setting at\n"
          "least as accurate (errors under U counted as U), *beyond* where no swept\n"
          "setting is (auto refines pixels the uniform grid cannot).\n\n"
          "| scene | E | auto's choice | auto rmse | meets E | auto s | cheapest swept meeting E "
          "| its rmse | its s | auto / cheapest | auto / default | auto / front at its error |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|\n", f);
    for (size_t k = 0; k < ns; k++) {
        const sa_point *dflt = find(ps, names[k], "default", 0.0);
        const sa_point *sw[1024];
        size_t n = swept(ps, names[k], sw, 1024);
        double u = uncertainty(ps, names[k]);
        for (int t = 0; t < 3; t++) {
            const sa_point *a = find(ps, names[k], "auto", TOLS[t]), *best = NULL, *at = NULL;
            char s1[160] = "—", s2[64] = "—";
            const char *verdict = "—";
            for (size_t i = 0; i < n && !best; i++)
                if (meets(sw[i]->err.rmse, u, TOLS[t]))
                    best = sw[i];
            if (best)
                setting(s1, sizeof s1, best);
            else if (!(u < TOLS[t]))
                snprintf(s1, sizeof s1, "none: E ≤ U = %.2g", u);
            for (size_t i = 0; a && i < n && !at; i++)
                if (fmax(sw[i]->err.rmse, u) <= fmax(a->err.rmse, u))
                    at = sw[i];
            if (a && at)
                snprintf(s2, sizeof s2, "%.2f", a->seconds / at->seconds);
            else if (a && a->err.rmse == a->err.rmse)
                snprintf(s2, sizeof s2, "beyond");
            if (a)
                verdict = meets(a->err.rmse, u, TOLS[t])     ? "yes"
                          : a->err.rmse - u > TOLS[t]        ? "**no**"
                                                             : "unresolved";
            fprintf(f,
                    "| %s | %g | %s | %.2g | %s | %.3g | %s | %.2g | %.3g | %.2f | %.2f | %s |\n",
                    names[k], TOLS[t], a ? a->note : "—", a ? a->err.rmse : NAN, verdict,
                    a ? a->seconds : NAN, s1, best ? best->err.rmse : NAN,
                    best ? best->seconds : NAN, a && best ? a->seconds / best->seconds : NAN,
                    a && dflt ? a->seconds / dflt->seconds : NAN, s2);
        }
    }
    fputs("\n## The references and POV-Ray\n\n"
          "| scene | reference | U | how far it converged | default polarized: rmse, s "
          "| POV-Ray: rmse, largest, share > 1/255, s |\n|---|---|---|---|---|---|\n", f);
    for (size_t k = 0; k < ns; k++) {
        const sa_point *r = find(ps, names[k], "reference", 0.0);
        const sa_point *d = find(ps, names[k], "default", 0.0);
        const sa_point *p = find(ps, names[k], "povray", 0.0);
        fprintf(f, "| %s | ", names[k]);
        if (r)
            fprintf(f, "%d wl, depth %d, cut-off %g | %.2g | %s | ", r->wavelengths, r->depth,
                    r->cutoff, r->err.rmse, r->note);
        else
            fputs("— | — | — | ", f);
        if (d)
            fprintf(f, "%.2g, %.3g | ", d->err.rmse, d->seconds);
        else
            fputs("— | ", f);
        if (p)
            fprintf(f, "%.2g, %.2g, %.1f %%, %.3g |\n", p->err.rmse, p->err.max_abs,
                    100.0 * p->err.share_visible, p->seconds);
        else
            fputs("— |\n", f);
    }
    if (fclose(f) != 0 || rename(tmp, path) != 0) {
        snprintf(msg, msg_size, "%s: cannot write", path);
        return -1;
    }
    return 0;
}

int sa_chart_write(const sa_points *ps, const char *dir, char *msg, size_t msg_size)
{
    const char *names[MAX_SCENES];
    size_t ns = scene_list(ps, names);
    if (ns == 0) {
        snprintf(msg, msg_size, "no points");
        return -1;
    }
    if (write_png(ps, names, ns, dir, msg, msg_size) != 0)
        return -1;
    return write_md(ps, names, ns, dir, msg, msg_size);
}
