/* test_render_physics.c -- whole renders checked against closed-form
 * optics written here, never against the renderer's own output.
 *
 *   a. Radiometry of a lossless plane-parallel plate in front of a uniform
 *      self-lit white plane: with every internal reflection summed
 *      incoherently, a plate transmits
 *          T = (1 - R)^2 (1 + R^2 + R^4 + ...) = (1 - R) / (1 + R)
 *      per polarization (R the single-interface reflectance, the same on
 *      both faces).  Checked to 1e-14 relative (rounding) in the polarized,
 *      fresnel and rgb modes (and schlick at exact normal incidence),
 *      facing the camera and tilted by 40 degrees (where polarized and
 *      fresnel differ by 2e-3 and one internal round trip too few by
 *      3.6e-5), each pixel
 *      against the same render without the plate.  The small obliquity of
 *      off-centre pixels (< 1 degree) is accounted for exactly: Rs, Rp from
 *      Fresnel's equations at the pixel's ray angle; the polarized mode
 *      averages T over s and p, the unpolarized models use R = (Rs+Rp)/2
 *      per interface.  Then N-BK7 given by its Sellmeier coefficients
 *      (lossless) in the rgb mode: T per channel at RS_RGB_LAMBDA[c].
 *   b. Newton's rings of scenes/newtons_rings.scene: the dark rings of the
 *      air film between a plano-convex lens (R = 1000 mm) and a flat plate
 *      lie where the film is m half-wavelengths thick, r_m = sqrt(m lambda
 *      R), lambda = 589.3 nm: found in the render to 2 %; the dark/bright
 *      ratio from Fresnel's R of the four faces, to 0.3 %.  Then the same
 *      set-up moved as a whole by 5 mm: physics does not know where the
 *      world origin is, so the same rings must come out.
 *   c. Crossed ideal polarizers in front of a light box: black to within
 *      the exact oblique-incidence leak (each pixel equal to it); with a
 *      strongly curved lens between them (scenes/crossed_polarizers.scene)
 *      the leak is mirror-symmetric in both polarizer axes, dark along
 *      them (the extinction cross), bright on the diagonals, and follows
 *      the sin^2(2 phi) azimuth law within the bounds that the polarizers'
 *      obliquity allows (derived at test_crossed_lens).
 *   d. The unpolarized fresnel model's known failure on the same set-up:
 *      each polarizer passes half of "natural" light, so the crossed pair
 *      passes 1/4 of the light box instead of (almost) nothing.
 *   e. The rim's shadow: a plate (flat caps, cylindrical rim of radius
 *      10 mm, z in [0, 5]) lit by an off-axis point light casts on a wall
 *      behind it the shadow of its rim only: a wall point is dark exactly
 *      when the straight segment to the light meets the rim's cylinder
 *      within z in [0, 5] (computed here), whether the segment reaches the
 *      rim from outside or through a cap from inside the glass; clear glass
 *      casts none.  Checked pixel by pixel in the fresnel model.
 *
 * Resolutions are small so that the whole program runs in a few seconds,
 * also under the sanitizers. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "integrator.h"
#include "render_check.h"
#include "scene.h"
#include "support/colorimetry.h"

#define PI 3.14159265358979323846

/* The direction of pixel (i, j) of a square-pixel camera looking along +z
 * (right = x * w/h, up = y, |D| = |right| / (2 tan(angle/2)), POV-Ray's
 * rules written out here), as (x, y, z) unit components. */
static void camera_dir_z(double angle_deg, int w, int h, int i, int j, double d[3])
{
    double rl = (double)w / (double)h;
    double dl = rl / (2.0 * tan(angle_deg * PI / 360.0));
    double a = ((i + 0.5) / w - 0.5) * rl, b = 0.5 - (j + 0.5) / h;
    double n = sqrt(a * a + b * b + dl * dl);
    d[0] = a / n;
    d[1] = b / n;
    d[2] = dl / n;
}

/* ---- Fresnel's equations (written here) -------------------------------- */

/* Power reflectances of an interface from index 1 into n at incidence
 * angle with cosine ci (no TIR possible). */
static void fresnel_rs_rp(double n, double ci, double *rs, double *rp)
{
    double si2 = 1.0 - ci * ci;
    double ct = sqrt(1.0 - si2 / (n * n));
    double s = (ci - n * ct) / (ci + n * ct);
    double p = (n * ci - ct) / (n * ci + ct);
    *rs = s * s;
    *rp = p * p;
}

/* Incoherent plate transmission, single-interface reflectance R (the same
 * at both faces, by Stokes' relations). */
static double plate_t(double r)
{
    return (1.0 - r) / (1.0 + r);
}

/* N-BK7 (Schott), Sellmeier, lambda in nm in air. */
static const double BK7[6] = {1.03961212, 0.231792344, 1.01046945,
                              0.00600069867, 0.0200179144, 103.560653};

static double sellmeier(const double *k, double lambda_nm)
{
    double l2 = (lambda_nm * 1e-3) * (lambda_nm * 1e-3);
    double n2 = 1.0;
    for (int i = 0; i < 3; i++)
        n2 += k[i] * l2 / (l2 - k[3 + i]);
    return sqrt(n2);
}

/* ---- a. radiometry of a plate ------------------------------------------ */

#define PLATE_W 5
#define PLATE_H 5
#define PLATE_ANGLE 2.0

static const char *plate_scene_fmt =
    "global_settings { max_trace_level 60 adc_bailout 1e-12 }\n"
    "camera { location <0, 0, -100> look_at <0, 0, 0>\n"
    "         right x*image_width/image_height angle %g }\n"
    "background { rgb 0 }\n"
    "%s\n"
    "plane { z, 50 pigment { rgb 1 } finish { ambient 0 diffuse 0 emission 1 } }\n";

