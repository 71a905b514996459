/* test_csg.c -- intersection and difference (csg.h): the surfaces a ray
 * meets, against closed forms and against an independent march along the
 * ray with the insides written out here; members sharing a face, rays along
 * a tangent or a face, rays that start on a surface (shadow rays); the
 * member's texture against the CSG's; the boxes a BVH gets; shadows in a
 * render; the torus's grazing chords. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bvh.h"
#include "check.h"
#include "csg.h"
#include "one_pixel.h"
#include "parser.h"
#include "round_shapes.h"

static lp_vec3 v3(double x, double y, double z)
{
    lp_vec3 r = {x, y, z};
    return r;
}

static lp_vec3 unit(lp_vec3 a)
{
    double l = sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
    return v3(a.x / l, a.y / l, a.z / l);
}

/* Parse a scene text whose first object is the CSG under test. */
static int parse(const char *text, rs_scene *s)
{
    char msg[512];
    rs_scene_init(s);
    if (rs_parse_string(text, "t.scene", NULL, s, msg, sizeof msg) != 0) {
        fprintf(stderr, "parse failed: %s\n  %s\n", msg, text);
        rs_scene_free(s);
        return -1;
    }
    return 0;
}

/* The first hit of one object: 1 and t, or 0. */
static int hit_t(const rs_object *o, lp_vec3 org, lp_vec3 dir, double t_min, double *t,
                 rs_hit *h)
{
    rs_hit tmp;
    if (h == NULL)
        h = &tmp;
    if (!rs_object_intersect(o, org, unit(dir), t_min, INFINITY, h))
        return 0;
    *t = h->t;
    return 1;
}

/* ---- the drilled block: box [-1,1]^3 minus a bore of radius 0.5 along z
 * and a bore of radius 0.25 along x; the insides written out here ---- */
static const char *const DRILLED =
    "difference { box { <-1,-1,-1>, <1,1,1> }"
    " cylinder { <0,0,-2>, <0,0,2>, 0.5 pigment { rgb <1,0,0> } }"
    " cylinder { <-2,0,0>, <2,0,0>, 0.25 } pigment { rgb <0,0,1> } }";

static int drilled_inside(lp_vec3 p)
{
    int box = fabs(p.x) < 1 && fabs(p.y) < 1 && fabs(p.z) < 1;
    int bore_z = p.x * p.x + p.y * p.y < 0.25 && fabs(p.z) < 2;
    int bore_x = p.y * p.y + p.z * p.z < 0.0625 && fabs(p.x) < 2;
    return box && !bore_z && !bore_x;
}

/* The first change of drilled_inside along the ray in (0, 10), by marching
 * at step h and bisecting the step where it changes: -1 when none. */
static double march(lp_vec3 o, lp_vec3 d, double h)
{
    int in0 = drilled_inside(o);
    for (double s = h; s < 10.0; s += h) {
        lp_vec3 p = v3(o.x + s * d.x, o.y + s * d.y, o.z + s * d.z);
        if (drilled_inside(p) != in0) {
            double a = s - h, b = s;
            for (int k = 0; k < 60; k++) {
                double m = 0.5 * (a + b);
                lp_vec3 q = v3(o.x + m * d.x, o.y + m * d.y, o.z + m * d.z);
                if (drilled_inside(q) == in0)
                    a = m;
                else
                    b = m;
            }
            return 0.5 * (a + b);
        }
    }
    return -1.0;
}

