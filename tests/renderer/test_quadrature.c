/* test_quadrature.c -- the spectral quadrature (quadrature.h) against a
 * closed form: a diffuse coloured plane lit head-on by a coloured light,
 * seen along the light's axis (one pixel), two colour pairs.
 *
 * The exact pixel, written here: with L(lambda) = rho(lambda) e(lambda)
 * (the pigment's Smits reflectance times the light's emission; diffuse
 * 1, cos 1), X = integral over 380-780 nm of L cmf and X_j the same of
 * the unit emitter of channel j, the renderer's pixel converges to the P
 * with X = sum_j P_j X_j (emitters exact: integrator.c's colour
 * correction).  The integrals are exact here: on every 1 nm interval
 * [n, n+1] the integrand is a quadratic (the colour-matching table is
 * linear between its 1 nm rows, D65 between its 5 nm rows, Smits'
 * spectra constant between their edges 414, 448 ... 686 nm, all whole
 * nm), and 2-point Gauss-Legendre, exact for cubics, integrates it
 * without touching the edges.
 *
 * The bound: the midpoint rule on a cell [a, b] of width h errs by the
 * integral of K f'' with the Peano kernel 0 <= K <= h^2 / 8, so by at
 * most h^2 / 8 times the total variation of f' on the cell, wherever f
 * is continuous there (no step) and f' of bounded variation.  The rule's
 * pixel is p_N = C_N^-1 M X_N (M: XYZ -> linear sRGB, C_N's columns
 * M X_N,j), so exactly p_N - P = C_N^-1 M E_N[g], E_N[g] the rule's error
 * on g = (rho e - sum_j P_j e_j) cmf, whose integral is 0: the colour
 * correction cancels what the plane shares with the emitter of its
 * colour, and the bound is taken on what is left (per channel, summed
 * over the cells, then through |C_N^-1 M|, computed here from this
 * file's own midpoint sums).  The render at N >= 10 wavelengths must be
 * within it, in the fresnel and polarized models (measured 0.03-0.07 of
 * it), and equal this file's midpoint sum on the renderer's cells
 * (rs_quadrature, checked to tile 380-780 nm with no step strictly
 * inside a cell).  The rule before, N equal bands (computed here), holds
 * steps in its bands: its error breaks the bound the same integrand
 * would give were it smooth there (no bound for it) from N = 100 on,
 * which shows the bound is no formality; at N = 400, 1 nm bands whose
 * edges are the steps, it keeps it.  Orders: from the errors at N = 40
 * ... 640 the render's falls as N^-2 (fitted order >= 1.8), the equal
 * bands' as N^-1 (<= 1.3).
 *
 * Tolerances: the bound itself (rigorous; 1e-12 for rounding); the
 * layout to 1e-9 nm; the render equals the midpoint sum on its cells to
 * 1e-12 (the same arithmetic in another order). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "mat3.h"
#include "emitter.h"
#include "one_pixel.h"
#include "quadrature.h"

#define LMIN 380.0
#define LMAX 780.0
#define MAX_N 1024

/* Smits (1999): 10 bins of (720 - 380) / 10 = 34 nm from 380 nm, the
 * first held below, the last above: steps at the 9 inner edges. */
static const double STEPS[9] = {414, 448, 482, 516, 550, 584, 618, 652, 686};

/* The case: the plane's pigment and the light's colour. */
static rs_color PIGMENT, LIGHT;

/* The exact pixel, once known (the integrand of kind 4 needs it). */
static double P[3];

/* The integrand of channel c: kind 0 the lit plane (rho e cmf_c), kind
 * 1 + j the unit emitter of channel j (e_j cmf_c), kind 4 the difference
 * of the lit plane and the emitter of its exact pixel's colour,
 * (rho e - sum_j P_j e_j) cmf_c, whose integral is 0. */
static double integrand(int kind, int c, double l)
{
    double cmf[3], e;
    rs_cmf(l, cmf);
    if (kind == 4) {
        e = integrand(0, c, l);
        for (int j = 0; j < 3; j++)
            e -= P[j] * integrand(1 + j, c, l);
        return e;
    }
    if (kind == 0) {
        rs_spectrum s = {RS_SPECTRUM_RGB, LIGHT, 0.0, 0.0};
        e = rs_reflectance(PIGMENT, l) * rs_spectrum_emission(&s, l);
    } else {
        rs_color u = {kind == 1, kind == 2, kind == 3};
        rs_spectrum s = {RS_SPECTRUM_RGB, u, 0.0, 0.0};
        e = rs_spectrum_emission(&s, l);
    }
    return e * cmf[c];
}

