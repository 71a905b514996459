/* test_auto_mode.c -- --mode auto keeps its promise on every shipped scene.
 *
 * For each scene of scenes/ (every one is listed: a new scene unlisted
 * fails) at a small size: a reference rendered here (polarized, depth 32,
 * REF_N wavelengths, a cut-off of 1e-7, which in the coherent
 * newtons_rings leaves 5e-5 against a render with a cut-off of 2.5e-9,
 * measured), then rs_auto_choose at E = 1e-2 and 1e-3 and a render with
 * what it chose: its RMSE against the reference must be <= E.  A
 * tolerance is tested only where the reference is converged far below
 * it: halving its wavelengths changes it by less than E / 4.  Through
 * dispersive glass the midpoint rule over wavelength converges slowly (a
 * pixel's spectrum has a step at every checker edge it crosses: error ~
 * N^-0.5..N^-1), and at this size 256 wavelengths change, measured, by
 * 5.2e-4 (biconcave), 1.31e-3 (conical_rim), 1.38e-3 (meniscus), 2.2e-3
 * (dispersion), 5.3e-4 (polariscope), 1.22e-3 (michel_levy) and 1.62e-3
 * (conoscope) from 128: more than 1e-3 / 4.  Those are checked at 1e-2
 * only; any other scene whose reference cannot check a tolerance fails.
 * Scenes with a polarizer, a crystal lens, a polarized light or a
 * coherent source must get the polarized model.  Where the default
 * polarized render meets E with a margin, auto's probe must be a small
 * part of its render at the chart's size (a deterministic count of
 * wavelength samples, not a time).  A scene with no lens and no
 * dispersion: few wavelengths. */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "auto_settings.h"
#include "check.h"
#include "integrator.h"
#include "load_scene.h"
#include "scene.h"

#define W 12
#define H 9
#define REF_N 256
#define REF_DEPTH 32
#define CHART_W 128 /* the chart's size (speed_accuracy) */
#define CHART_H 96
#define PROBE_SHARE_MAX 0.6
#define DEFAULT_MARGIN 0.25 /* the default meets E by this margin */
#define UNRESOLVED_1E3 \
    "biconcave", "conical_rim", "meniscus", "dispersion", "polariscope", "michel_levy", "conoscope"
#define REF_CUTOFF 1e-7 /* a dropped branch carries < 1e-7: far below every E */

/* Render o's image into out (NULL: not kept); *cost (when not NULL) gets
 * the render's cost in rs_work_cost's units, counted, not timed. */
static int render(const rs_scene *sc, const rs_render_opts *o, rs_color *out, double *cost)
{
    rs_color scratch;
    char msg[512];
    rs_integrator *it;
    rs_worker *w;
    rs_work work;
    if (rs_integrator_create(sc, o, &it, msg, sizeof msg) != 0)
        return -1;
    w = rs_worker_create(it);
    if (!w) {
        rs_integrator_destroy(it);
        return -1;
    }
    for (int j = 0; j < o->height; j++)
        for (int i = 0; i < o->width; i++)
            rs_integrator_pixel(it, w, i, j, out ? &out[j * o->width + i] : &scratch);
    rs_worker_work(w, &work);
    if (cost)
        *cost = rs_work_cost(&work, o->mode, (double)o->width * o->height);
    rs_worker_destroy(w);
    rs_integrator_destroy(it);
    return 0;
}

static double rmse_n(const rs_color *a, const rs_color *b, size_t n)
{
    double s = 0.0;
    for (size_t k = 0; k < n; k++) {
        double dr = a[k].r - b[k].r, dg = a[k].g - b[k].g, db = a[k].b - b[k].b;
        s += dr * dr + dg * dg + db * db;
    }
    return sqrt(s / (3.0 * (double)n));
}

static double rmse(const rs_color *a, const rs_color *b)
{
    return rmse_n(a, b, (size_t)W * H);
}

/* Every scene shipped in scenes/ (and scenes/microscope/, scenes/crystal/) is listed,
 * with its reference's wavelengths and cut-off when not REF_N and
 * REF_CUTOFF: the microscope's six lenses, crystal and two polarizers
 * make a tree that at a cut-off of 1e-7 and depth 32 takes minutes per
 * wavelength even at this size, and at its own depth 24 and a cut-off of
 * 1e-4 (3 s of CPU per 16 wavelengths) 32 wavelengths still differ from
 * 16 by 0.01, measured: no reference fits the suite, and only its model
 * is checked. */
typedef struct shipped_scene {
    const char *file, *name;
    int ref_n, ref_depth;
    double ref_cutoff;
    int model_only; /* no reference: only the model is checked */
} shipped_scene;

