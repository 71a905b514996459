/* test_camera.c -- POV-Ray 3.7's perspective camera: the vectors after
 * up/right/angle/look_at/sky/transforms, and the primary ray of known
 * pixels, against values worked out by hand below (left-handed
 * coordinates: x right, y up, z into the screen).
 *
 * The rules (POV-Ray 3.7, Parse_Camera, verified against its sources):
 *   angle A:  D = normalize(D) |R| / (2 tan(A/2))
 *   look_at:  D = |D| normalize(P - location);  R' = sky x D^ (kept right
 *             when D || sky);  U = |U| (D^ x R'^);  R = +-|R| R'^ with the
 *             sign of (U x D) . R taken before look_at
 *   pixel:    dir = D + ((i+0.5)/W - 0.5) R + (0.5 - (j+0.5)/H) U
 */
#include <math.h>
#include <string.h>

#include "camera.h"
#include "check.h"
#include "splitmix.h"
#include "scene.h"

#define TOL 1e-14

static lp_vec3 v3(double x, double y, double z)
{
    lp_vec3 r = { x, y, z };
    return r;
}

static lp_vec3 unit(lp_vec3 a)
{
    double l = sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
    return v3(a.x / l, a.y / l, a.z / l);
}

static double dot(lp_vec3 a, lp_vec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

#define CHECK_VEC(got, want, tol, ...)                                         \
    do {                                                                       \
        lp_vec3 g_ = (got), w_ = (want);                                       \
        char what_[400];                                                       \
        snprintf(what_, sizeof what_, __VA_ARGS__);                            \
        CHECK_ABS(g_.x, w_.x, (tol), "%s .x", what_);                          \
        CHECK_ABS(g_.y, w_.y, (tol), "%s .y", what_);                          \
        CHECK_ABS(g_.z, w_.z, (tol), "%s .z", what_);                          \
    } while (0)

/* POV-Ray's defaults, written out here (not taken from the code). */
static rs_camera pov_default(void)
{
    rs_camera c;
    memset(&c, 0, sizeof c);
    c.location = v3(0, 0, 0);
    c.direction = v3(0, 0, 1);
    c.right = v3(1.33, 0, 0);
    c.up = v3(0, 1, 0);
    c.sky = v3(0, 1, 0);
    c.look_at = v3(0, 0, 1);
    c.has_look_at = 0;
    c.angle = 0;
    c.has_angle = 0;
    rs_transform_identity(&c.xf);
    c.has_xf = 0;
    return c;
}

static int setup(const rs_camera *c, int w, int h, rs_view *v)
{
    char msg[256] = "";
    int rc = rs_camera_setup(c, w, h, v, msg, sizeof msg);
    if (rc != 0)
        fprintf(stderr, "unexpected camera error: %s\n", msg);
    return rc;
}

static void check_ray(const rs_view *v, double px, double py, int w, int h,
                      lp_vec3 want_unnormalized, const char *what)
{
    lp_vec3 o, d;
    rs_camera_ray(v, px, py, w, h, &o, &d);
    CHECK_VEC(o, v->location, 0.0, "%s: origin", what);
    CHECK_VEC(d, unit(want_unnormalized), TOL, "%s: direction", what);
    CHECK_ABS(dot(d, d), 1.0, 1e-15, "%s: |dir|", what);
}

static void check_frame_orthogonal(const rs_view *v, const char *what)
{
    double ld = sqrt(dot(v->D, v->D)), lr = sqrt(dot(v->R, v->R)),
           lu = sqrt(dot(v->U, v->U));
    CHECK_ABS(dot(v->D, v->R) / (ld * lr), 0.0, 1e-15, "%s: D.R", what);
    CHECK_ABS(dot(v->D, v->U) / (ld * lu), 0.0, 1e-15, "%s: D.U", what);
    CHECK_ABS(dot(v->R, v->U) / (lr * lu), 0.0, 1e-15, "%s: R.U", what);
}

static void test_scene_defaults(void)
{
    rs_scene s;
    rs_scene_init(&s);
    CHECK_VEC(s.camera.location, v3(0, 0, 0), 0.0, "rs_scene_init: location");
    CHECK_VEC(s.camera.direction, v3(0, 0, 1), 0.0, "rs_scene_init: direction");
    CHECK_VEC(s.camera.right, v3(1.33, 0, 0), 0.0, "rs_scene_init: right");
    CHECK_VEC(s.camera.up, v3(0, 1, 0), 0.0, "rs_scene_init: up");
    CHECK_VEC(s.camera.sky, v3(0, 1, 0), 0.0, "rs_scene_init: sky");
    CHECK(!s.camera.has_look_at && !s.camera.has_angle && !s.camera.has_xf,
          "rs_scene_init: no look_at, angle or transform");
    rs_scene_free(&s);
}

/* The default camera, 640x480: D = z, R = 1.33 x, U = y. */
static void test_default(void)
{
    rs_camera c = pov_default();
    rs_view v;
    CHECK(setup(&c, 640, 480, &v) == 0, "default camera sets up");
    CHECK_VEC(v.location, v3(0, 0, 0), 0.0, "default: location");
    CHECK_VEC(v.D, v3(0, 0, 1), 0.0, "default: D");
    CHECK_VEC(v.R, v3(1.33, 0, 0), 0.0, "default: R");
    CHECK_VEC(v.U, v3(0, 1, 0), 0.0, "default: U");

    /* image centre (not a pixel centre for an even size) */
    check_ray(&v, 320, 240, 640, 480, v3(0, 0, 1), "default: image centre");
    /* top-left pixel (0,0): px 0.5 -> 0.5/640 - 0.5 = -0.49921875, times
     * 1.33 = -0.6639609375; py 0.5 -> 0.5 - 0.5/480 = 0.498958333... */
    check_ray(&v, 0.5, 0.5, 640, 480, v3(-0.6639609375, 0.5 - 1.0 / 960.0, 1),
              "default: pixel (0,0)");
    /* bottom-right pixel (639,479) */
    check_ray(&v, 639.5, 479.5, 640, 480, v3(0.6639609375, -0.5 + 1.0 / 960.0, 1),
              "default: pixel (639,479)");
    /* top-right pixel (639,0) and bottom-left (0,479) */
    check_ray(&v, 639.5, 0.5, 640, 480, v3(0.6639609375, 0.5 - 1.0 / 960.0, 1),
              "default: pixel (639,0)");
    check_ray(&v, 0.5, 479.5, 640, 480, v3(-0.6639609375, -0.5 + 1.0 / 960.0, 1),
              "default: pixel (0,479)");
    /* centre pixel (320,240): x = 1.33 * 0.5/640 = 0.0010390625,
     * y = 0.5 - 240.5/480 = -1/960 */
    check_ray(&v, 320.5, 240.5, 640, 480, v3(0.0010390625, -1.0 / 960.0, 1),
              "default: pixel (320,240)");
    /* image corners */
    check_ray(&v, 0, 0, 640, 480, v3(-0.665, 0.5, 1), "default: top-left corner");
    check_ray(&v, 640, 480, 640, 480, v3(0.665, -0.5, 1), "default: bottom-right corner");
}

/* location <0,0,-5> look_at 0, right x*4/3, angle 90:
 * |D| = (4/3) / (2 tan 45) = 2/3, so the image spans x in [-1,1] at z = 1. */
static void test_look_at_angle(void)
{
    rs_camera c = pov_default();
    rs_view v;
    c.location = v3(0, 0, -5);
    c.look_at = v3(0, 0, 0);
    c.has_look_at = 1;
    c.right = v3(4.0 / 3.0, 0, 0);
    c.angle = 90;
    c.has_angle = 1;
    CHECK(setup(&c, 640, 480, &v) == 0, "look_at+angle sets up");
    CHECK_VEC(v.location, v3(0, 0, -5), 0.0, "look_at+angle: location");
    CHECK_VEC(v.D, v3(0, 0, 2.0 / 3.0), TOL, "look_at+angle: D");
    CHECK_VEC(v.R, v3(4.0 / 3.0, 0, 0), TOL, "look_at+angle: R (image x is +x)");
    CHECK_VEC(v.U, v3(0, 1, 0), TOL, "look_at+angle: U");
    /* top-left corner: (-2/3, 1/2, 2/3) ~ (-4, 3, 4) */
    check_ray(&v, 0, 0, 640, 480, v3(-4, 3, 4), "look_at+angle: top-left corner");
    /* middle of the right edge: (2/3, 0, 2/3): 45 degrees */
    check_ray(&v, 640, 240, 640, 480, v3(1, 0, 1), "look_at+angle: right edge");
    check_ray(&v, 0, 240, 640, 480, v3(-1, 0, 1), "look_at+angle: left edge");
    /* pixel (639,0): x = 4/3 * 0.49921875 = 0.665625 */
    check_ray(&v, 639.5, 0.5, 640, 480, v3(0.665625, 0.5 - 1.0 / 960.0, 2.0 / 3.0),
              "look_at+angle: pixel (639,0)");
    /* the camera looks at the origin through the image centre */
    check_ray(&v, 320, 240, 640, 480, v3(0, 0, 1), "look_at+angle: centre");

    /* The same with the keywords' lengths varied: |D| from the angle,
     * |U| kept: up <0,2,0> gives U = (0,2,0). */
    c.up = v3(0, 2, 0);
    CHECK(setup(&c, 640, 480, &v) == 0, "look_at+angle, up 2y sets up");
    CHECK_VEC(v.U, v3(0, 2, 0), TOL, "look_at+angle, up 2y: U keeps |U|");
    CHECK_VEC(v.D, v3(0, 0, 2.0 / 3.0), TOL, "look_at+angle, up 2y: D");
}

/* angle without look_at; the default right 1.33:
 * |D| = 1.33 / (2 tan 30) = 1.33 sqrt(3) / 2. */
static void test_angle_only(void)
{
    rs_camera c = pov_default();
    rs_view v;
    c.angle = 60;
    c.has_angle = 1;
    CHECK(setup(&c, 320, 240, &v) == 0, "angle 60 sets up");
    CHECK_VEC(v.D, v3(0, 0, 1.33 * sqrt(3.0) / 2.0), TOL, "angle 60: D");
    CHECK_VEC(v.R, v3(1.33, 0, 0), 0.0, "angle 60: R unchanged");
    /* The half width of the image subtends 30 degrees. */
    {
        lp_vec3 o, d;
        rs_camera_ray(&v, 320, 120, 320, 240, &o, &d);
        CHECK_ABS(atan2(d.x, d.z) * 180.0 / 3.14159265358979323846, 30.0, 1e-12,
                  "angle 60: right edge at 30 degrees");
    }
    /* direction's length does not matter with angle: normalised first */
    c.direction = v3(0, 0, 5);
    CHECK(setup(&c, 320, 240, &v) == 0, "angle 60, direction 5z sets up");
    CHECK_VEC(v.D, v3(0, 0, 1.33 * sqrt(3.0) / 2.0), TOL, "angle 60, direction 5z: D");
    /* angle 0 leaves direction alone (POV-Ray applies only A > 0) */
    c.angle = 0;
    CHECK(setup(&c, 320, 240, &v) == 0, "angle 0 sets up");
    CHECK_VEC(v.D, v3(0, 0, 5), 0.0, "angle 0: D untouched");
}

/* Looking along -x from <5,0,0>: R' = y x (-x) = +z, U = (-x) x z = +y. */
static void test_side(void)
{
    rs_camera c = pov_default();
    rs_view v;
    c.location = v3(5, 0, 0);
    c.look_at = v3(0, 0, 0);
    c.has_look_at = 1;
    CHECK(setup(&c, 640, 480, &v) == 0, "side view sets up");
    CHECK_VEC(v.D, v3(-1, 0, 0), TOL, "side view: D");
    CHECK_VEC(v.R, v3(0, 0, 1.33), TOL, "side view: R = +z");
    CHECK_VEC(v.U, v3(0, 1, 0), TOL, "side view: U");
    check_ray(&v, 640, 0, 640, 480, v3(-1, 0.5, 0.665), "side view: top-right corner");
}

/* Straight down: D || sky, so POV-Ray keeps the supplied right (1.33 x):
 * U = (-y) x x = +z. */
static void test_down(void)
{
    rs_camera c = pov_default();
    rs_view v;
    c.location = v3(0, 5, 0);
    c.look_at = v3(0, 0, 0);
    c.has_look_at = 1;
    CHECK(setup(&c, 640, 480, &v) == 0, "down view sets up");
    CHECK_VEC(v.D, v3(0, -1, 0), TOL, "down view: D");
    CHECK_VEC(v.R, v3(1.33, 0, 0), TOL, "down view: R kept");
    CHECK_VEC(v.U, v3(0, 0, 1), TOL, "down view: U = +z");
    /* with a kept right that is not perpendicular to D, U = |U| (D^ x R^)
     * is not renormalised: right <1,1,0>, D = -y: U = (-y) x (x+y)/sqrt2
     * = z/sqrt2 */
    c.right = v3(1, 1, 0);
    CHECK(setup(&c, 640, 480, &v) == 0, "down view, oblique right sets up");
    CHECK_VEC(v.U, v3(0, 0, 1.0 / sqrt(2.0)), TOL, "down view, oblique right: U");
    CHECK_VEC(v.R, v3(1, 1, 0), TOL, "down view, oblique right: R kept");
}

/* sky x: R' = x x z = -y, U = z x (-y) = +x. */
static void test_sky(void)
{
    rs_camera c = pov_default();
    rs_view v;
    c.location = v3(0, 0, -5);
    c.look_at = v3(0, 0, 0);
    c.has_look_at = 1;
    c.sky = v3(1, 0, 0);
    CHECK(setup(&c, 640, 480, &v) == 0, "sky x sets up");
    CHECK_VEC(v.D, v3(0, 0, 1), TOL, "sky x: D");
    CHECK_VEC(v.R, v3(0, -1.33, 0), TOL, "sky x: R = -y");
    CHECK_VEC(v.U, v3(1, 0, 0), TOL, "sky x: U = +x");
    check_ray(&v, 0, 0, 640, 480, v3(0.5, 0.665, 1), "sky x: top-left corner");

    /* sky's length does not matter */
    c.sky = v3(0, 7, 0);
    CHECK(setup(&c, 640, 480, &v) == 0, "sky 7y sets up");
    CHECK_VEC(v.R, v3(1.33, 0, 0), TOL, "sky 7y: R");
    CHECK_VEC(v.U, v3(0, 1, 0), TOL, "sky 7y: U");

    /* tilted sky <1,1,0>: R' = (x+y) x z = (1,-1,0), R^ = (1,-1,0)/sqrt2,
     * U = z x R^ = (1,1,0)/sqrt2 */
    c.sky = v3(1, 1, 0);
    CHECK(setup(&c, 640, 480, &v) == 0, "sky x+y sets up");
    CHECK_VEC(v.R, v3(1.33 / sqrt(2.0), -1.33 / sqrt(2.0), 0), TOL, "sky x+y: R");
    CHECK_VEC(v.U, v3(1.0 / sqrt(2.0), 1.0 / sqrt(2.0), 0), TOL, "sky x+y: U");
}

/* A mirrored right flips the image left-right, with and without look_at. */
static void test_mirror(void)
{
    rs_camera c = pov_default();
    rs_view v;
    c.right = v3(-1.33, 0, 0);
    CHECK(setup(&c, 640, 480, &v) == 0, "mirror sets up");
    CHECK_VEC(v.R, v3(-1.33, 0, 0), 0.0, "mirror: R");
    check_ray(&v, 0.5, 0.5, 640, 480, v3(0.6639609375, 0.5 - 1.0 / 960.0, 1),
              "mirror: pixel (0,0) looks to +x");

    /* with look_at: (U x D) . R = (y x z) . (-4/3 x) < 0, so
     * R = -|R| normalize(sky x D) = (-4/3, 0, 0); U stays +y */
    c.location = v3(0, 0, -5);
    c.look_at = v3(0, 0, 0);
    c.has_look_at = 1;
    c.right = v3(-4.0 / 3.0, 0, 0);
    CHECK(setup(&c, 640, 480, &v) == 0, "mirror+look_at sets up");
    CHECK_VEC(v.R, v3(-4.0 / 3.0, 0, 0), TOL, "mirror+look_at: R");
    CHECK_VEC(v.U, v3(0, 1, 0), TOL, "mirror+look_at: U not flipped");
    CHECK_VEC(v.D, v3(0, 0, 1), TOL, "mirror+look_at: D");

    /* mirrored, looking from the side: R = -1.33 (y x -x) = -1.33 z */
    c.location = v3(5, 0, 0);
    c.right = v3(-1.33, 0, 0);
    CHECK(setup(&c, 640, 480, &v) == 0, "mirror side sets up");
    CHECK_VEC(v.R, v3(0, 0, -1.33), TOL, "mirror side: R");

    /* POV-Ray's sign test is "> 0": an up parallel to direction makes it
     * zero and flips right too. */
    c = pov_default();
    c.location = v3(0, 0, -5);
    c.look_at = v3(0, 0, 0);
    c.has_look_at = 1;
    c.up = v3(0, 0, 1);
    CHECK(setup(&c, 640, 480, &v) == 0, "up || direction + look_at sets up");
    CHECK_VEC(v.R, v3(-1.33, 0, 0), TOL, "up || direction + look_at: R flipped");
    CHECK_VEC(v.U, v3(0, 1, 0), TOL, "up || direction + look_at: U");
}

/* right x*W/H and an oblique look_at (the comparison scene's camera):
 * location <0,6,-5>, look_at 0, angle 40.  D^ = (0,-6,5)/sqrt61,
 * R^ = y x D^ = (5,0,0)/sqrt61 -> x, U = D^ x x = (0,5,6)/sqrt61,
 * |D| = (4/3)/(2 tan 20). */
static void test_oblique(void)
{
    rs_camera c = pov_default();
    rs_view v;
    double s61 = sqrt(61.0), dl = (4.0 / 3.0) / (2.0 * tan(20.0 * 3.14159265358979323846 / 180.0));
    c.location = v3(0, 6, -5);
    c.look_at = v3(0, 0, 0);
    c.has_look_at = 1;
    c.right = v3(640.0 / 480.0, 0, 0);
    c.angle = 40;
    c.has_angle = 1;
    CHECK(setup(&c, 640, 480, &v) == 0, "oblique sets up");
    CHECK_VEC(v.D, v3(0, -6 * dl / s61, 5 * dl / s61), TOL, "oblique: D");
    CHECK_VEC(v.R, v3(4.0 / 3.0, 0, 0), TOL, "oblique: R");
    CHECK_VEC(v.U, v3(0, 5 / s61, 6 / s61), TOL, "oblique: U");
    check_frame_orthogonal(&v, "oblique");
    check_ray(&v, 320, 240, 640, 480, v3(0, -6, 5), "oblique: centre looks at the origin");
    /* top-left corner: D - R/2 + U/2 */
    check_ray(&v, 0, 0, 640, 480,
              v3(-2.0 / 3.0, -6 * dl / s61 + 2.5 / s61, 5 * dl / s61 + 3 / s61),
              "oblique: top-left corner");

    /* direction's own length is kept by look_at (no angle):
     * direction <0,0,2> -> |D| = 2 */
    c.has_angle = 0;
    c.direction = v3(0, 0, 2);
    CHECK(setup(&c, 640, 480, &v) == 0, "oblique, direction 2z sets up");
    CHECK_VEC(v.D, v3(0, -12 / s61, 10 / s61), TOL, "oblique, direction 2z: D");
    check_frame_orthogonal(&v, "oblique, direction 2z");
}

/* Transforms apply after look_at: location as a point, vectors as
 * directions. */
static void test_transform(void)
{
    rs_camera c = pov_default();
    rs_view v;

    /* translate <0,0,5> after location <0,0,-5> look_at 0 */
    c.location = v3(0, 0, -5);
    c.look_at = v3(0, 0, 0);
    c.has_look_at = 1;
    rs_transform_identity(&c.xf);
    c.xf.t[0] = 1;
    c.xf.t[1] = 2;
    c.xf.t[2] = 5;
    c.xf.inv_t[0] = -1;
    c.xf.inv_t[1] = -2;
    c.xf.inv_t[2] = -5;
    c.has_xf = 1;
    CHECK(setup(&c, 640, 480, &v) == 0, "translated camera sets up");
    CHECK_VEC(v.location, v3(1, 2, 0), 0.0, "translate: location");
    CHECK_VEC(v.D, v3(0, 0, 1), TOL, "translate: D unchanged");
    CHECK_VEC(v.R, v3(1.33, 0, 0), TOL, "translate: R unchanged");

    /* POV-Ray's rotate <0,90,0> (left-hand rule about +y) takes +z to +x
     * and +x to -z: x' = z, z' = -x.  Built by hand ... */
    c = pov_default();
    rs_transform_identity(&c.xf);
    memset(c.xf.m, 0, sizeof c.xf.m);
    c.xf.m[0][2] = 1;
    c.xf.m[1][1] = 1;
    c.xf.m[2][0] = -1;
    memset(c.xf.inv_m, 0, sizeof c.xf.inv_m);
    c.xf.inv_m[0][2] = -1;
    c.xf.inv_m[1][1] = 1;
    c.xf.inv_m[2][0] = 1;
    c.has_xf = 1;
    CHECK(setup(&c, 640, 480, &v) == 0, "rotated camera sets up");
    CHECK_VEC(v.D, v3(1, 0, 0), TOL, "rotate y 90: D = +x");
    CHECK_VEC(v.R, v3(0, 0, -1.33), TOL, "rotate y 90: R = -z");
    CHECK_VEC(v.U, v3(0, 1, 0), TOL, "rotate y 90: U");

    /* ... and with the scene's own rotate, which must agree. */
    {
        rs_camera c2 = pov_default();
        rs_view v2;
        rs_transform_identity(&c2.xf);
        CHECK(rs_transform_rotate(&c2.xf, v3(0, 90, 0)) != 0, "rs_transform_rotate ok");
        c2.has_xf = 1;
        CHECK(setup(&c2, 640, 480, &v2) == 0, "camera rotated by rs_transform_rotate sets up");
        CHECK_VEC(v2.D, v3(1, 0, 0), 1e-15, "rs_transform_rotate <0,90,0>: D = +x");
        CHECK_VEC(v2.R, v3(0, 0, -1.33), 1e-15, "rs_transform_rotate <0,90,0>: R = -z");
        CHECK_VEC(v2.U, v3(0, 1, 0), 1e-15, "rs_transform_rotate <0,90,0>: U");
    }

    /* scale <2,2,2> scales the vectors (the field of view is unchanged). */
    c = pov_default();
    rs_transform_identity(&c.xf);
    for (int k = 0; k < 3; k++) {
        c.xf.m[k][k] = 2;
        c.xf.inv_m[k][k] = 0.5;
    }
    c.location = v3(1, 1, 1);
    c.has_xf = 1;
    CHECK(setup(&c, 640, 480, &v) == 0, "scaled camera sets up");
    CHECK_VEC(v.location, v3(2, 2, 2), 0.0, "scale 2: location");
    CHECK_VEC(v.D, v3(0, 0, 2), 0.0, "scale 2: D");
    check_ray(&v, 0.5, 0.5, 640, 480, v3(-0.6639609375, 0.5 - 1.0 / 960.0, 1),
              "scale 2: pixel (0,0) unchanged");
}

static void expect_error(const rs_camera *c, int w, int h, const char *what)
{
    rs_view v, before;
    char msg[256] = "";
    memset(&v, 0x5a, sizeof v);
    before = v;
    CHECK(rs_camera_setup(c, w, h, &v, msg, sizeof msg) == -1, "%s: rejected", what);
    CHECK(msg[0] != '\0', "%s: message given", what);
    CHECK(memcmp(&v, &before, sizeof v) == 0, "%s: output untouched", what);
    CHECK(strchr(msg, '\n') == NULL, "%s: one-line message", what);
}

static void test_errors(void)
{
    rs_camera c;

    c = pov_default();
    c.location = v3(1, 2, 3);
    c.look_at = v3(1, 2, 3);
    c.has_look_at = 1;
    expect_error(&c, 320, 240, "look_at == location");

    c = pov_default();
    c.direction = v3(0, 0, 0);
    expect_error(&c, 320, 240, "zero direction");
    c.angle = 60;
    c.has_angle = 1;
    expect_error(&c, 320, 240, "zero direction with angle");

    c = pov_default();
    c.right = v3(0, 0, 0);
    expect_error(&c, 320, 240, "zero right");

    c = pov_default();
    c.up = v3(0, 0, 0);
    expect_error(&c, 320, 240, "zero up");

    c = pov_default();
    c.up = v3(2, 0, 0);
    expect_error(&c, 320, 240, "up parallel to right");

    c = pov_default();
    c.direction = v3(1, 1, 0);
    expect_error(&c, 320, 240, "direction in the plane of right and up");

    c = pov_default();
    c.angle = 180;
    c.has_angle = 1;
    expect_error(&c, 320, 240, "angle 180");
    c.angle = -1;
    expect_error(&c, 320, 240, "negative angle");
    c.angle = NAN;
    expect_error(&c, 320, 240, "angle NaN");

    c = pov_default();
    c.location = v3(0, INFINITY, 0);
    expect_error(&c, 320, 240, "infinite location");

    /* straight down with a kept right parallel to the view: no up left */
    c = pov_default();
    c.location = v3(0, 5, 0);
    c.look_at = v3(0, 0, 0);
    c.has_look_at = 1;
    c.right = v3(0, 1, 0);
    expect_error(&c, 320, 240, "kept right parallel to the view");

    c = pov_default();
    expect_error(&c, 0, 240, "width 0");
    expect_error(&c, 320, -3, "height -3");

    c = pov_default();
    rs_transform_identity(&c.xf);
    c.xf.m[2][2] = 0; /* a singular transform flattens direction */
    c.has_xf = 1;
    expect_error(&c, 320, 240, "singular camera transform");

    /* NULL message buffer is allowed */
    c = pov_default();
    c.right = v3(0, 0, 0);
    {
        rs_view v;
        CHECK(rs_camera_setup(&c, 320, 240, &v, NULL, 0) == -1, "error with no message buffer");
    }
}

/* Focal blur: aperture rays start on the lens disk (radius aperture/2,
 * perpendicular to D, centred on the location) and all pass through the
 * pixel's point in focus, location + F dir with F = |focal_point -
 * location|; a pinhole's one ray is the primary ray. */
static void test_aperture(void)
{
    rs_camera c = pov_default();
    rs_view v;
    lp_vec3 o0, d0, o, d;
    c.location = v3(1, 2, 3);
    c.focal_point = v3(1, 2, 13);
    c.aperture = 2.0;
    c.blur_samples = 9;
    CHECK(setup(&c, 320, 240, &v) == 0, "aperture camera sets up");
    CHECK(v.samples == 9, "blur_samples 9: %d rays", v.samples);
    CHECK_ABS(v.focal_distance, 10.0, 1e-15, "focal distance");
    rs_camera_ray(&v, 40.5, 200.5, 320, 240, &o0, &d0);
    lp_vec3 focus = v3(o0.x + 10.0 * d0.x, o0.y + 10.0 * d0.y, o0.z + 10.0 * d0.z);
    double rmax = 0.0;
    for (int k = 0; k < v.samples; k++) {
        rs_camera_aperture_ray(&v, 40.5, 200.5, 320, 240, k, &o, &d);
        lp_vec3 a = v3(o.x - c.location.x, o.y - c.location.y, o.z - c.location.z);
        double r = sqrt(dot(a, a));
        rmax = fmax(rmax, r);
        CHECK(r <= 1.0 + 1e-15, "ray %d starts on the disk (r = %g)", k, r);
        CHECK_ABS(a.z, 0.0, 1e-15, "ray %d: the disk is perpendicular to D", k);
        CHECK_ABS(dot(d, d), 1.0, 1e-15, "ray %d: unit direction", k);
        /* the point in focus lies on the ray */
        lp_vec3 f = v3(focus.x - o.x, focus.y - o.y, focus.z - o.z);
        double along = dot(f, d);
        lp_vec3 off = v3(f.x - along * d.x, f.y - along * d.y, f.z - along * d.z);
        CHECK_ABS(sqrt(dot(off, off)), 0.0, 1e-13, "ray %d passes the point in focus", k);
    }
    /* the sunflower's outermost point is at radius sqrt((N - 1/2)/N) */
    CHECK_ABS(rmax, sqrt(8.5 / 9.0), 1e-15, "outermost aperture point");

    /* the focal point moves with the camera */
    c.xf.t[2] = 5.0;
    c.xf.inv_t[2] = -5.0;
    c.has_xf = 1;
    CHECK(setup(&c, 320, 240, &v) == 0, "translated aperture camera sets up");
    CHECK_ABS(v.focal_distance, 10.0, 1e-15, "focal distance after translate");
    c.xf.t[2] = 0.0;
    c.xf.inv_t[2] = 0.0;
    c.has_xf = 0;

    /* default sample count */
    c.blur_samples = 0;
    CHECK(setup(&c, 320, 240, &v) == 0 && v.samples == RS_CAMERA_BLUR_SAMPLES,
          "default blur_samples");

    /* a pinhole: one ray, the primary one */
    c = pov_default();
    CHECK(setup(&c, 320, 240, &v) == 0 && v.samples == 1, "pinhole: one ray");
    rs_camera_ray(&v, 10.5, 20.5, 320, 240, &o0, &d0);
    rs_camera_aperture_ray(&v, 10.5, 20.5, 320, 240, 0, &o, &d);
    CHECK_VEC(o, o0, 0.0, "pinhole aperture ray: origin");
    CHECK_VEC(d, d0, 0.0, "pinhole aperture ray: direction");

    c.aperture = -1.0;
    expect_error(&c, 320, 240, "negative aperture");
    c.aperture = NAN;
    expect_error(&c, 320, 240, "aperture NaN");
    c.aperture = 1.0; /* focal_point <0,0,0> = location */
    expect_error(&c, 320, 240, "aperture with the focal point at the location");
    c = pov_default();
    c.blur_samples = -3;
    expect_error(&c, 320, 240, "negative blur_samples");
}

/* Does the ray o + t d, t >= 0, meet the box lo..hi?  (Slabs, written
 * here for the test.) */
static int ray_meets_box(lp_vec3 o, lp_vec3 d, lp_vec3 lo, lp_vec3 hi)
{
    double oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
    double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z}, t0 = 0.0, t1 = INFINITY;
    for (int k = 0; k < 3; k++) {
        if (dd[k] == 0.0) {
            if (oo[k] < l[k] || oo[k] > h[k])
                return 0;
            continue;
        }
        double a = (l[k] - oo[k]) / dd[k], b = (h[k] - oo[k]) / dd[k];
        t0 = fmax(t0, fmin(a, b));
        t1 = fmin(t1, fmax(a, b));
    }
    return t0 <= t1;
}