static const char *plate_lens_const =
    "lens { radius1 0 radius2 0 thickness 2 diameter 200 ior 1.5168 translate <0, 0, -1> }";

/* Tilted by 40 degrees about y: normal (sin 40, 0, cos 40) (rotate's
 * left-hand rule).  Camera rays meet it at 39-41 degrees, where polarized
 * and fresnel differ by 2e-3 (Rs 0.081, Rp 0.015), the reflections go
 * back to the black background (below 45 degrees), and a series cut after
 * one internal round trip misses (1-R)^2 R^4 / (1-R^2) = 3.6e-5 of the
 * s light. */
#define PLATE_TILT 40.0
static const char *plate_lens_tilted =
    "lens { radius1 0 radius2 0 thickness 2 diameter 200 ior 1.5168 translate <0, 0, -1>\n"
    "       rotate <0, 40, 0> }";

static const char *plate_lens_bk7 =
    "lens { radius1 0 radius2 0 thickness 2 diameter 200\n"
    "       sellmeier { 1.03961212, 0.231792344, 1.01046945,\n"
    "                   0.00600069867, 0.0200179144, 103.560653 }\n"
    "       translate <0, 0, -1> }";

/* Rounding through the series (up to ~30 bounces at the 1e-15 cut-off,
 * whose dropped tail is below 1e-15 of the pixel): measured <= 1.7e-15
 * (polarized), so 1e-14. */
#define PLATE_TOL 1e-14

/* Expected ratio plate / no plate for pixel direction cosine ci. */
static double plate_expected(rs_mode mode, double n, double ci)
{
    double rs, rp;
    fresnel_rs_rp(n, ci, &rs, &rp);
    if (mode == RS_MODE_POLARIZED) /* s and p stay s and p: each its own series */
        return 0.5 * (plate_t(rs) + plate_t(rp));
    if (mode == RS_MODE_SCHLICK) { /* only used at normal incidence */
        double r0 = (n - 1.0) / (n + 1.0);
        return plate_t(r0 * r0);
    }
    return plate_t(0.5 * (rs + rp)); /* unpolarized models: mean R per face */
}

static void test_plate_case(const char *lens, const char *what, rs_mode mode, int centre_only,
                            int sellmeier_glass, double tilt_deg)
{
    const double nx = sin(tilt_deg * PI / 180), nz = cos(tilt_deg * PI / 180);
    char text[2048];
    rs_scene with, without;
    rs_scene_init(&with);
    rs_scene_init(&without);
    picture pw = {0, 0, NULL}, pn = {0, 0, NULL};

    snprintf(text, sizeof text, plate_scene_fmt, PLATE_ANGLE, lens);
    int ok = rc_load_scene(&with, text, NULL, PLATE_W, PLATE_H) == 0;
    snprintf(text, sizeof text, plate_scene_fmt, PLATE_ANGLE, "");
    ok = ok && rc_load_scene(&without, text, NULL, PLATE_W, PLATE_H) == 0;
    CHECK(ok, "%s: scenes load", what);
    if (ok) {
        ok = rc_render(&with, mode, PLATE_W, PLATE_H, 0, 1e-15, 0, NULL, &pw) == 0 &&
             rc_render(&without, mode, PLATE_W, PLATE_H, 0, 1e-15, 0, NULL, &pn) == 0;
        CHECK(ok, "%s: renders", what);
    }
    if (ok) {
        double worst = 0.0;
        for (int j = 0; j < PLATE_H; j++)
            for (int i = 0; i < PLATE_W; i++) {
                if (centre_only && (i != PLATE_W / 2 || j != PLATE_H / 2))
                    continue;
                double d[3];
                camera_dir_z(PLATE_ANGLE, PLATE_W, PLATE_H, i, j, d);
                for (int c = 0; c < 3; c++) {
                    double n = sellmeier_glass ? sellmeier(BK7, RS_RGB_LAMBDA[c]) : 1.5168;
                    double bg = rc_px(&pn, i, j, c);
                    double want = bg * plate_expected(mode, n, fabs(nx * d[0] + nz * d[2]));
                    double got = rc_px(&pw, i, j, c);
                    CHECK(bg > 0.5, "%s: background pixel (%d,%d) ch %d is lit: %g", what, i, j,
                          c, bg);
                    CHECK_REL(got, want, PLATE_TOL, "%s: pixel (%d,%d) ch %d", what, i, j, c);
                    double e = fabs(got - want) / want;
                    if (e > worst)
                        worst = e;
                }
            }
        printf("plate %-34s worst relative error %.2e\n", what, worst);
    }
    free(pw.rgb);
    free(pn.rgb);
    rs_scene_free(&with);
    rs_scene_free(&without);
}

static void test_plate(void)
{
    double n = 1.5168, r0 = (n - 1) / (n + 1);
    printf("plate n = %.4f: R = %.6f, (1-R)/(1+R) = %.7f\n", n, r0 * r0, plate_t(r0 * r0));
    for (int c = 0; c < 3; c++) {
        double nc = sellmeier(BK7, RS_RGB_LAMBDA[c]), rc = (nc - 1) / (nc + 1);
        printf("N-BK7 at %.1f nm: n = %.6f, (1-R)/(1+R) = %.7f\n", RS_RGB_LAMBDA[c], nc,
               plate_t(rc * rc));
    }
    test_plate_case(plate_lens_const, "ior 1.5168, polarized", RS_MODE_POLARIZED, 0, 0, 0);
    test_plate_case(plate_lens_const, "ior 1.5168, fresnel", RS_MODE_FRESNEL, 0, 0, 0);
    test_plate_case(plate_lens_const, "ior 1.5168, rgb", RS_MODE_RGB, 0, 0, 0);
    test_plate_case(plate_lens_const, "ior 1.5168, schlick (centre)", RS_MODE_SCHLICK, 1, 0, 0);
    test_plate_case(plate_lens_bk7, "N-BK7 sellmeier, rgb", RS_MODE_RGB, 0, 1, 0);
    test_plate_case(plate_lens_tilted, "tilted 40 deg, polarized", RS_MODE_POLARIZED, 0, 0,
                    PLATE_TILT);
    test_plate_case(plate_lens_tilted, "tilted 40 deg, fresnel", RS_MODE_FRESNEL, 0, 0,
                    PLATE_TILT);
    test_plate_case(plate_lens_tilted, "tilted 40 deg, rgb", RS_MODE_RGB, 0, 0, PLATE_TILT);
}

