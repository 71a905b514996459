/* test_parser.c -- the .scene reader: every construct into the expected
 * values (written by hand here), every error with its line and column,
 * POV-Ray's transform rules, lens folding, and a 10^4-object file. */
#if defined(__unix__) || defined(__APPLE__)
#define _POSIX_C_SOURCE 200809L /* opendir, to read every scene in scenes/ */
#include <dirent.h>
#define HAVE_DIRENT 1
#endif
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "library_path.h"
#include "parser.h"
#include "scene.h"

#ifndef LP_TEST_TMP
#define LP_TEST_TMP "."
#endif

#define TOL 1e-12

static void check_vec(lp_vec3 got, double x, double y, double z, double tol, const char *what)
{
    CHECK_ABS(got.x, x, tol, "%s.x", what);
    CHECK_ABS(got.y, y, tol, "%s.y", what);
    CHECK_ABS(got.z, z, tol, "%s.z", what);
}

static void check_color(rs_color got, double r, double g, double b, const char *what)
{
    CHECK_ABS(got.r, r, TOL, "%s.r", what);
    CHECK_ABS(got.g, g, TOL, "%s.g", what);
    CHECK_ABS(got.b, b, TOL, "%s.b", what);
}

/* Parse text named "t.scene"; returns the parser's status. */
static int parse_opts(const char *text, const rs_parse_opts *opts, rs_scene *s, char *msg,
                      size_t n)
{
    rs_scene_init(s);
    return rs_parse_string(text, "t.scene", opts, s, msg, n);
}

static int parse(const char *text, rs_scene *s, char *msg, size_t n)
{
    return parse_opts(text, NULL, s, msg, n);
}

/* The text must fail with "t.scene:LINE:COL: ..." containing `part`. */
static void expect_error_opts(const char *text, const rs_parse_opts *opts, int line, int col,
                              const char *part)
{
    rs_scene s;
    char msg[512], prefix[64];
    int rc = parse_opts(text, opts, &s, msg, sizeof msg);
    snprintf(prefix, sizeof prefix, "t.scene:%d:%d: ", line, col);
    CHECK(rc == -1, "parse should fail: %s", text);
    CHECK(strncmp(msg, prefix, strlen(prefix)) == 0, "location: want '%s', got '%s' (text: %s)",
          prefix, msg, text);
    CHECK(strstr(msg, part) != NULL, "message: want '%s' in '%s'", part, msg);
    rs_scene_free(&s);
}

static void expect_error(const char *text, int line, int col, const char *part)
{
    expect_error_opts(text, NULL, line, col, part);
}

/* ------------------------------------------------------------------ */

static void test_transforms(void)
{
    rs_transform xf;
    lp_vec3 v;

    /* rotate <0,90,0>, left-hand rule about +y: +x -> -z, +z -> +x. */
    rs_transform_identity(&xf);
    CHECK(rs_transform_rotate(&xf, (lp_vec3){ 0, 90, 0 }) == 1, "rotate returns 1");
    check_vec(rs_xf_point(&xf, (lp_vec3){ 1, 0, 0 }), 0, 0, -1, TOL, "roty90(x)");
    check_vec(rs_xf_point(&xf, (lp_vec3){ 0, 1, 0 }), 0, 1, 0, TOL, "roty90(y)");
    check_vec(rs_xf_point(&xf, (lp_vec3){ 0, 0, 1 }), 1, 0, 0, TOL, "roty90(z)");
    check_vec(rs_xf_inv_point(&xf, (lp_vec3){ 0, 0, -1 }), 1, 0, 0, TOL, "roty90^-1(-z)");

    /* rotate <90,0,0>: +y -> +z, +z -> -y.  rotate <0,0,90>: +x -> +y. */
    rs_transform_identity(&xf);
    rs_transform_rotate(&xf, (lp_vec3){ 90, 0, 0 });
    check_vec(rs_xf_dir(&xf, (lp_vec3){ 0, 1, 0 }), 0, 0, 1, TOL, "rotx90(y)");
    check_vec(rs_xf_dir(&xf, (lp_vec3){ 0, 0, 1 }), 0, -1, 0, TOL, "rotx90(z)");
    rs_transform_identity(&xf);
    rs_transform_rotate(&xf, (lp_vec3){ 0, 0, 90 });
    check_vec(rs_xf_dir(&xf, (lp_vec3){ 1, 0, 0 }), 0, 1, 0, TOL, "rotz90(x)");
    check_vec(rs_xf_dir(&xf, (lp_vec3){ 0, 1, 0 }), -1, 0, 0, TOL, "rotz90(y)");

    /* rotate <90,90,0>: x first (y -> z), then y (z -> x): y ends at +x. */
    rs_transform_identity(&xf);
    rs_transform_rotate(&xf, (lp_vec3){ 90, 90, 0 });
    check_vec(rs_xf_dir(&xf, (lp_vec3){ 0, 1, 0 }), 1, 0, 0, TOL, "rot<90,90,0>(y)");
    check_vec(rs_xf_dir(&xf, (lp_vec3){ 1, 0, 0 }), 0, 0, -1, TOL, "rot<90,90,0>(x)");

    /* rotate <0,30,0>: x -> (cos 30, 0, -sin 30). */
    rs_transform_identity(&xf);
    rs_transform_rotate(&xf, (lp_vec3){ 0, 30, 0 });
    check_vec(rs_xf_dir(&xf, (lp_vec3){ 1, 0, 0 }), sqrt(3.0) / 2, 0, -0.5, 1e-15, "roty30(x)");
    check_vec(rs_xf_inv_dir(&xf, (lp_vec3){ sqrt(3.0) / 2, 0, -0.5 }), 1, 0, 0, 1e-15,
              "roty30^-1");

    /* scale 2 then translate <1,0,0>, and the other order. */
    rs_transform_identity(&xf);
    rs_transform_scale(&xf, (lp_vec3){ 2, 2, 2 });
    rs_transform_translate(&xf, (lp_vec3){ 1, 0, 0 });
    check_vec(rs_xf_point(&xf, (lp_vec3){ 1, 1, 1 }), 3, 2, 2, TOL, "scale;translate");
    check_vec(rs_xf_inv_point(&xf, (lp_vec3){ 3, 2, 2 }), 1, 1, 1, TOL, "(scale;translate)^-1");
    check_vec(rs_xf_dir(&xf, (lp_vec3){ 1, 0, 0 }), 2, 0, 0, TOL, "dir ignores translate");
    rs_transform_identity(&xf);
    rs_transform_translate(&xf, (lp_vec3){ 1, 0, 0 });
    rs_transform_scale(&xf, (lp_vec3){ 2, 2, 2 });
    check_vec(rs_xf_point(&xf, (lp_vec3){ 1, 1, 1 }), 4, 2, 2, TOL, "translate;scale");
    check_vec(rs_xf_inv_point(&xf, (lp_vec3){ 4, 2, 2 }), 1, 1, 1, TOL, "(translate;scale)^-1");

    /* Normals: inverse transpose.  Under scale <1,2,1> the normal (1,1,0)
     * of the tangent (1,-1,0) becomes (1,0.5,0), still perpendicular to
     * the scaled tangent (1,-2,0). */
    rs_transform_identity(&xf);
    rs_transform_scale(&xf, (lp_vec3){ 1, 2, 1 });
    v = rs_xf_normal(&xf, (lp_vec3){ 1, 1, 0 });
    check_vec(v, 1, 0.5, 0, TOL, "normal under scale");

    /* compose(a, b) = b after a. */
    {
        rs_transform a, b, c;
        rs_transform_identity(&a);
        rs_transform_identity(&b);
        rs_transform_rotate(&a, (lp_vec3){ 0, 0, 90 });
        rs_transform_translate(&b, (lp_vec3){ 5, 0, 0 });
        rs_transform_compose(&a, &b, &c);
        check_vec(rs_xf_point(&c, (lp_vec3){ 1, 0, 0 }), 5, 1, 0, TOL, "compose order");
        check_vec(rs_xf_inv_point(&c, (lp_vec3){ 5, 1, 0 }), 1, 0, 0, TOL, "compose inverse");
    }

    /* A general chain and its inverse round trip. */
    rs_transform_identity(&xf);
    rs_transform_rotate(&xf, (lp_vec3){ 13, -47, 101 });
    rs_transform_scale(&xf, (lp_vec3){ 0.5, 3, -2 });
    rs_transform_translate(&xf, (lp_vec3){ 7, -3, 11 });
    rs_transform_rotate(&xf, (lp_vec3){ 200, 5, -33 });
    v = rs_xf_inv_point(&xf, rs_xf_point(&xf, (lp_vec3){ 0.3, -1.7, 2.9 }));
    check_vec(v, 0.3, -1.7, 2.9, 1e-13, "chain round trip");

    /* Singular and non-finite steps are refused and leave xf alone. */
    rs_transform_identity(&xf);
    CHECK(rs_transform_scale(&xf, (lp_vec3){ 1, 0, 1 }) == 0, "zero scale refused");
    CHECK(rs_transform_translate(&xf, (lp_vec3){ NAN, 0, 0 }) == 0, "NaN translate refused");
    CHECK(rs_transform_rotate(&xf, (lp_vec3){ 0, INFINITY, 0 }) == 0, "inf rotate refused");
    check_vec(rs_xf_point(&xf, (lp_vec3){ 1, 2, 3 }), 1, 2, 3, 0, "unchanged after refusals");
}

/* ------------------------------------------------------------------ */

static const char full_scene[] =
    "// a full scene\n"                                                         /* 1 */
    "#version 3.7;\n"                                                           /* 2 */
    "/* block /* nested */ still // comment */\n"                               /* 3 */
    "#declare R = 2.5;\n"                                                       /* 4 */
    "#declare C = rgb <0.2, 0.4, 0.6>;\n"                                       /* 5 */
    "#local V = <1, 2, 3> * 2 + x;\n"                                           /* 6 */
    "global_settings { max_trace_level 10 adc_bailout 0 ambient_light rgb 0.5 "
    "assumed_gamma 2.2 coherent on }\n"                                         /* 7 */
    "background { color rgb <0.1, 0.2, 0.3> }\n"                                /* 8 */
    "camera { perspective location <0, 2, -10> look_at <0, 1, 0> angle 40\n"    /* 9 */
    "  right x*image_width/image_height up y sky <0,1,0.5> direction 2*z }\n"   /* 10 */
    "light_source { <10, 20, -30>, color rgb 1 polarization <2,0,0> "
    "spectrum { line 589.3 } coherent translate <1,0,0> }\n"                    /* 11 */
    "light_source { <0,0,0> C spectrum { blackbody 5800 } }\n"                  /* 12 */
    "plane { y, -1 pigment { checker rgb 0.9, rgb 0.1 scale 0.5 } "
    "finish { ambient 0 diffuse 0 emission 1 } }\n"                             /* 13 */
    "sphere { <0, R, 0>, R/2 texture { pigment { C } finish { specular 0.5 phong 1 "
    "reflection 0.2 } } translate <1,0,0> }\n"                                  /* 14 */
    "  box { <1,1,1>, <-1,-1,-1> pigment { color red 1 green 0.5 } rotate <0,90,0> }\n" /* 15 */
    "disc { <0,0,5>, <0,0,-2>, 3, 1 }\n"                                        /* 16 */
    "lens { radius1 50 radius2 -50 thickness 5 diameter 25 glass \"N-BK7\" "
    "rotate <0,90,0> translate <10,0,0> }\n"                                    /* 17 */
    "lens { radius1 inf radius2 -inf thickness 2 diameter 10 diameter2 8 ior 1.5 "
    "medium ior 1.33 scale 2 translate z*100 }\n"                               /* 18 */
    "lens { radius1 0 radius2 -30 thickness 3 diameter 12 sellmeier { 1.03961212, "
    "0.231792344, 1.01046945, 0.00600069867, 0.0200179144, 103.560653 } }\n"    /* 19 */
    "polarizer { center <0,0,20> normal <0,0,3> radius 15 axis <1,1,0> rotate <0,0,90> }\n" /* 20 */
    "sphere { V, 1 }\n";                                                        /* 21 */

