/* test_bvh.c -- the bounding volume hierarchy finds exactly what a loop
 * over every object finds.
 *
 *   a. Scenes of spheres, boxes, discs, cylinders, cones, tori, lenses,
 *      polarizers and planes, scaled, rotated and translated at random (a
 *      fixed seed), and with coincident objects (the same sphere twice, touching spheres, a lens
 *      on a plane): for random rays, from outside and from points on
 *      objects, the nearest hit of rs_scene_intersect (through the tree)
 *      is the one the loop below finds with rs_object_intersect object by
 *      object: the same object (ties go to the lower index), the same t,
 *      point and normal, bit for bit; with a skipped object too; and so
 *      is rs_bvh_intersect's, also in the small scenes where
 *      rs_scene_intersect keeps the loop.
 *   b. rs_bvh_any visits every object whose segment hit the loop finds
 *      (an occluder is never missed): for each ray and t_max, the set of
 *      objects the loop hits within (t_min, t_max) is a subset of the
 *      objects visited.
 *   c. Structure: every object with a finite bound is in the tree, planes
 *      are not; an empty scene and a scene of planes only work; the tree
 *      of 10^4 spheres has fewer than 2N nodes.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "check.h"
#include "parser.h"
#include "scene.h"
#include "shapes.h"

static unsigned long long rng = 0x243f6a8885a308d3ull;
static double uni(void)
{
    rng = rng * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}
static double range(double a, double b) { return a + (b - a) * uni(); }

/* The reference: every object, in index order, t_max shrinking. */
static int loop_intersect(const rs_scene *sc, lp_vec3 o, lp_vec3 d, double t_min, double t_max,
                          int skip, rs_hit *hit)
{
    int found = 0;
    rs_hit h;
    for (size_t i = 0; i < sc->n_objects; i++) {
        if ((int)i == skip)
            continue;
        if (rs_object_intersect(&sc->objects[i], o, d, t_min, t_max, &h)) {
            h.object = (int)i;
            *hit = h;
            t_max = h.t;
            found = 1;
        }
    }
    return found;
}

static int load(rs_scene *sc, const char *text)
{
    char msg[1024] = "";
    rs_scene_init(sc);
    if (rs_parse_string(text, "<test>", NULL, sc, msg, sizeof msg) != 0 ||
        rs_scene_prepare(sc, msg, sizeof msg) != 0) {
        fprintf(stderr, "scene: %s\n", msg);
        return -1;
    }
    return 0;
}

/* A random scene of n objects of every kind. */
static char *random_scene(int n)
{
    size_t cap = 256 + (size_t)n * 400, len = 0;
    char *s = malloc(cap);
    if (!s)
        return NULL;
    len += (size_t)snprintf(s + len, cap - len, "camera { location <0,0,-10> look_at <0,0,0> }\n");
    len += (size_t)snprintf(s + len, cap - len,
                            "plane { y, -30 pigment { rgb 1 } }\nplane { <1,1,0>, 40 pigment { rgb 1 } }\n");
    for (int i = 0; i < n; i++) {
        double x = range(-20, 20), y = range(-20, 20), z = range(-20, 20);
        double rx = range(0, 360), ry = range(0, 360), rz = range(0, 360);
        int kind = i % 9;
        const char *xf = "";
        char buf[160];
        snprintf(buf, sizeof buf, "scale <%g,%g,%g> rotate <%g,%g,%g> translate <%g,%g,%g>",
                 range(0.5, 2), range(0.5, 2), range(0.5, 2), rx, ry, rz, x, y, z);
        xf = buf;
        if (kind == 0)
            len += (size_t)snprintf(s + len, cap - len,
                                    "sphere { <%g,%g,%g>, %g pigment { rgb 1 } %s }\n",
                                    range(-1, 1), range(-1, 1), range(-1, 1), range(0.2, 2), xf);
        else if (kind == 1)
            len += (size_t)snprintf(s + len, cap - len,
                                    "box { <%g,%g,%g>, <%g,%g,%g> pigment { rgb 1 } %s }\n",
                                    range(-2, 0), range(-2, 0), range(-2, 0), range(0, 2),
                                    range(0, 2), range(0, 2), xf);
        else if (kind == 2)
            len += (size_t)snprintf(s + len, cap - len,
                                    "disc { <0,0,0>, <%g,%g,%g>, %g, %g pigment { rgb 1 } %s }\n",
                                    range(-1, 1), range(-1, 1), 1.0, range(1, 3), range(0, 0.5),
                                    xf);
        else if (kind == 3)
            len += (size_t)snprintf(s + len, cap - len,
                                    "lens { radius1 %g radius2 %g thickness 2 diameter 4 ior 1.5 "
                                    "rotate <%g,%g,%g> translate <%g,%g,%g> }\n",
                                    range(5, 20), -range(5, 20), rx, ry, rz, x, y, z);
        else if (kind == 4)
            len += (size_t)snprintf(s + len, cap - len,
                                    "polarizer { center <%g,%g,%g> normal <%g,%g,1> radius %g "
                                    "axis <1,0,0> }\n",
                                    x, y, z, range(-1, 1), range(-1, 1), range(0.5, 3));
        else if (kind == 6)
            len += (size_t)snprintf(s + len, cap - len,
                                    "cylinder { <%g,%g,%g>, <%g,%g,%g>, %g %s pigment { rgb 1 } "
                                    "%s }\n",
                                    range(-1, 1), range(-2, -1), range(-1, 1), range(-1, 1),
                                    range(1, 2), range(-1, 1), range(0.2, 1.5),
                                    uni() < 0.5 ? "open" : "", xf);
        else if (kind == 7)
            len += (size_t)snprintf(s + len, cap - len,
                                    "cone { <%g,%g,%g>, %g, <%g,%g,%g>, %g %s pigment { rgb 1 } "
                                    "%s }\n",
                                    range(-1, 1), range(-2, -1), range(-1, 1), range(0, 1.5),
                                    range(-1, 1), range(1, 2), range(-1, 1), range(0.2, 1.5),
                                    uni() < 0.5 ? "open" : "", xf);
        else if (kind == 8)
            len += (size_t)snprintf(s + len, cap - len,
                                    "torus { %g, %g pigment { rgb 1 } %s }\n", range(1, 2),
                                    range(0.2, 0.8), xf);
        else /* the previous sphere again, and one touching it */
            len += (size_t)snprintf(s + len, cap - len,
                                    "sphere { <%g,%g,%g>, 1 pigment { rgb 1 } }\n"
                                    "sphere { <%g,%g,%g>, 1 pigment { rgb 1 } }\n"
                                    "sphere { <%g,%g,%g>, 1 pigment { rgb 1 } }\n",
                                    x, y, z, x, y, z, x + 2, y, z);
    }
    return s;
}