/* rs_camera_box_pixels: every pixel whose primary ray meets a box lies in
 * its rectangle, and the rectangle is no more than the bounding
 * rectangle of those pixels and 3 pixels a side: the margin's 1, 1 more
 * where the projected extreme falls between two pixel centres, and 1
 * more where the hull's extreme corner is a spike no pixel centre lies
 * in.  Measured on the 99 boxes below that fall wholly in the image: 1
 * on 5 of their 396 sides, 2 on 383, 3 on 8.  A box not wholly in front
 * of a perspective camera gives the whole image. */
static void check_box_pixels(const rs_view *v, int w, int h, uint64_t *seed, const char *what)
{
    for (int n = 0; n < 40; n++) {
        lp_vec3 c = v3(6.0 * splitmix_uniform(seed) - 3.0, 6.0 * splitmix_uniform(seed) - 3.0,
                       6.0 * splitmix_uniform(seed) - 3.0);
        lp_vec3 e = v3(0.05 + splitmix_uniform(seed), 0.05 + splitmix_uniform(seed),
                       0.05 + splitmix_uniform(seed));
        lp_vec3 lo = v3(c.x - e.x, c.y - e.y, c.z - e.z), hi = v3(c.x + e.x, c.y + e.y, c.z + e.z);
        int r[4], known = rs_camera_box_pixels(v, w, h, lo, hi, r), hit = 0, missed = 0;
        int bi0 = w, bi1 = -1, bj0 = h, bj1 = -1;
        for (int j = 0; j < h; j++)
            for (int i = 0; i < w; i++) {
                lp_vec3 o, d;
                rs_camera_ray(v, i + 0.5, j + 0.5, w, h, &o, &d);
                if (!ray_meets_box(o, d, lo, hi))
                    continue;
                hit++;
                bi0 = i < bi0 ? i : bi0, bi1 = i > bi1 ? i : bi1;
                bj0 = j < bj0 ? j : bj0, bj1 = j > bj1 ? j : bj1;
                if (!(i >= r[0] && i < r[1] && j >= r[2] && j < r[3]))
                    missed++;
            }
        CHECK(missed == 0, "%s box %d: %d of %d pixels meeting it outside [%d,%d)x[%d,%d)", what,
              n, missed, hit, r[0], r[1], r[2], r[3]);
        if (!known) {
            CHECK(r[0] == 0 && r[1] == w && r[2] == 0 && r[3] == h,
                  "%s box %d: not known, the whole image", what, n);
            continue;
        }
        if (hit == 0 || bi0 == 0 || bj0 == 0 || bi1 == w - 1 || bj1 == h - 1)
            continue; /* empty, or cut by the image's edge */
        CHECK(r[0] >= bi0 - 3 && r[1] <= bi1 + 4 && r[2] >= bj0 - 3 && r[3] <= bj1 + 4,
              "%s box %d: [%d,%d)x[%d,%d) within 3 pixels of the pixels meeting it "
              "[%d,%d]x[%d,%d]",
              what, n, r[0], r[1], r[2], r[3], bi0, bi1, bj0, bj1);
    }
}