/* ---- b. Newton's rings --------------------------------------------------- */

/* scenes/newtons_rings.scene: camera at y = 150 looking down, angle 1.6,
 * right x*image_width/image_height; the lens's flat top at y = 4, its
 * convex face (R = 1000) touching the plate at the origin. */
#define NR_SIZE 241
#define NR_ANGLE 1.6
#define NR_CAM_H 150.0
#define NR_LENS_T 4.0
#define NR_R 1000.0
#define NR_LAMBDA 589.3
#define NR_BIN 0.005     /* mm^2 of r^2 per bin */
#define NR_R2_MAX 3.70   /* mm^2: beyond the 6th dark ring (3.54) */

/* The radius at which pixel (i, j)'s ray crosses the contact plane y = 0:
 * it travels 146 mm of air at angle theta, then the 4 mm of glass at
 * theta' (sin theta = n sin theta'), then a film of at most 1.5 um (whose
 * contribution, < 2e-5 mm, is neglected). */
static double nr_radius(int i, int j, double n)
{
    double d[3];
    camera_dir_z(NR_ANGLE, NR_SIZE, NR_SIZE, i, j, d);
    double st = sqrt(d[0] * d[0] + d[1] * d[1]), ct = d[2];
    double st2 = st / n, ct2 = sqrt(1.0 - st2 * st2);
    return (NR_CAM_H - NR_LENS_T) * st / ct + NR_LENS_T * st2 / ct2;
}

/* The scene file's set-up moved as a whole by S (camera, light, lenses,
 * ceiling): physics does not know where the world origin is, so the same
 * rings must come out.  (A phase model that referred the light leaving
 * the ceiling to a plane wave through the world origin once put the
 * rings' centre at the origin instead of the contact point; one that took
 * a plane wavefront per pixel perpendicular to the camera ray made the
 * radii grow with the glass above the film, +0.54 % here.) */
static const char *nr_shifted_fmt =
    "#declare S = <%g, 0, %g>;\n"
    "global_settings { max_trace_level 8 adc_bailout 0.0001 }\n"
    "camera { location <0, 150, 0> look_at <0, 0, 0> sky <0, 0, 1>\n"
    "         right x*image_width/image_height angle 1.6 translate S }\n"
    "background { rgb 0 }\n"
    "light_source { <0, 150, 0> color rgb 1 spectrum { line 589.3 } coherent 0.3 translate S }\n"
    "lens { radius1 0 radius2 -1000 thickness 4 diameter 20 glass \"N-BK7\"\n"
    "       rotate <90, 0, 0> translate <0, 4, 0> translate S }\n"
    "lens { radius1 0 radius2 0 thickness 5 diameter 40 glass \"N-BK7\"\n"
    "       rotate <90, 0, 0> translate S }\n"
    "plane { y, 300 pigment { rgb 1 } finish { ambient 0 diffuse 1 } translate S }\n";

