/* test_packet.c -- the lane classes of spectral packets against their
 * definition.
 *
 * rs_lane_class(c, i, k) is the first lane whose optics at lens i (glass
 * index, medium index, absorption, whether the data cover the wavelength)
 * equal lane k's; a non-lens object and a crystal lens give every lane
 * its own.  Checked against that definition, computed here by comparing
 * every pair of lanes, on wavelength lists where classes are many, few
 * and of one lane each: a dispersive glass (every lane alone but repeated
 * wavelengths), a constant index (one class), a glass with a table of
 * indices (equal indices outside its range), and a crystal; in ascending,
 * descending and scrambled wavelength order. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "load_scene.h"
#include "packet.h"
#include "scene.h"

#define N 700

static const char text[] =
    "camera { location <0, 0, -50> look_at <0, 0, 0> }\n"
    "plane { y, -20 pigment { rgb 1 } }\n"
    "lens { radius1 40 radius2 -40 thickness 6 diameter 20 glass \"N-BK7\" }\n"
    "lens { radius1 40 radius2 -40 thickness 6 diameter 20 ior 1.5 translate <30, 0, 0> }\n"
    "lens { radius1 40 radius2 -40 thickness 6 diameter 20 glass \"N-SF11\"\n"
    "       medium ior 1.33 translate <-30, 0, 0> }\n"
    "lens { radius1 40 radius2 -40 thickness 6 diameter 20 crystal \"calcite\"\n"
    "       translate <0, 30, 0> }\n";

/* The definition: lane j's optics equal lane k's at lens desc d. */
static int same_optics(const lp_lens_desc *d, double a, double b)
{
    double ga = lp_glass_index(&d->glass, a), gb = lp_glass_index(&d->glass, b);
    double ma = lp_glass_index(&d->medium, a), mb = lp_glass_index(&d->medium, b);
    return ga == gb && ma == mb &&
           lp_glass_absorption(&d->glass, a) == lp_glass_absorption(&d->glass, b) &&
           lp_glass_covers(&d->glass, a) == lp_glass_covers(&d->glass, b) &&
           lp_glass_covers(&d->medium, a) == lp_glass_covers(&d->medium, b);
}

static void check_lanes(const rs_scene *sc, const double *lambda, int n, const char *what)
{
    rs_lane_classes *c = NULL;
    int bad = 0, classes = 0;
    CHECK(rs_lane_classes_create(sc, lambda, n, &c) == 0, "%s: classes made", what);
    if (!c)
        return;
    for (size_t i = 0; i < sc->n_objects; i++) {
        const rs_object *o = &sc->objects[i];
        lp_lens_desc d;
        int lens = o->type == RS_OBJ_LENS && o->lens;
        if (lens)
            lp_lens_get_desc(o->lens, &d);
        for (int k = 0; k < n; k++) {
            int want = k;
            if (lens && !d.uniaxial)
                for (int j = 0; j < k; j++)
                    if (same_optics(&d, lambda[j], lambda[k])) {
                        want = j;
                        break;
                    }
            classes += want == k;
            if (rs_lane_class(c, (int)i, k) != want && bad++ < 3)
                CHECK(0, "%s: object %zu lane %d (%.6g nm): class %d, the first of equal optics "
                         "%d",
                      what, i, k, lambda[k], rs_lane_class(c, (int)i, k), want);
        }
    }
    CHECK(bad == 0, "%s: %d lanes in a wrong class", what, bad);
    printf("%s: %d classes over %zu objects\n", what, classes, sc->n_objects);
    rs_lane_classes_destroy(c);
}

int main(void)
{
    rs_scene sc;
    static double lambda[N];
    rs_scene_init(&sc);
    if (load_scene(&sc, NULL, text, "packet.scene", 16, 12) != 0) {
        CHECK(0, "the scene loads");
        return check_finish("test_packet");
    }
    /* 380..780 nm with every tenth wavelength repeated later, and two
     * outside N-SF11's table */
    for (int k = 0; k < N; k++)
        lambda[k] = k % 10 == 9 ? lambda[k - 7] : 380.0 + 400.0 * k / N;
    lambda[N - 2] = 2600.0;
    lambda[N - 1] = 2700.0;
    check_lanes(&sc, lambda, N, "ascending, repeats");
    for (int k = 0; k < N / 2; k++) {
        double t = lambda[k];
        lambda[k] = lambda[N - 1 - k];
        lambda[N - 1 - k] = t;
    }
    check_lanes(&sc, lambda, N, "descending");
    for (int k = 0; k < N; k++) {
        int j = (int)(((unsigned)k * 2654435761u) % N);
        double t = lambda[k];
        lambda[k] = lambda[j];
        lambda[j] = t;
    }
    check_lanes(&sc, lambda, N, "scrambled");
    for (int k = 0; k < N; k++)
        lambda[k] = 550.0;
    check_lanes(&sc, lambda, N, "one wavelength");
    rs_scene_free(&sc);
    return check_finish("test_packet");
}