static void test_full_scene(void)
{
    rs_scene s;
    char msg[512];
    rs_parse_opts opts;
    const rs_object *o;
    lp_vec3 w;

    rs_parse_opts_init(&opts);
    opts.image_width = 1000;
    opts.image_height = 500;
    CHECK(parse_opts(full_scene, &opts, &s, msg, sizeof msg) == 0, "full scene: %s", msg);
    CHECK(s.n_objects == 9, "9 objects, got %zu", s.n_objects);
    CHECK(s.n_lights == 2, "2 lights, got %zu", s.n_lights);
    if (s.n_objects != 9 || s.n_lights != 2) {
        rs_scene_free(&s);
        return;
    }
    CHECK(s.n_files == 1 && strcmp(s.files[0], "t.scene") == 0, "file name kept");

    /* global settings, background */
    CHECK(s.settings.max_trace_level == 10, "max_trace_level");
    CHECK_ABS(s.settings.adc_bailout, 0.0, 0, "adc_bailout");
    check_color(s.settings.ambient_light, 0.5, 0.5, 0.5, "ambient_light");
    CHECK_ABS(s.settings.assumed_gamma, 2.2, TOL, "assumed_gamma");
    CHECK(s.settings.coherent == 1, "coherent on");
    check_color(s.background, 0.1, 0.2, 0.3, "background");

    /* camera: raw keywords; right from image_width/image_height = 2 */
    check_vec(s.camera.location, 0, 2, -10, TOL, "location");
    check_vec(s.camera.look_at, 0, 1, 0, TOL, "look_at");
    CHECK(s.camera.has_look_at == 1 && s.camera.has_angle == 1, "has_look_at, has_angle");
    CHECK_ABS(s.camera.angle, 40, TOL, "angle");
    check_vec(s.camera.right, 2, 0, 0, TOL, "right = x*image_width/image_height");
    check_vec(s.camera.up, 0, 1, 0, TOL, "up");
    check_vec(s.camera.sky, 0, 1, 0.5, TOL, "sky");
    check_vec(s.camera.direction, 0, 0, 2, TOL, "direction");
    CHECK(s.camera.has_xf == 0, "no camera transform");

    /* lights */
    check_vec(s.lights[0].position, 11, 20, -30, TOL, "light 0 translated");
    check_color(s.lights[0].color, 1, 1, 1, "light 0 colour");
    CHECK(s.lights[0].polarized == 1, "light 0 polarized");
    check_vec(s.lights[0].polarization, 1, 0, 0, TOL, "light 0 polarization (normalized)");
    CHECK(s.lights[0].spectrum.type == RS_SPECTRUM_LINE, "light 0 line spectrum");
    CHECK_ABS(s.lights[0].spectrum.line_nm, 589.3, TOL, "line nm");
    check_color(s.lights[0].spectrum.rgb, 1, 1, 1, "line tint = colour");
    CHECK(s.lights[0].coherent == 1, "light 0 coherent");
    CHECK_ABS(s.lights[0].coherence_length, 0, 0, "bare coherent: infinite length");
    CHECK(s.lights[0].loc.line == 11 && s.lights[0].loc.column == 1, "light 0 loc");
    check_vec(s.lights[1].position, 0, 0, 0, TOL, "light 1 position");
    check_color(s.lights[1].color, 0.2, 0.4, 0.6, "light 1 colour from #declare");
    CHECK(s.lights[1].spectrum.type == RS_SPECTRUM_BLACKBODY, "blackbody");
    CHECK_ABS(s.lights[1].spectrum.temperature_k, 5800, TOL, "blackbody T");
    CHECK(s.lights[1].polarized == 0 && s.lights[1].coherent == 0, "light 1 natural");

    /* plane: checker, scale 0.5 in the pigment -> pattern = 2 * world */
    o = &s.objects[0];
    CHECK(o->type == RS_OBJ_PLANE, "plane type");
    CHECK(o->loc.line == 13 && o->loc.column == 1, "plane loc %d:%d", o->loc.line,
          o->loc.column);
    check_vec(o->u.plane.normal, 0, 1, 0, TOL, "plane normal");
    CHECK_ABS(o->u.plane.distance, -1, TOL, "plane distance");
    CHECK(o->pigment.type == RS_PIGMENT_CHECKER, "checker");
    check_color(o->pigment.color[0], 0.9, 0.9, 0.9, "checker colour 0");
    check_color(o->pigment.color[1], 0.1, 0.1, 0.1, "checker colour 1");
    w = rs_xf_point(&o->pigment.to_pattern, (lp_vec3){ 1, -1.5, 0.25 });
    check_vec(w, 2, -3, 0.5, TOL, "plane to_pattern");
    check_color(o->finish.ambient, 0, 0, 0, "plane ambient");
    CHECK_ABS(o->finish.diffuse, 0, 0, "plane diffuse");
    check_color(o->finish.emission, 1, 1, 1, "plane emission");

    /* sphere: texture, then translate moves object and pattern */
    o = &s.objects[1];
    CHECK(o->type == RS_OBJ_SPHERE, "sphere type");
    check_vec(o->u.sphere.center, 0, 2.5, 0, TOL, "sphere center from R");
    CHECK_ABS(o->u.sphere.radius, 1.25, TOL, "sphere radius R/2");
    CHECK(o->pigment.type == RS_PIGMENT_SOLID, "solid");
    check_color(o->pigment.color[0], 0.2, 0.4, 0.6, "solid C");
    check_color(o->finish.ambient, 0.1, 0.1, 0.1, "default ambient 0.1");
    CHECK_ABS(o->finish.diffuse, 0.6, TOL, "default diffuse 0.6");
    check_color(o->finish.emission, 0, 0, 0, "default emission 0");
    check_vec(rs_xf_point(&o->xf, (lp_vec3){ 0, 0, 0 }), 1, 0, 0, TOL, "sphere xf");
    check_vec(rs_xf_point(&o->pigment.to_pattern, (lp_vec3){ 1, 0, 0 }), 0, 0, 0, TOL,
              "sphere to_pattern");

    /* box: corners sorted; rotate <0,90,0> */
    o = &s.objects[2];
    CHECK(o->type == RS_OBJ_BOX, "box type");
    CHECK(o->loc.line == 15 && o->loc.column == 3, "box loc %d:%d", o->loc.line, o->loc.column);
    check_vec(o->u.box.corner1, -1, -1, -1, TOL, "box corner1");
    check_vec(o->u.box.corner2, 1, 1, 1, TOL, "box corner2");
    check_color(o->pigment.color[0], 1, 0.5, 0, "color red 1 green 0.5");
    check_vec(rs_xf_point(&o->xf, (lp_vec3){ 1, 0, 0 }), 0, 0, -1, TOL, "box rotate");
    check_vec(rs_xf_point(&o->pigment.to_pattern, (lp_vec3){ 0, 0, -1 }), 1, 0, 0, TOL,
              "box to_pattern");

    /* disc: normal normalized */
    o = &s.objects[3];
    CHECK(o->type == RS_OBJ_DISC, "disc type");
    check_vec(o->u.disc.center, 0, 0, 5, TOL, "disc center");
    check_vec(o->u.disc.normal, 0, 0, -1, TOL, "disc normal");
    CHECK_ABS(o->u.disc.radius, 3, TOL, "disc radius");
    CHECK_ABS(o->u.disc.hole, 1, TOL, "disc hole");
    CHECK(o->pigment.type == RS_PIGMENT_SOLID, "default pigment solid");
    check_color(o->pigment.color[0], 0, 0, 0, "default pigment black");

    /* lens 1: rotate <0,90,0> takes the axis +z to +x; then translate */
    o = &s.objects[4];
    CHECK(o->type == RS_OBJ_LENS, "lens type");
    CHECK_ABS(o->u.lens.desc.radius1, 50, TOL, "lens r1");
    CHECK_ABS(o->u.lens.desc.radius2, -50, TOL, "lens r2");
    CHECK_ABS(o->u.lens.desc.thickness, 5, TOL, "lens t");
    CHECK_ABS(o->u.lens.desc.diameter, 25, TOL, "lens D");
    CHECK_ABS(o->u.lens.desc.diameter2, 0, 0, "lens D2 default");
    CHECK(strcmp(o->u.lens.glass_name, "N-BK7") == 0, "glass name");
    check_vec(o->u.lens.desc.position, 10, 0, 0, TOL, "lens position");
    check_vec(o->u.lens.desc.axis, 1, 0, 0, TOL, "lens axis");
    check_vec(rs_xf_point(&o->xf, (lp_vec3){ 1, 2, 3 }), 1, 2, 3, 0, "lens xf identity");
    CHECK(o->lens == NULL, "lens not created before prepare");

    /* lens 2: flat inf surfaces; scale 2 doubles sizes; then translate */
    o = &s.objects[5];
    CHECK(isinf(o->u.lens.desc.radius1) && o->u.lens.desc.radius1 > 0, "radius1 inf");
    CHECK(isinf(o->u.lens.desc.radius2) && o->u.lens.desc.radius2 < 0, "radius2 -inf");
    CHECK_ABS(o->u.lens.desc.thickness, 4, TOL, "scaled thickness");
    CHECK_ABS(o->u.lens.desc.diameter, 20, TOL, "scaled diameter");
    CHECK_ABS(o->u.lens.desc.diameter2, 16, TOL, "scaled diameter2");
    CHECK(o->u.lens.glass_name[0] == '\0', "no glass name for ior");
    CHECK_ABS(lp_glass_index(&o->u.lens.desc.glass, 587.56), 1.5, TOL, "ior 1.5");
    CHECK_ABS(lp_glass_index(&o->u.lens.desc.medium, 587.56), 1.33, TOL, "medium ior");
    check_vec(o->u.lens.desc.position, 0, 0, 100, TOL, "lens 2 position");
    check_vec(o->u.lens.desc.axis, 0, 0, 1, TOL, "lens 2 axis");

    /* lens 3: Sellmeier (N-BK7 coefficients, C in um^2) */
    o = &s.objects[6];
    {
        double l2 = 0.58756 * 0.58756;
        double n2 = 1 + 1.03961212 * l2 / (l2 - 0.00600069867) +
                    0.231792344 * l2 / (l2 - 0.0200179144) + 1.01046945 * l2 / (l2 - 103.560653);
        CHECK_ABS(lp_glass_index(&o->u.lens.desc.glass, 587.56), sqrt(n2), 1e-9, "sellmeier n");
        CHECK_ABS(o->u.lens.desc.radius1, 0, 0, "radius1 0 = flat");
        check_vec(o->u.lens.desc.position, 0, 0, 0, TOL, "lens 3 position");
        check_vec(o->u.lens.desc.axis, 0, 0, 1, TOL, "lens 3 axis");
    }

    /* polarizer: rotate <0,0,90> takes (1,1,0) to (-1,1,0) */
    o = &s.objects[7];
    CHECK(o->type == RS_OBJ_POLARIZER, "polarizer type");
    check_vec(o->u.polarizer.center, 0, 0, 20, TOL, "polarizer center");
    check_vec(o->u.polarizer.normal, 0, 0, 1, TOL, "polarizer normal");
    check_vec(o->u.polarizer.axis, -sqrt(0.5), sqrt(0.5), 0, 1e-15, "polarizer axis");
    CHECK_ABS(o->u.polarizer.radius, 15, TOL, "polarizer radius");

    /* #local V = <1,2,3>*2 + x = <3,4,6> */
    o = &s.objects[8];
    check_vec(o->u.sphere.center, 3, 4, 6, TOL, "#local vector");

    /* prepare: the catalog glass resolves and all lenses are created */
    CHECK(rs_scene_prepare(&s, msg, sizeof msg) == 0, "prepare: %s", msg);
    for (size_t i = 4; i <= 6; i++)
        CHECK(s.objects[i].lens != NULL, "lens %zu created", i);
    if (s.objects[4].lens != NULL) {
        lp_lens_desc d;
        lp_glass bk7;
        lp_error err;
        lp_lens_get_desc(s.objects[4].lens, &d);
        check_vec(d.axis, 1, 0, 0, TOL, "created lens axis");
        CHECK(lp_glass_builtin("N-BK7", &bk7, &err) == LP_OK, "N-BK7 builtin");
        CHECK_ABS(lp_glass_index(&d.glass, 587.56), lp_glass_index(&bk7, 587.56), 0,
                  "catalog glass resolved");
    }
    CHECK(rs_scene_prepare(&s, msg, sizeof msg) == 0, "prepare twice: %s", msg);
    rs_scene_free(&s);
    rs_scene_free(&s); /* harmless on a freed (re-initialized) scene */
}