static void test_newtons_rings(double sx, double sz)
{
    char path[4096], text[2048];
    rs_scene sc;
    rs_scene_init(&sc);
    picture pic = {0, 0, NULL};
    double n = sellmeier(BK7, NR_LAMBDA);
    int nb = (int)(NR_R2_MAX / NR_BIN) + 1;
    unsigned char *mask = calloc((size_t)NR_SIZE * NR_SIZE, 1);
    double *r2 = malloc((size_t)NR_SIZE * NR_SIZE * sizeof *r2);
    double *sum = calloc((size_t)nb, sizeof *sum), *sum_r2 = calloc((size_t)nb, sizeof *sum_r2);
    int *cnt = calloc((size_t)nb, sizeof *cnt);

    snprintf(path, sizeof path, "%s/scenes/newtons_rings.scene", LP_SOURCE_DIR);
    snprintf(text, sizeof text, nr_shifted_fmt, sx, sz);
    int shifted = sx != 0.0 || sz != 0.0;
    char tag[64] = "";
    if (shifted)
        snprintf(tag, sizeof tag, " (set-up moved by <%g,0,%g>)", sx, sz);
    int ok = mask && r2 && sum && sum_r2 && cnt &&
             rc_load_scene(&sc, shifted ? text : NULL, path, NR_SIZE, NR_SIZE) == 0;
    CHECK(ok, "newtons_rings.scene loads");
    printf("newton: %s\n", shifted ? "the set-up moved as a whole" : "scenes/newtons_rings.scene");
    if (shifted)
        printf("newton: moved by <%g, 0, %g> mm\n", sx, sz);
    if (!ok)
        goto out;
    for (int j = 0; j < NR_SIZE; j++)
        for (int i = 0; i < NR_SIZE; i++) {
            double r = nr_radius(i, j, n);
            r2[(size_t)j * NR_SIZE + i] = r * r;
            mask[(size_t)j * NR_SIZE + i] = r * r < NR_R2_MAX;
        }
    {
        double mm_px = nr_radius(NR_SIZE / 2 + 1, NR_SIZE / 2, n);
        printf("newton: n(589.3) = %.6f, %.5f mm per pixel at the film\n", n, mm_px);
    }
    /* Few continuum samples: only the sodium line lights the scene, the
     * continuum bands see black (no ambient, black background).  (4, not
     * 1: the integrator refuses 1 and 2 -- "singular colour quadrature".) */
    ok = rc_render(&sc, RS_MODE_POLARIZED, NR_SIZE, NR_SIZE, 0, -1.0, 4, mask, &pic) == 0;
    CHECK(ok, "newtons_rings renders");
    if (!ok)
        goto out;

    /* The radial profile: the mean luminance of the pixels in bins of
     * equal width in r^2 (the fringes are periodic in r^2, period
     * lambda R), each bin placed at its pixels' mean r^2. */
    for (int j = 0; j < NR_SIZE; j++)
        for (int i = 0; i < NR_SIZE; i++) {
            size_t k = (size_t)j * NR_SIZE + i;
            if (!mask[k])
                continue;
            int b = (int)(r2[k] / NR_BIN);
            if (b >= nb)
                continue;
            sum[b] += rc_luminance(&pic, i, j);
            sum_r2[b] += r2[k];
            cnt[b]++;
        }
    double prof[1024], x[1024], peak = 0.0;
    int np = 0;
    for (int b = 0; b < nb && np < 1024; b++)
        if (cnt[b] > 0) {
            prof[np] = sum[b] / cnt[b];
            x[np] = sum_r2[b] / cnt[b];
            if (prof[np] > peak)
                peak = prof[np];
            np++;
        }
    CHECK(peak > 0.0, "newton%s: the rings are lit (peak %g)", tag, peak);

    /* Dark rings: local minima of the profile, each the lowest within a
     * sixth of a fringe period on either side, away from the central dark
     * spot (m = 0); located by a least-squares parabola through the +-5
     * bins around it. */
    double period = NR_LAMBDA * 1e-6 * NR_R;
    int half = (int)(period / 6.0 / NR_BIN);
    int found = 0;
    double rm[8], rmin[8];
    for (int k = half; k < np - half && found < 8; k++) {
        if (x[k] < 0.5 * period)
            continue;
        int is_min = 1;
        for (int q = k - half; q <= k + half; q++)
            if (prof[q] < prof[k])
                is_min = 0;
        if (!is_min)
            continue;
        double xm = x[k], xv;
        if (rc_parabola_min(x + k - 5, prof + k - 5, 11, &xv, NULL) == 0 && fabs(xv - x[k]) < 5.0 * NR_BIN)
            xm = xv;
        printf("newton: minimum %d at r^2 = %.4f mm^2, %.3f of the peak\n", found + 1, xm,
               prof[k] / peak);
        rmin[found] = prof[k];
        rm[found++] = sqrt(xm);
        k += half;
    }
    CHECK(found >= 5, "newton%s: found %d dark rings, want >= 5", tag, found);
    /* Fringe contrast.  At (near) normal incidence every face reflects
     * R = ((n-1)/(n+1))^2.  The two film reflections, off the convex face
     * (through the top face twice: (1-R)^2 R) and off the plate (through
     * two more faces: (1-R)^4 R), add as amplitudes (their path
     * difference, 2h < 4 um, is far inside the 0.3 mm coherence length);
     * the top face (R) and the plate's bottom face ((1-R)^6 R) are
     * millimetres of glass away and add as intensities.  So the dark and
     * bright rings are
     *     I = R + (1-R)^6 R + (sqrt((1-R)^2 R) -+ sqrt((1-R)^4 R))^2
     * times the ceiling's radiance.  Neglected: paths with three or more
     * reflections (< R^3 / R = 0.2 % of the background) and the ceiling's
     * non-uniformity (< 1e-3).  Checked to 0.3 %, those two bounds added;
     * measured 0.05 %. */
    if (found >= 1) {
        double rr = (n - 1) / (n + 1), R1 = rr * rr, t = 1 - R1;
        double a1 = sqrt(t * t * R1), a2 = sqrt(t * t * t * t * R1);
        double bg = R1 + pow(t, 6) * R1;
        double want = (bg + (a1 - a2) * (a1 - a2)) / (bg + (a1 + a2) * (a1 + a2));
        double worst = 0.0;
        for (int m = 0; m < found && m < 5; m++)
            worst = fmax(worst, fabs(rmin[m] / peak - want) / want);
        printf("newton: dark/bright ring ratio theory %.4f, worst deviation %.2f %%\n", want,
               100.0 * worst);
        for (int m = 0; m < found && m < 5; m++)
            CHECK_REL(rmin[m] / peak, want, 3e-3, "newton%s: dark ring m=%d / brightest", tag,
                      m + 1);
    }
    for (int m = 1; m <= 5 && m <= found; m++) {
        double want = sqrt(m * NR_LAMBDA * 1e-6 * NR_R);
        printf("newton: dark ring m=%d  r = %.4f mm  theory %.4f mm  error %+.3f %%\n", m,
               rm[m - 1], want, 100.0 * (rm[m - 1] - want) / want);
        /* Measured +0.001 .. +0.003 % (rings 1..5, both set-ups): the
         * sub-pixel fit on bins of r^2 (the pixel's chief ray, used to map
         * it to the film, neglects the film's own 1.5 um).  Checked at
         * 0.05 %, ten times under the +0.54 % of the per-pixel plane
         * wavefront above. */
        CHECK_REL(rm[m - 1], want, 5e-4, "newton%s: dark ring m=%d radius", tag, m);
    }
out:
    free(pic.rgb);
    free(mask);
    free(r2);
    free(sum);
    free(sum_r2);
    free(cnt);
    rs_scene_free(&sc);
}

/* ---- c, d. crossed polarizers -------------------------------------------- */

#define XP_SIZE 61
#define XP_ANGLE 16.0
#define XP_BOX 100.0

static const char *xp_scene_fmt =
    "global_settings { max_trace_level 6 adc_bailout 0.001 }\n"
    "camera { location <0, 0, -120> look_at <0, 0, 0> right x*image_width/image_height angle 16 }\n"
    "background { rgb 0 }\n"
    "%s"
    "disc { <0, 0, 80>, z, 35  pigment { rgb 1 } finish { ambient 0 diffuse 0 emission 100 } }\n";

