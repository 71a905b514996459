/* test_spectrum.c -- the colorimetry of the spectral modes (emitter.h, support/colorimetry.h).
 *
 * Expected values come from published tables and standards, written here:
 *   - CIE 1931 2-degree observer, 5 nm abridged table (CIE 15:2004 Table
 *     T.4): x̄ ȳ z̄ at 380, 445, 500, 555, 600, 700, 780 nm; and the CIE's
 *     published sums of the 1 nm table, 360-830 nm:
 *     106.865469489595, 106.856917101172, 106.892251278636.
 *   - D65 (CIE 15:2004 Table T.1) at 300, 460, 560, 830 nm, and its white
 *     point for the 1931 observer at 1 nm, X = 95.047, Z = 108.883
 *     (ASTM E308 / CIE 15), i.e. (0.9505, 1, 1.089).
 *   - sRGB (IEC 61966-2-1): the printed matrices, the white point
 *     (0.3127, 0.3290), the transfer function's knee 0.0031308 -> 0.04045
 *     and 0.5 -> 0.735357 (= 1.055 * 0.5^(1/2.4) - 0.055).
 *   - Planck's law: Wien's displacement constant b = 2.897771955e-3 m K
 *     and the Stefan-Boltzmann constant sigma = 5.670374419e-8 W m^-2 K^-4
 *     (CODATA 2018); CIE illuminant A, a black body of 2848 K with the
 *     old c2 = 1.435e-2 m K (= 2855.50 K with c2 = 1.438776877e-2), has
 *     chromaticity (0.44757, 0.40745) (CIE 15:2004).
 *
 * Tolerances: table values 1e-6 absolute (the 5 nm table prints six
 * decimals); sums 1e-12 relative (rounding of 471 additions); sRGB
 * matrices 5e-5 (the standard prints four decimals, so half a unit of the
 * last digit) and 5e-4 for the printed inverse (it is the inverse of the
 * rounded forward matrix); D65 white 2e-5 (five printed digits); emitter
 * white 1e-3 (the brief's bound; the 380-780 nm band leaves about 5e-4);
 * illuminant A 5e-5 (the band again); Smits' round trips 0.05 (Smits'
 * method is approximate: its basis spectra were fitted to about this; the
 * worst channel measured is printed).  The renderer's colour correction
 * (a directly seen RGB emitter renders as exactly its RGB) is checked
 * through the integrator to the rounding its 3x3 matrix allows. */
#include <float.h>
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "emitter.h"
#include "integrator.h"
#include "one_pixel.h"

static rs_color rgb(double r, double g, double b)
{
    rs_color c = {r, g, b};
    return c;
}

static rs_spectrum spec_rgb(double r, double g, double b)
{
    rs_spectrum s = {RS_SPECTRUM_RGB, {r, g, b}, 0.0, 0.0};
    return s;
}

/* The estimator of emitter.h with N midpoint-stratified wavelengths. */
static void estimate_xyz(const rs_spectrum *s, int n, double xyz[3])
{
    double norm = rs_spectrum_norm(s);

    xyz[0] = xyz[1] = xyz[2] = 0.0;
    for (int i = 0; i < n; i++) {
        double l = RS_LAMBDA_MIN + (RS_LAMBDA_MAX - RS_LAMBDA_MIN) * (i + 0.5) / n;
        rs_xyz_accumulate(xyz, rs_spectrum_emission_norm(s, norm, l), l,
                          (RS_LAMBDA_MAX - RS_LAMBDA_MIN) / n);
    }
}

