/* test_conoscope.c -- a uniaxial crystal plate between crossed polarizers,
 * whole renders against closed forms written here.
 *
 *   isochromes  a c-cut plate (n_o 1.6584, n_e 1.4864, d = 0.1 mm) seen by
 *               a camera focused at infinity (each pixel one direction of
 *               plane waves) at 580 nm (one wavelength band), polarizers
 *               at +-45 degrees to the image row: along the row the
 *               intensity is ~ sin^2(Gamma/2), dark where
 *                 Gamma = (2 pi d/lambda)[(n_o/n_e) sqrt(n_e^2 - s^2)
 *                         - sqrt(n_o^2 - s^2)] = -2 pi m,
 *               s = sin(theta).  The minima of the rendered row (a
 *               parabola through the three darkest pixels) against the
 *               roots of that equation, rings 1..4, within 0.5 % in angle.
 *   isogyres    the same plate with the polarizers along the row and
 *               across it: o and e do not mix there, so the row stays at
 *               the crossed polarizers' own level (0: ideal polarizers).
 *   Michel-Levy an a-cut plate at 45 degrees between crossed polarizers,
 *               normal incidence, natural white light: its colour against
 *               the CIE integral (1 nm steps) of the light's spectrum times
 *                 I(lambda) = 1/2 [(T_o - T_e)^2/4 + T_o T_e sin^2(pi R/lambda)],
 *               T = 1 - ((n-1)/(n+1))^2 (two faces), R = (n_o - n_e) d the
 *               retardation (Sorensen, Eur. J. Mineral. 25, 2013), as
 *               CIELAB under D65: Delta E*ab <= 1 for several R.  The
 *               render takes 200 wavelengths (2 nm bands; the reference is
 *               the renderer's own colour definition, C^-1 M integral,
 *               in 1 nm steps): measured worst Delta E*ab 0.015.  Fewer
 *               bands alias the fast spectral oscillation of high orders:
 *               64 bands give 2.4, 100 give 1.6.
 * The o and e rays of each pixel come from an incoherent light box: they
 * interfere only because the renderer makes the rays a crystal splits from
 * one ray mutually coherent. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "mat3.h"
#include "integrator.h"
#include "parser.h"
#include "scene.h"
#include "emitter.h"
#include "support/colorimetry.h"

#define PI 3.14159265358979323846

static const double NO = 1.6584, NE = 1.4864;
#define ML_WAVELENGTHS 200 /* see the head comment */


/* Render the row j = 0 of a W x 1 image (or one pixel) into v[] (green,
 * or all three channels into rgb when given). */
static int render_row(const char *text, int W, int wavelengths, double *v, rs_color *rgb)
{
    char msg[512] = "";
    rs_scene sc;
    rs_parse_opts po;
    rs_render_opts o;
    rs_integrator *it = NULL;
    int rc = -1;
    rs_scene_init(&sc);
    rs_parse_opts_init(&po);
    po.image_width = W;
    po.image_height = 1;
    rs_render_opts_init(&o);
    o.mode = RS_MODE_POLARIZED;
    o.width = W;
    o.height = 1;
    o.wavelengths = wavelengths;
    if (rs_parse_string(text, "<test>", &po, &sc, msg, sizeof msg) == 0 &&
        rs_scene_prepare(&sc, msg, sizeof msg) == 0 &&
        rs_integrator_create(&sc, &o, &it, msg, sizeof msg) == 0) {
        rs_worker *w = rs_worker_create(it);
        if (w != NULL) {
            for (int i = 0; i < W; i++) {
                rs_color c;
                rs_integrator_pixel(it, w, i, 0, &c);
                if (v)
                    v[i] = c.g;
                if (rgb)
                    rgb[i] = c;
            }
            rs_worker_destroy(w);
            rc = 0;
        }
        rs_integrator_destroy(it);
    }
    if (rc != 0)
        fprintf(stderr, "render_row: %s\n", msg);
    rs_scene_free(&sc);
    return rc;
}

static const char *cono_fmt =
    "global_settings { max_trace_level 3 adc_bailout 0 }\n"
    "camera { location <0, 0, 0> direction <0, 0, 0.5> right <1, 0, 0> up <0, 1, 0> }\n"
    "background { rgb 0 }\n"
    "polarizer { center <0, 0, 1> normal z radius 50 axis <%s> }\n"
    "%s\n"
    "polarizer { center <0, 0, 4> normal z radius 50 axis <%s> }\n"
    "disc { <0, 0, 8>, z, 60 pigment { rgb 1 } finish { ambient 0 diffuse 0 emission 1 } }\n";

static const char *plate_c =
    "lens { radius1 0 radius2 0 thickness 0.1 diameter 60 "
    "uniaxial { ordinary 1.6584 extraordinary 1.4864 axis <0, 0, 1> } translate <0, 0, 2> }";

/* Gamma / 2pi of the c-cut plate at s = sin(theta), in waves (negative:
 * calcite is optically negative). */