static void test_drilled(void)
{
    rs_scene s;
    double t;
    rs_hit h;
    if (parse(DRILLED, &s) != 0) {
        CHECK(0, "drilled block parses");
        return;
    }
    const rs_object *o = &s.objects[0];
    CHECK(s.n_objects == 1 && o->type == RS_OBJ_CSG && o->u.csg.n_members == 3,
          "one CSG object of 3 members");

    /* through the bore: nothing; beside it: the front face */
    CHECK(!hit_t(o, v3(0.2, 0.1, -5), v3(0, 0, 1), 0, &t, NULL), "a ray down the bore passes");
    CHECK(hit_t(o, v3(0.7, 0.1, -5), v3(0, 0, 1), 0, &t, &h) && fabs(t - 4.0) < 1e-12,
          "beside the bore: the front face at t = 4 (got %.17g)", t);
    CHECK(fabs(h.normal.z + 1.0) < 1e-12, "the front face's normal faces the ray");
    CHECK(h.surface == &o->u.csg.members[0], "the front face is the box's surface");
    /* inside the bore, looking at its wall: the cutter's own texture */
    CHECK(hit_t(o, v3(0, 0, 0.6), v3(1, 0, 0), 0, &t, &h) && fabs(t - 0.5) < 1e-12,
          "the bore wall at t = 0.5 (got %.17g)", t);
    CHECK(h.surface == &o->u.csg.members[1] && h.surface->pigment.color[0].r == 1.0 &&
              h.surface->pigment.color[0].b == 0.0,
          "the bore wall shows the cutter's red, not the block's blue");
    CHECK(fabs(h.normal.x + 1.0) < 1e-12, "the bore wall's normal faces the ray (got %g)",
          h.normal.x);
    /* the second bore has no texture: it takes the CSG's blue */
    CHECK(hit_t(o, v3(0.7, 0, 0), v3(0, 0, 1), 0, &t, &h) &&
              fabs(t - sqrt(0.0625)) < 1e-12 && h.surface == &o->u.csg.members[2] &&
              h.surface->pigment.color[0].b == 1.0 && h.surface->pigment.color[0].r == 0.0,
          "the x bore's wall, untextured, is the CSG's blue (t %.17g)", t);

    /* 4000 rays from a sphere of radius 4 towards random points of the
     * block's cube, against the march (step 1e-4: a chord shorter than that
     * could hide, a sweep of this size meets none) */
    unsigned long long seed = 12345;
    int wrong = 0, hits = 0;
    double worst = 0.0;
    for (int k = 0; k < 4000; k++) {
        double u[6];
        for (int i = 0; i < 6; i++) {
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
            u[i] = (double)(seed >> 11) / 9007199254740992.0;
        }
        lp_vec3 org = unit(v3(u[0] - 0.5, u[1] - 0.5, u[2] - 0.5));
        org = v3(4 * org.x, 4 * org.y, 4 * org.z);
        lp_vec3 aim = v3(2.4 * u[3] - 1.2, 2.4 * u[4] - 1.2, 2.4 * u[5] - 1.2);
        lp_vec3 d = unit(v3(aim.x - org.x, aim.y - org.y, aim.z - org.z));
        double want = march(org, d, 1e-4);
        int got = hit_t(o, org, d, 0, &t, NULL);
        if (got != (want >= 0.0)) {
            wrong++;
            continue;
        }
        if (got) {
            hits++;
            worst = fmax(worst, fabs(t - want));
        }
    }
    CHECK(wrong == 0, "%d of 4000 rays disagree with the march about hitting", wrong);
    /* bisection to 60 halvings of 1e-4: 1e-22; the roots themselves carry
     * ~1e-14 (measured worst 1.24e-14) */
    CHECK(worst < 1e-12, "hit distances within 1e-12 of the march (worst %.3g)", worst);
    CHECK(hits > 1000, "the sweep hits the block (%d hits)", hits);
    printf("test_csg: drilled block: 4000 rays, %d hits, %d disagree, worst |dt| %.3g\n", hits,
           wrong, worst);

    /* rays that start on the surface (shadow rays from a lit point) */
    CHECK(!hit_t(o, v3(0.8, 1, 0.7), v3(0, 1, 0), 1e-9, &t, NULL),
          "from the top face upwards: nothing");
    CHECK(hit_t(o, v3(0.8, 1, 0.7), v3(0, -1, 0), 1e-9, &t, NULL) && fabs(t - 2.0) < 1e-12,
          "from the top face into the block: the bottom face at t = 2 (got %.17g)", t);
    CHECK(hit_t(o, v3(0.5, 0, 0.6), v3(-1, 0, 0), 1e-9, &t, NULL) && fabs(t - 1.0) < 1e-12,
          "from the bore wall across the bore: the far wall at t = 1 (got %.17g)", t);
    CHECK(!hit_t(o, v3(0.5, 0, 0.6), v3(1, 0, 0), 1e-9, &t, &h) ||
              (t > 0.49 && h.surface == &o->u.csg.members[0]),
          "from the bore wall into the metal: only the block's outer face (t %.17g)", t);

    /* a ray along a face (the top, y = 1) meets no surface there; just
     * below it meets the side face, just above nothing */
    CHECK(!hit_t(o, v3(-5, 1, 0.7), v3(1, 0, 0), 0, &t, NULL), "a ray along the top face: nothing");
    CHECK(hit_t(o, v3(-5, 1 - 1e-6, 0.7), v3(1, 0, 0), 0, &t, NULL) && fabs(t - 4.0) < 1e-12,
          "just under the top face: the side at t = 4");
    CHECK(!hit_t(o, v3(-5, 1 + 1e-6, 0.7), v3(1, 0, 0), 0, &t, NULL), "just over it: nothing");
    rs_scene_free(&s);
}