static void test_expressions(void)
{
    static const char text[] =
        "#declare A = -2 * (3 + 4) / 7;\n"
        "#declare B = vlength(<3, 4, 0>);\n"
        "#declare D = <1, 2, 3>.y + - - 1;\n"
        "sphere { <A, B, D>, 1 }\n"                                  /* 0: (-2, 5, 3) */
        "sphere { vcross(x, y), max(1, 5, 3) }\n"                     /* 1: z, 5 */
        "sphere { <pow(2, 10), mod(7, 3), int(-2.7)>, degrees(pi) }\n" /* 2 */
        "sphere { <atan2(1, 1), sqrt(16), abs(-3)>, min(4, 2) }\n"     /* 3 */
        "sphere { <.5, 1e-3, 2.5E+2>, 1. }\n"                         /* 4 */
        "sphere { <floor(-1.5), ceil(1.2), radians(180)>, exp(0) + ln(1) + log(100) }\n" /* 5 */
        "sphere { vnormalize(<0, 0, 5>) * 2 + 1, vdot(<1, 2, 3>, <4, 5, 6>) }\n" /* 6 */
        "sphere { <sin(0), cos(0), tan(0)>, asin(1) + acos(1) + atan(0) }\n"     /* 7 */
        "sphere { <true, off, yes>, 2 * on }\n"                      /* 8 */
        "sphere { 3, 1 }\n"                                           /* 9: promoted */
        "sphere { <1, 2, 3> * <2, 2, 2> / 2 - 1, 1 }\n"               /* 10 */
        "#declare A = A + 10;\n"
        "sphere { A, 1 }\n";                                          /* 11: redeclared */
    rs_scene s;
    char msg[512];
    const rs_object *o;

    CHECK(parse(text, &s, msg, sizeof msg) == 0, "expressions: %s", msg);
    CHECK(s.n_objects == 12, "12 spheres, got %zu", s.n_objects);
    if (s.n_objects != 12) {
        rs_scene_free(&s);
        return;
    }
    o = s.objects;
    check_vec(o[0].u.sphere.center, -2, 5, 3, TOL, "A B D");
    check_vec(o[1].u.sphere.center, 0, 0, 1, TOL, "vcross(x,y)");
    CHECK_ABS(o[1].u.sphere.radius, 5, TOL, "max");
    check_vec(o[2].u.sphere.center, 1024, 1, -2, TOL, "pow mod int");
    CHECK_ABS(o[2].u.sphere.radius, 180, TOL, "degrees(pi)");
    check_vec(o[3].u.sphere.center, atan(1.0), 4, 3, TOL, "atan2 sqrt abs");
    CHECK_ABS(o[3].u.sphere.radius, 2, TOL, "min");
    check_vec(o[4].u.sphere.center, 0.5, 0.001, 250, TOL, "number forms");
    CHECK_ABS(o[4].u.sphere.radius, 1, TOL, "1.");
    check_vec(o[5].u.sphere.center, -2, 2, 3.14159265358979323846, TOL, "floor ceil radians");
    CHECK_ABS(o[5].u.sphere.radius, 3, TOL, "exp ln log");
    check_vec(o[6].u.sphere.center, 1, 1, 3, TOL, "vnormalize*2+1");
    CHECK_ABS(o[6].u.sphere.radius, 32, TOL, "vdot");
    check_vec(o[7].u.sphere.center, 0, 1, 0, TOL, "sin cos tan");
    CHECK_ABS(o[7].u.sphere.radius, 3.14159265358979323846 / 2, TOL, "asin acos atan");
    check_vec(o[8].u.sphere.center, 1, 0, 1, TOL, "booleans");
    CHECK_ABS(o[8].u.sphere.radius, 2, TOL, "2*on");
    check_vec(o[9].u.sphere.center, 3, 3, 3, TOL, "float promoted to vector");
    check_vec(o[10].u.sphere.center, 0, 1, 2, TOL, "componentwise vector arithmetic");
    check_vec(o[11].u.sphere.center, 8, 8, 8, TOL, "redeclared A");
    rs_scene_free(&s);
}

static void test_colors_and_pigments(void)
{
    static const char text[] =
        "#declare White = colour rgb 1;\n"
        "#declare Red = color red 1;\n"
        "sphere { 0, 1 pigment { White blue 0.5 } }\n"             /* 0: override */
        "sphere { 0, 1 pigment { colour <1, 0, 0> } }\n"            /* 1 */
        "sphere { 0, 1 pigment { rgb <1, 1, 1> * 0.25 } }\n"        /* 2 */
        "sphere { 0, 1 pigment { checker } }\n"                     /* 3: blue, green */
        "sphere { 0, 1 pigment { checker Red White } }\n"           /* 4: no comma */
        "sphere { 0, 1 pigment { 0 } finish { ambient rgb <0.1,0.2,0.3> emission 0.5 } }\n" /* 5 */
        "sphere { 0, 1 scale 3 pigment { checker scale 0.5 } translate <1, 0, 0> }\n" /* 6 */
        "sphere { 0, 1 pigment { checker } pigment { scale 2 } }\n"   /* 7 */
        "sphere { 0, 1 finish { ambient 0.3 } finish { diffuse 0.2 } }\n" /* 8 */
        "sphere { 0, 1 texture { pigment { checker } rotate <0, 90, 0> } }\n"; /* 9 */
    rs_scene s;
    char msg[512];
    const rs_object *o;

    CHECK(parse(text, &s, msg, sizeof msg) == 0, "colours: %s", msg);
    CHECK(s.n_objects == 10, "10 spheres, got %zu", s.n_objects);
    if (s.n_objects != 10) {
        rs_scene_free(&s);
        return;
    }
    o = s.objects;
    check_color(o[0].pigment.color[0], 1, 1, 0.5, "identifier then blue 0.5");
    check_color(o[1].pigment.color[0], 1, 0, 0, "colour <1,0,0>");
    check_color(o[2].pigment.color[0], 0.25, 0.25, 0.25, "rgb expression");
    CHECK(o[3].pigment.type == RS_PIGMENT_CHECKER, "checker");
    check_color(o[3].pigment.color[0], 0, 0, 1, "default checker: blue first");
    check_color(o[3].pigment.color[1], 0, 1, 0, "default checker: green second");
    check_color(o[4].pigment.color[0], 1, 0, 0, "checker Red");
    check_color(o[4].pigment.color[1], 1, 1, 1, "checker White");
    check_color(o[5].pigment.color[0], 0, 0, 0, "pigment { 0 } is black");
    check_color(o[5].finish.ambient, 0.1, 0.2, 0.3, "ambient colour");
    check_color(o[5].finish.emission, 0.5, 0.5, 0.5, "emission float");
    /* scale 3 came before the pigment: it moves the object, not the
     * pattern.  pattern -> world = scale 0.5, then translate x. */
    check_vec(rs_xf_point(&o[6].xf, (lp_vec3){ 1, 0, 0 }), 4, 0, 0, TOL, "object xf");
    check_vec(rs_xf_point(&o[6].pigment.to_pattern, (lp_vec3){ 1.5, 0.5, 0.25 }), 1, 1, 0.5,
              TOL, "transforms before a pigment do not move it");
    CHECK(o[7].pigment.type == RS_PIGMENT_CHECKER, "second pigment block modifies");
    check_vec(rs_xf_point(&o[7].pigment.to_pattern, (lp_vec3){ 2, 4, 6 }), 1, 2, 3, TOL,
              "pigment { scale 2 } scales the existing checker");
    check_color(o[8].finish.ambient, 0.3, 0.3, 0.3, "finish blocks accumulate");
    CHECK_ABS(o[8].finish.diffuse, 0.2, TOL, "finish blocks accumulate (diffuse)");
    check_vec(rs_xf_point(&o[9].pigment.to_pattern, (lp_vec3){ 0, 0, -1 }), 1, 0, 0, TOL,
              "texture transform moves the pigment");
    check_vec(rs_xf_point(&o[9].xf, (lp_vec3){ 1, 0, 0 }), 1, 0, 0, TOL,
              "texture transform does not move the object");
    rs_scene_free(&s);
}