static const shipped_scene shipped[] = {
    {"biconcave.scene", "biconcave", 0, 0, 0, 0},
    {"conical_rim.scene", "conical_rim", 0, 0, 0, 0},
    {"conoscope.scene", "conoscope", 0, 0, 0, 0},
    {"crossed_polarizers.scene", "crossed_polarizers", 0, 0, 0, 0},
    {"default.scene", "default", 0, 0, 0, 0},
    {"desk_lamp.scene", "desk_lamp", 0, 0, 0, 0},
    {"dispersion.scene", "dispersion", 0, 0, 0, 0},
    {"machined_parts.scene", "machined_parts", 0, 0, 0, 0},
    {"meniscus.scene", "meniscus", 0, 0, 0, 0},
    {"michel_levy.scene", "michel_levy", 0, 0, 0, 0},
    {"mirror_ball.scene", "mirror_ball", 0, 0, 0, 0},
    {"newtons_rings.scene", "newtons_rings", 0, 0, 0, 0},
    {"plan_view.scene", "plan_view", 0, 0, 0, 0},
    {"plano_convex.scene", "plano_convex", 0, 0, 0, 0},
    {"polariscope.scene", "polariscope", 0, 0, 0, 0},
    {"microscope/microscope.scene", "microscope", 0, 0, 0, 1},
    /* A crystal and no polarizer: the polarized model for the crystal
     * alone (here the unpolarized models render it alike, so no measured
     * departure would ask for it). */
    {"crystal/calcite_rhomb.scene", "calcite_rhomb", 0, 0, 0, 1},
};

/* The polarized model is needed where polarization is the effect: a
 * polarizer, a polarized or coherent light, global coherence, or a
 * crystal lens (its o and e rays split the light by polarization). */
static int needs_polarization(const rs_scene *sc)
{
    if (sc->settings.coherent)
        return 1;
    for (size_t i = 0; i < sc->n_objects; i++)
        if (sc->objects[i].type == RS_OBJ_POLARIZER ||
            (sc->objects[i].type == RS_OBJ_LENS && sc->objects[i].u.lens.desc.uniaxial))
            return 1;
    for (size_t k = 0; k < sc->n_lights; k++)
        if (sc->lights[k].polarized || sc->lights[k].coherent)
            return 1;
    return 0;
}

/* Scenes whose reference at this size does not resolve 1e-3 (halving its
 * wavelengths changes it by more than E / 4, measured in the header
 * comment): checked at 1e-2 only. */
static int unresolved_at_1e3(const char *name)
{
    static const char *const list[] = {UNRESOLVED_1E3};
    for (size_t k = 0; k < sizeof list / sizeof *list; k++)
        if (strcmp(name, list[k]) == 0)
            return 1;
    return 0;
}

/* A reference's options: polarized, width x height, the depth, cut-off
 * and wavelengths given. */
static rs_render_opts polarized_opts(int width, int height, int depth, double cutoff, int n)
{
    rs_render_opts o;
    rs_render_opts_init(&o);
    o.mode = RS_MODE_POLARIZED;
    o.width = width;
    o.height = height;
    o.depth = depth;
    o.cutoff = cutoff;
    o.wavelengths = n;
    return o;
}

/* Does some lens's glass change its index over the visible (400 nm
 * against 700 nm)? */
static int dispersive(const rs_scene *sc)
{
    for (size_t i = 0; i < sc->n_objects; i++) {
        const lp_lens_desc *d;
        if (sc->objects[i].type != RS_OBJ_LENS)
            continue;
        d = &sc->objects[i].u.lens.desc;
        if (lp_glass_index(&d->glass, 400.0) != lp_glass_index(&d->glass, 700.0))
            return 1;
    }
    return 0;
}