static void test_cmf_table(void)
{
    /* CIE 15:2004 Table T.4 (5 nm), six decimals. */
    static const struct { double l, x, y, z; } pub[] = {
        {380, 0.001368, 0.000039, 0.006450},
        {445, 0.348060, 0.029800, 1.782600},
        {500, 0.004900, 0.323000, 0.272000},
        {555, 0.512050, 1.000000, 0.005750},
        {600, 1.062200, 0.631000, 0.000800},
        {700, 0.011359, 0.004102, 0.000000},
        {780, 0.000042, 0.000015, 0.000000},
    };
    const double sums[3] = {106.865469489595, 106.856917101172,
                            106.892251278636};
    double c[3], a[3], b[3], s[3] = {0, 0, 0}, integ[3] = {0, 0, 0};

    for (size_t i = 0; i < sizeof pub / sizeof pub[0]; i++) {
        rs_cmf(pub[i].l, c);
        CHECK_ABS(c[0], pub[i].x, 1e-6, "xbar(%g)", pub[i].l);
        CHECK_ABS(c[1], pub[i].y, 1e-6, "ybar(%g)", pub[i].l);
        CHECK_ABS(c[2], pub[i].z, 1e-6, "zbar(%g)", pub[i].l);
    }
    rs_cmf(555.0, c);
    CHECK(c[1] == 1.0, "ybar(555) = %.17g, want exactly 1", c[1]);

    /* Linear interpolation between the 1 nm rows. */
    rs_cmf(555.25, c);
    rs_cmf(555.0, a);
    rs_cmf(556.0, b);
    for (int k = 0; k < 3; k++)
        CHECK_ABS(c[k], 0.75 * a[k] + 0.25 * b[k], 1e-15, "cmf(555.25)[%d]", k);

    /* Zero outside 360-830 nm (and for NaN). */
    rs_cmf(359.9, c);
    CHECK(c[0] == 0 && c[1] == 0 && c[2] == 0, "cmf(359.9) not 0");
    rs_cmf(830.1, c);
    CHECK(c[0] == 0 && c[1] == 0 && c[2] == 0, "cmf(830.1) not 0");
    rs_cmf(NAN, c);
    CHECK(c[0] == 0 && c[1] == 0 && c[2] == 0, "cmf(NaN) not 0");
    rs_cmf(830.0, c);
    CHECK(c[0] > 0 && c[1] > 0, "cmf(830) is the last row, not 0");

    /* The CIE's published 1 nm sums: the whole table is as published. */
    for (int l = 360; l <= 830; l++) {
        rs_cmf(l, c);
        for (int k = 0; k < 3; k++)
            s[k] += c[k];
    }
    for (int k = 0; k < 3; k++)
        CHECK_REL(s[k], sums[k], 1e-12, "1 nm sum of cmf[%d] 360-830", k);

    /* The integrals over 360-830 nm (fine midpoint rule on the
     * interpolant): the sums less half the end values (trapezoid rule, exact
     * for a piecewise linear function), i.e. 106.86... */
    for (int i = 0; i < 470 * 20; i++) {
        double l = 360.0 + (i + 0.5) / 20.0;
        rs_cmf(l, c);
        for (int k = 0; k < 3; k++)
            integ[k] += c[k] / 20.0;
    }
    rs_cmf(360.0, a);
    rs_cmf(830.0, b);
    for (int k = 0; k < 3; k++) {
        CHECK_REL(integ[k], sums[k] - 0.5 * (a[k] + b[k]), 1e-9,
                  "integral of cmf[%d] 360-830", k);
        CHECK_REL(integ[k], sums[k], 1e-5, "integral of cmf[%d] ~ 106.86", k);
    }
}

