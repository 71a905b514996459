/* test_polarized_light.c -- polarized light sources and polarizers, whole
 * renders against Malus's law written here.
 *
 *   a. A point light lights a white diffuse wall through polarizers on
 *      the straight segment between them (the shadow ray).  The light's
 *      `polarization <v>` (or natural light: two incoherent orthogonal
 *      halves) is projected by each polarizer on its axis, from the light
 *      on: intensity cos^2 of the angle each time (Malus).  The wall point
 *      seen by the single pixel, the light and the polarizers' centres lie
 *      on one line along z, so the law is exact: natural light through one
 *      polarizer 1/2, crossed pair 0, a pair at 45 degrees 1/4; light
 *      polarized along x through an axis at 30 degrees 3/4, through y 0;
 *      through 45 degrees and then y 1/4 (a crossed pair with one between).
 *      The unpolarized models (fresnel) pass 1/2 at each polarizer
 *      whatever the light (their known limit).
 *   b. A tilted polarizer equals the same polarizer with its axis turned:
 *      a polarizer acts on a ray through its axis's component
 *      perpendicular to the ray.  Tilted by 40 degrees about y with its
 *      axis at 30 degrees in its own plane, it must give what an untilted
 *      one with that projected axis gives, and Malus's law with the
 *      projected angle: on a camera ray (light box seen through an x
 *      polarizer and the tilted one) and on a shadow ray (light polarized
 *      along x).
 * Every ratio is against the same render without the polarizers; only
 * rounding separates them: tolerance 1e-14, the worst measured printed. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "integrator.h"
#include "one_pixel.h"

#define PI 3.14159265358979323846
#define TOL 1e-14

static double worst;

/* The green channel of the single pixel of a 1x1 render of text (all
 * three are checked equal: white light on white). */
static int render_pixel(const char *text, rs_mode mode, double *out)
{
    rs_color c;
    if (one_pixel(text, mode, 0, &c) != 0)
        return -1;
    CHECK(fabs(c.r - c.g) <= 1e-12 * c.g && fabs(c.b - c.g) <= 1e-12 * c.g,
          "white light on white stays grey (%g %g %g)", c.r, c.g, c.b);
    *out = c.g;
    return 0;
}

static void check_ratio(const char *what, rs_mode mode, const char *text, double base,
                        double want)
{
    double got = 0;
    if (render_pixel(text, mode, &got) != 0) {
        CHECK(0, "%s: renders", what);
        return;
    }
    CHECK_ABS(got / base, want, TOL, "%s", what);
    worst = fmax(worst, fabs(got / base - want));
    printf("%-58s %.15f (want %.15f)\n", what, got / base, want);
}

/* ---- a. shadow rays ---------------------------------------------------- */

static const char *wall_fmt =
    "camera { location <0, 0, -20> look_at <0, 0, 0> angle 1 }\n"
    "background { rgb 0 }\n"
    "light_source { <0, 0, -50> color rgb 1 %s }\n"
    "plane { z, 0 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
    "%s\n";

static void wall(char *buf, size_t n, const char *light, const char *pols)
{
    snprintf(buf, n, wall_fmt, light, pols);
}

#define POL(z, ax) "polarizer { center <0, 0, " #z "> normal z radius 10 axis " ax " }\n"

static void test_shadow_rays(void)
{
    char t[2048];
    const char *px = "polarization <1, 0, 0>";
    const rs_mode modes[2] = {RS_MODE_POLARIZED, RS_MODE_FRESNEL};
    for (int m = 0; m < 2; m++) {
        double base_nat = 0, base_pol = 0;
        wall(t, sizeof t, "", "");
        int ok = render_pixel(t, modes[m], &base_nat) == 0;
        wall(t, sizeof t, px, "");
        ok = ok && render_pixel(t, modes[m], &base_pol) == 0;
        CHECK(ok && base_nat > 0.1 && base_pol > 0.1, "the wall is lit (%g, %g)", base_nat,
              base_pol);
        if (!ok)
            continue;
        CHECK_ABS(base_pol / base_nat, 1.0, TOL, "a polarized light is as bright as a natural one");
        int pol = modes[m] == RS_MODE_POLARIZED;
        const char *name = pol ? "polarized" : "fresnel";
        char what[128];
        struct { const char *light, *pols, *label; double want_pol, want_unpol; } cases[] = {
            {"", POL(-30, "x"), "natural, one polarizer", 0.5, 0.5},
            {"", POL(-40, "x") POL(-30, "y"), "natural, crossed pair", 0.0, 0.25},
            {"", POL(-40, "x") POL(-30, "<1, 1, 0>"), "natural, pair at 45 deg", 0.25, 0.25},
            {px, POL(-30, "x"), "polarized x, axis x", 1.0, 0.5},
            {px, POL(-30, "<0.8660254037844386, 0.5, 0>"), "polarized x, axis at 30 deg", 0.75,
             0.5},
            {px, POL(-30, "y"), "polarized x, axis y", 0.0, 0.5},
            {px, POL(-40, "<1, 1, 0>") POL(-30, "y"), "polarized x, 45 deg then y", 0.25, 0.25},
            {"polarization <0, 1, 0>", POL(-40, "<1, 1, 0>") POL(-30, "y"),
             "polarized y, 45 deg then y", 0.25, 0.25},
            /* a polarizer off the segment does nothing */
            {px, "polarizer { center <30, 0, -30> normal z radius 10 axis y }",
             "polarized x, polarizer beside the segment", 1.0, 1.0},
        };
        for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
            wall(t, sizeof t, cases[k].light, cases[k].pols);
            snprintf(what, sizeof what, "%s: %s", name, cases[k].label);
            check_ratio(what, modes[m], t, base_nat, pol ? cases[k].want_pol : cases[k].want_unpol);
        }
    }
}