static void test_object_transforms(void)
{
    static const char text[] =
        "sphere { 0, 1 scale 2 translate x }\n"
        "sphere { 0, 1 translate x scale 2 }\n"
        "sphere { 0, 1 rotate 90*y translate <0, 0, 5> }\n"
        "camera { location <0,0,-5> rotate <0,90,0> }\n";
    rs_scene s;
    char msg[512];
    CHECK(parse(text, &s, msg, sizeof msg) == 0, "object transforms: %s", msg);
    if (s.n_objects == 3) {
        check_vec(rs_xf_point(&s.objects[0].xf, (lp_vec3){ 1, 0, 0 }), 3, 0, 0, TOL,
                  "scale 2 translate x");
        check_vec(rs_xf_point(&s.objects[1].xf, (lp_vec3){ 1, 0, 0 }), 4, 0, 0, TOL,
                  "translate x scale 2");
        check_vec(rs_xf_point(&s.objects[2].xf, (lp_vec3){ 1, 0, 0 }), 0, 0, 4, TOL,
                  "rotate 90*y translate 5z");
    }
    CHECK(s.camera.has_xf == 1, "camera has_xf");
    check_vec(s.camera.location, 0, 0, -5, TOL, "camera location stored raw");
    check_vec(rs_xf_point(&s.camera.xf, s.camera.location), -5, 0, 0, TOL, "camera xf");
    rs_scene_free(&s);
}

static void test_lens_folding(void)
{
    static const char text[] =
        "lens { radius1 20 radius2 -20 thickness 4 diameter 10 ior 1.5\n"
        "       translate <0, 0, 3> scale -2 rotate <0, 90, 0> translate <1, 2, 3> }\n"
        "polarizer { normal y radius 2 axis x scale 3 translate <0, 1, 0> }\n";
    rs_scene s;
    char msg[512];
    CHECK(parse(text, &s, msg, sizeof msg) == 0, "lens folding: %s", msg);
    if (s.n_objects == 2) {
        const lp_lens_desc *d = &s.objects[0].u.lens.desc;
        /* vertex: (0,0,3) -> scale -2 -> (0,0,-6) -> roty90 -> (-6,0,0) -> +(1,2,3).
         * axis: +z -> -z -> roty90 -> (-1,0,0).  sizes x |-2| = 2. */
        check_vec(d->position, -5, 2, 3, TOL, "folded position");
        check_vec(d->axis, -1, 0, 0, TOL, "folded axis");
        CHECK_ABS(d->radius1, 40, TOL, "folded radius1");
        CHECK_ABS(d->radius2, -40, TOL, "folded radius2");
        CHECK_ABS(d->thickness, 8, TOL, "folded thickness");
        CHECK_ABS(d->diameter, 20, TOL, "folded diameter");
        check_vec(s.objects[1].u.polarizer.center, 0, 1, 0, TOL, "polarizer center");
        check_vec(s.objects[1].u.polarizer.normal, 0, 1, 0, TOL, "polarizer normal");
        check_vec(s.objects[1].u.polarizer.axis, 1, 0, 0, TOL, "polarizer axis");
        CHECK_ABS(s.objects[1].u.polarizer.radius, 6, TOL, "polarizer radius scaled");
        CHECK(rs_scene_prepare(&s, msg, sizeof msg) == 0, "prepare folded lens: %s", msg);
    } else {
        CHECK(0, "2 objects expected, got %zu", s.n_objects);
    }
    rs_scene_free(&s);
}

static void test_light_coherence(void)
{
    static const char text[] =
        "#declare L = 0.5;\n"
        "light_source { 0, 1 coherent 0.3 }\n"
        "light_source { 0, 1 coherent off }\n"
        "light_source { 0, 1 coherent on translate x }\n"
        "light_source { 0, 1 coherent 2*L }\n"
        "light_source { 0, 1 }\n";
    rs_scene s;
    char msg[512];
    CHECK(parse(text, &s, msg, sizeof msg) == 0, "coherence: %s", msg);
    CHECK(s.n_lights == 5, "5 lights, got %zu", s.n_lights);
    if (s.n_lights == 5) {
        CHECK(s.lights[0].coherent == 1, "coherent 0.3");
        CHECK_ABS(s.lights[0].coherence_length, 0.3, TOL, "coherence length 0.3");
        CHECK(s.lights[1].coherent == 0, "coherent off");
        CHECK(s.lights[2].coherent == 1, "coherent on");
        CHECK_ABS(s.lights[2].coherence_length, 0, 0, "coherent on: infinite");
        check_vec(s.lights[2].position, 1, 0, 0, TOL, "coherent on, then a transform");
        CHECK_ABS(s.lights[3].coherence_length, 1.0, TOL, "coherent 2*L");
        CHECK(s.lights[4].coherent == 0, "natural by default");
        check_color(s.lights[4].color, 1, 1, 1, "a float light colour promotes");
        CHECK(s.lights[4].spectrum.type == RS_SPECTRUM_RGB, "rgb spectrum by default");
    }
    rs_scene_free(&s);
    expect_error("light_source { 0, 1 coherent -1 }", 1, 30,
                 "the coherence length must not be negative");
}

static void test_camera_focus(void)
{
    rs_scene s;
    char msg[512];
    CHECK(parse("camera { location <0, 0, -5> aperture 0.5 * 2 blur_samples 7\n"
                "         focal_point <1, 2, 3> }", &s, msg, sizeof msg) == 0,
          "focal blur: %s", msg);
    CHECK_ABS(s.camera.aperture, 1.0, 0, "aperture 0.5 * 2");
    CHECK(s.camera.blur_samples == 7, "blur_samples 7");
    check_vec(s.camera.focal_point, 1, 2, 3, 0, "focal_point");
    rs_scene_free(&s);
    CHECK(parse("camera { }", &s, msg, sizeof msg) == 0, "camera: %s", msg);
    CHECK(s.camera.aperture == 0.0 && s.camera.blur_samples == 0, "a pinhole by default");
    check_vec(s.camera.focal_point, 0, 0, 0, 0, "focal_point <0,0,0> by default");
    rs_scene_free(&s);
    expect_error("camera { aperture -1 }", 1, 19, "the aperture must be a finite size >= 0");
    expect_error("camera { blur_samples 0 }", 1, 23, "blur_samples must be between 1 and 4096");
    expect_error("camera { blur_samples 5000 }", 1, 23, "blur_samples must be between 1 and 4096");
    expect_error("camera { focus 1 }", 1, 10, "focal_point, aperture, blur_samples");
}

static void test_image_size(void)
{
    static const char text[] = "camera { right x*image_width/image_height up y*image_height }";
    rs_scene s;
    char msg[512];
    rs_parse_opts opts;

    rs_parse_opts_init(&opts);
    opts.image_width = 800;
    opts.image_height = 200;
    CHECK(parse_opts(text, &opts, &s, msg, sizeof msg) == 0, "image size: %s", msg);
    check_vec(s.camera.right, 4, 0, 0, TOL, "right 800/200");
    check_vec(s.camera.up, 0, 200, 0, TOL, "up image_height");
    rs_scene_free(&s);
    CHECK(parse(text, &s, msg, sizeof msg) == 0, "default image size: %s", msg);
    check_vec(s.camera.right, 640.0 / 480.0, 0, 0, TOL, "default 640x480");
    rs_scene_free(&s);
}