/* Members sharing a face: a drill flush with the faces it opens leaves an
 * open hole (no skin from the coincident faces); two boxes sharing the
 * bottom face intersect to the smaller. */
static void test_coincident(void)
{
    rs_scene s;
    double t;
    if (parse("difference { box { <0,0,0>, <2,2,2> } box { <0.5,0.5,0>, <1.5,1.5,2> } }", &s) ==
        0) {
        const rs_object *o = &s.objects[0];
        CHECK(!hit_t(o, v3(1, 1, -1), v3(0, 0, 1), 0, &t, NULL),
              "a flush drill: the ray passes the open hole (t %.17g)", t);
        CHECK(!hit_t(o, v3(1, 1, 3), v3(0, 0, -1), 0, &t, NULL), "... from the other side too");
        CHECK(hit_t(o, v3(0.25, 1, -1), v3(0, 0, 1), 0, &t, NULL) && fabs(t - 1.0) < 1e-12,
              "beside the hole: the face at t = 1 (got %.17g)", t);
        CHECK(hit_t(o, v3(1, 1, 1), v3(1, 0, 0), 0, &t, NULL) && fabs(t - 0.5) < 1e-12,
              "inside the hole: its wall at t = 0.5 (got %.17g)", t);
        rs_scene_free(&s);
    } else {
        CHECK(0, "flush drill parses");
    }
    if (parse("intersection { box { <0,0,0>, <1,1,1> } box { <0,0,0>, <1,1,2> } }", &s) == 0) {
        const rs_object *o = &s.objects[0];
        CHECK(hit_t(o, v3(0.5, 0.5, -1), v3(0, 0, 1), 0, &t, NULL) && fabs(t - 1.0) < 1e-12,
              "a shared face is a surface where both begin (t %.17g)", t);
        CHECK(hit_t(o, v3(0.5, 0.5, 3), v3(0, 0, -1), 0, &t, NULL) && fabs(t - 2.0) < 1e-12,
              "from above: the smaller box's top at t = 2 (got %.17g)", t);
        CHECK(!hit_t(o, v3(-1, 0.5, 1.5), v3(1, 0, 0), 0, &t, NULL),
              "above the smaller box: nothing");
        rs_scene_free(&s);
    } else {
        CHECK(0, "shared-face intersection parses");
    }
}

/* Spheres: a lens-shaped intersection, a shell (an inverted member), a
 * ray along a tangent; nested CSG (a rounded die with a dimple). */