/* ---- b. tilted polarizers ---------------------------------------------- */

/* Tilt 40 degrees about y (rotate's left-hand rule: normal (sin, 0, cos));
 * the axis at phi = 30 degrees from u = (cos 40, 0, -sin 40) towards y, in
 * the polarizer's plane.  Its component perpendicular to a ray along z is
 * (cos phi cos 40, sin phi, 0): at atan(tan phi / cos 40) from x. */
#define TILT (40.0 * PI / 180)
#define PHI (30.0 * PI / 180)

static void tilted_axes(char *tilted, size_t n1, char *turned, size_t n2, double *cos2)
{
    double ax = cos(PHI) * cos(TILT), ay = sin(PHI), az = -cos(PHI) * sin(TILT);
    snprintf(tilted, n1, "normal <%.17g, 0, %.17g> axis <%.17g, %.17g, %.17g>", sin(TILT),
             cos(TILT), ax, ay, az);
    snprintf(turned, n2, "normal z axis <%.17g, %.17g, 0>", ax, ay);
    *cos2 = ax * ax / (ax * ax + ay * ay);
}

static void test_tilted(void)
{
    char tilted[256], turned[256], t[2048], pols[600];
    double c2;
    tilted_axes(tilted, sizeof tilted, turned, sizeof turned, &c2);
    printf("tilted polarizer: projected axis at %.4f deg from x, cos^2 %.6f\n",
           acos(sqrt(c2)) * 180 / PI, c2);

    /* camera rays: a light box behind an x polarizer and the tilted one */
    const char *box_fmt =
        "camera { location <0, 0, -20> look_at <0, 0, 0> angle 1 }\n"
        "background { rgb 0 }\n"
        "polarizer { center <0, 0, -5> normal z radius 10 axis x }\n"
        "%s\n"
        "plane { z, 20 pigment { rgb 1 } finish { ambient 0 diffuse 0 emission 1 } }\n";
    double base = 0;
    snprintf(t, sizeof t, box_fmt, "");
    if (render_pixel(t, RS_MODE_POLARIZED, &base) != 0) {
        CHECK(0, "light box renders");
        return;
    }
    CHECK_ABS(base, 0.5, 1e-12, "natural light box through one polarizer: 1/2 (got %g)", base);
    double got_tilted = 0, got_turned = 0;
    snprintf(pols, sizeof pols, "polarizer { center <0, 0, 5> radius 10 %s }", tilted);
    snprintf(t, sizeof t, box_fmt, pols);
    int ok = render_pixel(t, RS_MODE_POLARIZED, &got_tilted) == 0;
    snprintf(pols, sizeof pols, "polarizer { center <0, 0, 5> radius 10 %s }", turned);
    snprintf(t, sizeof t, box_fmt, pols);
    ok = ok && render_pixel(t, RS_MODE_POLARIZED, &got_turned) == 0;
    CHECK(ok, "tilted and turned polarizers render");
    if (ok) {
        CHECK_ABS(got_tilted / base, c2, TOL, "camera ray: tilted polarizer = Malus at the "
                  "projected angle");
        CHECK_ABS(got_tilted, got_turned, TOL * base, "camera ray: tilted = axis turned");
        worst = fmax(worst, fmax(fabs(got_tilted / base - c2), fabs(got_tilted - got_turned)));
        printf("camera ray: tilted %.15f, turned %.15f, Malus %.15f\n", got_tilted / base,
               got_turned / base, c2);
    }

    /* shadow rays: light polarized along x through the tilted polarizer */
    double wall_base = 0;
    wall(t, sizeof t, "polarization <1, 0, 0>", "");
    if (render_pixel(t, RS_MODE_POLARIZED, &wall_base) != 0) {
        CHECK(0, "wall renders");
        return;
    }
    snprintf(pols, sizeof pols, "polarizer { center <0, 0, -30> radius 10 %s }", tilted);
    wall(t, sizeof t, "polarization <1, 0, 0>", pols);
    check_ratio("shadow ray: polarized x, tilted polarizer (Malus)", RS_MODE_POLARIZED, t,
                wall_base, c2);
    snprintf(pols, sizeof pols, "polarizer { center <0, 0, -30> radius 10 %s }", turned);
    wall(t, sizeof t, "polarization <1, 0, 0>", pols);
    check_ratio("shadow ray: polarized x, axis turned instead", RS_MODE_POLARIZED, t, wall_base,
                c2);
}

int main(void)
{
    test_shadow_rays();
    test_tilted();
    printf("polarized light: worst deviation from Malus's law %.3g\n", worst);
    return check_finish("test_polarized_light");
}