static void test_d65(void)
{
    double s[3] = {0, 0, 0}, c[3], k = 0.0;

    CHECK_ABS(rs_d65(300.0), 0.0341, 1e-12, "D65(300)");
    CHECK_ABS(rs_d65(460.0), 117.812, 1e-12, "D65(460)");
    CHECK_ABS(rs_d65(560.0), 100.0, 1e-12, "D65(560)");
    CHECK_ABS(rs_d65(830.0), 60.3125, 1e-12, "D65(830)");
    CHECK_ABS(rs_d65(562.5), 0.5 * (100.0 + 98.1671), 1e-12, "D65(562.5)");
    CHECK(rs_d65(299.0) == 0.0 && rs_d65(831.0) == 0.0 && rs_d65(NAN) == 0.0,
          "D65 outside 300-830 not 0");

    /* White point with the 1 nm observer, 360-830 nm. */
    for (int l = 360; l <= 830; l++) {
        rs_cmf(l, c);
        for (int q = 0; q < 3; q++)
            s[q] += rs_d65(l) * c[q];
    }
    CHECK_ABS(100.0 * s[0] / s[1], 95.047, 2e-3, "D65 X (Y = 100)");
    CHECK_ABS(100.0 * s[2] / s[1], 108.883, 2e-3, "D65 Z (Y = 100)");

    /* K: Simpson's rule on each 1 nm interval is exact for the product of
     * the two piecewise-linear interpolants. */
    for (int l = 380; l < 780; l++) {
        double y0, ym, y1;
        rs_cmf(l, c);
        y0 = c[1] * rs_d65(l);
        rs_cmf(l + 0.5, c);
        ym = c[1] * rs_d65(l + 0.5);
        rs_cmf(l + 1, c);
        y1 = c[1] * rs_d65(l + 1);
        k += (y0 + 4.0 * ym + y1) / 6.0;
    }
    CHECK_REL(1.0 / rs_spectral_normalization(), k, 1e-12, "K = int D65 ybar");
}

static void test_srgb_matrices(void)
{
    /* IEC 61966-2-1 as printed. */
    static const double fwd[3][3] = {{0.4124, 0.3576, 0.1805},
                                     {0.2126, 0.7152, 0.0722},
                                     {0.0193, 0.1192, 0.9505}};
    static const double inv[3][3] = {{3.2406, -1.5372, -0.4986},
                                     {-0.9689, 1.8758, 0.0415},
                                     {0.0557, -0.2040, 1.0570}};
    static const rs_color samples[] = {{0.2, 0.5, 0.9}, {1, 0, 0}, {0, 0, 1},
                                       {0.01, 0.99, 0.3}, {2.5, -0.1, 0.7}};
    double xyz[3];
    rs_color c;

    for (int j = 0; j < 3; j++) {
        rs_color e = rgb(j == 0, j == 1, j == 2);
        rs_linear_srgb_to_xyz(&e, xyz);
        for (int i = 0; i < 3; i++)
            CHECK_ABS(xyz[i], fwd[i][j], 5e-5, "sRGB->XYZ [%d][%d]", i, j);
    }
    for (int j = 0; j < 3; j++) {
        double u[3] = {j == 0, j == 1, j == 2};
        double got[3];
        rs_xyz_to_linear_srgb(u, &c);
        got[0] = c.r;
        got[1] = c.g;
        got[2] = c.b;
        for (int i = 0; i < 3; i++)
            CHECK_ABS(got[i], inv[i][j], 5e-4, "XYZ->sRGB [%d][%d]", i, j);
    }
    /* White (1,1,1) is the D65 white point of the standard. */
    c = rgb(1, 1, 1);
    rs_linear_srgb_to_xyz(&c, xyz);
    CHECK_ABS(xyz[0], 0.3127 / 0.3290, 1e-12, "sRGB white X");
    CHECK_ABS(xyz[1], 1.0, 1e-12, "sRGB white Y");
    CHECK_ABS(xyz[2], (1.0 - 0.3127 - 0.3290) / 0.3290, 1e-12, "sRGB white Z");
    /* Round trips. */
    for (size_t i = 0; i < sizeof samples / sizeof samples[0]; i++) {
        rs_color back;
        rs_linear_srgb_to_xyz(&samples[i], xyz);
        rs_xyz_to_linear_srgb(xyz, &back);
        CHECK_ABS(back.r, samples[i].r, 1e-14, "round trip %zu r", i);
        CHECK_ABS(back.g, samples[i].g, 1e-14, "round trip %zu g", i);
        CHECK_ABS(back.b, samples[i].b, 1e-14, "round trip %zu b", i);
    }
    CHECK_ABS(rs_luminance(rgb(1, 1, 1)), 1.0, 1e-15, "luminance of white");
    CHECK_ABS(rs_luminance(rgb(0, 1, 0)), 0.7152, 1e-15, "luminance of green");
}