static void test_round(void)
{
    rs_scene s;
    double t;
    rs_hit h;
    if (parse("intersection { sphere { <0,0,-0.6>, 1 } sphere { <0,0,0.6>, 1 pigment "
              "{ rgb <1,0,0> } } pigment { rgb <0,1,0> } interior { ior 1.7 } }",
              &s) == 0) {
        const rs_object *o = &s.objects[0];
        /* the near face is the far sphere's cap: z = 0.6 - 1 */
        CHECK(hit_t(o, v3(0, 0, -5), v3(0, 0, 1), 0, &t, &h) && fabs(t - 4.6) < 1e-12 &&
                  h.surface == &o->u.csg.members[1],
              "the lens shape's front cap at t = 4.6 on the +z sphere (got %.17g)", t);
        CHECK(h.surface->pigment.color[0].r == 1.0 && h.surface->ior == 1.7,
              "the member's own red wins; the CSG's interior fills in");
        CHECK(o->u.csg.members[0].pigment.color[0].g == 1.0 && o->u.csg.members[0].ior == 1.7,
              "the member without a texture takes the CSG's green and interior");
        /* off axis at y = 0.5: both spheres give |z -/+ 0.6| = sqrt(0.75) */
        CHECK(hit_t(o, v3(0, 0.5, -5), v3(0, 0, 1), 0, &t, NULL) &&
                  fabs(t - (5 + 0.6 - sqrt(0.75))) < 1e-12,
              "off axis: t = 5.6 - sqrt(0.75) (got %.17g)", t);
        /* the rim circle: z = 0, r = 0.8; a ray along y at z = 0, x = 0.8
         * touches it only: nothing */
        CHECK(!hit_t(o, v3(0.8, -5, 0), v3(0, 1, 0), 0, &t, NULL) || fabs(t - 5.0) < 1e-6,
              "a ray grazing the rim edge (t %.17g)", t);
        rs_scene_free(&s);
    } else {
        CHECK(0, "lens shape parses");
    }
    if (parse("intersection { sphere { 0, 2 } sphere { 0, 1 inverse } }", &s) == 0) {
        const rs_object *o = &s.objects[0];
        CHECK(hit_t(o, v3(-5, 0, 0), v3(1, 0, 0), 0, &t, NULL) && fabs(t - 3.0) < 1e-12,
              "a shell from outside: t = 3 (got %.17g)", t);
        CHECK(hit_t(o, v3(0, 0, 0), v3(1, 0, 0), 0, &t, &h) && fabs(t - 1.0) < 1e-12 &&
                  h.surface == &o->u.csg.members[1],
              "a shell from its hollow: the inverted sphere at t = 1 (got %.17g)", t);
        CHECK(rs_object_inside(o, v3(1.5, 0, 0)) && !rs_object_inside(o, v3(0.5, 0, 0)) &&
                  !rs_object_inside(o, v3(2.5, 0, 0)),
              "the shell's inside");
        /* tangent to the outer sphere: nothing; just inside it: a chord */
        CHECK(!hit_t(o, v3(-5, 2, 0), v3(1, 0, 0), 0, &t, NULL), "a ray along a tangent: nothing");
        CHECK(hit_t(o, v3(-5, 2 - 1e-6, 0), v3(1, 0, 0), 0, &t, NULL) &&
                  fabs(t - (5 - sqrt(4 - (2 - 1e-6) * (2 - 1e-6)))) < 1e-9,
              "1e-6 inside the tangent: its chord (t %.17g)", t);
        rs_scene_free(&s);
    } else {
        CHECK(0, "shell parses");
    }
    if (parse("difference { intersection { box { -1, 1 } sphere { 0, 1.3 } } "
              "sphere { <0,1,0>, 0.5 } rotate x*90 translate <0,0,3> }",
              &s) == 0) {
        const rs_object *o = &s.objects[0];
        /* rotate x*90 turns +y to +z (left-handed): the dimple faces +z */
        CHECK(hit_t(o, v3(0, 0, 10), v3(0, 0, -1), 0, &t, NULL) && fabs(t - 6.5) < 1e-12,
              "the dimple's bottom at z = 3.5 (t %.17g)", t);
        CHECK(hit_t(o, v3(0.9, 0, 10), v3(0, 0, -1), 0, &t, NULL) &&
                  fabs(t - (7 - sqrt(1.69 - 0.81))) < 1e-12,
              "a rounded corner: the sphere at z = 3 + sqrt(1.69 - 0.81) (t %.17g)", t);
        CHECK(hit_t(o, v3(0.7, 0, 10), v3(0, 0, -1), 0, &t, NULL) && fabs(t - 6.0) < 1e-12,
              "the flat top face at z = 4 (t %.17g)", t);
        rs_scene_free(&s);
    } else {
        CHECK(0, "die parses");
    }
    /* a plane turned inside out cuts a torus to an arch */
    if (parse("intersection { torus { 2, 0.5 } plane { x, 0 inverse } }", &s) == 0) {
        const rs_object *o = &s.objects[0];
        CHECK(hit_t(o, v3(-5, 0, 0), v3(1, 0, 0), 0, &t, NULL) && fabs(t - 6.5) < 1e-12,
              "the half torus (x > 0): the tube's inner side at x = 1.5 (t %.17g)", t);
        CHECK(hit_t(o, v3(-1, 0.2, -2), v3(1, 0, 0), 0, &t, &h) && fabs(t - 1.0) < 1e-12 &&
                  h.surface == &o->u.csg.members[1],
              "the cut face at x = 0 (t %.17g)", t);
        rs_scene_free(&s);
    } else {
        CHECK(0, "arch parses");
    }
}

/* A torus met along a chord shorter than any sampling step: the ray dips
 * delta into the tube's top (y = minor - delta), the chord is
 * 2 sqrt(2 minor delta). */