static double waves_c(double s, double d_mm, double lambda_nm)
{
    return d_mm * 1e6 / lambda_nm *
           (NO / NE * sqrt(NE * NE - s * s) - sqrt(NO * NO - s * s));
}

#define W 601

static void test_isochromes(void)
{
    static char t[4096];
    static double row[W];
    snprintf(t, sizeof t, cono_fmt, "-1, 1, 0", plate_c, "1, 1, 0");
    if (render_row(t, W, 1, row, NULL) != 0) {
        CHECK(0, "renders");
        return;
    }
    /* pixel i looks along (u, 0, 0.5), u = (i + 0.5)/W - 0.5 */
    double worst = 0, minima[4] = {0, 0, 0, 0};
    int ring = 0;
    for (int i = W / 2 + 2; i < W - 1 && ring < 4; i++) {
        if (!(row[i] < row[i - 1] && row[i] <= row[i + 1]))
            continue;
        /* a parabola through the three pixels, in pixel units */
        double a = row[i - 1], b = row[i], c = row[i + 1];
        double x = i + 0.5 * (a - c) / (a - 2 * b + c);
        double u = (x + 0.5) / W - 0.5;
        double theta = atan(2 * u);
        ring++;
        /* the root of Gamma = -2 pi ring, by bisection in theta */
        double lo = 0, hi = PI / 4;
        for (int k = 0; k < 200; k++) {
            double mid = 0.5 * (lo + hi);
            if (waves_c(sin(mid), 0.1, 580.0) > -ring)
                lo = mid;
            else
                hi = mid;
        }
        double want = 0.5 * (lo + hi);
        double e = fabs(theta - want) / want;
        printf("ring %d: rendered %.4f deg, closed form %.4f deg, error %.3g %%\n", ring,
               theta * 180 / PI, want * 180 / PI, 100 * e);
        /* the acceptance: 0.5 %; measured worst 0.011 % (ring 1) */
        CHECK(e <= 0.005, "ring %d at %.4f deg, want %.4f", ring, theta * 180 / PI,
              want * 180 / PI);
        worst = fmax(worst, e);
        minima[ring - 1] = b;
    }
    CHECK(ring == 4, "four rings found (%d)", ring);
    double peak = 0;
    for (int i = 0; i < W; i++)
        peak = fmax(peak, row[i]);
    CHECK(peak > 0.05, "bright isochromes (%g)", peak);
    /* the darkest pixel of each ring: sampled 0.1-0.2 degrees off its
     * zero, it is still far below the bright rings (measured <= 0.05) */
    for (int k = 0; k < ring; k++)
        CHECK(minima[k] < 0.1 * peak, "ring %d is dark (%g of %g)", k + 1, minima[k], peak);
    printf("isochromes: worst ring-angle error %.3g %%\n", 100 * worst);
}

static void test_isogyres(void)
{
    static char t[4096];
    static double row[W], open[W];
    snprintf(t, sizeof t, cono_fmt, "0, 1, 0", plate_c, "1, 0, 0");
    int ok = render_row(t, W, 1, row, NULL) == 0;
    snprintf(t, sizeof t, cono_fmt, "1, 0, 0", plate_c, "1, 0, 0");
    ok = ok && render_row(t, W, 1, open, NULL) == 0;
    CHECK(ok, "renders");
    if (!ok)
        return;
    double worst = 0;
    for (int i = 0; i < W; i++) {
        CHECK(open[i] > 0.1, "parallel polarizers pass light (%g)", open[i]);
        worst = fmax(worst, row[i] / open[i]);
    }
    /* measured: 0 to rounding (3e-17) */
    CHECK(worst <= 1e-12, "isogyre along the polarizer: leak %g of the open level", worst);
    printf("isogyres: worst leak along the polarizer axis %.3g of the open level\n", worst);
}

/* ---- Michel-Levy ---- */

static void xyz_to_lab(const double xyz[3], const double white[3], double lab[3])
{
    double f[3];
    for (int k = 0; k < 3; k++) {
        double t = xyz[k] / white[k];
        f[k] = t > 216.0 / 24389.0 ? cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0;
    }
    lab[0] = 116 * f[1] - 16;
    lab[1] = 500 * (f[0] - f[1]);
    lab[2] = 200 * (f[1] - f[2]);
}

static void rgb_to_xyz(rs_color c, double xyz[3])
{
    /* IEC 61966-2-1 linear sRGB to XYZ (D65) */
    xyz[0] = 0.4124 * c.r + 0.3576 * c.g + 0.1805 * c.b;
    xyz[1] = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
    xyz[2] = 0.0193 * c.r + 0.1192 * c.g + 0.9505 * c.b;
}