static void test_transfer(void)
{
    double knee_lo = 12.92 * 0.0031308;
    double knee_hi = 1.055 * pow(0.0031308, 1.0 / 2.4) - 0.055;

    CHECK_ABS(rs_srgb_encode(0.0031308), 0.04045, 1e-6, "encode(0.0031308)");
    CHECK_ABS(rs_srgb_encode(0.5), 0.735357, 1e-6, "encode(0.5)");
    CHECK_ABS(rs_srgb_encode(0.18), 0.461356, 1e-6, "encode(0.18)");
    CHECK_ABS(rs_srgb_encode(0.001), 0.01292, 1e-12, "encode(0.001)");
    CHECK(rs_srgb_encode(0.0) == 0.0 && rs_srgb_encode(1.0) == 1.0,
          "encode(0), encode(1)");
    CHECK(rs_srgb_encode(-0.5) == 0.0 && rs_srgb_encode(7.0) == 1.0
              && rs_srgb_encode(NAN) == 0.0,
          "encode clamps to [0,1], NaN -> 0");
    CHECK_ABS(knee_lo, knee_hi, 1e-7, "the two branches meet at the knee");
    for (int i = 0; i <= 1000; i++) {
        double v = i / 1000.0;
        CHECK_ABS(rs_srgb_decode(rs_srgb_encode(v)), v, 1e-12, "decode(encode(%g))", v);
    }
    for (int i = 1; i <= 1000; i++) {
        double a = rs_srgb_encode((i - 1) / 1000.0), b = rs_srgb_encode(i / 1000.0);
        CHECK(b > a, "encode not increasing at %d", i);
    }
}

/* Golden-section search for the maximum of planck(T, .) in [a, b] nm. */
static double planck_peak(double t, double a, double b)
{
    const double r = (sqrt(5.0) - 1.0) / 2.0;
    double c = b - r * (b - a), d = a + r * (b - a);

    while (b - a > 1e-7) {
        if (rs_planck(t, c) > rs_planck(t, d))
            b = d;
        else
            a = c;
        c = b - r * (b - a);
        d = a + r * (b - a);
    }
    return 0.5 * (a + b);
}

static void test_planck(void)
{
    static const double temps[] = {1000, 2856, 3000, 5778, 6500, 10000, 20000};
    const double wien_b_nm = 2.897771955e6;        /* nm K */
    const double sigma = 5.670374419e-8;           /* W m^-2 K^-4 */

    for (size_t i = 0; i < sizeof temps / sizeof temps[0]; i++) {
        double t = temps[i], want = wien_b_nm / t;
        CHECK_ABS(planck_peak(t, 0.3 * want, 3.0 * want), want, 1e-4,
                  "Wien peak at %g K", t);
    }
    /* Stefan-Boltzmann: pi * integral B dlambda = sigma T^4 (W/m^2; B is
     * per nm).  Simpson in u = ln(lambda), 10 nm .. 1 mm. */
    {
        const double t = 5778.0, a = log(10.0), b = log(1e6);
        const int n = 20000;
        double h = (b - a) / n, sum = 0.0;
        for (int i = 0; i <= n; i++) {
            double l = exp(a + i * h);
            double f = rs_planck(t, l) * l;
            sum += f * (i == 0 || i == n ? 1.0 : (i % 2 ? 4.0 : 2.0));
        }
        sum *= h / 3.0;
        CHECK_REL(3.14159265358979323846 * sum, sigma * t * t * t * t, 1e-7, "Stefan-Boltzmann");
    }
    CHECK(rs_planck(0.0, 500.0) == 0.0 && rs_planck(-5.0, 500.0) == 0.0
              && rs_planck(5000.0, 0.0) == 0.0,
          "planck of invalid input not 0");
    CHECK(rs_planck(10.0, 400.0) == 0.0, "a 10 K body is black at 400 nm");

    /* A black body emitter: Y = luminance of the tint over 380-780 nm,
     * chromaticity of the black body. */
    {
        rs_spectrum s = {RS_SPECTRUM_BLACKBODY, {1, 1, 1},
                         2848.0 * 1.438776877e-2 / 1.435e-2, 0.0};
        double xyz[3], sum;
        estimate_xyz(&s, 4000, xyz);
        CHECK_REL(xyz[1], 1.0, 1e-6, "black body Y = 1");
        sum = xyz[0] + xyz[1] + xyz[2];
        CHECK_ABS(xyz[0] / sum, 0.44757, 5e-5, "illuminant A x");
        CHECK_ABS(xyz[1] / sum, 0.40745, 5e-5, "illuminant A y");
        s.rgb = rgb(0.5, 0.2, 0.1);
        estimate_xyz(&s, 4000, xyz);
        CHECK_REL(xyz[1], rs_luminance(s.rgb), 1e-6, "black body Y = tint");
        CHECK_REL(rs_spectrum_emission(&s, 550.0),
                  rs_spectrum_emission_norm(&s, rs_spectrum_norm(&s), 550.0),
                  1e-15, "emission = emission_norm(norm)");
        s.temperature_k = 0.0;
        CHECK(rs_spectrum_norm(&s) == 0.0 && rs_spectrum_emission(&s, 500) == 0.0,
              "black body at 0 K emits nothing");
    }
}