static void test_torus_grazing(void)
{
    for (int e = 4; e <= 10; e += 2) {
        double delta = pow(10.0, -e), y = 0.5 - delta, t;
        lp_vec3 n;
        int got = rs_torus_hit(2.0, 0.5, v3(-5, y, 0), v3(1, 0, 0), 0, INFINITY, &t, &n);
        double want = 5 - 2 - sqrt(0.25 - y * y);
        /* the roots of a near-double root: ~sqrt(eps) relative in the
         * chord; measured worst 3e-12 at delta 1e-10 */
        CHECK(got && fabs(t - want) < 1e-9, "a chord of %.2g: hit at %.17g, want %.17g",
              2 * sqrt(2 * 0.5 * delta), got ? t : -1, want);
    }
    double t;
    lp_vec3 n;
    CHECK(!rs_torus_hit(2.0, 0.5, v3(-5, 0.5 + 1e-9, 0), v3(1, 0, 0), 0, INFINITY, &t, &n),
          "1e-9 over the tube: nothing");
}

static int sphere_box_bounds(const rs_object *o, lp_vec3 *lo, lp_vec3 *hi)
{
    if (o->type == RS_OBJ_CSG)
        return rs_csg_bounds(o, sphere_box_bounds, lo, hi);
    if (o->type == RS_OBJ_SPHERE) {
        /* untransformed in these scenes */
        lp_vec3 c = o->u.sphere.center;
        double r = o->u.sphere.radius;
        *lo = v3(c.x - r, c.y - r, c.z - r);
        *hi = v3(c.x + r, c.y + r, c.z + r);
        return 1;
    }
    if (o->type == RS_OBJ_BOX) {
        *lo = o->u.box.corner1;
        *hi = o->u.box.corner2;
        return 1;
    }
    return 0;
}

static void test_bounds(void)
{
    static const struct {
        const char *text;
        int bounded;
        double lo[3], hi[3];
    } cases[] = {
        {"intersection { sphere { 0, 1 } box { <0,0,0>, <3,3,3> } }", 1, {0, 0, 0}, {1, 1, 1}},
        {"difference { box { <0,0,0>, <3,3,3> } sphere { 0, 1 } }", 1, {0, 0, 0}, {3, 3, 3}},
        {"intersection { sphere { 0, 1 } plane { y, 0 } }", 1, {-1, -1, -1}, {1, 1, 1}},
        {"intersection { sphere { 0, 1 } box { <0,0,0>, <3,3,3> inverse } }", 1, {-1, -1, -1},
         {1, 1, 1}},
        {"difference { plane { y, 0 } sphere { 0, 1 } }", 0, {0}, {0}},
        {"difference { box { -1, 1 } sphere { 0, 1 } inverse }", 0, {0}, {0}},
        {"intersection { union { sphere { 0, 1 } box { <2,2,2>, <3,3,3> } } box { -5, 5 } }", 1,
         {-1, -1, -1}, {3, 3, 3}},
        {"intersection { union { sphere { 0, 1 } plane { y, 0 } } box { -5, 5 } }", 1,
         {-5, -5, -5}, {5, 5, 5}},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        rs_scene s;
        lp_vec3 lo, hi;
        if (parse(cases[i].text, &s) != 0) {
            CHECK(0, "parses: %s", cases[i].text);
            continue;
        }
        int b = rs_csg_bounds(&s.objects[0], sphere_box_bounds, &lo, &hi);
        CHECK(b == cases[i].bounded, "bounded %d, want %d: %s", b, cases[i].bounded,
              cases[i].text);
        if (b && cases[i].bounded)
            CHECK(lo.x == cases[i].lo[0] && lo.y == cases[i].lo[1] && lo.z == cases[i].lo[2] &&
                      hi.x == cases[i].hi[0] && hi.y == cases[i].hi[1] &&
                      hi.z == cases[i].hi[2],
                  "box <%g,%g,%g> <%g,%g,%g>: %s", lo.x, lo.y, lo.z, hi.x, hi.y, hi.z,
                  cases[i].text);
        rs_scene_free(&s);
    }
}

/* Shadows through a CSG in a render: a light high above a drilled plate
 * (y 5..6, a bore of radius 3 about the y axis), an orthographic camera
 * under the plate looking straight down at a floor point.  Where the
 * segment to the light passes the bore the floor is lit: ambient 0.1 +
 * diffuse 0.6 cos(theta); under the metal it has the ambient alone. */