static void test_michel_levy(void)
{
    static char t[4096];
    const double Ro = (NO - 1) / (NO + 1), Re = (NE - 1) / (NE + 1);
    const double To = 1 - Ro * Ro, Te = 1 - Re * Re;
    const rs_spectrum white = {RS_SPECTRUM_RGB, {1, 1, 1}, 0, 0};
    const double R_nm[] = {100, 250, 450, 550, 800, 1100, 1500};
    double worst = 0;
    /* The renderer's colour of a spectrum is C^-1 M (integral of it times
     * the CMFs), C making each unit RGB emitter exactly its RGB; the
     * reference is the same definition with the integral in 1 nm steps. */
    double C[3][3], Ci[3][3], cmf[3];
    for (int k = 0; k < 3; k++) {
        rs_spectrum u = {RS_SPECTRUM_RGB, {k == 0, k == 1, k == 2}, 0, 0};
        double x[3] = {0, 0, 0};
        for (double l = RS_LAMBDA_MIN + 0.5; l < RS_LAMBDA_MAX; l += 1.0) {
            rs_cmf(l, cmf);
            for (int c = 0; c < 3; c++)
                x[c] += rs_spectrum_emission(&u, l) * cmf[c];
        }
        rs_color rgb;
        rs_xyz_to_linear_srgb(x, &rgb);
        C[0][k] = rgb.r;
        C[1][k] = rgb.g;
        C[2][k] = rgb.b;
    }
    mat3_invert(C, Ci);
    for (size_t n = 0; n < sizeof R_nm / sizeof R_nm[0]; n++) {
        double d = R_nm[n] * 1e-6 / (NO - NE);
        char plate[512];
        snprintf(plate, sizeof plate,
                 "lens { radius1 0 radius2 0 thickness %.17g diameter 60 uniaxial { ordinary "
                 "1.6584 extraordinary 1.4864 axis <1, 1, 0> } translate <0, 0, 2> }",
                 d);
        snprintf(t, sizeof t,
                 "global_settings { max_trace_level 3 adc_bailout 0 }\n"
                 "camera { location <0, 0, 0> direction <0, 0, 1> right <1e-4, 0, 0> "
                 "up <0, 1e-4, 0> }\n"
                 "background { rgb 0 }\n"
                 "polarizer { center <0, 0, 1> normal z radius 50 axis <0, 1, 0> }\n"
                 "%s\n"
                 "polarizer { center <0, 0, 4> normal z radius 50 axis <1, 0, 0> }\n"
                 "disc { <0, 0, 8>, z, 60 pigment { rgb 1 } finish { ambient 0 diffuse 0 "
                 "emission 1 } }\n",
                 plate);
        rs_color got;
        if (render_row(t, 1, ML_WAVELENGTHS, NULL, &got) != 0) {
            CHECK(0, "renders");
            continue;
        }
        double xyz[3] = {0, 0, 0};
        for (double l = RS_LAMBDA_MIN + 0.5; l < RS_LAMBDA_MAX; l += 1.0) {
            double s = sin(PI * R_nm[n] / l);
            double I = 0.5 * (0.25 * (To - Te) * (To - Te) + To * Te * s * s);
            rs_cmf(l, cmf);
            for (int k = 0; k < 3; k++)
                xyz[k] += rs_spectrum_emission(&white, l) * I * cmf[k];
        }
        rs_color raw, want;
        rs_xyz_to_linear_srgb(xyz, &raw);
        want.r = Ci[0][0] * raw.r + Ci[0][1] * raw.g + Ci[0][2] * raw.b;
        want.g = Ci[1][0] * raw.r + Ci[1][1] * raw.g + Ci[1][2] * raw.b;
        want.b = Ci[2][0] * raw.r + Ci[2][1] * raw.g + Ci[2][2] * raw.b;
        double d65[3], wx[3];
        rgb_to_xyz((rs_color){1, 1, 1}, d65);
        rgb_to_xyz(want, wx);
        double gx[3], lg[3], lw[3];
        rgb_to_xyz(got, gx);
        xyz_to_lab(gx, d65, lg);
        xyz_to_lab(wx, d65, lw);
        double dE = sqrt((lg[0] - lw[0]) * (lg[0] - lw[0]) + (lg[1] - lw[1]) * (lg[1] - lw[1]) +
                         (lg[2] - lw[2]) * (lg[2] - lw[2]));
        printf("Michel-Levy R = %4.0f nm: rendered Lab %.2f %.2f %.2f, CIE integral %.2f %.2f "
               "%.2f, Delta E*ab %.3f\n",
               R_nm[n], lg[0], lg[1], lg[2], lw[0], lw[1], lw[2], dE);
        CHECK(dE <= 1.0, "Michel-Levy colour of R = %g nm: Delta E*ab %g", R_nm[n], dE);
        worst = fmax(worst, dE);
    }
    printf("Michel-Levy: worst Delta E*ab %.3f\n", worst);
}

int main(void)
{
    test_isochromes();
    test_isogyres();
    test_michel_levy();
    return check_finish("test_conoscope");
}