static void test_rgb_emitter(void)
{
    rs_spectrum white = spec_rgb(1, 1, 1);
    double xyz[3];
    rs_color c;

    estimate_xyz(&white, 4000, xyz);
    CHECK_ABS(xyz[1], 1.0, 1e-3, "white emitter Y");
    CHECK_ABS(xyz[0], 0.9505, 1e-3, "white emitter X");
    CHECK_ABS(xyz[2], 1.089, 1e-3, "white emitter Z");
    rs_xyz_to_linear_srgb(xyz, &c);
    CHECK_ABS(c.r, 1.0, 1e-3, "white emitter -> sRGB r");
    CHECK_ABS(c.g, 1.0, 1e-3, "white emitter -> sRGB g");
    CHECK_ABS(c.b, 1.0, 1e-3, "white emitter -> sRGB b");
    printf("white emitter, 4000 samples: XYZ (%.6f %.6f %.6f) sRGB (%.6f %.6f %.6f)\n",
           xyz[0], xyz[1], xyz[2], c.r, c.g, c.b);


    /* Linear in the colour, also above 1. */
    {
        rs_spectrum two = spec_rgb(2, 2, 2), half = spec_rgb(0.5, 0.5, 0.5);
        rs_spectrum red = spec_rgb(1, 0, 0), red3 = spec_rgb(3, 0, 0);
        for (double l = 380; l <= 780; l += 7.3) {
            double e = rs_spectrum_emission(&white, l);
            CHECK_REL(rs_spectrum_emission(&two, l), 2 * e, 1e-15, "2x white at %g", l);
            CHECK_REL(rs_spectrum_emission(&half, l), 0.5 * e, 1e-15, "0.5x white at %g", l);
            CHECK_REL(rs_spectrum_emission(&red3, l), 3 * rs_spectrum_emission(&red, l),
                      1e-15, "3x red at %g", l);
            CHECK_ABS(e, rs_d65(l) * rs_spectral_normalization(), 1e-18,
                      "white emitter = D65 / K at %g", l);
        }
        CHECK(rs_spectrum_emission(&(rs_spectrum){RS_SPECTRUM_RGB, {0, 0, 0}, 0, 0}, 550) == 0,
              "black emitter");
    }
}

/* The renderer's colour correction (integrator.c): a pixel that sees an
 * RGB emitter directly renders as exactly that RGB in every spectral mode
 * and with any number of wavelengths >= 3 (white included); with 1 or 2
 * wavelengths colour is lost and white renders as grey 1.  Uncorrected,
 * the midpoint rule on 16 bands of 25 nm misses white by 0.0084 (green,
 * measured here): the correction must remove it.  What is left is the
 * rounding of C^-1 (C c), C the quadrature's 3x3 colour matrix: a few
 * ulps times its condition number kappa, computed here from the test's
 * own quadrature of the three unit emitters (kappa 1.07 at 100
 * wavelengths, 1.18 at 16, 788 at 3).  Tolerance 8 eps kappa max(1, c);
 * measured worst 3.4 eps kappa, 2.8e-14 absolute (at 3 wavelengths). */