static void test_errors(void)
{
    char deep[256];
    rs_parse_opts opts;
    int n;

    /* syntax */
    expect_error("sphere { <0,0,0>, 1 }\nfoo", 2, 1,
                 "expected camera, light_source, background, global_settings, an object (plane, "
                 "sphere, box, disc, cylinder, cone, torus, lens, polarizer, object, union, "
                 "merge, intersection, difference) or a directive, found identifier 'foo'");
    expect_error("sphere <0,0,0>, 1 }", 1, 8, "expected '{' after 'sphere', found '<'");
    expect_error("camera { location <0,0,0>\n", 2, 1, "or '}' in camera, found end of file");
    expect_error("sphere { 0, 1 } }", 1, 17, "found '}'");
    expect_error("sphere { 0, 1 shine 3 }", 1, 15,
                 "expected pigment, finish, texture, interior, inverse, translate, rotate, scale "
                 "or '}' in sphere, found identifier 'shine'");
    expect_error("sphere { \"a\", 1 }", 1, 10, "expected a vector, found a string");
    expect_error("sphere { <1,2>, 1 }", 1, 14,
                 "expected ',' after the second vector component, found '>'");
    expect_error("sphere { <1,2,3,4,5,6>, 1 }", 1, 20,
                 "expected '>' to close the vector, found ','");
    expect_error("#declare A = 1\nsphere { 0, 1 }", 2, 1,
                 "expected ';' after the declared value, found identifier 'sphere'");
    expect_error("#declare x = 1;", 1, 10, "'x' is a reserved word");
    expect_error("#declare 3 = 1;", 1, 10, "expected an identifier after '#declare', found number 3");
    expect_error("#declare A = camera { };", 1, 14, "a camera cannot be declared");
    expect_error("#include \"no-such.inc\"", 1, 10,
                 "#include: cannot find \"no-such.inc\" beside t.scene or in the 0 library "
                 "directories (add one with -L DIR)");
    expect_error("camera { fisheye }", 1, 10,
                 "only the perspective and orthographic cameras are supported");
    expect_error("light_source { 0, rgb 1 shadowless }", 1, 25, "found identifier 'shadowless'");
    expect_error("sphere { 0, 1 pigment { checker rgb 1 rgb 0 rgb 1 } }", 1, 45,
                 "expected translate, rotate, scale or '}' in pigment, found identifier 'rgb'");
    expect_error("lens { ior 1.5 glass \"F2\" }", 1, 16, "lens: the glass is already given");
    expect_error("lens { glass F2 }", 1, 14, "expected a glass name in quotes after 'glass'");
    expect_error("sphere { sqrt 2, 1 }", 1, 15, "expected '(' after 'sqrt', found number 2");
    expect_error("sphere { V.w, 1 }", 1, 10, "undeclared identifier 'V'");
    expect_error("#declare V = 1; sphere { V.x, 1 }", 1, 27, "'.' needs a vector");

    /* lexical (with a syntax error before the lexical one, the first wins) */
    expect_error("sphere { 0, 1 }\n  /* open /* nested */ \n", 2, 3, "unterminated comment");
    expect_error("/* a /* b */", 1, 1, "unterminated comment");
    expect_error("lens { glass \"N-BK7\n }", 1, 14, "unterminated string");
    expect_error("#declare A = 1e+;", 1, 14, "bad number '1e+'");
    expect_error("#declare A = 3x;", 1, 14, "bad number '3x'");
    expect_error("#declare A = 1e999;", 1, 14, "number '1e999' is out of range");
    expect_error("sphere { 0, 1 } $", 1, 17, "unexpected character '$'");
    expect_error("sphere { 0, 1 } } $", 1, 17, "found '}'");
    expect_error("# 1", 1, 1, "expected a directive name after '#'");

    /* types and values */
    expect_error("sphere { 0, <1,2,3> }", 1, 13,
                 "expected a float for the sphere radius, found a vector");
    expect_error("global_settings { max_trace_level <1,2,3> }", 1, 35,
                 "expected a float for max_trace_level, found a vector");
    expect_error("#declare A = sqrt(<1,2,3>);", 1, 19,
                 "expected a float for the argument of sqrt(), found a vector");
    expect_error("sphere { 0, Foo }", 1, 13, "undeclared identifier 'Foo'");
    expect_error("sphere { 0, -1 }", 1, 13, "the sphere radius must be positive");
    expect_error("plane { <0,0,0>, 1 }", 1, 9, "the plane normal must not be a zero vector");
    expect_error("disc { 0, y, 1, 2 }", 1, 17, "the disc hole radius");
    expect_error("camera { angle 180 }", 1, 16, "the camera angle must be between 0 and 180");
    expect_error("global_settings { max_trace_level 0 }", 1, 35,
                 "max_trace_level must be between 1 and 256");
    expect_error("light_source { 0, 1 polarization 0 }", 1, 34,
                 "the polarization must not be a zero vector");
    expect_error("light_source { 0, 1 spectrum { line -5 } }", 1, 37,
                 "the line wavelength must be positive");

    /* arithmetic */
    expect_error("#declare A = 1/(2-2);", 1, 15, "division by zero");
    expect_error("#declare A = <1,1,1>/<1,0,1>;", 1, 21, "division by zero");
    expect_error("#declare A = 1e300*1e300;", 1, 19, "the result of '*' is not a finite number");
    expect_error("#declare A = sqrt(-1);", 1, 14, "the result of sqrt() is not a finite number");
    expect_error("#declare A = ln(0);", 1, 14, "the result of ln() is not a finite number");
    expect_error("#declare A = mod(1, 0);", 1, 14, "mod(): division by zero");
    expect_error("#declare A = vnormalize(<0,0,0>);", 1, 14, "vnormalize() of a zero vector");
    expect_error("#declare A = pow(0, -1);", 1, 14, "the result of pow() is not a finite number");

    /* transparency refused */
    expect_error("plane { y, 0 pigment { rgbf <1,1,1,0.5> } }", 1, 24,
                 "transparent pigments are not supported: use a lens object");
    expect_error("plane { y, 0 pigment { rgb 1 transmit 0.5 } }", 1, 24,
                 "transparent pigments are not supported");
    expect_error("plane { y, 0 pigment { 0.5 } }", 1, 24,
                 "a lone float colour also sets filter and transmit");

    /* transforms */
    expect_error("sphere { 0, 1 scale <1,0,1> }", 1, 21, "scale <1,0,1> has a zero component");
    expect_error("lens {\n  radius1 50 radius2 -50 thickness 5 diameter 25 ior 1.5\n"
                 "  scale <1,2,1>\n}", 3, 3, "non-uniform scale <1,2,1> of a lens");
    expect_error("polarizer { normal z radius 1 axis x scale <2,2,1> }", 1, 38,
                 "non-uniform scale <2,2,1> of a polarizer");
    expect_error("polarizer { normal z radius 1 axis <0,0,2> }", 1, 31,
                 "the polarizer axis must not be parallel to its normal");
    expect_error("polarizer { normal z radius 1 }", 1, 1, "polarizer: missing axis");
    expect_error("lens { radius1 1 radius2 1 diameter 1 ior 1.5 }", 1, 1,
                 "lens: missing thickness");
    expect_error("lens { radius1 1 radius2 1 diameter 1 thickness 1 }", 1, 1,
                 "lens: missing a glass");
    expect_error("lens { thickness 0 }", 1, 18, "thickness must be positive");
    expect_error("sphere { 0, 1 translate 1e308*x translate 1e308*x }", 1, 33,
                 "the transforms are too large");
    expect_error("sphere { 0, 1 pigment { scale 1e200 scale 1e200 } }", 1, 37,
                 "the transforms are too large");
    expect_error("lens { radius1 1e300 radius2 0 thickness 1 diameter 1 ior 1.5 scale 1e10 }",
                 1, 1, "lens: a value is not finite after the transforms");
    expect_error("light_source { 1e308*x, 1 scale 10 }", 1, 1,
                 "light_source: the position is not finite");

    /* nesting: 64 levels pass, 65 are refused at the 65th '(' */
    n = snprintf(deep, sizeof deep, "#declare A = ");
    for (int i = 0; i < 64; i++)
        deep[n++] = '(';
    deep[n++] = '1';
    for (int i = 0; i < 64; i++)
        deep[n++] = ')';
    deep[n++] = ';';
    deep[n] = '\0';
    {
        rs_scene s;
        char msg[256];
        CHECK(parse(deep, &s, msg, sizeof msg) == 0, "64 levels: %s", msg);
        rs_scene_free(&s);
    }
    n = snprintf(deep, sizeof deep, "#declare A = ");
    for (int i = 0; i < 65; i++)
        deep[n++] = '(';
    deep[n++] = '1';
    for (int i = 0; i < 65; i++)
        deep[n++] = ')';
    deep[n++] = ';';
    deep[n] = '\0';
    expect_error(deep, 1, 14 + 64, "nesting deeper than 64 levels");
    /* braces count too: 1 (camera) + 63 = 64 ok, 1 + 64 refused */
    n = snprintf(deep, sizeof deep, "camera { location ");
    for (int i = 0; i < 64; i++)
        deep[n++] = '(';
    deep[n++] = '1';
    for (int i = 0; i < 64; i++)
        deep[n++] = ')';
    snprintf(deep + n, sizeof deep - (size_t)n, " }");
    expect_error(deep, 1, 19 + 63, "nesting deeper than 64 levels");

    /* the object limit */
    rs_parse_opts_init(&opts);
    opts.max_objects = 3;
    expect_error_opts("sphere{0,1}\nsphere{0,1}\nsphere{0,1}\n  sphere{0,1}", &opts, 4, 3,
                      "too many objects (the limit is 3)");
}

static void test_prepare_errors(void)
{
    rs_scene s;
    char msg[512];

    CHECK(parse("\n  lens { radius1 50 radius2 -50 thickness 5 diameter 25 glass \"NOPE\" }", &s,
                msg, sizeof msg) == 0, "unknown glass parses: %s", msg);
    CHECK(rs_scene_prepare(&s, msg, sizeof msg) == -1, "unknown glass refused");
    CHECK(strncmp(msg, "t.scene:2:3: lens: glass \"NOPE\"", 31) == 0, "message: %s", msg);
    rs_scene_free(&s);

    CHECK(parse("lens { radius1 5 radius2 -50 thickness 5 diameter 25 ior 1.5 }", &s, msg,
                sizeof msg) == 0, "impossible lens parses: %s", msg);
    CHECK(rs_scene_prepare(&s, msg, sizeof msg) == -1, "impossible lens refused");
    CHECK(strncmp(msg, "t.scene:1:1: lens: ", 19) == 0, "message: %s", msg);
    CHECK(s.objects[0].lens == NULL, "no lens after failure");
    rs_scene_free(&s);
}

static void test_files(void)
{
    char path[1024], msg[512];
    rs_scene s;
    FILE *f;
    clock_t t0;
    double secs;
    int rc;
    const size_t count = 10000;

    /* a generated file with 10^4 spheres */
    snprintf(path, sizeof path, "%s/test_parser_many.scene", LP_TEST_TMP);
    f = fopen(path, "wb");
    CHECK(f != NULL, "cannot write %s", path);
    if (f == NULL)
        return;
    fprintf(f, "#declare S = 0.25;\ncamera { location <0, 0, -100> look_at 0 }\n");
    for (size_t i = 0; i < count; i++)
        fprintf(f, "sphere { <%zu, %zu, 0>, S pigment { rgb <0.5, 0.5, 0.5> } "
                   "finish { ambient 0 } translate <0, 0, %zu> }\n",
                i % 100, i / 100, i % 7);
    fclose(f);
    rs_scene_init(&s);
    t0 = clock();
    rc = rs_parse_file(path, NULL, &s, msg, sizeof msg);
    secs = (double)(clock() - t0) / CLOCKS_PER_SEC;
    CHECK(rc == 0, "many: %s", msg);
    CHECK(s.n_objects == count, "10^4 objects, got %zu", s.n_objects);
    CHECK(secs < 5.0, "10^4 objects parsed in %.3f s", secs);
    printf("test_parser: 10^4 spheres parsed in %.3f s\n", secs);
    if (s.n_objects == count) {
        check_vec(s.objects[9999].u.sphere.center, 99, 99, 0, 0, "last sphere");
        CHECK(s.objects[9999].loc.line == 10002, "last sphere line %d", s.objects[9999].loc.line);
        CHECK(strcmp(s.objects[9999].loc.file, path) == 0, "loc file is the path");
    }
    rs_scene_free(&s);

    /* a NUL byte in a file is an unexpected character at its place */
    snprintf(path, sizeof path, "%s/test_parser_nul.scene", LP_TEST_TMP);
    f = fopen(path, "wb");
    if (f != NULL) {
        fwrite("sphere { 0, 1 }\n  \0", 1, 19, f);
        fclose(f);
        rs_scene_init(&s);
        CHECK(rs_parse_file(path, NULL, &s, msg, sizeof msg) == -1, "NUL refused");
        CHECK(strstr(msg, ":2:3: unexpected character 0x00") != NULL, "NUL message: %s", msg);
        CHECK(s.n_objects == 1, "the object before the error is kept");
        rs_scene_free(&s);
    }

    /* a missing file */
    rs_scene_init(&s);
    CHECK(rs_parse_file("/nonexistent/dir/x.scene", NULL, &s, msg, sizeof msg) == -1,
          "missing file refused");
    CHECK(strstr(msg, "/nonexistent/dir/x.scene: cannot read") == msg, "message: %s", msg);
    rs_scene_free(&s);

    /* every scene of the project parses and its lenses can be created */
#ifdef HAVE_DIRENT
    {
        char dir[600];
        DIR *d;
        struct dirent *e;
        int seen = 0;
        const char *dirs[4];
        rs_parse_opts lib;
        rs_parse_opts_init(&lib);
        lib.include_dirs = dirs;
        lib.n_include_dirs = rs_library_path(NULL, 0, dirs, sizeof dirs / sizeof dirs[0]);
        snprintf(dir, sizeof dir, "%s/scenes", LP_SOURCE_DIR);
        d = opendir(dir);
        while (d != NULL && (e = readdir(d)) != NULL) {
            size_t n = strlen(e->d_name);
            if (n < 7 || strcmp(e->d_name + n - 6, ".scene") != 0)
                continue;
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            rs_scene_init(&s);
            rc = rs_parse_file(path, &lib, &s, msg, sizeof msg);
            if (rc != 0 && lib.n_include_dirs == 0 && strstr(msg, "cannot find") != NULL) {
                printf("test_parser: SKIPPED %s: it includes POV-Ray's files, and "
                       RS_POVRAY_INCLUDE_DIR " is not installed\n", e->d_name);
                rs_scene_free(&s);
                continue;
            }
            CHECK(rc == 0, "%s", msg);
            if (rc == 0)
                CHECK(rs_scene_prepare(&s, msg, sizeof msg) == 0, "%s", msg);
            rs_scene_free(&s);
            seen++;
        }
        if (d != NULL)
            closedir(d);
        printf("test_parser: %d project scenes parsed and prepared\n", seen);
    }
#endif
}