static lp_vec3 unit(lp_vec3 a)
{
    double l = sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
    return (lp_vec3){a.x / l, a.y / l, a.z / l};
}

typedef struct visited {
    unsigned char *seen;
} visited;

static int mark(void *ctx, int i)
{
    ((visited *)ctx)->seen[i] = 1;
    return 0;
}

static int same_hit(const rs_hit *a, const rs_hit *b)
{
    return a->object == b->object && a->t == b->t && a->point.x == b->point.x &&
           a->point.y == b->point.y && a->point.z == b->point.z && a->normal.x == b->normal.x &&
           a->normal.y == b->normal.y && a->normal.z == b->normal.z &&
           a->lens_surface == b->lens_surface;
}

static void check_rays(const rs_scene *sc, int n_rays, const char *what)
{
    unsigned char *seen = calloc(sc->n_objects + 1, 1);
    visited v = {seen};
    int mismatches = 0, any_missed = 0, hits = 0;
    if (!seen) {
        CHECK(0, "out of memory");
        return;
    }
    for (int k = 0; k < n_rays; k++) {
        lp_vec3 o = {range(-40, 40), range(-40, 40), range(-40, 40)};
        lp_vec3 d = unit((lp_vec3){range(-1, 1), range(-1, 1), range(-1, 1)});
        if (k % 4 == 1)
            d = (lp_vec3){0, 0, 1}; /* axis-parallel: zero components */
        rs_hit a, b;
        memset(&a, 0, sizeof a);
        memset(&b, 0, sizeof b);
        int skip = k % 3 == 0 ? -1 : (int)(uni() * (double)sc->n_objects);
        int fa = rs_scene_intersect(sc, o, d, 0.0, INFINITY, skip, &a);
        int fb = loop_intersect(sc, o, d, 0.0, INFINITY, skip, &b);
        if (fa != fb || (fa && !same_hit(&a, &b)))
            mismatches++;
        /* the tree itself, also where rs_scene_intersect keeps the loop */
        fa = rs_bvh_intersect(sc->bvh, sc, o, d, 0.0, INFINITY, skip, &a);
        if (fa != fb || (fa && !same_hit(&a, &b)))
            mismatches++;
        hits += fb;
        /* From the hit point on, as secondary rays start. */
        if (fb && k % 2 == 0) {
            lp_vec3 o2 = b.point, d2 = unit((lp_vec3){range(-1, 1), range(-1, 1), range(-1, 1)});
            rs_hit c;
            memset(&c, 0, sizeof c);
            fa = rs_scene_intersect(sc, o2, d2, 1e-9, INFINITY, b.object, &a);
            int fc = rs_bvh_intersect(sc->bvh, sc, o2, d2, 1e-9, INFINITY, b.object, &c);
            int fb2 = loop_intersect(sc, o2, d2, 1e-9, INFINITY, b.object, &b);
            if (fa != fb2 || (fa && !same_hit(&a, &b)))
                mismatches++;
            if (fc != fb2 || (fc && !same_hit(&c, &b)))
                mismatches++;
        }
        /* Every object the segment meets is visited by rs_bvh_any. */
        double t_max = range(1, 80);
        memset(seen, 0, sc->n_objects);
        rs_bvh_any(sc->bvh, o, d, 1e-9, t_max, mark, &v);
        for (size_t i = 0; i < sc->n_objects; i++) {
            rs_hit h;
            if (!seen[i] && rs_object_intersect(&sc->objects[i], o, d, 1e-9, t_max, &h))
                any_missed++;
        }
    }
    CHECK(mismatches == 0, "%s: %d of %d rays differ from the loop over objects", what,
          mismatches, n_rays);
    CHECK(any_missed == 0, "%s: rs_bvh_any missed %d object hits", what, any_missed);
    CHECK(hits > n_rays / 10, "%s: only %d of %d rays hit anything (a test that tests nothing)",
          what, hits, n_rays);
    free(seen);
}