static double colour_condition(int n)
{
    double C[3][3], A[3][3], nc = 0, na = 0;
    for (int k = 0; k < 3; k++) {
        rs_spectrum u = spec_rgb(k == 0, k == 1, k == 2);
        double xyz[3];
        rs_color c;
        estimate_xyz(&u, n, xyz);
        rs_xyz_to_linear_srgb(xyz, &c);
        C[0][k] = c.r;
        C[1][k] = c.g;
        C[2][k] = c.b;
    }
    double det = C[0][0] * (C[1][1] * C[2][2] - C[1][2] * C[2][1]) -
                 C[0][1] * (C[1][0] * C[2][2] - C[1][2] * C[2][0]) +
                 C[0][2] * (C[1][0] * C[2][1] - C[1][1] * C[2][0]);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
            A[r][c] = (C[r1][c1] * C[r2][c2] - C[r1][c2] * C[r2][c1]) / det;
        }
    for (int r = 0; r < 3; r++) {
        nc = fmax(nc, fabs(C[r][0]) + fabs(C[r][1]) + fabs(C[r][2]));
        na = fmax(na, fabs(A[r][0]) + fabs(A[r][1]) + fabs(A[r][2]));
    }
    return nc * na;
}
static void test_colour_correction(void)
{
    static const rs_color cols[] = {{1, 1, 1}, {0.8, 0.3, 0.1}, {0.2, 0.4, 0.6}, {3, 0, 0.5}};
    static const int counts[] = {1, 2, 3, 4, 7, 16, 100};
    static const rs_mode modes[] = {RS_MODE_POLARIZED, RS_MODE_FRESNEL, RS_MODE_SCHLICK};
    double worst = 0.0, worst_n = 0.0;
    {
        rs_spectrum white = spec_rgb(1, 1, 1);
        double xyz[3];
        rs_color c;
        estimate_xyz(&white, 16, xyz);
        rs_xyz_to_linear_srgb(xyz, &c);
        printf("white emitter, 16 samples uncorrected: sRGB (%.4f %.4f %.4f)\n", c.r, c.g, c.b);
        CHECK(fabs(c.g - 1.0) > 1e-3, "16 uncorrected samples miss white (%.4f): the "
              "correction has work to do", c.g);
    }
    for (size_t i = 0; i < sizeof cols / sizeof cols[0]; i++)
        for (size_t m = 0; m < sizeof modes / sizeof modes[0]; m++)
            for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++) {
                char text[256];
                rs_color got = {0, 0, 0}, want = cols[i];
                int n = counts[k];
                snprintf(text, sizeof text,
                         "camera { location <0,0,0> look_at <0,0,1> angle 10 }\n"
                         "background { rgb <%.17g, %.17g, %.17g> }\n",
                         want.r, want.g, want.b);
                if (one_pixel(text, modes[m], n, &got) != 0) {
                    CHECK(0, "background scene renders");
                    continue;
                }
                if (n < 3) {
                    if (i != 0)
                        continue; /* only white is promised with < 3 wavelengths */
                }
                const double g[3] = {got.r, got.g, got.b}, x[3] = {want.r, want.g, want.b};
                double kappa = n < 3 ? 1.0 : colour_condition(n);
                double big = fmax(1.0, fmax(x[0], fmax(x[1], x[2])));
                if (m == 0 && i == 0)
                    printf("colour matrix condition at %d wavelengths: %.3g\n", n, kappa);
                for (int ch = 0; ch < 3; ch++) {
                    CHECK_ABS(g[ch], x[ch], 8 * DBL_EPSILON * kappa * big,
                              "emitter (%g %g %g), mode %d, %d wavelengths: channel %d", want.r,
                              want.g, want.b, (int)modes[m], n, ch);
                    worst = fmax(worst, fabs(g[ch] - x[ch]));
                    worst_n = fmax(worst_n, fabs(g[ch] - x[ch]) / (DBL_EPSILON * kappa * big));
                }
            }
    printf("colour correction: worst channel error of a directly seen emitter %.3g "
           "(%.2g eps kappa)\n", worst, worst_n);
}