/* The checks at the chart's size (see one_scene). */
static void at_chart_size(const rs_scene *sc, const char *name)
{
    static const double tols[2] = {1e-2, 1e-3};
    const size_t n = (size_t)CHART_W * CHART_H;
    rs_color *ref = malloc(n * sizeof *ref), *img = malloc(n * sizeof *img);
    rs_render_opts o, def;
    double d_cost = 0.0;
    if (!ref || !img) {
        CHECK(0, "%s: memory", name);
        free(ref);
        free(img);
        return;
    }
    o = polarized_opts(CHART_W, CHART_H, REF_DEPTH, REF_CUTOFF, REF_N);
    rs_render_opts_init(&def);
    def.mode = RS_MODE_POLARIZED;
    def.width = CHART_W;
    def.height = CHART_H;
    CHECK(render(sc, &o, ref, NULL) == 0 && render(sc, &def, img, &d_cost) == 0,
          "%s: renders at %d x %d", name, CHART_W, CHART_H);
    double e_def = rmse_n(img, ref, n);
    for (int t = 0; t < 2; t++) {
        rs_auto_request req = {tols[t], CHART_W, CHART_H, 0, 0, -1.0};
        rs_render_opts ch;
        rs_auto_cost ac = {0, 0};
        char why[1024], msg[512];
        double a_cost = 0.0;
        if (!(e_def <= DEFAULT_MARGIN * tols[t]))
            continue;
        CHECK(rs_auto_choose(sc, &req, &ch, &ac, why, sizeof why, msg, sizeof msg) == 0,
              "%s: auto chooses at %d x %d (%s)", name, CHART_W, CHART_H, msg);
        CHECK(render(sc, &ch, img, &a_cost) == 0, "%s: auto renders at %d x %d", name, CHART_W,
              CHART_H);
        double e = rmse_n(img, ref, n);
        fprintf(stderr, "%s E=%g at %dx%d: rmse %.3g (default %.3g); cost %.3g (probe %.2f of "
                "its render), %.2f of the default's: %s\n", name, tols[t], CHART_W, CHART_H, e,
                e_def, ac.probe + a_cost, ac.probe / a_cost, (ac.probe + a_cost) / d_cost, why);
        CHECK(e <= tols[t], "%s: auto at E = %g, %d x %d: rmse %.3g (%s)", name, tols[t],
              CHART_W, CHART_H, e, why);
        CHECK(ac.probe + a_cost <= d_cost,
              "%s at E = %g, %d x %d: auto costs %.3g, the default %.3g (%s)", name, tols[t],
              CHART_W, CHART_H, ac.probe + a_cost, d_cost, why);
        CHECK(ac.probe <= PROBE_SHARE_MAX * a_cost,
              "%s at E = %g, %d x %d: probe %.2f of the render (%s)", name, tols[t], CHART_W,
              CHART_H, ac.probe / a_cost, why);
    }
    free(ref);
    free(img);
}

static void one_scene(const shipped_scene *ss)
{
    const char *name = ss->name;
    const int ref_depth = ss->ref_depth > 0 ? ss->ref_depth : REF_DEPTH;
    const int ref_n = ss->ref_n > 0 ? ss->ref_n : REF_N;
    char path[1024];
    rs_scene sc;
    rs_color ref[W * H], ref2[W * H], img[W * H];
    rs_render_opts o, def;
    static const double tols[2] = {1e-2, 1e-3};

    snprintf(path, sizeof path, "%s/scenes/%s", LP_SOURCE_DIR, ss->file);
    rs_scene_init(&sc);
    if (load_scene(&sc, path, NULL, NULL, W, H) != 0) {
        CHECK(0, "%s: loads", name);
        rs_scene_free(&sc);
        return;
    }
    if (ss->model_only) {
        rs_auto_request req = {1e-2, W, H, 0, 0, -1.0};
        rs_render_opts ch;
        char why[1024], msg[512];
        CHECK(rs_auto_choose(&sc, &req, &ch, NULL, why, sizeof why, msg, sizeof msg) == 0,
              "%s: auto chooses (%s)", name, msg);
        fprintf(stderr, "%s E=0.01: %s\n", name, why);
        CHECK(!needs_polarization(&sc) || ch.mode == RS_MODE_POLARIZED, "%s: polarized model (%s)",
              name, why);
        rs_scene_free(&sc);
        return;
    }
    o = polarized_opts(W, H, ref_depth, ss->ref_cutoff > 0.0 ? ss->ref_cutoff : REF_CUTOFF, ref_n);
    CHECK(render(&sc, &o, ref, NULL) == 0, "%s: reference renders", name);
    o.wavelengths = ref_n / 2;
    CHECK(render(&sc, &o, ref2, NULL) == 0, "%s: half reference renders", name);
    double conv = rmse(ref, ref2);
    /* The default polarized render: 16 wavelengths, the scene's depth and
     * adc_bailout. */
    rs_render_opts_init(&def);
    def.mode = RS_MODE_POLARIZED;
    def.width = W;
    def.height = H;
    double def_cost = 0.0;
    CHECK(render(&sc, &def, img, &def_cost) == 0, "%s: default renders", name);
    double e_def = rmse(img, ref);
    fprintf(stderr, "%s: reference: halving its wavelengths changes it by %.3g; default "
                    "polarized: rmse %.3g\n", name, conv, e_def);
    for (int t = 0; t < 2; t++) {
        if (!(conv < 0.25 * tols[t])) {
            CHECK(t == 1 && unresolved_at_1e3(name),
                  "%s: the reference converges to %.3g, not below E / 4 = %.3g", name, conv,
                  0.25 * tols[t]);
            continue;
        }
        rs_auto_request req = {tols[t], W, H, 0, 0, -1.0};
        rs_render_opts ch;
        char why[1024], msg[512];
        rs_auto_cost ac = {0, 0};
        double auto_cost = 0.0;
        CHECK(rs_auto_choose(&sc, &req, &ch, &ac, why, sizeof why, msg, sizeof msg) == 0,
              "%s: auto chooses (%s)", name, msg);
        CHECK(render(&sc, &ch, img, &auto_cost) == 0, "%s: auto's choice renders", name);
        double e = rmse(img, ref);
        fprintf(stderr, "%s E=%g: rmse %.3g, cost %.3g (probe %.3g) against the default's %.3g: %s\n",
                name, tols[t], e, ac.probe + auto_cost, ac.probe, def_cost, why);
        CHECK(e <= tols[t], "%s: auto at E = %g: rmse %.3g (%s)", name, tols[t], e, why);
        if (needs_polarization(&sc))
            CHECK(ch.mode == RS_MODE_POLARIZED, "%s: polarized model (%s)", name, why);
    }
    /* At the chart's size: where the scene has no polarizer, no coherent
     * light and no dispersive glass, a reference is affordable there
     * (without dispersion the wavelengths share every path); where the
     * default polarized render meets E by a margin, auto -- its probe and
     * its render -- must cost no more than the default render, its probe
     * must be a small part of its render, and its error must be within E.
     * Costs are counted work (rs_work_cost), not times.  (At this test's
     * size the probe is most of the image; a dispersive scene's error at
     * 12 x 9 says nothing of its error at the chart's size, where more
     * pixels see the lens's coloured edges.) */
    if (!needs_polarization(&sc) && !dispersive(&sc))
        at_chart_size(&sc, name);
    rs_scene_free(&sc);
}