static const char *xp_polarizers =
    "polarizer { center <0, 0, -30> normal <0, 0, 1> radius 40 axis <1, 0, 0> }\n"
    "polarizer { center <0, 0, 30> normal <0, 0, 1> radius 40 axis <0, 1, 0> }\n";

/* Crossed ideal polarizers (axes x and y, normal z) seen along unit d:
 * each passes the field component along its axis projected perpendicular
 * to d, a_perp = (a - (a.d) d) / |...|.  The two projected axes are no
 * longer orthogonal:
 *     x_perp . y_perp = -dx dy / sqrt((1 - dx^2)(1 - dy^2)),
 * so natural light (1/2 through the first) leaks
 *     L(d) = 1/2 dx^2 dy^2 / ((1 - dx^2)(1 - dy^2)).
 * (The dichroic-sheet form, the field perpendicular to the absorbing axis,
 * normalize(d x absorbing axis), gives the same value for a crossed pair.)
 * L grows with |dx| and |dy|, so the field's corner bounds it: with the
 * 16 degree field of a square image, 1.9e-4 of the box, under the 1e-3
 * the test allows every pixel.  Each pixel is also checked against L of
 * its own ray (1e-6 relative), and the box radiance it multiplies comes
 * from a render of the box alone.  L is symmetric in x and y, so here the
 * transposed pixel is exactly equal too (not so with the lens, below). */
static double crossed_leak(const double d[3])
{
    double x2 = d[0] * d[0], y2 = d[1] * d[1];
    return 0.5 * x2 * y2 / ((1.0 - x2) * (1.0 - y2));
}

static void test_crossed_no_lens(void)
{
    char text[2048];
    rs_scene sp, sb;
    rs_scene_init(&sp);
    rs_scene_init(&sb);
    picture pp = {0, 0, NULL}, pf = {0, 0, NULL}, pb = {0, 0, NULL};

    /* the bound over the whole field: the image corner (not a pixel
     * centre), d = normalize(R/2 + U/2 + D) */
    double dl = 1.0 / (2.0 * tan(XP_ANGLE * PI / 360.0));
    double nn = sqrt(0.5 + dl * dl);
    double corner[3] = {0.5 / nn, 0.5 / nn, dl / nn};
    double bound = crossed_leak(corner);
    printf("crossed polarizers: field corner at %.2f deg off axis, leak bound %.3e of the box\n",
           acos(corner[2]) * 180.0 / PI, bound);
    CHECK(bound < 1e-3, "crossed: the leak bound %g is below the 1e-3 tolerance", bound);

    snprintf(text, sizeof text, xp_scene_fmt, xp_polarizers);
    int ok = rc_load_scene(&sp, text, NULL, XP_SIZE, XP_SIZE) == 0;
    snprintf(text, sizeof text, xp_scene_fmt, "");
    ok = ok && rc_load_scene(&sb, text, NULL, XP_SIZE, XP_SIZE) == 0;
    CHECK(ok, "crossed polarizers: scenes load");
    if (!ok)
        goto out;
    ok = rc_render(&sp, RS_MODE_POLARIZED, XP_SIZE, XP_SIZE, 0, -1.0, 0, NULL, &pp) == 0 &&
         rc_render(&sp, RS_MODE_FRESNEL, XP_SIZE, XP_SIZE, 0, -1.0, 0, NULL, &pf) == 0 &&
         rc_render(&sb, RS_MODE_POLARIZED, XP_SIZE, XP_SIZE, 0, -1.0, 0, NULL, &pb) == 0;
    CHECK(ok, "crossed polarizers: renders");
    if (!ok)
        goto out;

    int lit = 0;
    double worst_leak = 0.0, worst_model = 0.0, worst_quarter = 0.0;
    for (int j = 0; j < XP_SIZE; j++)
        for (int i = 0; i < XP_SIZE; i++) {
            double d[3];
            camera_dir_z(XP_ANGLE, XP_SIZE, XP_SIZE, i, j, d);
            double leak = crossed_leak(d);
            for (int c = 0; c < 3; c++) {
                double box = rc_px(&pb, i, j, c), got = rc_px(&pp, i, j, c);
                if (box > 0.5 * XP_BOX)
                    lit++;
                /* c. black: below 1e-3 of the box everywhere */
                CHECK(got < 1e-3 * XP_BOX && got >= 0.0,
                      "crossed, polarized: pixel (%d,%d) ch %d = %g, box %g", i, j, c, got, box);
                if (got / XP_BOX > worst_leak)
                    worst_leak = got / XP_BOX;
                /* ... and exactly the ideal polarizers' oblique leak */
                CHECK_ABS(got, box * leak, 1e-6 * box * leak + 1e-12 * XP_BOX,
                          "crossed, polarized: pixel (%d,%d) ch %d vs oblique leak", i, j, c);
                if (box > 0.0 && leak > 0.0 && fabs(got - box * leak) / (box * leak) > worst_model)
                    worst_model = fabs(got - box * leak) / (box * leak);
                /* d. the unpolarized model: 1/2 * 1/2 of the box */
                double f = rc_px(&pf, i, j, c);
                CHECK_ABS(f, 0.25 * box, 1e-9 * XP_BOX,
                          "crossed, fresnel: pixel (%d,%d) ch %d is box/4", i, j, c);
                if (box > 0.5 * XP_BOX && fabs(f / box - 0.25) > worst_quarter)
                    worst_quarter = fabs(f / box - 0.25);
            }
        }
    lit /= 3;
    CHECK(lit > XP_SIZE * XP_SIZE / 4, "crossed: the box fills %d pixels", lit);
    printf("crossed, no lens: %d pixels see the box; polarized max %.3e of the box, "
           "max rel. deviation from the oblique leak %.1e; fresnel = box/4 to %.1e "
           "(the unpolarized model's failure: a real crossed pair is dark)\n",
           lit, worst_leak, worst_model, worst_quarter);
out:
    free(pp.rgb);
    free(pf.rgb);
    free(pb.rgb);
    rs_scene_free(&sp);
    rs_scene_free(&sb);
}