static void test_comments_and_misc(void)
{
    static const char text[] =
        "\xEF\xBB\xBF// BOM first\r\n"
        "/* a // b */ sphere {0,1}\r\n"
        "/* /* deep /* deeper */ */ */ sphere {0 1}\n"
        "sphere { 0, 1 } // trailing\n"
        "#local K = 2; sphere { <K,0,0>, K }";
    rs_scene s;
    char msg[256];
    CHECK(parse(text, &s, msg, sizeof msg) == 0, "comments: %s", msg);
    CHECK(s.n_objects == 4, "4 spheres, got %zu", s.n_objects);
    if (s.n_objects == 4) {
        CHECK(s.objects[1].loc.line == 3 && s.objects[1].loc.column == 31, "loc after comments");
        check_vec(s.objects[3].u.sphere.center, 2, 0, 0, TOL, "#local");
    }
    rs_scene_free(&s);

    /* two parses add to one scene; locations keep their file names */
    rs_scene_init(&s);
    CHECK(rs_parse_string("sphere{0,1}", "a.scene", NULL, &s, msg, sizeof msg) == 0, "a");
    CHECK(rs_parse_string("\nsphere{0,1}", "b.scene", NULL, &s, msg, sizeof msg) == 0, "b");
    CHECK(s.n_objects == 2 && s.n_files == 2, "two files");
    if (s.n_objects == 2) {
        CHECK(strcmp(s.objects[0].loc.file, "a.scene") == 0, "file a");
        CHECK(strcmp(s.objects[1].loc.file, "b.scene") == 0 && s.objects[1].loc.line == 2,
              "file b");
    }
    rs_scene_free(&s);

    /* NULL text, NULL message buffer */
    rs_scene_init(&s);
    CHECK(rs_parse_string(NULL, NULL, NULL, &s, msg, sizeof msg) == -1, "NULL text");
    CHECK(rs_parse_string("sphere {", NULL, NULL, &s, NULL, 0) == -1, "NULL msg ok");
    CHECK(rs_parse_string("sphere {", NULL, NULL, &s, msg, sizeof msg) == -1 &&
              strncmp(msg, "<string>:1:9: ", 14) == 0, "default name: %s", msg);
    rs_scene_free(&s);

    /* empty text is an empty scene with the defaults */
    CHECK(parse("", &s, msg, sizeof msg) == 0, "empty: %s", msg);
    CHECK(s.n_objects == 0 && s.settings.max_trace_level == 5, "defaults");
    CHECK_ABS(s.settings.adc_bailout, 1.0 / 255.0, TOL, "adc default");
    check_vec(s.camera.right, 1.33, 0, 0, TOL, "default right");
    rs_scene_free(&s);
}

/* ------------------------------------------------------------------ */
/* The directive language, declared values, new shapes, warnings      */
/* ------------------------------------------------------------------ */

static const char *const test_dirs[] = { LP_TEST_TMP };

/* Parse with LP_TEST_TMP as the library directory; returns the status. */
static int parse_lib(const char *text, rs_scene *s, char *msg, size_t n)
{
    rs_parse_opts o;
    rs_parse_opts_init(&o);
    o.include_dirs = test_dirs;
    o.n_include_dirs = 1;
    return parse_opts(text, &o, s, msg, n);
}

static void write_file(const char *name, const char *text)
{
    char path[1024];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", LP_TEST_TMP, name);
    f = fopen(path, "wb");
    CHECK(f != NULL, "cannot write %s", path);
    if (f != NULL) {
        fputs(text, f);
        fclose(f);
    }
}

/* The scene must parse; its sphere radii (in order) must be want[0..n). */
static void expect_radii(const char *text, const double *want, size_t n, const char *what)
{
    rs_scene s;
    char msg[512] = "";
    int rc = parse_lib(text, &s, msg, sizeof msg);
    CHECK(rc == 0, "%s: %s", what, msg);
    CHECK(s.n_objects == n, "%s: %zu objects, want %zu", what, s.n_objects, n);
    for (size_t i = 0; rc == 0 && i < n && i < s.n_objects; i++)
        CHECK_ABS(s.objects[i].u.sphere.radius, want[i], TOL, "%s: radius %zu", what, i);
    rs_scene_free(&s);
}

static void test_directives(void)
{
    static const double r123[] = { 1, 2, 3 }, r1[] = { 1 }, r2[] = { 2 }, r3[] = { 3 };
    static const double r4[] = { 4 }, r24[] = { 2, 4 }, r5[] = { 5 };
    rs_scene s;
    char msg[512];

    /* #if / #elseif / #else, nested skipping */
    expect_radii("#if (1) sphere{0,1} #else sphere{0,2} #end", r1, 1, "#if true");
    expect_radii("#if (0) sphere{0,1} #else sphere{0,2} #end", r2, 1, "#if false");
    expect_radii("#if (0) sphere{0,1} #elseif (1) sphere{0,2} #else sphere{0,3} #end", r2, 1,
                 "#elseif");
    expect_radii("#if (0) #if (1) sphere{0,1} #end #while (1) #end #else sphere{0,3} #end",
                 r3, 1, "nested blocks skipped");
    expect_radii("#if (2 > 1 & 1 <= 1 & !(1 = 2) & (3 != 4 | 0)) sphere{0,4} #end", r4, 1,
                 "comparisons and logic");
    expect_radii("sphere{0, (1 < 2 ? 2 : 3)} sphere{0, 0 ? 1 : 4}", r24, 2, "?:");
    /* #ifdef / #ifndef / #undef */
    expect_radii("#declare A = 1; #ifdef (A) sphere{0,A} #end #ifndef (B) sphere{0,2} #end",
                 (const double[]){ 1, 2 }, 2, "#ifdef/#ifndef");
    expect_radii("#declare A = 1; #undef A #ifdef (A) sphere{0,1} #else sphere{0,2} #end", r2,
                 1, "#undef");
    /* #while */
    expect_radii("#declare I = 1; #while (I <= 3) sphere{0,I} #declare I = I + 1; #end", r123,
                 3, "#while");
    /* #switch: #case, #range, #break, #else, falling through */
    expect_radii("#switch (2) #case (1) sphere{0,1} #break #case (2) sphere{0,2} #break "
                 "#else sphere{0,3} #end", r2, 1, "#case");
    expect_radii("#switch (2.5) #case (1) sphere{0,1} #break #range (2, 3) sphere{0,3} #break "
                 "#end", r3, 1, "#range");
    expect_radii("#switch (7) #case (1) sphere{0,1} #break #else sphere{0,4} #end", r4, 1,
                 "#switch #else");
    expect_radii("#switch (1) #case (1) sphere{0,2} #case (2) sphere{0,4} #break #end", r24, 2,
                 "a case without #break falls through");
    /* #macro: parameters, a value, objects, locals, recursion */
    expect_radii("#macro Twice(X) (2*X) #end sphere{0, Twice(2.5)}", r5, 1, "macro value");
    expect_radii("#macro Ball(R) sphere{0, R} #end Ball(1) Ball(2) Ball(3)", r123, 3,
                 "macro objects");
    expect_radii("#macro M() #local L = 4; sphere{0,L} #end M() #ifndef (L) sphere{0,5} #end",
                 (const double[]){ 4, 5 }, 2, "#local is local to the macro");
    expect_radii("#macro Fact(N) #if (N <= 1) 1 #else N*Fact(N-1) #end #end sphere{0,Fact(3)}",
                 (const double[]){ 6 }, 1, "recursive macro");
    expect_radii("#declare V = <1,2,3,4,5>; sphere{0, V.filter + V.t - V.u}", (const double[]){ 8 },
                 1, "5-component vectors");
    expect_radii("#declare S = concat(\"a\", str(12.5, 0, 1), chr(66)); sphere{0, strlen(S)}",
                 (const double[]){ 6 }, 1, "strings");
    expect_radii("sphere{0, select(-1, 1, 2) + select(0, 1, 2, 3) + div(7, 2) + version/3.7}",
                 (const double[]){ 7 }, 1, "select, div, version");
    /* #include beside the file, then in the library directories */
    write_file("test_parser_inc.inc", "#declare IncR = 3;\n#macro IncBall() sphere{0,IncR} #end\n");
    expect_radii("#include \"test_parser_inc.inc\" IncBall()", r3, 1, "#include");
    /* #version, #debug, #warning */
    {
        int rc = parse("#version 3.5;\n#debug \"hello\\n\"\n  #warning concat(\"w\", \"x\")\n"
                       "sphere{0,1}", &s, msg, sizeof msg);
        CHECK(rc == 0, "#debug/#warning: %s", msg);
        CHECK(s.n_messages == 2, "two messages, got %zu", s.n_messages);
        if (s.n_messages == 2) {
            CHECK(s.messages[0].kind == RS_MSG_DEBUG && strcmp(s.messages[0].text, "hello\n") == 0,
                  "#debug text '%s'", s.messages[0].text);
            CHECK(s.messages[1].kind == RS_MSG_WARNING &&
                      strcmp(s.messages[1].text, "t.scene:3:3: warning: #warning: wx") == 0,
                  "#warning text '%s'", s.messages[1].text);
        }
        rs_scene_free(&s);
    }

    /* errors of the directives, each at its place */
    expect_error("#error \"stop here\"", 1, 1, "#error: stop here");
    expect_error("sphere{0,1}\n#if (1)\nsphere{0,1}", 2, 1, "#if has no #end");
    expect_error("#if (0)\nsphere{0,1}", 1, 1, "#if has no #end");
    expect_error("#while (0) sphere{0,1}", 1, 1, "#while has no #end");
    expect_error("#end", 1, 1, "#end without #if, #ifdef, #ifndef, #while, #switch or #macro");
    expect_error("#else", 1, 1, "#else without #if");
    expect_error("#break", 1, 1, "#break without #switch");
    expect_error("#case (1)", 1, 1, "#case without #switch");
    expect_error("#for (I, 1, 2) #end", 1, 1, "unsupported directive '#for'");
    expect_error("#if 1 #end", 1, 5, "expected '(' after '#if', found number 1");
    expect_error("#if (<1,2,3>) #end", 1, 6, "#if needs a float");
    expect_error("#if (1 sphere", 1, 8,
                 "expected ')' to close the condition of '#if', found identifier 'sphere'");
    expect_error("#ifdef (1) #end", 1, 9, "expected an identifier, found number 1");
    expect_error("#range (1, 2)", 1, 1, "#range without #switch");
    expect_error("#macro M(A) #end M(1, 2)", 1, 23, "macro 'M' takes 1 argument");
    expect_error("#macro M(A, B) #end M(1)", 1, 24, "macro 'M' takes 2 arguments, found 1");
    expect_error("#macro M(A) A", 1, 1, "#macro has no #end");
    expect_error("#macro sphere() #end", 1, 8, "'sphere' is a reserved word");
    expect_error("#macro M() M() #end M()", 1, 12, "nested deeper than");
    expect_error("#declare A = \"s\"; sphere{0, A}", 1, 29, "expected a float for the sphere "
                                                          "radius, found a string");
    expect_error("#include \"\"", 1, 10, "#include of an empty file name");
    expect_error("#debug 1", 1, 8, "expected a string, found number 1");
    expect_error("#declare A = 1 < <1,2,3>;", 1, 16, "'<' needs floats on both sides");
    expect_error("#declare A = 1 ! 2;", 1, 18, "expected '=' after '!'");
    expect_error("#declare A = 1 ? 2;", 1, 19, "expected ':' in 'c ? a : b'");
    {
        rs_parse_opts o;
        rs_parse_opts_init(&o);
        o.max_tokens = 100000;
        expect_error_opts("#while (1)\n#end", &o, 2, 1, "the scene reads too many tokens");
    }
}