/* Auto's choice alone (no render) on a scene read from path or, when
 * path is NULL, from text, at w x h and tolerance E; its line printed
 * after name.  Returns 0, or -1 (a failed check). */
static int choice_only(const char *name, const char *path, const char *text, int w, int h,
                       double E, rs_render_opts *ch, char *why, size_t why_size)
{
    char msg[512];
    rs_scene sc;
    rs_auto_request req = {E, w, h, 0, 0, -1.0};
    int ok;
    rs_scene_init(&sc);
    if (load_scene(&sc, path, text, path ? NULL : name, w, h) != 0) {
        CHECK(0, "%s: loads", name);
        rs_scene_free(&sc);
        return -1;
    }
    ok = rs_auto_choose(&sc, &req, ch, NULL, why, why_size, msg, sizeof msg) == 0;
    CHECK(ok, "%s: auto chooses (%s)", name, msg);
    if (ok)
        fprintf(stderr, "%s E=%g at %dx%d: %s\n", name, E, w, h, why);
    rs_scene_free(&sc);
    return ok ? 0 : -1;
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
    char why[1024];
    rs_render_opts ch;
    if (choice_only("<plain>", NULL, text, W, H, 1e-2, &ch, why, sizeof why) == 0)
        CHECK(ch.mode == RS_MODE_RGB || (ch.mode != RS_MODE_POLARIZED && ch.wavelengths <= 8),
              "plain scene: cheap (%s)", why);
}

static void every_scene_listed(void)
{
    char path[1024];
    DIR *d;
    struct dirent *e;
    snprintf(path, sizeof path, "%s/scenes", LP_SOURCE_DIR);
    d = opendir(path);
    CHECK(d != NULL, "scenes/ opens");
    if (!d)
        return;
    while ((e = readdir(d)) != NULL) {
        size_t n = strlen(e->d_name), k;
        if (n < 7 || strcmp(e->d_name + n - 6, ".scene") != 0)
            continue;
        for (k = 0; k < sizeof shipped / sizeof *shipped; k++)
            if (strcmp(shipped[k].file, e->d_name) == 0)
                break;
        CHECK(k < sizeof shipped / sizeof *shipped, "scenes/%s is tested", e->d_name);
    }
    closedir(d);
}

/* A scene whose faint branches cost thousands of times its main rays
 * (the microscope: ten surfaces and a crystal under coherent light, where
 * the cut-off's floor is squared): the trees dearer than 64 times the
 * cheapest are not probed, the probe ends (it had not in 12 minutes at
 * 64 x 48 before), and its line says so.
 * Only the choice: its render takes hundreds of wavelengths. */
static void dear_trees(void)
{
    char path[1024], why[1024];
    rs_render_opts ch;
    snprintf(path, sizeof path, "%s/scenes/microscope/microscope.scene", LP_SOURCE_DIR);
    if (choice_only("microscope", path, NULL, 8, 6, 1e-3, &ch, why, sizeof why) == 0)
        CHECK(strstr(why, "not probed, each over 64 x the cheapest's cost") != NULL,
              "microscope: its dearest trees not probed (%s)", why);
}

int main(void)
{
    dear_trees();
    plain_scene();
    every_scene_listed();
    for (size_t k = 0; k < sizeof shipped / sizeof *shipped; k++)
        one_scene(&shipped[k]);
    return check_finish("test_auto_mode");
}