static void test_smits(void)
{
    static const struct { rs_color c; const char *name; } prim[] = {
        {{1, 0, 0}, "red"},     {{0, 1, 0}, "green"},  {{0, 0, 1}, "blue"},
        {{0, 1, 1}, "cyan"},    {{1, 0, 1}, "magenta"}, {{1, 1, 0}, "yellow"},
        {{0.8, 0.3, 0.1}, "orange"}, {{0.2, 0.4, 0.6}, "steel"},
    };
    double worst = 0.0;
    const char *worst_name = "";
    unsigned seed = 12345u;

    for (double l = 300; l <= 850; l += 2.5) {
        CHECK(rs_reflectance(rgb(1, 1, 1), l) == 1.0, "white reflects 1 at %g", l);
        CHECK(rs_reflectance(rgb(0, 0, 0), l) == 0.0, "black reflects 0 at %g", l);
        CHECK_ABS(rs_reflectance(rgb(0.5, 0.5, 0.5), l), 0.5, 1e-15, "grey at %g", l);
    }
    /* Published bins: red is 0.1012 in the first bin (380-414 nm) and
     * 1.0149 -> clamped 1 in the last ones; blue 0.8916 in 448-482 nm. */
    CHECK_ABS(rs_reflectance(rgb(1, 0, 0), 400.0), 0.1012, 1e-12, "red(400)");
    CHECK_ABS(rs_reflectance(rgb(1, 0, 0), 700.0), 1.0, 1e-12, "red(700) clamped");
    CHECK_ABS(rs_reflectance(rgb(0, 0, 1), 460.0), 0.8916, 1e-12, "blue(460)");
    CHECK_ABS(rs_reflectance(rgb(0, 0, 1), 379.0), 1.0, 1e-12, "blue below 380");
    CHECK_ABS(rs_reflectance(rgb(0, 1, 0), 800.0), 0.0025, 1e-12, "green above 720");
    /* In [0,1] for colours in [0,1]. */
    for (int i = 0; i < 20000; i++) {
        double v[4];
        for (int k = 0; k < 4; k++) {
            seed = seed * 1664525u + 1013904223u;
            v[k] = (seed >> 8) / 16777216.0;
        }
        double r = rs_reflectance(rgb(v[0], v[1], v[2]), 350.0 + 500.0 * v[3]);
        CHECK(r >= 0.0 && r <= 1.0, "reflectance %g out of [0,1]", r);
    }
    CHECK(rs_reflectance(rgb(-1, NAN, 0.5), 500) >= 0.0, "negative/NaN input");

    /* Spectrum -> XYZ (lit by D65) -> sRGB is close to the colour. */
    for (size_t i = 0; i < sizeof prim / sizeof prim[0]; i++) {
        rs_spectrum s = spec_rgb(prim[i].c.r, prim[i].c.g, prim[i].c.b);
        double xyz[3], e[3];
        rs_color c;
        estimate_xyz(&s, 4000, xyz);
        rs_xyz_to_linear_srgb(xyz, &c);
        e[0] = c.r - prim[i].c.r;
        e[1] = c.g - prim[i].c.g;
        e[2] = c.b - prim[i].c.b;
        printf("smits %-7s -> (%.4f %.4f %.4f)\n", prim[i].name, c.r, c.g, c.b);
        for (int k = 0; k < 3; k++) {
            CHECK_ABS(e[k], 0.0, 0.05, "Smits %s channel %d", prim[i].name, k);
            if (fabs(e[k]) > worst) {
                worst = fabs(e[k]);
                worst_name = prim[i].name;
            }
        }
    }
    printf("smits: worst channel error %.4f (%s)\n", worst, worst_name);
}