static void test_declared_values(void)
{
    rs_scene s;
    char msg[512];
    int rc;

    /* declared finish, pigment, texture, interior, object; object { } */
    rc = parse("#declare F = finish { phong 0.5 phong_size 20 specular 0.25 roughness 0.01 "
               "brilliance 2 reflection { 0.1, 0.8 fresnel on } }\n"
               "#declare P = pigment { rgb <1, 0.5, 0> }\n"
               "#declare T = texture { pigment { P } finish { F diffuse 0.3 } }\n"
               "#declare I = interior { ior 1.5 }\n"
               "#declare Ball = sphere { 0, 1 texture { T } interior { I } }\n"
               "object { Ball translate <1, 2, 3> }\n"
               "object { Ball scale 2 finish { reflection rgb <0.2, 0.3, 0.4> } }\n",
               &s, msg, sizeof msg);
    CHECK(rc == 0, "declared values: %s", msg);
    CHECK(s.n_objects == 2, "declared values: %zu objects", s.n_objects);
    if (rc == 0 && s.n_objects == 2) {
        const rs_object *a = &s.objects[0], *b = &s.objects[1];
        const rs_finish *f = &a->finish;
        check_color(a->pigment.color[0], 1, 0.5, 0, "declared pigment");
        CHECK_ABS(f->phong, 0.5, TOL, "phong");
        CHECK_ABS(f->phong_size, 20, TOL, "phong_size");
        CHECK_ABS(f->specular, 0.25, TOL, "specular");
        CHECK_ABS(f->roughness, 0.01, TOL, "roughness");
        CHECK_ABS(f->brilliance, 2, TOL, "brilliance");
        CHECK_ABS(f->diffuse, 0.3, TOL, "diffuse over the declared finish");
        check_color(f->reflection_min, 0.1, 0.1, 0.1, "reflection min");
        check_color(f->reflection_max, 0.8, 0.8, 0.8, "reflection max");
        CHECK(f->fresnel == 1, "fresnel on");
        CHECK_ABS(a->ior, 1.5, TOL, "interior ior");
        check_vec(rs_xf_point(&a->xf, (lp_vec3){ 0, 0, 0 }), 1, 2, 3, TOL, "object translate");
        check_vec(rs_xf_point(&b->xf, (lp_vec3){ 1, 0, 0 }), 2, 0, 0, TOL, "object scale");
        check_color(b->finish.reflection_max, 0.2, 0.3, 0.4, "reflection colour");
        CHECK(b->finish.fresnel == 0, "reflection colour: no fresnel");
        CHECK_ABS(b->finish.phong, 0.5, TOL, "object { } keeps the finish it modifies");
    }
    rs_scene_free(&s);

    /* union: members without a texture take the union's; transforms move all */
    rc = parse("union { sphere { 0, 1 pigment { rgb 1 } } box { 0, 1 } cylinder { 0, y, 0.5 open }"
               " cone { 0, 1, 2*y, 0 } torus { 2, 0.5 } pigment { rgb <0, 1, 0> } "
               "translate x }\n", &s, msg, sizeof msg);
    CHECK(rc == 0, "union: %s", msg);
    CHECK(s.n_objects == 5, "union: %zu objects", s.n_objects);
    if (rc == 0 && s.n_objects == 5) {
        check_color(s.objects[0].pigment.color[0], 1, 1, 1, "own pigment kept");
        check_color(s.objects[1].pigment.color[0], 0, 1, 0, "union pigment given");
        CHECK(s.objects[2].type == RS_OBJ_CYLINDER && s.objects[2].u.cylinder.open == 1,
              "open cylinder");
        CHECK_ABS(s.objects[2].u.cylinder.radius, 0.5, TOL, "cylinder radius");
        check_vec(s.objects[2].u.cylinder.cap, 0, 1, 0, TOL, "cylinder cap");
        CHECK(s.objects[3].type == RS_OBJ_CONE, "cone");
        CHECK_ABS(s.objects[3].u.cone.base_radius, 1, TOL, "cone base radius");
        CHECK_ABS(s.objects[3].u.cone.cap_radius, 0, TOL, "cone cap radius");
        CHECK(s.objects[4].type == RS_OBJ_TORUS, "torus");
        CHECK_ABS(s.objects[4].u.torus.major, 2, TOL, "torus major");
        CHECK_ABS(s.objects[4].u.torus.minor, 0.5, TOL, "torus minor");
        check_vec(rs_xf_point(&s.objects[4].xf, (lp_vec3){ 0, 0, 0 }), 1, 0, 0, TOL,
                  "union translate");
    }
    rs_scene_free(&s);

    /* a declared lens moved by object { } folds into its description */
    rc = parse("#declare L = lens { radius1 50 radius2 -50 thickness 5 diameter 20 ior 1.5 }\n"
               "object { L rotate y*90 translate <1, 0, 0> scale 2 }\n", &s, msg, sizeof msg);
    CHECK(rc == 0, "declared lens: %s", msg);
    if (rc == 0 && s.n_objects == 1) {
        const lp_lens_desc *d = &s.objects[0].u.lens.desc;
        check_vec(d->position, 2, 0, 0, 1e-12, "lens position");
        check_vec(d->axis, 1, 0, 0, 1e-12, "lens axis");
        CHECK_ABS(d->radius1, 100, 1e-12, "lens radius1 scaled");
        CHECK_ABS(d->thickness, 10, 1e-12, "lens thickness scaled");
    }
    rs_scene_free(&s);

    /* colours: rgbf, rgbt, rgbft, filter, transmit */
    rc = parse("#declare A = rgbf <1, 0.5, 0.25, 0.75>; #declare B = rgbt 0.5;\n"
               "#declare C = color red 1 filter 0.25 transmit 0.5; #declare D = color 0.5;\n"
               "sphere { 0, A.filter + B.transmit + B.filter + C.filter + C.transmit + D.t }",
               &s, msg, sizeof msg);
    CHECK(rc == 0, "colours: %s", msg);
    if (rc == 0 && s.n_objects == 1)
        CHECK_ABS(s.objects[0].u.sphere.radius, 0.75 + 0.5 + 0 + 0.25 + 0.5 + 0.5, TOL,
                  "filter and transmit components");
    rs_scene_free(&s);

    /* orthographic camera */
    rc = parse("camera { orthographic location <0,0,-5> right 4*x up 3*y }", &s, msg, sizeof msg);
    CHECK(rc == 0 && s.camera.orthographic == 1, "orthographic: %s", msg);
    rs_scene_free(&s);

    /* warnings: read but not rendered, with file:line:col; an empty scene */
    rc = parse("global_settings { assumed_gamma 2.2 }\n"
               "sphere { 0, 1 finish { metallic reflection { 0, 1 falloff 2 } } }", &s, msg,
               sizeof msg);
    CHECK(rc == 0, "warnings: %s", msg);
    CHECK(s.n_messages == 3, "three warnings, got %zu", s.n_messages);
    if (s.n_messages == 3) {
        CHECK(strstr(s.messages[0].text, "t.scene:1:19: warning: assumed_gamma 2.2 is read but "
                                         "not used") == s.messages[0].text,
              "%s", s.messages[0].text);
        CHECK(strcmp(s.messages[1].text,
                     "t.scene:2:24: warning: finish metallic is read but not rendered") == 0,
              "%s", s.messages[1].text);
        CHECK(strcmp(s.messages[2].text,
                     "t.scene:2:51: warning: reflection falloff is read but not rendered") == 0,
              "%s", s.messages[2].text);
    }
    rs_scene_free(&s);
    rc = parse("// nothing\ncamera { }\n", &s, msg, sizeof msg);
    CHECK(rc == 0 && s.n_messages == 1 &&
              strcmp(s.messages[0].text, "t.scene:3:1: warning: no objects in the scene") == 0,
          "empty scene warns: %s", s.n_messages ? s.messages[0].text : "(none)");
    rs_scene_free(&s);

    /* errors of the new values and shapes */
    expect_error("#declare Ball = sphere { 0, 1 }\nBall", 2, 1,
                 "'Ball' is a declared object: write object { Ball }");
    expect_error("object { Nope }", 1, 10, "undeclared identifier 'Nope'");
    expect_error("#declare F = finish { }; object { F }", 1, 35, "'F' is a finish, not an object");
    expect_error("union { lens { radius1 50 radius2 -50 thickness 5 diameter 20 ior 1.5 } }", 1, 9,
                 "a lens cannot be part of a union");
    expect_error("cylinder { 0, 0, 1 }", 1, 15, "the cylinder's base and cap points must differ");
    expect_error("cylinder { 0, y, -1 }", 1, 18, "the cylinder radius must be positive");
    expect_error("cone { 0, -1, y, 1 }", 1, 11, "the cone's radii must be at least 0");
    expect_error("torus { 1, 0 }", 1, 9, "the torus radii must be positive");
    expect_error("sphere { 0, 1 finish { phong_size 0 } }", 1, 35, "phong_size must be positive");
    expect_error("sphere { 0, 1 finish { roughness -1 } }", 1, 34, "roughness must be positive");
    expect_error("sphere { 0, 1 finish { reflection { 0, 1 bogus } } }", 1, 42,
                 "expected fresnel, falloff, exponent, metallic or '}' in reflection");
    expect_error("camera { orthographic angle 30 }", 1, 23,
                 "angle with an orthographic camera is not supported");
    expect_error("sphere { 0, 1 interior { fade_distance 1 } }", 1, 26,
                 "expected ior or '}' in interior");
    expect_error("object { lens { radius1 50 radius2 -50 thickness 5 diameter 20 ior 1.5 } "
                 "scale <1, 2, 1> }", 1, 74,
                 "a lens can only be moved, turned and scaled by the same factor");
}

