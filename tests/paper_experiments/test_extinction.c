/* test_extinction.c -- the empty polarizing microscope's leak against the
 * numerical aperture (extinction_na), against a closed form written here.
 *
 * A test instrument of its own (two lenses of constant index 1.5168
 * between a polarizer along x and an analyzer along y, written here):
 * for a ray parallel to the axis at height h and azimuth phi from the
 * polarizer, meridional through spherical surfaces, the field keeps its p
 * part (in the meridional plane) and its s part (across it), each scaled
 * at every surface by the Fresnel amplitude transmission normalized to
 * power, t = t_Fresnel sqrt(n2 cos t / n1 cos i).  With P, S the products
 * and beta the exit angle, a unit field along x leaves as
 *     E = P cos(phi) p_out - S sin(phi) s,
 * whose y part is 1/2 sin(2 phi) (P cos(beta) - S) and x part
 * P cos^2(phi) cos(beta) + S sin^2(phi): the crossed and parallel
 * transmissions are their squares.  The aperture's leak at NA is the sum
 * over a uniform beam (rings of equal area, h up to the ray that reaches
 * sin(theta) = NA in its steepest segment; azimuths at midpoints) of the
 * crossed over the sum of the parallel.  This file traces the rays by
 * Snell's law through its own spheres, finds h(NA) by its own
 * bisection, and compares the program's traced columns (the library's
 * polarized trace) with that closed form.  And on the shipped empty
 * microscope: the program runs, the traced leak matches its prediction,
 * and at small NA it grows as NA^4 ((P - S) ~ theta^2). */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "subprocess.h"
#include "test_files.h"

#define PI 3.14159265358979323846
#define N_GLASS 1.5168
#define RINGS 6
#define AZIMUTHS 8

/* The test instrument: light from the polarizer at z = 50 towards -z. */
static const char scene[] =
    "camera { location <0, 0, 0> direction <0, 0, 1> }\n"
    "polarizer { center <0, 0, 5> normal z radius 30 axis y }\n"
    "lens { radius1 20 radius2 -20 thickness 4 diameter 16 ior 1.5168 translate <0, 0, 10> }\n"
    "lens { radius1 0 radius2 -15 thickness 5 diameter 16 ior 1.5168 translate <0, 0, 30> }\n"
    "polarizer { center <0, 0, 50> normal z radius 30 axis x }\n"
    "disc { <0, 0, 60>, z, 40 pigment { rgb 1 } finish { emission 1 } }\n";

/* The surfaces in the order the light meets them: vertex z, radius (0:
 * flat), the index behind. */
static const struct {
    double z, R, n_after;
} surf[4] = {
    {35.0, -15.0, N_GLASS}, {30.0, 0.0, 1.0}, {14.0, -20.0, N_GLASS}, {10.0, 20.0, 1.0}};

typedef struct { double x, z; } v2; /* the meridional plane: x radial */

/* Trace the ray of height h; P, S, cos(beta) and the steepest sine. */
static int trace(double h, double *P, double *S, double *cb, double *smax)
{
    v2 p = {h, 50}, d = {0, -1};
    double n1 = 1;
    *P = *S = 1;
    *smax = 0;
    for (int k = 0; k < 4; k++) {
        v2 q, nrm;
        if (surf[k].R == 0) {
            double t = (surf[k].z - p.z) / d.z;
            q = (v2){p.x + t * d.x, surf[k].z};
            nrm = (v2){0, 1};
        } else {
            v2 c = {0, surf[k].z + surf[k].R};
            v2 oc = {p.x - c.x, p.z - c.z};
            double b = oc.x * d.x + oc.z * d.z, cc = oc.x * oc.x + oc.z * oc.z - surf[k].R * surf[k].R;
            double disc = b * b - cc;
            if (disc < 0)
                return -1;
            /* the root on the cap near the vertex */
            double t1 = -b - sqrt(disc), t2 = -b + sqrt(disc);
            v2 q1 = {p.x + t1 * d.x, p.z + t1 * d.z}, q2 = {p.x + t2 * d.x, p.z + t2 * d.z};
            q = fabs(q1.z - surf[k].z) < fabs(q2.z - surf[k].z) ? q1 : q2;
            nrm = (v2){(q.x - c.x) / fabs(surf[k].R), (q.z - c.z) / fabs(surf[k].R)};
        }
        if (fabs(q.x) > 8)
            return -1; /* the rim */
        double ci = -(d.x * nrm.x + d.z * nrm.z);
        if (ci < 0) {
            nrm = (v2){-nrm.x, -nrm.z};
            ci = -ci;
        }
        double n2 = surf[k].n_after, r = n1 / n2, kk = 1 - r * r * (1 - ci * ci);
        if (kk < 0)
            return -1;
        double ct = sqrt(kk);
        d = (v2){r * d.x + (r * ci - ct) * nrm.x, r * d.z + (r * ci - ct) * nrm.z};
        double g = sqrt(n2 * ct / (n1 * ci));
        *S *= 2 * n1 * ci / (n1 * ci + n2 * ct) * g;
        *P *= 2 * n1 * ci / (n2 * ci + n1 * ct) * g;
        n1 = n2;
        p = q;
        if (n2 == 1.0)
            *smax = fmax(*smax, fabs(d.x) / sqrt(d.x * d.x + d.z * d.z));
    }
    *cb = fabs(d.z) / sqrt(d.x * d.x + d.z * d.z);
    return 0;
}