/* The exact integral over [LMIN, LMAX]: 2-point Gauss-Legendre on each
 * 1 nm interval. */
static double exact(int kind, int c)
{
    const double g = 0.5 / sqrt(3.0);
    double s = 0.0;
    for (double n = LMIN; n < LMAX; n += 1.0)
        s += 0.5 * (integrand(kind, c, n + 0.5 - g) + integrand(kind, c, n + 0.5 + g));
    return s;
}

/* The quadratic q(x) = a0 + a1 (x - n - 0.5) + a2 (x - n - 0.5)^2 that is
 * the integrand on [n, n + 1], from three inner points. */
static void quadratic(int kind, int c, double n, double a[3])
{
    double fm = integrand(kind, c, n + 0.25), f0 = integrand(kind, c, n + 0.5);
    double fp = integrand(kind, c, n + 0.75);
    a[0] = f0;
    a[1] = (fp - fm) / 0.5;
    a[2] = (fp - 2.0 * f0 + fm) / (2.0 * 0.0625);
}

static int holds_step(double a, double b)
{
    for (int k = 0; k < 9; k++)
        if (STEPS[k] > a + 1e-9 && STEPS[k] < b - 1e-9)
            return 1;
    return 0;
}

/* The total variation of f' on [a, b]: inside each 1 nm interval f' is
 * linear (variation 2 |a2| per nm), at each whole nm strictly inside it
 * jumps.  smooth = 1 ignores Smits' steps (the jump of f itself): what
 * the bound would be were the integrand smooth there. */
static double slope_tv(int kind, int c, double a, double b)
{
    double tv = 0.0, q[3], prev[3] = {0, 0, 0};
    int have = 0;
    for (double n = floor(a); n < b; n += 1.0) {
        double u = fmax(a, n), v = fmin(b, n + 1.0);
        if (v <= u)
            continue;
        quadratic(kind, c, n, q);
        tv += 2.0 * fabs(q[2]) * (v - u);
        if (have && u == n) /* the kink at n, between [n-1, n] and [n, n+1] */
            tv += fabs((q[1] - q[2]) - (prev[1] + prev[2]));
        memcpy(prev, q, sizeof q);
        have = 1;
    }
    return tv;
}

/* The midpoint sum on cells (lambda, w), and its bound sum h^2/8 TV(f'). */
static double midpoint(int kind, int c, const double *lambda, const double *w, int n)
{
    double s = 0.0;
    for (int k = 0; k < n; k++)
        s += w[k] * integrand(kind, c, lambda[k]);
    return s;
}

static double bound(int kind, int c, const double *lambda, const double *w, int n)
{
    double b = 0.0;
    for (int k = 0; k < n; k++)
        b += w[k] * w[k] / 8.0 * slope_tv(kind, c, lambda[k] - 0.5 * w[k], lambda[k] + 0.5 * w[k]);
    return b;
}

static void xyz_to_rgb(const double x[3], double out[3])
{
    rs_color c;
    rs_xyz_to_linear_srgb(x, &c);
    out[0] = c.r, out[1] = c.g, out[2] = c.b;
}

/* The exact pixel P: X = sum_j P_j X_j, the emitters' integrals. */
static void make_truth(void)
{
    double x[3], rgb[3], C[3][3], Ci[3][3];
    for (int j = 0; j < 3; j++) {
        for (int c = 0; c < 3; c++)
            x[c] = exact(1 + j, c);
        xyz_to_rgb(x, rgb);
        for (int r = 0; r < 3; r++)
            C[r][j] = rgb[r];
    }
    mat3_invert(C, Ci);
    for (int c = 0; c < 3; c++)
        x[c] = exact(0, c);
    xyz_to_rgb(x, rgb);
    for (int r = 0; r < 3; r++)
        P[r] = Ci[r][0] * rgb[0] + Ci[r][1] * rgb[1] + Ci[r][2] * rgb[2];
}