/* The lens between the crossed pair (scenes/crossed_polarizers.scene).
 * Light goes box -> polarizer P (z = +30, axis y) -> lens -> analyzer A
 * (z = -30, axis x) -> camera.  The camera sits on the lens axis, so every
 * camera ray is meridional: at azimuth phi, all its paths through the
 * rotationally symmetric lens stay in one plane and s (normal to it) and p
 * never mix; per path the lens is diag(t_s, t_p).  Let theta_c be the
 * camera ray's angle to the axis (at A) and theta_b the path's angle
 * between the lens and the box (at P), s_c = sin^2 theta_c,
 * s_b = sin^2 theta_b.  With the renderer's ideal polarizer (the axis
 * projected normal to the ray), P passes e_P = y_perp, |y_perp|^2 =
 * 1 - s_b sin^2 phi, with s and p components cos phi and cos theta_b
 * sin phi; A passes x_perp, |x_perp|^2 = 1 - s_c cos^2 phi, components
 * -sin phi and cos theta_c cos phi.  Natural light leaks
 *     L = 1/2 |x_perp . J y_perp|^2
 *       = 1/2 sin^2 phi cos^2 phi (t_p cos theta_b cos theta_c - t_s)^2 / D,
 *     D = (1 - s_b sin^2 phi)(1 - s_c cos^2 phi)
 * per path, summed incoherently.  (A dichroic sheet, passing the field
 * normal to its absorbing axis, gives the same form with
 * D = (1 - s_b cos^2 phi)(1 - s_c sin^2 phi).)  Everything but
 * sin^2 2phi / D is the same at every azimuth of one radius.  Hence:
 *   - mirror symmetry in x (phi -> pi - phi) and in y (phi -> -phi),
 *     exact;
 *   - the extinction cross: L = 0 at phi = 0 and 90 degrees;
 *   - at one radius L(phi1) / L(phi2) = [sin^2 2phi1 / sin^2 2phi2] *
 *     D(phi2) / D(phi1), with s_b somewhere in [0, s_max]: the ratio
 *     lies between its values at s_b = 0 and s_b = s_max (it is monotone
 *     in s_b, and a positive sum of paths stays in between), for either
 *     polarizer model.  s_max: a path from the lens's back cap (radius
 *     <= 10, z <= 6) to the light box (radius <= 35, z = 80) has
 *     tan theta_b <= 45 / 74.
 * Transposition (phi -> 90 deg - phi) is NOT a symmetry of this set-up:
 * it swaps the roles of P and A, and P sees the steep rays between the
 * lens and the box while A sees the camera's nearly axial ones; the ratio
 * is only bounded as above (it would be 1 if s_b = s_c, as without the
 * lens, where the transposition symmetry is exact and checked above via
 * the exact leak).  The pixel values compared are luminances, sums over
 * wavelengths with (nearly) the positive weights ybar, to which each
 * wavelength's bound applies. */
#define XP_SMAX_TAN (45.0 / 74.0)

static double xp_d(int dichroic, double sb, double sc, double phi)
{
    double c2 = cos(phi) * cos(phi), s2 = sin(phi) * sin(phi);
    return dichroic ? (1.0 - sb * c2) * (1.0 - sc * s2) : (1.0 - sb * s2) * (1.0 - sc * c2);
}

/* The interval of L(phi1)/L(phi2) at one radius (s_c), both models,
 * s_b in [0, s_max]. */
static void xp_ratio_bounds(double sc, double phi1, double phi2, double *lo, double *hi)
{
    double smax = XP_SMAX_TAN * XP_SMAX_TAN / (1.0 + XP_SMAX_TAN * XP_SMAX_TAN);
    double law = pow(sin(2 * phi1), 2) / pow(sin(2 * phi2), 2);
    *lo = INFINITY;
    *hi = -INFINITY;
    for (int m = 0; m < 2; m++)
        for (int e = 0; e < 2; e++) {
            double sb = e ? smax : 0.0;
            double r = law * xp_d(m, sb, sc, phi2) / xp_d(m, sb, sc, phi1);
            *lo = fmin(*lo, r);
            *hi = fmax(*hi, r);
        }
}