static void test_shadow_render(void)
{
    static const char *const fmt =
        "camera { orthographic location <%g, 2, %g> look_at <%g, 0, %g> sky z right x*0.01 "
        "up z*0.01 }\n"
        "light_source { <0, 1000, 0> color rgb 1 }\n"
        "plane { y, 0 pigment { rgb 1 } finish { ambient 0.1 diffuse 0.6 } }\n"
        "difference { box { <-10, 5, -10>, <10, 6, 10> } cylinder { <0, 4, 0>, <0, 7, 0>, 3 }\n"
        "  pigment { rgb 1 } finish { ambient 0 diffuse 0 } }\n";
    /* where the segment crosses the plate: r = |(x, z)| (1 - y/1000) */
    static const struct { double x, z; int lit; } pts[] = {
        {0.0, 0.0, 1}, {2.5, 1.0, 1}, {2.98, 0.0, 1}, {3.1, 0.0, 0}, {4.0, 0.0, 0},
        {0.0, -8.0, 0},
    };
    char text[1024];
    for (size_t i = 0; i < sizeof pts / sizeof pts[0]; i++) {
        rs_color c;
        double x = pts[i].x, z = pts[i].z;
        double want = 0.1 + (pts[i].lit ? 0.6 * 1000 / sqrt(1e6 + x * x + z * z) : 0.0);
        snprintf(text, sizeof text, fmt, x, z, x, z);
        if (one_pixel(text, RS_MODE_RGB, 0, &c) != 0) {
            CHECK(0, "render %zu", i);
            continue;
        }
        /* rgb mode: the arithmetic above, to rounding */
        CHECK_ABS(c.g, want, 1e-12, "floor at (%g, %g): %s", x, z,
                  pts[i].lit ? "lit through the bore" : "in the plate's shadow");
    }
}

/* A scene of 12 CSG objects is served by the bounding volume hierarchy:
 * its nearest hits must be those of a loop over every object, and the
 * boxes it uses must be finite (no object left unbounded). */
static void test_bvh(void)
{
    char text[8192];
    size_t n = 0;
    rs_scene s;
    char msg[512];
    for (int k = 0; k < 12; k++)
        n += (size_t)snprintf(text + n, sizeof text - n,
                              "%s { box { -1, 1 } sphere { <0.3,0.4,0>, %s } %s translate <%d, %d, %d> }\n",
                              k % 2 ? "difference" : "intersection", k % 3 ? "1.2" : "0.6",
                              k % 4 == 1 ? "rotate y*30" : "", 3 * (k % 4) - 4, 3 * (k / 4) - 3,
                              k % 3);
    rs_scene_init(&s);
    if (rs_parse_string(text, "t.scene", NULL, &s, msg, sizeof msg) != 0 ||
        rs_scene_prepare(&s, msg, sizeof msg) != 0) {
        CHECK(0, "12 CSG objects: %s", msg);
        rs_scene_free(&s);
        return;
    }
    CHECK(rs_bvh_serves(s.bvh, &s) && rs_bvh_unbounded_count(s.bvh) == 0,
          "the tree serves the scene with every CSG object bounded (%zu unbounded)",
          rs_bvh_unbounded_count(s.bvh));
    unsigned long long seed = 777;
    int wrong = 0;
    for (int k = 0; k < 3000; k++) {
        double u[4];
        for (int i = 0; i < 4; i++) {
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
            u[i] = (double)(seed >> 11) / 9007199254740992.0;
        }
        lp_vec3 o = v3(12 * u[0] - 6, 10 * u[1] - 5, -20);
        lp_vec3 d = unit(v3(0.3 * (u[2] - 0.5), 0.3 * (u[3] - 0.5), 1));
        rs_hit h, best;
        int got = rs_scene_intersect(&s, o, d, 0.0, INFINITY, -1, &h), want = 0;
        double tmax = INFINITY;
        for (size_t i = 0; i < s.n_objects; i++)
            if (rs_object_intersect(&s.objects[i], o, d, 0.0, tmax, &best)) {
                tmax = best.t;
                want = 1;
            }
        if (got != want || (got && h.t != tmax))
            wrong++;
    }
    CHECK(wrong == 0, "%d of 3000 rays: the tree's nearest hit differs from the loop's", wrong);
    rs_scene_free(&s);
}

int main(void)
{
    test_drilled();
    test_coincident();
    test_round();
    test_torus_grazing();
    test_bounds();
    test_shadow_render();
    test_bvh();
    return check_finish("test_csg");
}