/* The pixel of the midpoint rule on cells (lambda, w), computed here, and
 * the bound on its distance from P.  With X_N, C_N the rule's sums,
 *     p_N - P = C_N^-1 M (X_N - sum_j P_j X_N,j) = C_N^-1 M E_N[g],
 * E_N[g] the rule's error on the integrand of kind 4 (its integral is
 * 0), so |p_N - P|_r <= sum_c |C_N^-1 M|_rc bound_c(g). */
static double rule_pixel(const double *lambda, const double *w, int n, double p[3])
{
    double x[3], rgb[3], C[3][3], Ci[3][3], CiM[3][3], b[3], worst = 0.0;
    for (int j = 0; j < 3; j++) {
        for (int c = 0; c < 3; c++)
            x[c] = midpoint(1 + j, c, lambda, w, n);
        xyz_to_rgb(x, rgb);
        for (int r = 0; r < 3; r++)
            C[r][j] = rgb[r];
    }
    mat3_invert(C, Ci);
    for (int c = 0; c < 3; c++) {
        double u[3] = {c == 0, c == 1, c == 2};
        xyz_to_rgb(u, rgb); /* column c of M */
        for (int r = 0; r < 3; r++)
            CiM[r][c] = Ci[r][0] * rgb[0] + Ci[r][1] * rgb[1] + Ci[r][2] * rgb[2];
        x[c] = midpoint(0, c, lambda, w, n);
        b[c] = bound(4, c, lambda, w, n);
    }
    xyz_to_rgb(x, rgb);
    for (int r = 0; r < 3; r++) {
        p[r] = Ci[r][0] * rgb[0] + Ci[r][1] * rgb[1] + Ci[r][2] * rgb[2];
        worst = fmax(worst, fabs(CiM[r][0]) * b[0] + fabs(CiM[r][1]) * b[1] +
                                fabs(CiM[r][2]) * b[2]);
    }
    return worst;
}

static double dist(const double a[3], const double b[3])
{
    return fmax(fabs(a[0] - b[0]), fmax(fabs(a[1] - b[1]), fabs(a[2] - b[2])));
}

/* The renderer's pixel at n wavelengths in mode m. */
static int render(rs_mode m, int n, double p[3])
{
    char text[512];
    rs_color c;
    snprintf(text, sizeof text,
             "camera { location <0,0,-5> look_at <0,0,0> angle 5 }\n"
             "light_source { <0,0,-100> color rgb <%.17g, %.17g, %.17g> }\n"
             "plane { z, 0 pigment { color rgb <%.17g, %.17g, %.17g> }\n"
             "        finish { ambient 0 diffuse 1 } }\n",
             LIGHT.r, LIGHT.g, LIGHT.b, PIGMENT.r, PIGMENT.g, PIGMENT.b);
    if (one_pixel(text, m, n, &c) != 0)
        return -1;
    p[0] = c.r, p[1] = c.g, p[2] = c.b;
    return 0;
}

/* The renderer's cells: N of them, contiguous from 380 to 780 nm, nodes
 * at their midpoints, no step inside. */
static void check_layout(int n, const double *lambda, const double *w)
{
    double a = LMIN;
    int inside = 0;
    for (int k = 0; k < n; k++) {
        CHECK(w[k] > 0.0, "N = %d: cell %d has width %g", n, k, w[k]);
        CHECK_ABS(lambda[k] - 0.5 * w[k], a, 1e-9, "N = %d: cell %d starts where %d ends", n, k,
                  k - 1);
        inside += holds_step(lambda[k] - 0.5 * w[k], lambda[k] + 0.5 * w[k]);
        a = lambda[k] + 0.5 * w[k];
    }
    CHECK_ABS(a, LMAX, 1e-9, "N = %d: the cells end at 780 nm", n);
    CHECK(inside == 0, "N = %d: %d cells hold a step of Smits' spectra", n, inside);
}

static double order(const double *n, const double *e, int k)
{
    /* least-squares slope of log e against log n, negated */
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i < k; i++) {
        double x = log(n[i]), y = log(e[i]);
        sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    return -(k * sxy - sx * sy) / (k * sxx - sx * sx);
}

static void equal_bands(int n, double *lambda, double *w)
{
    for (int k = 0; k < n; k++) {
        w[k] = (LMAX - LMIN) / n;
        lambda[k] = LMIN + w[k] * (k + 0.5);
    }
}

