/* test_auto_mode.c -- --mode auto keeps its promise on every shipped scene.
 *
 * For each scene of scenes/ at a small size: a reference rendered here
 * (polarized, depth 16, REF_N wavelengths, a cut-off of 1e-7, which in
 * the coherent newtons_rings leaves 5e-5 against auto's render with a
 * cut-off of 2.5e-9, measured), then
 * rs_auto_choose at E = 1e-2 and 1e-3 and a render with what it chose:
 * its RMSE against the reference must be <= E.  A tolerance is tested only
 * where the reference is converged far below it: halving its wavelengths
 * changes it by less than E / 4.  Through dispersive glass the midpoint
 * rule over wavelength converges slowly (a pixel's spectrum has a step at
 * every checker edge it crosses: error ~ N^-0.5..N^-1), and at this size
 * 256 wavelengths change, measured, by 5.2e-4 (biconcave), 1.31e-3
 * (conical_rim), 1.38e-3 (meniscus), 2.2e-3 (dispersion) and 5.3e-4
 * (polariscope) from 128: more than 1e-3 / 4.  Those five are checked at
 * 1e-2 only; any other scene whose reference cannot check a tolerance
 * fails.  Scenes with a polarizer, a polarized light or
 * a coherent source must get the polarized model.  A scene with no lens
 * and no dispersion: few wavelengths. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "auto_settings.h"
#include "check.h"
#include "integrator.h"
#include "parser.h"
#include "scene.h"

#define W 12
#define H 9
#define REF_N 256
#define REF_CUTOFF 1e-7 /* a dropped branch carries < 1e-7: far below every E */

static int load(rs_scene *sc, const char *path)
{
    char msg[1024] = "";
    rs_parse_opts po;
    rs_parse_opts_init(&po);
    po.image_width = W;
    po.image_height = H;
    if (rs_parse_file(path, &po, sc, msg, sizeof msg) != 0 ||
        rs_scene_prepare(sc, msg, sizeof msg) != 0) {
        fprintf(stderr, "%s: %s\n", path, msg);
        return -1;
    }
    return 0;
}

static int render(const rs_scene *sc, const rs_render_opts *o, rs_color *out)
{
    char msg[512];
    rs_integrator *it;
    rs_worker *w;
    if (rs_integrator_create(sc, o, &it, msg, sizeof msg) != 0)
        return -1;
    w = rs_worker_create(it);
    if (!w) {
        rs_integrator_destroy(it);
        return -1;
    }
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++)
            rs_integrator_pixel(it, w, i, j, &out[j * W + i]);
    rs_worker_destroy(w);
    rs_integrator_destroy(it);
    return 0;
}

static double rmse(const rs_color *a, const rs_color *b)
{
    double s = 0.0;
    for (int k = 0; k < W * H; k++) {
        double dr = a[k].r - b[k].r, dg = a[k].g - b[k].g, db = a[k].b - b[k].b;
        s += dr * dr + dg * dg + db * db;
    }
    return sqrt(s / (3.0 * W * H));
}

static int needs_polarization(const rs_scene *sc)
{
    if (sc->settings.coherent)
        return 1;
    for (size_t i = 0; i < sc->n_objects; i++)
        if (sc->objects[i].type == RS_OBJ_POLARIZER)
            return 1;
    for (size_t k = 0; k < sc->n_lights; k++)
        if (sc->lights[k].polarized || sc->lights[k].coherent)
            return 1;
    return 0;
}