static void test_box_pixels(void)
{
    rs_camera c = pov_default();
    rs_view v;
    uint64_t seed = 12345;
    lp_vec3 lo = v3(-1, -1, -1), hi = v3(1, 1, 1);
    int r[4];
    c.location = v3(0, 1, -8);
    c.look_at = v3(0, 0, 0);
    c.has_look_at = 1;
    c.right = v3(4.0 / 3.0, 0, 0);
    c.angle = 50;
    c.has_angle = 1;
    CHECK(setup(&c, 64, 48, &v) == 0, "box pixels: perspective sets up");
    check_box_pixels(&v, 64, 48, &seed, "perspective");
    c.right = v3(-4.0 / 3.0, 0, 0);
    CHECK(setup(&c, 64, 48, &v) == 0, "box pixels: mirrored sets up");
    check_box_pixels(&v, 64, 48, &seed, "mirrored");
    c.location = v3(5, 4, -3);
    c.right = v3(4.0 / 3.0, 0, 0);
    CHECK(setup(&c, 48, 64, &v) == 0, "box pixels: oblique sets up");
    check_box_pixels(&v, 48, 64, &seed, "oblique");
    /* the camera inside the box, or the box behind it: not known */
    c.location = v3(0, 0, 0);
    c.look_at = v3(0, 0, 5);
    CHECK(setup(&c, 64, 48, &v) == 0, "box pixels: inside sets up");
    CHECK(rs_camera_box_pixels(&v, 64, 48, lo, hi, r) == 0 && r[0] == 0 && r[1] == 64 &&
              r[2] == 0 && r[3] == 48,
          "the camera inside the box: the whole image");
    CHECK(rs_camera_box_pixels(&v, 64, 48, v3(-1, -1, -5), v3(1, 1, -3), r) == 0,
          "a box behind the camera: not known");
    /* orthographic: projected along D */
    c = pov_default();
    c.orthographic = 1;
    c.location = v3(0, 2, -10);
    c.look_at = v3(0, 0, 0);
    c.has_look_at = 1;
    c.right = v3(8, 0, 0);
    c.up = v3(0, 6, 0);
    CHECK(setup(&c, 64, 48, &v) == 0, "box pixels: orthographic sets up");
    check_box_pixels(&v, 64, 48, &seed, "orthographic");
    /* a box off the image: an empty rectangle */
    c = pov_default();
    c.location = v3(0, 0, -5);
    CHECK(setup(&c, 64, 48, &v) == 0, "box pixels: straight sets up");
    CHECK(rs_camera_box_pixels(&v, 64, 48, v3(20, -1, -1), v3(22, 1, 1), r) == 1 &&
              r[0] == r[1],
          "a box far right of the view: no pixel [%d,%d)", r[0], r[1]);
    lo = v3(NAN, 0, 0);
    CHECK(rs_camera_box_pixels(&v, 64, 48, lo, hi, r) == 0 && r[1] == 64,
          "a box with a NaN: not known, the whole image");
}

int main(void)
{
    test_box_pixels();
    test_scene_defaults();
    test_aperture();
    test_default();
    test_look_at_angle();
    test_angle_only();
    test_side();
    test_down();
    test_sky();
    test_mirror();
    test_oblique();
    test_transform();
    test_errors();
    return check_finish("test_camera");
}
