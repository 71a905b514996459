/* test_coherent_sources.c -- which sources interfere: a light declared
 * `coherent`, and every source (lights, self-lit objects, the background)
 * under `global_settings { coherent on }`; the rest add as intensities.
 *
 * The probe is a lossless plate of index 1.5 (ior, no dispersion; R =
 * ((n-1)/(n+1))^2 = 0.04 per face) seen at normal incidence (one pixel),
 * a white diffuse wall or a self-lit plane behind it, monochromatic light
 * (a 589.3 nm line: one wavelength, no quadrature).  The beams leaving the
 * plate after 0, 2, 4, ... internal reflections (the series is summed to
 * R^60) are
 *   incoherent:  T = (1 - R)^2 sum R^2k = (1 - R) / (1 + R)  = 0.923077
 *   coherent:    T = (1 - R)^2 / (1 + R^2 - 2 R cos delta)   (Airy),
 *                delta = 4 pi n t / lambda:
 *                t = 3000 lambda / (2n)   (cos delta = 1)  -> T = 1
 *                t = 3000.5 lambda / (2n) (cos delta = -1) -> (1-R)^2/(1+R)^2
 *                                                            = 0.852071
 * against the same scene without the plate.  Tolerance 5e-11: the beams'
 * optical paths (~110 mm from the camera) round to ~2.4e-14 mm, 2.6e-10
 * rad of phase at 580 nm, times |dT/ddelta| <= 2R = 0.08: 2e-11 off an
 * extremum of cos delta (measured 5.8e-12), second order at one (measured
 * 4e-16). */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>

#include "check.h"
#include "integrator.h"
#include "one_pixel.h"

#define LAMBDA 589.3 /* nm, standard air */
#define PI 3.14159265358979323846
#define N 1.5
#define TOL 5e-11

static double worst;

static const char *fmt =
    "global_settings { max_trace_level 64 adc_bailout 0 %s }\n"
    "camera { location <0, 0, -100> look_at <0, 0, 0> angle 1 }\n"
    "background { rgb 0 }\n"
    "%s\n"
    "%s\n";

/* the plate, or nothing when t <= 0 */
static void plate(char *buf, size_t n, double t)
{
    if (t > 0)
        snprintf(buf, n, "lens { radius1 0 radius2 0 thickness %.17g diameter 50 ior %g }", t, N);
    else
        buf[0] = '\0';
}

static int render(const char *global, const char *source, double t, int nl, double *g)
{
    char text[2048], p[256];
    rs_color c;
    plate(p, sizeof p, t);
    snprintf(text, sizeof text, fmt, global, source, p);
    if (one_pixel(text, RS_MODE_POLARIZED, nl, &c) != 0)
        return -1;
    *g = c.g;
    return 0;
}

static void check_case(const char *what, const char *global, const char *source, double t,
                       int nl, double want)
{
    double base = 0, got = 0;
    if (render(global, source, 0, nl, &base) != 0 || render(global, source, t, nl, &got) != 0) {
        CHECK(0, "%s: renders", what);
        return;
    }
    CHECK(base > 0.05, "%s: the scene is lit (%g)", what, base);
    CHECK_ABS(got / base, want, TOL, "%s", what);
    worst = fmax(worst, fabs(got / base - want));
    printf("%-62s T %.13f (want %.13f)\n", what, got / base, want);
}

int main(void)
{
    const double r = (N - 1) / (N + 1), R = r * r;
    const double t_inc = (1 - R) / (1 + R), t_dark = (1 - R) * (1 - R) / ((1 + R) * (1 + R));
    const double tb = 3000.0 * LAMBDA * 1e-6 / (2 * N), td = 3000.5 * LAMBDA * 1e-6 / (2 * N);
    /* a white diffuse wall lit by a point light at the camera */
    const char *wall = "plane { z, 10 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
                       "light_source { <0, 0, -100> color rgb 1 spectrum { line 589.3 } %s }";
    char plain[512], coh[512];
    snprintf(plain, sizeof plain, wall, "");
    snprintf(coh, sizeof coh, wall, "coherent");
    /* a self-lit plane: an object, which only coherent on makes coherent */
    const char *glow = "plane { z, 10 pigment { rgb 1 } finish { ambient 0 diffuse 0 emission 1 } }";

    check_case("light, incoherent: (1-R)/(1+R)", "", plain, tb, 0, t_inc);
    check_case("light, incoherent, dark thickness: the same", "", plain, td, 0, t_inc);
    check_case("light coherent, bright thickness: 1", "", coh, tb, 0, 1.0);
    check_case("light coherent, dark thickness: (1-R)^2/(1+R)^2", "", coh, td, 0, t_dark);
    check_case("coherent on, light, bright thickness: 1", "coherent on", plain, tb, 0, 1.0);
    check_case("coherent on, light, dark thickness", "coherent on", plain, td, 0, t_dark);
    check_case("coherent off, light coherent: the light's own", "coherent off", coh, td, 0, t_dark);
    /* The self-lit plane emits a continuum: with one wavelength (580 nm,
     * the midpoint of 380-780) the pixel is that wavelength's, so Airy at
     * 580 nm: cos delta = cos(4 pi n t / 580 nm) for the same plates. */
    const double l1 = 580e-6;
    const double a_b = (1 - R) * (1 - R) / (1 + R * R - 2 * R * cos(4 * PI * N * tb / l1));
    const double a_d = (1 - R) * (1 - R) / (1 + R * R - 2 * R * cos(4 * PI * N * td / l1));
    check_case("self-lit plane, incoherent", "", glow, td, 1, t_inc);
    check_case("coherent on, self-lit plane, t_b at 580 nm (Airy)", "coherent on", glow, tb, 1,
               a_b);
    check_case("coherent on, self-lit plane, t_d at 580 nm (Airy)", "coherent on", glow, td, 1,
               a_d);
    printf("coherent sources: worst deviation from the plate's closed forms %.3g\n", worst);
    return check_finish("test_coherent_sources");
}