static void test_crossed_lens(void)
{
    char path[4096];
    rs_scene sc;
    rs_scene_init(&sc);
    picture p = {0, 0, NULL};
    const int N = XP_SIZE, c0 = XP_SIZE / 2;

    snprintf(path, sizeof path, "%s/scenes/crossed_polarizers.scene", LP_SOURCE_DIR);
    int ok = rc_load_scene(&sc, NULL, path, N, N) == 0;
    CHECK(ok, "crossed_polarizers.scene loads");
    if (!ok)
        goto out;
    ok = rc_render(&sc, RS_MODE_POLARIZED, N, N, 0, -1.0, 0, NULL, &p) == 0;
    CHECK(ok, "crossed_polarizers.scene renders");
    if (!ok)
        goto out;

    /* Mirror symmetry.  The camera rays of mirrored pixels are exact
     * mirror images (odd square image, right = x, up = y), so 1e-6
     * relative, with a floor of 1e-12 of the box for pixels that are
     * zero up to rounding (the dark cross). */
    double vmax = 0.0, worst_sym = 0.0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            vmax = fmax(vmax, rc_luminance(&p, i, j));
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            for (int c = 0; c < 3; c++) {
                double v = rc_px(&p, i, j, c);
                double other[2] = {rc_px(&p, N - 1 - i, j, c), rc_px(&p, i, N - 1 - j, c)};
                static const char *const name[2] = {"x-mirror", "y-mirror"};
                for (int s = 0; s < 2; s++) {
                    double big = fmax(fabs(v), fabs(other[s]));
                    CHECK_ABS(v, other[s], 1e-6 * big + 1e-12 * XP_BOX,
                              "lens leak %s symmetry at (%d,%d) ch %d", name[s], i, j, c);
                    if (big > 1e-6 * vmax && fabs(v - other[s]) / big > worst_sym)
                        worst_sym = fabs(v - other[s]) / big;
                }
            }

    /* The extinction cross: the central row and column are dark next to
     * the diagonal maximum; and the diagonals leak more than the crossed
     * pair alone can anywhere in the field (the lens turns the
     * polarization). */
    double diag_max = 0.0, axis_max = 0.0;
    for (int k = 0; k < N; k++) {
        diag_max = fmax(diag_max, fmax(rc_luminance(&p, k, k), rc_luminance(&p, k, N - 1 - k)));
        axis_max = fmax(axis_max, fmax(rc_luminance(&p, k, c0), rc_luminance(&p, c0, k)));
    }
    {
        double dl = 1.0 / (2.0 * tan(XP_ANGLE * PI / 360.0)), nn = sqrt(0.5 + dl * dl);
        double corner[3] = {0.5 / nn, 0.5 / nn, dl / nn};
        double bound = crossed_leak(corner) * XP_BOX;
        CHECK(diag_max > bound, "lens leak: the diagonals (max %g) leak more than the crossed "
              "pair alone can (%g)", diag_max, bound);
    }
    CHECK(axis_max < 1e-3 * diag_max, "lens leak: the polarizer axes are dark: %g vs diagonal %g",
          axis_max, diag_max);

    /* Azimuth law at equal radii: every lit pixel against its transpose,
     * and Pythagorean pairs (same i^2 + j^2) at different sin^2 2phi. */
    int pairs_checked = 0;
    double worst_transpose = 1.0, sb_eff = 0.0;
    for (int b = -c0; b <= c0; b++)
        for (int a = -c0; a <= c0; a++) {
            double l1 = rc_luminance(&p, c0 + a, c0 - b), l2 = rc_luminance(&p, c0 + b, c0 - a);
            if (a == 0 || b == 0 || a == b || a == -b || l1 < 1e-3 * vmax)
                continue;
            double d[3], lo, hi, phi = atan2((double)b, (double)a);
            camera_dir_z(XP_ANGLE, N, N, c0 + a, c0 - b, d);
            double scam = d[0] * d[0] + d[1] * d[1];
            xp_ratio_bounds(scam, phi, PI / 2 - phi, &lo, &hi);
            double r = l1 / l2;
            CHECK(l2 > 0.0 && r >= lo * (1 - 1e-9) && r <= hi * (1 + 1e-9),
                  "lens leak: (%d,%d) / transposed = %g, outside [%g, %g]", a, b, r, lo, hi);
            pairs_checked++;
            if (fabs(log(r)) > fabs(log(worst_transpose))) {
                /* the s_b that explains r in the projection model */
                double u = cos(phi) * cos(phi), v = 1.0 - u;
                double kappa = r * (1.0 - scam * u) / (1.0 - scam * v);
                worst_transpose = r;
                sb_eff = (1.0 - kappa) / (u - kappa * v);
            }
        }
    CHECK(pairs_checked > 20, "lens leak: %d transposed pairs checked", pairs_checked);
    printf("crossed, lens: transposition is not a symmetry here: worst L(phi)/L(90-phi) = %.4f "
           "(projection model: theta_b = %.1f deg between lens and box; bound %.1f deg)\n",
           worst_transpose, asin(sqrt(fmax(sb_eff, 0.0))) * 180.0 / PI,
           atan(XP_SMAX_TAN) * 180.0 / PI);

    static const int pairs[][4] = {{5, 5, 7, 1}, {7, 4, 8, 1}, {4, 3, 5, 0}, {5, 5, 1, 7}};
    for (size_t q = 0; q < sizeof pairs / sizeof *pairs; q++) {
        int a = pairs[q][0], b = pairs[q][1], e = pairs[q][2], f = pairs[q][3];
        double phi1 = atan2((double)b, (double)a), phi2 = atan2((double)f, (double)e);
        double l1 = rc_luminance(&p, c0 + a, c0 - b), l2 = rc_luminance(&p, c0 + e, c0 - f);
        double d[3], lo, hi;
        camera_dir_z(XP_ANGLE, N, N, c0 + a, c0 - b, d);
        CHECK(l1 > l2, "lens leak: (%d,%d) nearer the diagonal is brighter than (%d,%d): %g vs %g",
              a, b, e, f, l1, l2);
        if (f != 0) {
            xp_ratio_bounds(d[0] * d[0] + d[1] * d[1], phi1, phi2, &lo, &hi);
            printf("lens leak (%+d,%+d) / (%+d,%+d) = %.4f, sin^2 2phi law with obliquity "
                   "[%.4f, %.4f]\n", a, b, e, f, l1 / l2, lo, hi);
            CHECK(l1 / l2 >= lo * (1 - 1e-9) && l1 / l2 <= hi * (1 + 1e-9),
                  "lens leak (%d,%d)/(%d,%d) = %g outside the azimuth law [%g, %g]", a, b, e, f,
                  l1 / l2, lo, hi);
        } else {
            printf("lens leak (%+d,%+d) = %.4e, on the axis (%+d,%+d) = %.4e\n", a, b, l1, e, f,
                   l2);
        }
    }
    printf("crossed, lens: diagonal max %.4e (%.2e of the box), axis max %.3e (ratio %.2e), "
           "worst mirror-symmetry error %.2e\n",
           diag_max, diag_max / XP_BOX, axis_max, axis_max / diag_max, worst_sym);
out:
    free(p.rgb);
    rs_scene_free(&sc);
}