/* POV-Ray 3.7's own colors.inc and finish.inc, read unchanged from the
 * installed POV-Ray (skipped, saying why, when it is not installed). */
static void test_povray_includes(void)
{
    static const char *const dirs[] = { "/usr/share/povray-3.7/include" };
    rs_parse_opts o;
    rs_scene s;
    char msg[512];
    FILE *f = fopen("/usr/share/povray-3.7/include/colors.inc", "rb");
    int rc;

    if (f == NULL) {
        printf("test_parser: SKIPPED colors.inc/finish.inc: POV-Ray's include directory "
               "/usr/share/povray-3.7/include is not installed\n");
        return;
    }
    fclose(f);
    rs_parse_opts_init(&o);
    o.include_dirs = dirs;
    o.n_include_dirs = 1;
    rc = parse_opts("#include \"colors.inc\"\n#include \"finish.inc\"\n"
                    "#declare H = CHSV2RGB(<240, 1, 0.5>);\n"
                    "sphere { 0, 1 pigment { Gray50 } finish { Phong_Shiny } }\n"
                    "sphere { 0, 1 pigment { H } finish { Dull } }\n"
                    "sphere { 0, 1 pigment { MediumSlateBlue } finish { Mirror } }\n",
                    &o, &s, msg, sizeof msg);
    CHECK(rc == 0, "colors.inc, finish.inc: %s", msg);
    CHECK(s.n_objects == 3, "three spheres, got %zu", s.n_objects);
    if (rc == 0 && s.n_objects == 3) {
        /* the values as the two files write them */
        check_color(s.objects[0].pigment.color[0], 0.5, 0.5, 0.5, "Gray50 = White*0.50");
        CHECK_ABS(s.objects[0].finish.phong, 1, TOL, "Phong_Shiny phong");
        CHECK_ABS(s.objects[0].finish.phong_size, 200, TOL, "Phong_Shiny phong_size");
        /* CHSV2RGB: hue 240 is pure blue; value 0.5 */
        check_color(s.objects[1].pigment.color[0], 0, 0, 0.5, "CHSV2RGB(<240,1,0.5>)");
        CHECK_ABS(s.objects[1].finish.specular, 0.5, TOL, "Dull specular");
        CHECK_ABS(s.objects[1].finish.roughness, 0.15, TOL, "Dull roughness");
        check_color(s.objects[2].pigment.color[0], 0.498039, 0, 1, "MediumSlateBlue");
        check_color(s.objects[2].finish.reflection_max, 1, 1, 1, "Mirror reflection");
        CHECK_ABS(s.objects[2].finish.diffuse, 0, TOL, "Mirror diffuse");
        CHECK(s.n_messages == 0, "no warnings, got %zu", s.n_messages);
    }
    rs_scene_free(&s);
}

/* intersection and difference: the tree the parser builds (members in
 * order, a union inside as one member, transforms moved down to the
 * members, lights out to the scene, textures after POV-Ray's rule) and
 * every error they can give. */
static void test_csg(void)
{
    rs_scene s;
    rs_parse_opts opts;
    char msg[512];
    int rc;

    rc = parse("difference {\n"
               "  box { -1, 1 }\n"
               "  union { sphere { <0,1,0>, 0.5 } sphere { <0,-1,0>, 0.5 pigment { rgb <1,0,0> } } }\n"
               "  cylinder { <0,0,-2>, <0,0,2>, 0.3 inverse }\n"
               "  light_source { <0, 5, 0> rgb 1 }\n"
               "  pigment { rgb <0,1,0> } interior { ior 1.4 } inverse\n"
               "  translate <10, 0, 0>\n"
               "}\n", &s, msg, sizeof msg);
    CHECK(rc == 0, "difference parses: %s", msg);
    if (rc == 0) {
        const rs_object *o = &s.objects[0];
        CHECK(s.n_objects == 1 && o->type == RS_OBJ_CSG && o->u.csg.op == RS_CSG_DIFFERENCE &&
                  o->u.csg.n_members == 3 && o->inverse,
              "one inverted difference of 3 members");
        CHECK(o->loc.line == 1 && o->loc.column == 1, "the difference's location");
        const rs_object *u = &o->u.csg.members[1];
        CHECK(u->type == RS_OBJ_CSG && u->u.csg.op == RS_CSG_UNION && u->u.csg.n_members == 2,
              "the union is one member, a union node of 2");
        CHECK(o->u.csg.members[0].type == RS_OBJ_BOX && o->u.csg.members[2].inverse &&
                  o->u.csg.members[2].type == RS_OBJ_CYLINDER,
              "box first, the inverted cylinder last");
        CHECK_ABS(o->u.csg.members[0].xf.t[0], 10, TOL, "the box moved with the difference");
        CHECK_ABS(u->u.csg.members[1].xf.t[0], 10, TOL, "the union's sphere moved too");
        CHECK(s.n_lights == 1, "the light inside goes to the scene");
        if (s.n_lights == 1)
            check_vec(s.lights[0].position, 10, 5, 0, TOL, "the light moved with it");
        check_color(o->u.csg.members[0].pigment.color[0], 0, 1, 0, "untextured box: the CSG's");
        check_color(u->u.csg.members[0].pigment.color[0], 0, 1, 0,
                    "untextured sphere of the union: the CSG's");
        check_color(u->u.csg.members[1].pigment.color[0], 1, 0, 0, "textured sphere: its own");
        CHECK_ABS(o->u.csg.members[2].ior, 1.4, TOL, "the interior goes down too");
    }
    rs_scene_free(&s);

    /* a declared CSG used twice: each copy its own, re-textured */
    rc = parse("#declare D = intersection { box { -1, 1 } sphere { 0, 1.3 pigment { rgb <1,0,0> } } }\n"
               "object { D translate x*5 pigment { rgb <0,0,1> } }\n"
               "object { D translate -x*5 }\n", &s, msg, sizeof msg);
    CHECK(rc == 0 && s.n_objects == 2, "declared CSG used twice: %s", msg);
    if (rc == 0 && s.n_objects == 2) {
        const rs_object *a = &s.objects[0], *b = &s.objects[1];
        CHECK(a->u.csg.members != b->u.csg.members, "each copy owns its members");
        CHECK_ABS(a->u.csg.members[0].xf.t[0], 5, TOL, "first copy at +5");
        CHECK_ABS(b->u.csg.members[0].xf.t[0], -5, TOL, "second copy at -5");
        check_color(a->u.csg.members[0].pigment.color[0], 0, 0, 1,
                    "object { D pigment }: the untextured member takes it");
        check_color(a->u.csg.members[1].pigment.color[0], 1, 0, 0,
                    "... the textured member keeps its own");
        check_color(b->u.csg.members[0].pigment.color[0], 0, 0, 0,
                    "the other copy: POV-Ray's default pigment (black)");
    }
    rs_scene_free(&s);

    /* nested, inside a union, in a #while */
    rc = parse("#declare I = 0;\n#while (I < 3)\n"
               "union { difference { sphere { 0, 1 } intersection { box { -1, 1 } plane { y, 0 } } }"
               " translate x*I }\n#declare I = I + 1;\n#end\n", &s, msg, sizeof msg);
    CHECK(rc == 0 && s.n_objects == 3 && s.objects[2].u.csg.n_members == 2 &&
              s.objects[2].u.csg.members[1].type == RS_OBJ_CSG &&
              s.objects[2].u.csg.members[1].u.csg.op == RS_CSG_INTERSECTION,
          "nested CSG in a loop: %s", msg);
    rs_scene_free(&s);

    /* errors */
    expect_error("intersection { lens { radius1 50 radius2 -50 thickness 5 diameter 20 ior 1.5 } }",
                 1, 16, "a lens cannot be part of an intersection: write it on its own");
    expect_error("difference { box { 0, 1 }\n  disc { 0, y, 1 } }", 2, 3,
                 "a disc has no inside and cannot be part of a difference: use a thin cylinder "
                 "or box");
    expect_error("intersection { box { 0, 1 } polarizer { normal z radius 1 axis x } }", 1, 29,
                 "a polarizer has no inside and cannot be part of an intersection");
    expect_error("difference { box { 0, 1 } union { sphere { 0, 1 } disc { 0, y, 1 } } }", 1, 51,
                 "a disc has no inside and cannot be part of a difference");
    expect_error("intersection { }", 1, 1, "an intersection needs at least one object");
    expect_error("difference { light_source { 0, 1 } }", 1, 1,
                 "a difference needs at least one object");
    expect_error("difference { box { 0, 1 } pigment { rgb 1 } sphere { 0, 1 } }", 1, 45,
                 "expected pigment, finish, texture, interior, inverse, translate, rotate, scale "
                 "or '}' in difference, found identifier 'sphere'");
    expect_error("intersection { box { 0, 1 }", 1, 28, "or '}' in intersection, found end of file");
    expect_error("difference sphere { 0, 1 }", 1, 12, "expected '{' after 'difference'");
    rs_parse_opts_init(&opts);
    opts.max_objects = 3;
    expect_error_opts("intersection {\n sphere{0,1}\n sphere{0,1}\n sphere{0,1}\n sphere{0,1} }",
                      &opts, 5, 2, "too many members (the limit is 3)");
    expect_error_opts("#declare D = intersection { sphere{0,1} sphere{0,1} }\n"
                      "object { D }\nobject {\n D }", &opts, 2, 10,
                      "too many objects in intersections and differences (the limit is 3)");
}

int main(void)
{
    test_transforms();
    test_full_scene();
    test_expressions();
    test_colors_and_pigments();
    test_object_transforms();
    test_lens_folding();
    test_light_coherence();
    test_camera_focus();
    test_image_size();
    test_errors();
    test_prepare_errors();
    test_files();
    test_directives();
    test_declared_values();
    test_povray_includes();
    test_comments_and_misc();
    test_csg();
    return check_finish("test_parser");
}