static double height_of(double na)
{
    double lo = 0, hi = 6, P, S, cb, s;
    for (int k = 0; k < 200; k++) {
        double mid = 0.5 * (lo + hi);
        if (trace(mid, &P, &S, &cb, &s) == 0 && s < na)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

static void closed_form(double na, double *h, double *leak, double *rim)
{
    double P, S, cb, s, cr = 0, pa = 0;
    *h = height_of(na);
    for (int i = 0; i < RINGS; i++) {
        trace(*h * sqrt((i + 0.5) / RINGS), &P, &S, &cb, &s);
        for (int k = 0; k < AZIMUTHS; k++) {
            double phi = 2 * PI * (k + 0.5) / AZIMUTHS, c = cos(phi), sn = sin(phi);
            cr += pow(0.5 * sin(2 * phi) * (P * cb - S), 2);
            pa += pow(P * c * c * cb + S * sn * sn, 2);
        }
    }
    *leak = cr / pa;
    trace(*h, &P, &S, &cb, &s);
    double c2 = 0.5; /* cos^2 45 = sin^2 45 */
    *rim = pow(0.5 * (P * cb - S), 2) / pow(P * c2 * cb + S * c2, 2);
}

typedef struct { double na, h, lt, lp, rt, rp; } row;

static int run(const char *scene_path, const char *step, const char *na_max, const char *csv,
               const char *png, row *rows, int max_rows)
{
    const char *args[] = {"--scene", scene_path, "--step", step, "--na-max", na_max,
                          "--rings", "6", "--azimuths", "8", "--csv", csv, "--png", png, NULL};
    tp_result r;
    if (tp_run(LP_BIN_DIR "/extinction_na", args, NULL, &r) != 0) {
        fprintf(stderr, "extinction_na: %s\n", r.error);
        return -1;
    }
    int n = -1;
    if (r.status != 0) {
        fprintf(stderr, "extinction_na: status %d: %s\n", r.status, r.err);
    } else {
        printf("%s", r.out);
        size_t len;
        char *text = tf_read(csv, &len);
        n = 0;
        for (char *line = text ? strchr(text, '\n') : NULL; line && n < max_rows;
             line = strchr(line + 1, '\n')) {
            row *w = &rows[n];
            if (sscanf(line + 1, "%lf,%lf,%lf,%lf,%lf,%lf", &w->na, &w->h, &w->lt, &w->lp, &w->rt,
                       &w->rp) == 6)
                n++;
        }
        free(text);
    }
    tp_result_free(&r);
    return n;
}

static void test_against_closed_form(void)
{
    const char *sp = LP_TEST_TMP "/extinction_test.scene";
    const char *csv = LP_TEST_TMP "/extinction_test.csv", *png = LP_TEST_TMP "/extinction_test.png";
    row rows[16];
    CHECK(tf_write(sp, scene, strlen(scene)) == 0, "writes the test scene");
    int n = run(sp, "0.05", "0.25", csv, png, rows, 16);
    CHECK(n == 5, "five points (%d)", n);
    CHECK(tf_is_png(png), "the chart is a PNG");
    double worst = 0, worst_h = 0;
    for (int i = 0; i < n; i++) {
        double h, leak, rim;
        closed_form(rows[i].na, &h, &leak, &rim);
        double el = fabs(rows[i].lt - leak) / leak, er = fabs(rows[i].rt - rim) / rim;
        printf("NA %.2f: h %.6f (closed form %.6f); leak traced %.6e closed form %.6e (%.2g); "
               "rim ray %.6e vs %.6e (%.2g)\n",
               rows[i].na, rows[i].h, h, rows[i].lt, leak, el, rows[i].rt, rim, er);
        /* measured: 7.2e-13 relative at worst, heights to 6.2e-13 mm: both
         * sides exact, the rounding of P - S (~1e-3 of P at NA 0.05) and
         * the bisections' stop at 1e-13 of the height */
        CHECK(el <= 1e-11, "NA %.2f: aperture leak %.9g, closed form %.9g", rows[i].na, rows[i].lt,
              leak);
        CHECK(er <= 1e-11, "NA %.2f: rim ray %.9g, closed form %.9g", rows[i].na, rows[i].rt, rim);
        CHECK(fabs(rows[i].h - h) <= 1e-11, "NA %.2f: height %.12g, closed form %.12g", rows[i].na,
              rows[i].h, h);
        worst = fmax(worst, fmax(el, er));
        worst_h = fmax(worst_h, fabs(rows[i].h - h));
    }
    printf("test instrument: worst relative difference from the closed form %.3g, heights %.3g mm\n",
           worst, worst_h);
}

static void test_shipped_microscope(void)
{
    const char *csv = LP_TEST_TMP "/extinction_shipped.csv";
    const char *png = LP_TEST_TMP "/extinction_shipped.png";
    row rows[8];
    int n = run(LP_SOURCE_DIR "/scenes/microscope/microscope_empty.scene", "0.02", "0.1", csv, png,
                rows, 8);
    CHECK(n == 5, "five points (%d)", n);
    if (n < 2)
        return;
    for (int i = 0; i < n; i++)
        /* measured 5.8e-12 at worst (at NA 0.02, where P - S is 3e-5 of P:
         * rounding 1e-16 / 3e-5); the glass's absorption is in both */
        CHECK(fabs(rows[i].lt - rows[i].lp) <= 5e-11 * rows[i].lp,
              "NA %.2f: traced %.9g, predicted %.9g", rows[i].na, rows[i].lt, rows[i].lp);
    /* (P - S)^2 ~ theta^4: from NA 0.02 to 0.04, x 16 (measured 16.04:
     * the next order, ~(1 + c NA^2)) */
    double ratio = rows[1].lt / rows[0].lt;
    CHECK(fabs(ratio / 16 - 1) < 0.01, "the leak grows as NA^4: x %.4g from 0.02 to 0.04", ratio);
    printf("shipped microscope: leak at NA 0.02 %.4g, 0.04 %.4g: ratio %.4f\n", rows[0].lt,
           rows[1].lt, ratio);
}

/* Bad input: a usage error exits 2, a scene that is no empty instrument
 * exits 1, each with one line naming the problem. */
static void test_refusals(void)
{
    static const struct {
        const char *args[8];
        int status;
        const char *says;
    } cases[] = {
        {{"--lambda", "100", NULL}, 2, "--lambda"},
        {{"--rings", "0", NULL}, 2, "--rings"},
        {{"--azimuths", "4", NULL}, 2, "--azimuths"},
        {{"--bogus", "1", NULL}, 2, "unknown option"},
        {{"--step", NULL}, 2, "needs a value"},
        {{"--scene", LP_SOURCE_DIR "/scenes/microscope/microscope.scene", NULL}, 1, "crystal"},
        {{"--scene", LP_SOURCE_DIR "/scenes/conoscope.scene", NULL}, 1, "crystal"},
        {{"--scene", LP_SOURCE_DIR "/scenes/default.scene", NULL}, 1, "0 polarizers"},
        {{"--scene", LP_TEST_TMP "/no_such.scene", NULL}, 1, "no_such.scene"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        tp_result r;
        if (tp_run(LP_BIN_DIR "/extinction_na", cases[k].args, NULL, &r) != 0) {
            CHECK(0, "runs: %s", r.error);
            continue;
        }
        CHECK(r.status == cases[k].status && strstr(r.err, cases[k].says) != NULL &&
                  strchr(r.err, '\n') == r.err + strlen(r.err) - 1,
              "%s %s: status %d (want %d), says '%s' (want '%s' on one line)", cases[k].args[0],
              cases[k].args[1] ? cases[k].args[1] : "", r.status, cases[k].status, r.err,
              cases[k].says);
        tp_result_free(&r);
    }
}

int main(void)
{
    test_refusals();
    test_against_closed_form();
    test_shipped_microscope();
    return check_finish("test_extinction");
}