/* ---- e. the rim's shadow ------------------------------------------------- */

static const char *rim_shadow_scene =
    "camera { location <0, 0, -60> direction <0, 0, 1> right <1.5, 0, 0> up <0, 1, 0> }\n"
    "light_source { <70, 8, -30> color rgb 1 }\n"
    "plane { z, 30 pigment { rgb 1 } finish { ambient 0 diffuse 1 } }\n"
    "lens { radius1 inf radius2 inf thickness 5 diameter 20 ior 1.5 }\n";

#define RS_W 96
#define RS_H 64
#define RS_RIM_R 10.0
#define RS_RIM_Z1 5.0
#define RS_WALL_Z 30.0

/* The camera ray of pixel (i, j) of rim_shadow_scene (explicit vectors:
 * dir = D + ((i+0.5)/W - 0.5) R + (0.5 - (j+0.5)/H) U, unnormalized). */
static void rim_shadow_ray(int i, int j, double d[3])
{
    d[0] = ((i + 0.5) / RS_W - 0.5) * 1.5;
    d[1] = 0.5 - (j + 0.5) / RS_H;
    d[2] = 1.0;
}

/* Where the line o + s u, s in (0, 1), meets the cylinder x^2 + y^2 = r^2
 * with z in [z0, z1]: returns 1 (shadow), 0 (none), -1 (too close to an
 * edge of the rim to call). */
static int segment_meets_cylinder(const double o[3], const double u[3])
{
    double a = u[0] * u[0] + u[1] * u[1];
    double b = o[0] * u[0] + o[1] * u[1];
    double c = o[0] * o[0] + o[1] * o[1] - RS_RIM_R * RS_RIM_R;
    double disc = b * b - a * c;
    int hit = 0;
    if (a == 0.0 || disc < 0.0)
        return 0;
    if (disc < 1e-9 * a * RS_RIM_R * RS_RIM_R)
        return -1; /* grazing */
    for (int k = -1; k <= 1; k += 2) {
        double s = (-b + k * sqrt(disc)) / a;
        double z = o[2] + s * u[2];
        if (!(s > 0.0 && s < 1.0))
            continue;
        if (fabs(z) < 1e-6 || fabs(z - RS_RIM_Z1) < 1e-6)
            return -1;
        if (z > 0.0 && z < RS_RIM_Z1)
            hit = 1;
    }
    return hit;
}

static void test_rim_shadow(void)
{
    const double light[3] = {70.0, 8.0, -30.0};
    rs_scene sc;
    picture p = {0, 0, NULL};
    int checked = 0, dark = 0, through_cap = 0, wrong = 0;
    unsigned char mask[RS_W * RS_H];

    rs_scene_init(&sc);
    if (rc_load_scene(&sc, rim_shadow_scene, NULL, RS_W, RS_H) != 0) {
        CHECK(0, "rim shadow scene");
        goto out;
    }
    /* Only wall pixels seen directly: the camera ray must miss the plate's
     * cylinder r <= 10 over z in [0, 5]. */
    for (int j = 0; j < RS_H; j++)
        for (int i = 0; i < RS_W; i++) {
            double d[3], r0, r1;
            rim_shadow_ray(i, j, d);
            r0 = hypot(d[0] * 60.0, d[1] * 60.0);
            r1 = hypot(d[0] * 65.0, d[1] * 65.0);
            mask[j * RS_W + i] = r0 > RS_RIM_R + 0.5 && r1 > RS_RIM_R + 0.5;
        }
    if (rc_render(&sc, RS_MODE_FRESNEL, RS_W, RS_H, 0, 0.0, 4, mask, &p) != 0) {
        CHECK(0, "rim shadow render");
        goto out;
    }
    for (int j = 0; j < RS_H; j++)
        for (int i = 0; i < RS_W; i++) {
            double d[3], o[3], u[3], s;
            int expect;
            if (!mask[j * RS_W + i])
                continue;
            rim_shadow_ray(i, j, d);
            s = (RS_WALL_Z + 60.0) / d[2];
            o[0] = d[0] * s, o[1] = d[1] * s, o[2] = RS_WALL_Z;
            for (int k = 0; k < 3; k++)
                u[k] = light[k] - o[k];
            expect = segment_meets_cylinder(o, u);
            if (expect < 0)
                continue;
            checked++;
            if (expect) {
                /* Does the segment cross the back cap (z = 5, r < 10) first? */
                double sb = (RS_RIM_Z1 - o[2]) / u[2];
                double xb = o[0] + sb * u[0], yb = o[1] + sb * u[1];
                dark++;
                through_cap += hypot(xb, yb) < RS_RIM_R;
            }
            if ((rc_luminance(&p, i, j) > 0.0) == expect)
                wrong++;
        }
    /* Measured: 5752 wall pixels called, 377 dark, 282 of them reached
     * through the back cap, 0 wrong (a shadow test that looks only at the
     * lens's first hit gets those 282 wrong). */
    CHECK(checked > 3000, "rim shadow: %d pixels called", checked);
    CHECK(dark > 100, "rim shadow: %d dark", dark);
    CHECK(through_cap > 50, "rim shadow: %d through the cap", through_cap);
    CHECK(wrong == 0, "rim shadow: %d pixels wrong", wrong);
    printf("rim shadow: %d wall pixels, %d in the rim's shadow (%d through the back cap), "
           "%d wrong\n", checked, dark, through_cap, wrong);
out:
    free(p.rgb);
    rs_scene_free(&sc);
}

int main(void)
{
    test_plate();
    test_newtons_rings(0.0, 0.0);
    test_newtons_rings(5.0, 0.0);
    test_crossed_no_lens();
    test_crossed_lens();
    test_rim_shadow();
    return check_finish("test_render_physics");
}