static void one_case(void)
{
    static double lambda[MAX_N], w[MAX_N];
    static const int counts[] = {10, 11, 16, 20, 32, 40, 64, 100, 128, 256, 400};
    static const int ladder[] = {40, 80, 160, 320, 640};
    make_truth();
    printf("pigment (%g %g %g), light (%g %g %g): exact pixel (%.9f %.9f %.9f)\n", PIGMENT.r,
           PIGMENT.g, PIGMENT.b, LIGHT.r, LIGHT.g, LIGHT.b, P[0], P[1], P[2]);

    /* The renderer at N >= 10: within the bound, in two models. */
    for (size_t i = 0; i < sizeof counts / sizeof *counts; i++) {
        int n = counts[i];
        double mine[3], got[3];
        rs_quadrature(n, lambda, w);
        check_layout(n, lambda, w);
        double b = rule_pixel(lambda, w, n, mine);
        for (int m = 0; m < 2; m++) {
            rs_mode mode = m ? RS_MODE_POLARIZED : RS_MODE_FRESNEL;
            if (render(mode, n, got) != 0) {
                CHECK(0, "N = %d: the scene renders", n);
                continue;
            }
            double err = dist(got, P);
            CHECK(err <= b + 1e-12, "N = %d, %s: error %.3g over the bound %.3g", n,
                  m ? "polarized" : "fresnel", err, b);
            CHECK(dist(got, mine) <= 1e-12, "N = %d, %s: the render is the midpoint rule on "
                  "its cells (off by %.3g)", n, m ? "polarized" : "fresnel", dist(got, mine));
            if (m == 0)
                printf("  N = %3d cells:       error %.3e, bound %.3e (%.2f of it)\n", n, err, b,
                       err / b);
        }
    }

    /* The rule before: where its equal bands hold steps its error falls
     * as 1/N, the smooth bound as 1/N^2: from N = 100 on it breaks the
     * bound (measured: 0.7-1.3 of it at 32-64, 2.2-15 at 100-256); at 400
     * bands of 1 nm the steps are band edges and it keeps the bound. */
    for (size_t i = 0; i < sizeof counts / sizeof *counts; i++) {
        int n = counts[i], steps = 0;
        double p[3];
        equal_bands(n, lambda, w);
        for (int k = 0; k < n; k++)
            steps += holds_step(lambda[k] - 0.5 * w[k], lambda[k] + 0.5 * w[k]);
        double b = rule_pixel(lambda, w, n, p), err = dist(p, P);
        printf("  N = %3d equal bands: error %.3e, smooth bound %.3e (%.2f of it), %d bands "
               "hold a step\n", n, err, b, err / b, steps);
        if (steps == 0)
            CHECK(err <= b + 1e-12, "N = %d equal bands, no step inside: error %.3g over the "
                  "bound %.3g", n, err, b);
        else if (n >= 100)
            CHECK(err > b, "N = %d equal bands: error %.3g within the smooth bound %.3g", n,
                  err, b);
    }

    /* Orders of convergence. */
    {
        double ns[5], er[5], eq[5];
        for (int i = 0; i < 5; i++) {
            double got[3], p[3];
            int n = ladder[i];
            ns[i] = n;
            er[i] = render(RS_MODE_FRESNEL, n, got) == 0 ? dist(got, P) : NAN;
            equal_bands(n, lambda, w);
            rule_pixel(lambda, w, n, p);
            eq[i] = dist(p, P);
        }
        double pr = order(ns, er, 5), pe = order(ns, eq, 5);
        printf("  order of convergence, N = 40 .. 640: cells %.2f, equal bands %.2f\n", pr, pe);
        CHECK(pr >= 1.8, "the render's error falls as N^-%.2f, not N^-2", pr);
        CHECK(pe <= 1.3, "the equal bands' error falls as N^-%.2f, faster than N^-1", pe);
    }
}

int main(void)
{
    static const rs_color cases[][2] = {
        {{0.2, 0.7, 0.4}, {1.0, 0.8, 0.5}}, /* a green plane, a warm light */
        {{0.9, 0.1, 0.3}, {0.3, 0.6, 1.0}}, /* a red plane, a blue light */
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        PIGMENT = cases[i][0];
        LIGHT = cases[i][1];
        one_case();
    }
    return check_finish("test_quadrature");
}