static void one_scene(const char *name)
{
    char path[1024];
    rs_scene sc;
    rs_color ref[W * H], ref2[W * H], img[W * H];
    rs_render_opts o;
    static const double tols[2] = {1e-2, 1e-3};

    snprintf(path, sizeof path, "%s/scenes/%s.scene", LP_SOURCE_DIR, name);
    rs_scene_init(&sc);
    if (load(&sc, path) != 0) {
        CHECK(0, "%s: loads", name);
        rs_scene_free(&sc);
        return;
    }
    rs_render_opts_init(&o);
    o.mode = RS_MODE_POLARIZED;
    o.width = W;
    o.height = H;
    o.depth = 16;
    o.cutoff = REF_CUTOFF;
    o.wavelengths = REF_N;
    CHECK(render(&sc, &o, ref) == 0, "%s: reference renders", name);
    o.wavelengths = REF_N / 2;
    CHECK(render(&sc, &o, ref2) == 0, "%s: half reference renders", name);
    double conv = rmse(ref, ref2);
    fprintf(stderr, "%s: reference: halving its wavelengths changes it by %.3g\n", name, conv);
    for (int t = 0; t < 2; t++) {
        if (!(conv < 0.25 * tols[t])) {
            CHECK(t == 1 && (strcmp(name, "dispersion") == 0 || strcmp(name, "biconcave") == 0 ||
                             strcmp(name, "conical_rim") == 0 || strcmp(name, "meniscus") == 0 ||
                             strcmp(name, "polariscope") == 0),
                  "%s: the reference converges to %.3g, not below E / 4 = %.3g", name, conv,
                  0.25 * tols[t]);
            continue;
        }
        rs_auto_request req = {tols[t], W, H, 0, 0, -1.0};
        rs_render_opts ch;
        char why[512], msg[512];
        CHECK(rs_auto_choose(&sc, &req, &ch, why, sizeof why, msg, sizeof msg) == 0,
              "%s: auto chooses (%s)", name, msg);
        CHECK(render(&sc, &ch, img) == 0, "%s: auto's choice renders", name);
        double e = rmse(img, ref);
        fprintf(stderr, "%s E=%g: rmse %.3g: %s\n", name, tols[t], e, why);
        CHECK(e <= tols[t], "%s: auto at E = %g: rmse %.3g (%s)", name, tols[t], e, why);
        if (needs_polarization(&sc))
            CHECK(ch.mode == RS_MODE_POLARIZED, "%s: polarized model (%s)", name, why);
    }
    rs_scene_free(&sc);
}

/* No lens, no dispersion, no polarizer: the unpolarized model and few
 * wavelengths (only Smits' reflectance bins make the spectrum vary). */
static void plain_scene(void)
{
    static const char text[] =
        "camera { location <0, 5, -10> look_at <0, 0, 0> }\n"
        "light_source { <10, 20, -10> color rgb 1 }\n"
        "plane { y, 0 pigment { checker rgb 1, rgb 0.2 } }\n"
        "sphere { <0, 1, 0>, 1 pigment { color rgb <1, 0.5, 0.2> } }\n";
    char msg[512], why[512];
    rs_parse_opts po;
    rs_scene sc;
    rs_render_opts ch;
    rs_auto_request req = {1e-2, W, H, 0, 0, -1.0};
    rs_scene_init(&sc);
    rs_parse_opts_init(&po);
    po.image_width = W;
    po.image_height = H;
    if (rs_parse_string(text, "<plain>", &po, &sc, msg, sizeof msg) != 0 ||
        rs_scene_prepare(&sc, msg, sizeof msg) != 0) {
        CHECK(0, "plain scene: %s", msg);
        rs_scene_free(&sc);
        return;
    }
    CHECK(rs_auto_choose(&sc, &req, &ch, why, sizeof why, msg, sizeof msg) == 0, "plain: %s", msg);
    fprintf(stderr, "plain: %s\n", why);
    CHECK(ch.mode == RS_MODE_FRESNEL && ch.wavelengths <= 8, "plain scene: cheap (%s)", why);
    rs_scene_free(&sc);
}

int main(void)
{
    plain_scene();
    static const char *const scenes[] = {"biconcave",     "conical_rim",  "crossed_polarizers",
                                         "default",       "dispersion",   "meniscus",
                                         "newtons_rings", "plano_convex", "polariscope"};
    for (size_t k = 0; k < sizeof scenes / sizeof *scenes; k++)
        one_scene(scenes[k]);
    return check_finish("test_auto_mode");
}