static void test_lines(void)
{
    rs_spectrum s = {RS_SPECTRUM_LINE, {1, 1, 1}, 0.0, 555.0};
    double xyz[3], c[3];

    rs_spectrum_line_xyz(&s, xyz);
    rs_cmf(555.0, c);
    CHECK_ABS(xyz[1], 1.0, 1e-15, "555 nm line Y");
    CHECK_ABS(xyz[0], c[0], 1e-15, "555 nm line X");
    CHECK(rs_spectrum_emission(&s, 555.0) == 0.0, "a line's emission is 0 (a delta)");

    s.line_nm = 486.1;
    s.rgb = rgb(0.5, 0.5, 0.5);
    rs_spectrum_line_xyz(&s, xyz);
    rs_cmf(486.1, c);
    CHECK_REL(xyz[1], 0.5, 1e-14, "486.1 nm line Y = tint luminance");
    CHECK_REL(xyz[0] / xyz[1], c[0] / c[1], 1e-14, "line chromaticity x/y");
    CHECK_REL(xyz[2] / xyz[1], c[2] / c[1], 1e-14, "line chromaticity z/y");
    CHECK_REL(rs_spectrum_line_power(&s) * c[1], 0.5, 1e-14, "line power * ybar = Y");
    CHECK_REL(rs_spectrum_norm(&s), rs_spectrum_line_power(&s), 1e-15, "norm of a line");

    s.rgb = rgb(1, 0, 0);
    rs_spectrum_line_xyz(&s, xyz);
    CHECK_REL(xyz[1], 0.2126, 1e-14, "red-tinted line Y");

    /* Deep violet: ybar(380) = 3.9e-5 < 1e-3: capped power. */
    s.rgb = rgb(1, 1, 1);
    s.line_nm = 380.0;
    rs_spectrum_line_xyz(&s, xyz);
    CHECK_REL(xyz[1], 3.9e-5 / RS_LINE_YBAR_MIN, 1e-9, "380 nm line, capped");
    s.line_nm = 900.0;
    rs_spectrum_line_xyz(&s, xyz);
    CHECK(xyz[0] == 0 && xyz[1] == 0 && xyz[2] == 0, "900 nm line is invisible");
    {
        rs_spectrum r = spec_rgb(1, 1, 1);
        rs_spectrum_line_xyz(&r, xyz);
        CHECK(xyz[0] == 0 && xyz[1] == 0 && xyz[2] == 0, "line_xyz of an RGB spectrum");
    }
}

/* RS_RGB_LAMBDA is what colorimetry.h says: the first moment of each
 * channel's D65-weighted response (to the 0.1 nm it is rounded to). */
static void test_rgb_lambda(void)
{
    for (int ch = 0; ch < 3; ch++) {
        double num = 0.0, den = 0.0;
        for (int i = 0; i < 40000; i++) {
            double l = 380.0 + (i + 0.5) * 0.01, c[3], w;
            double xyz[3];
            rs_color r;
            rs_cmf(l, c);
            xyz[0] = c[0];
            xyz[1] = c[1];
            xyz[2] = c[2];
            rs_xyz_to_linear_srgb(xyz, &r);
            w = (ch == 0 ? r.r : ch == 1 ? r.g : r.b) * rs_d65(l);
            num += l * w;
            den += w;
        }
        CHECK_ABS(RS_RGB_LAMBDA[ch], num / den, 0.05, "RS_RGB_LAMBDA[%d]", ch);
    }
    CHECK(RS_RGB_LAMBDA[0] > RS_RGB_LAMBDA[1] && RS_RGB_LAMBDA[1] > RS_RGB_LAMBDA[2],
          "R > G > B wavelengths");
}

int main(void)
{
    test_cmf_table();
    test_d65();
    test_srgb_matrices();
    test_transfer();
    test_planck();
    test_rgb_emitter();
    test_colour_correction();
    test_smits();
    test_lines();
    test_rgb_lambda();
    return check_finish("test_spectrum");
}