int main(void)
{
    rs_scene sc;

    /* a, b: random scenes of every kind, small and large. */
    int sizes[] = {1, 7, 60, 600};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        char *text = random_scene(sizes[i]), what[64];
        snprintf(what, sizeof what, "%d random objects", sizes[i]);
        if (!text || load(&sc, text) != 0) {
            CHECK(0, "%s: scene", what);
            free(text);
            continue;
        }
        CHECK(sc.bvh != NULL, "%s: rs_scene_prepare built no tree", what);
        if (sc.bvh) {
            CHECK(rs_bvh_unbounded_count(sc.bvh) == 2, "%s: %zu unbounded objects, want the 2 planes",
                  what, rs_bvh_unbounded_count(sc.bvh));
            check_rays(&sc, 4000, what);
            /* the loop below RS_BVH_MIN_BOUNDED bounded objects, the tree
             * from there on */
            int want = sc.n_objects - rs_bvh_unbounded_count(sc.bvh) >= RS_BVH_MIN_BOUNDED;
            CHECK(rs_bvh_serves(sc.bvh, &sc) == want, "%s: rs_bvh_serves %d, want %d", what,
                  rs_bvh_serves(sc.bvh, &sc), want);
        }
        rs_scene_free(&sc);
        free(text);
    }

    /* A lens resting on a plane, seen along its axis (touching surfaces). */
    if (load(&sc, "plane { y, 0 pigment { rgb 1 } }\n"
                  "lens { radius1 0 radius2 -100 thickness 3 diameter 10 ior 1.5\n"
                  "       rotate <90,0,0> translate <0,3,0> }\n"
                  "sphere { <0,0,0>, 1 pigment { rgb 1 } }\n") == 0) {
        check_rays(&sc, 2000, "lens on a plane");
        rs_scene_free(&sc);
    }

    /* c: an empty scene, planes only, and the size of a big tree. */
    if (load(&sc, "camera { location <0,0,-5> }\n") == 0) {
        rs_hit h;
        CHECK(sc.bvh && rs_bvh_node_count(sc.bvh) == 0, "empty scene: no nodes");
        CHECK(!rs_scene_intersect(&sc, (lp_vec3){0, 0, 0}, (lp_vec3){0, 0, 1}, 0, INFINITY, -1, &h),
              "empty scene: no hit");
        rs_scene_free(&sc);
    }
    if (load(&sc, "plane { y, 0 pigment { rgb 1 } } plane { z, 5 pigment { rgb 1 } }\n") == 0) {
        check_rays(&sc, 500, "planes only");
        rs_scene_free(&sc);
    }
    {
        size_t n = 10000, cap = n * 64 + 64, len = 0;
        char *text = malloc(cap);
        if (text) {
            for (size_t i = 0; i < n; i++)
                len += (size_t)snprintf(text + len, cap - len, "sphere{<%.3f,%.3f,%.3f>,0.3}\n",
                                        range(-40, 40), range(-40, 40), range(-40, 40));
            if (load(&sc, text) == 0) {
                CHECK(sc.bvh && rs_bvh_node_count(sc.bvh) < 2 * n,
                      "10^4 spheres: %zu nodes, want < 2N", rs_bvh_node_count(sc.bvh));
                check_rays(&sc, 300, "10^4 spheres");
                rs_scene_free(&sc);
            }
            free(text);
        }
    }
    return check_finish("test_bvh");
}
