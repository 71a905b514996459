/* test_geometry.c -- lens shapes, validation, intersection, placement,
 * containment, bounds and self-intersection.
 *
 * Every expected value is computed here from closed-form geometry in
 * ref_real, binary128 where available (a reference intersector of my own: spherical caps in the
 * optical-design form c(x^2+y^2+z^2) - 2z = 0, a cylinder or cone rim),
 * never from the library.  Conventions from lensprim.h: front vertex at
 * z = 0, back vertex at z = t, R > 0 means the centre of curvature is at +z
 * of the vertex, so the front cap is z = sag1(r) and the back cap
 * z = t + sag2(r) with sag(r) = R - sign(R) sqrt(R^2 - r^2).
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include "lensprim.h"
#include "ref_real.h"

/* ------------------------------------------------------------------ */
/* small helpers                                                       */
/* ------------------------------------------------------------------ */

#include "lens_reference.h"

/* A placement: world = P + e1*x + e2*y + A*z (A = the lens axis). */

/* local -> world, in ref_real */
/* world -> local, in ref_real */

/* ------------------------------------------------------------------ */
/* reference lens geometry, ref_real, local frame                      */
/* ------------------------------------------------------------------ */

/* sag(h) = R - sign(R) sqrt(R^2 - h^2), written without cancellation:
 * c h^2 / (1 + sqrt(1 - c^2 h^2)), c = 1/R (0 for flat). */

/* roots of A s^2 + 2 B s + C = 0 (stable form) */

/* Nearest surface hit of O + s d, s > smin (d unit). surf -1: none. */

/* Inside test with a margin (a lower bound-ish of the distance to the
 * boundary, vertical for the caps). */

/* ------------------------------------------------------------------ */
/* lens construction                                                   */
/* ------------------------------------------------------------------ */

static lp_lens *make_lens(double R1, double R2, double t, double D, double D2, const frame *f,
                          lp_error *err)
{
    lp_lens_desc desc;
    lp_lens_desc_init(&desc);
    desc.radius1 = R1;
    desc.radius2 = R2;
    desc.thickness = t;
    desc.diameter = D;
    desc.diameter2 = D2;
    lp_glass_init_constant(&desc.glass, 1.5);
    if (f) {
        desc.position = f->P;
        desc.axis = f->A;
    }
    lp_lens *lens = NULL;
    lp_status st = lp_lens_create(&desc, &lens, err);
    if (st != LP_OK)
        return NULL;
    return lens;
}

typedef struct {
    const char *name;
    double R1, R2, t, D, D2;
} shape;

static const shape good_shapes[] = {
    {"biconvex", 50, -50, 8, 25, 0},
    {"plano-convex", 25.8, INFINITY, 5.3, 25.4, 0},
    {"plano-convex reversed", INFINITY, -25.8, 5.3, 25.4, 0},
    {"positive meniscus", 30, 60, 5, 25, 0},
    {"negative meniscus", 60, 30, 3, 25, 0},
    {"negative meniscus mirrored", -30, -60, 3, 25, 0},
    {"plano-concave", -40, INFINITY, 2, 25, 0},
    {"plano-concave reversed", 0, 40, 2, 25, 0},
    {"biconcave", -40, 40, 2, 25, 0},
    {"flat plate", 0, INFINITY, 3, 20, 0},
    {"flat plate -inf", -INFINITY, 0, 3, 20, 0},
    {"knife-edge biconvex 5/-5", 5, -5, 2, 6, 0},      /* sag(3) = 5-4 = 1 exactly */
    {"knife-edge biconvex 5/-3.75", 5, -3.75, 2.5, 6, 0}, /* sag = 3.75-2.25 = 1.5 */
    {"knife-edge plano-convex", 5, INFINITY, 1, 6, 0},
    {"steep biconvex", 10, -10, 20, 19.8, 0},
    {"conical rim narrowing", 50, -50, 8, 30, 20},
    {"conical rim widening", 50, -50, 8, 20, 30},
};
#define N_GOOD (sizeof good_shapes / sizeof good_shapes[0])

static int is_knife(const shape *s) { return strncmp(s->name, "knife", 5) == 0; }

/* ------------------------------------------------------------------ */

static void test_accepts(void)
{
    for (size_t i = 0; i < N_GOOD; i++) {
        const shape *s = &good_shapes[i];
        lp_error err;
        memset(&err, 0x55, sizeof err);
        lp_lens *lens = make_lens(s->R1, s->R2, s->t, s->D, s->D2, NULL, &err);
        CHECK(lens != NULL, "%s refused: %s", s->name, lens ? "" : err.message);
        if (!lens)
            continue;
        CHECK(err.status == LP_OK, "%s: err.status %d on success", s->name, (int)err.status);
        double e = lp_lens_edge_thickness(lens);
        if (s->D2 == 0) {
            /* edge thickness t + sag2(h) - sag1(h), sag(h) = R - sign(R) sqrt(R^2 - h^2) */
            ref_real h = s->D / REF(2.0), want = s->t;
            if (!(s->R2 == 0 || isinf(s->R2)))
                want += s->R2 - ref_copysign(REF(1.0), s->R2) * ref_sqrt((ref_real)s->R2 * s->R2 - h * h);
            if (!(s->R1 == 0 || isinf(s->R1)))
                want -= s->R1 - ref_copysign(REF(1.0), s->R1) * ref_sqrt((ref_real)s->R1 * s->R1 - h * h);
            if (is_knife(s))
                CHECK_ABS(e, 0.0, 1e-12 * s->t, "%s edge thickness (knife edge)", s->name);
            else
                CHECK_REL(e, (double)want, 1e-12, "%s edge thickness", s->name);
        } else {
            CHECK(isfinite(e) && e > 0, "%s: conical edge thickness %g", s->name, e);
        }
        lp_lens_desc d;
        lp_lens_get_desc(lens, &d);
        CHECK(d.thickness == s->t && d.diameter == s->D, "%s: get_desc returns the description",
              s->name);
        lp_lens_destroy(lens);
    }
    /* the axis is normalized in get_desc */
    lp_lens_desc desc;
    lp_lens_desc_init(&desc);
    desc.radius1 = 50;
    desc.radius2 = -50;
    desc.thickness = 8;
    desc.diameter = 25;
    desc.axis = V(0, 0, 2.5);
    lp_lens *lens = NULL;
    CHECK(lp_lens_create(&desc, &lens, NULL) == LP_OK, "axis (0,0,2.5) accepted");
    if (lens) {
        lp_lens_get_desc(lens, &desc);
        CHECK_ABS(desc.axis.z, 1.0, 1e-15, "get_desc axis normalized");
        lp_lens_destroy(lens);
    }
    lp_lens_destroy(NULL); /* harmless */
    CHECK(1, "lp_lens_destroy(NULL) returned");
}

typedef struct {
    const char *name;
    double R1, R2, t, D, D2;
    lp_vec3 axis;
    const char *kw[3];
} bad_shape;

static void test_refuses(void)
{
    const bad_shape bad[] = {
        {"front cap wider than its sphere", 10, -50, 30, 25, 0, {0, 0, 1}, {"radius", "diameter", 0}},
        {"back cap wider than its sphere", 50, -10, 30, 25, 0, {0, 0, 1}, {"radius", "diameter", 0}},
        {"back cap (D2) wider than its sphere", 50, -10, 30, 10, 25, {0, 0, 1}, {"radius", "diameter", 0}},
        {"thickness 0", 50, -50, 0, 25, 0, {0, 0, 1}, {"thickness", 0, 0}},
        {"thickness negative", 0, 0, -1, 25, 0, {0, 0, 1}, {"thickness", 0, 0}},
        {"NaN radius1", NAN, -50, 8, 25, 0, {0, 0, 1}, {"radius", 0, 0}},
        {"NaN radius2", 50, NAN, 8, 25, 0, {0, 0, 1}, {"radius", 0, 0}},
        {"NaN thickness", 50, -50, NAN, 25, 0, {0, 0, 1}, {"thickness", 0, 0}},
        {"infinite thickness", 50, -50, INFINITY, 25, 0, {0, 0, 1}, {"thickness", 0, 0}},
        {"caps cross before the rim", 50, -50, 2, 25, 0, {0, 0, 1}, {"cross", "edge", 0}},
        {"meniscus caps cross", 20, 200, 1, 25, 0, {0, 0, 1}, {"cross", "edge", 0}},
        {"diameter 0", 50, -50, 8, 0, 0, {0, 0, 1}, {"diameter", 0, 0}},
        {"diameter negative", 50, -50, 8, -25, 0, {0, 0, 1}, {"diameter", 0, 0}},
        {"NaN diameter", 50, -50, 8, NAN, 0, {0, 0, 1}, {"diameter", 0, 0}},
        {"zero axis", 50, -50, 8, 25, 0, {0, 0, 0}, {"axis", 0, 0}},
        {"NaN axis", 50, -50, 8, 25, 0, {NAN, 0, 1}, {"axis", 0, 0}},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const bad_shape *b = &bad[i];
        lp_lens_desc desc;
        lp_lens_desc_init(&desc);
        desc.radius1 = b->R1;
        desc.radius2 = b->R2;
        desc.thickness = b->t;
        desc.diameter = b->D;
        desc.diameter2 = b->D2;
        desc.axis = b->axis;
        lp_lens *lens = (lp_lens *)&desc; /* must be reset to NULL */
        lp_error err;
        memset(&err, 0, sizeof err);
        lp_status st = lp_lens_create(&desc, &lens, &err);
        CHECK(st == LP_ERROR_INVALID_LENS, "%s: status %d (%s), want LP_ERROR_INVALID_LENS", b->name,
              (int)st, lp_status_string(st));
        CHECK(err.status == st, "%s: err.status %d != returned %d", b->name, (int)err.status, (int)st);
        CHECK(lens == NULL, "%s: *out not NULL on error", b->name);
        if (lens && lens != (lp_lens *)&desc)
            lp_lens_destroy(lens);
        CHECK(err.message[0] != 0, "%s: empty error message", b->name);
        int found = 0;
        for (int k = 0; k < 3 && b->kw[k]; k++)
            found |= has_word(err.message, b->kw[k]);
        CHECK(found, "%s: message \"%s\" does not name the problem (want \"%s\"%s%s)", b->name,
              err.message, b->kw[0], b->kw[1] ? " or " : "", b->kw[1] ? b->kw[1] : "");
        /* NULL err is allowed */
        lens = NULL;
        st = lp_lens_create(&desc, &lens, NULL);
        CHECK(st == LP_ERROR_INVALID_LENS && lens == NULL, "%s with err NULL: status %d", b->name,
              (int)st);
    }
}

/* ------------------------------------------------------------------ */
/* intersections                                                       */
/* ------------------------------------------------------------------ */

static double worst_hit_err, worst_place_err, worst_normal_err;

static void check_hit(const char *what, const lp_lens *lens, const ref_lens *L, const frame *f,
                      lp_vec3 Ow, lp_vec3 dw, double tol_rel)
{
    /* reference computed from the same (double) world ray */
    lv3 O = fl_point(f, Ow), d = lnorm(fl_dir(f, dw));
    ref_hit r = ref_intersect(L, O, d, REF(0.0));
    lp_hit h;
    memset(&h, 0, sizeof h);
    int got = lp_lens_intersect(lens, Ow, dw, 0.0, INFINITY, &h);
    if (r.surf < 0) {
        CHECK(!got, "%s: library hit (surface %d) where the reference misses", what, h.surface);
        return;
    }
    CHECK(got, "%s: library misses, reference hits surface %d at s=%.17g", what, r.surf,
          (double)r.s);
    if (!got)
        return;
    lv3 pw = fw_point(f, r.p), nw = fw_dir(f, r.n);
    double scale = L->size;
    double dp = (double)llen(lsub(lfrom(h.point), pw));
    CHECK_ABS(dp / scale, 0.0, tol_rel, "%s: hit point error / lens size", what);
    worst_hit_err = fmax(worst_hit_err, dp / scale);
    CHECK_ABS(h.t, (double)r.s, tol_rel * scale, "%s: hit distance", what);
    double dn = (double)llen(lsub(lfrom(h.normal), nw));
    worst_normal_err = fmax(worst_normal_err, dn);
    CHECK_ABS(dn, 0.0, 1e-10, "%s: normal error", what);
    CHECK(h.surface == r.surf, "%s: surface %d, want %d", what, h.surface, r.surf);
}

/* An origin in front of / behind the lens aimed at a point of a cap. */
static void cap_target(const ref_lens *L, int back, double frac, double phi, lv3 *target)
{
    ref_real a = back ? L->a2 : L->a1;
    ref_real r = frac * a;
    ref_real z = back ? L->t + rsag(L->c2, r) : rsag(L->c1, r);
    *target = L3(r * ref_cos(phi), r * ref_sin(phi), z);
}

static void test_axial_and_parallel(void)
{
    for (size_t i = 0; i < N_GOOD; i++) {
        const shape *s = &good_shapes[i];
        ref_lens L;
        ref_init(&L, s->R1, s->R2, s->t, s->D, s->D2);
        frame f = frame_identity();
        lp_lens *lens = make_lens(s->R1, s->R2, s->t, s->D, s->D2, NULL, NULL);
        if (!lens)
            continue;
        lp_hit h;
        int got = lp_lens_intersect(lens, V(0, 0, -10), V(0, 0, 1), 0.0, INFINITY, &h);
        CHECK(got, "%s: axial ray misses the front vertex", s->name);
        if (got) {
            CHECK_ABS(h.point.z, 0.0, 1e-13, "%s: axial front hit z", s->name);
            CHECK_ABS(hypot(h.point.x, h.point.y), 0.0, 1e-13, "%s: axial front hit r", s->name);
            CHECK_ABS(h.t, 10.0, 1e-13, "%s: axial front t", s->name);
            CHECK_ABS(h.normal.z, -1.0, 1e-13, "%s: front vertex normal z", s->name);
            CHECK_ABS(hypot(h.normal.x, h.normal.y), 0.0, 1e-13, "%s: front vertex normal xy", s->name);
            CHECK(h.surface == LP_SURFACE_FRONT, "%s: axial hit surface %d", s->name, h.surface);
        }
        got = lp_lens_intersect(lens, V(0, 0, s->t + 10), V(0, 0, -1), 0.0, INFINITY, &h);
        CHECK(got, "%s: axial ray from behind misses", s->name);
        if (got) {
            CHECK_ABS(h.point.z, s->t, 1e-13, "%s: axial back hit z", s->name);
            CHECK_ABS(h.t, 10.0, 1e-13, "%s: axial back t", s->name);
            CHECK_ABS(h.normal.z, 1.0, 1e-13, "%s: back vertex normal z", s->name);
            CHECK(h.surface == LP_SURFACE_BACK, "%s: axial back surface %d", s->name, h.surface);
        }
        /* rays parallel to the axis at height h: front hit at z = sag1(h) */
        for (int k = 0; k < 40; k++) {
            double frac = k < 20 ? 0.05 * k : urange(0, 0.999);
            double phi = urange(0, 2 * M_PI);
            for (int back = 0; back < 2; back++) {
                lv3 T;
                cap_target(&L, back, frac, phi, &T);
                lp_vec3 O = V((double)T.x, (double)T.y, back ? s->t + 20.0 : -20.0);
                lp_vec3 d = V(0, 0, back ? -1 : 1);
                lp_hit hh;
                int g = lp_lens_intersect(lens, O, d, 0.0, INFINITY, &hh);
                CHECK(g, "%s: parallel ray at %g of the %s aperture misses", s->name, frac,
                      back ? "back" : "front");
                if (!g)
                    continue;
                /* the sag at this exact (double) height */
                ref_real hgt = ref_sqrt((ref_real)O.x * O.x + (ref_real)O.y * O.y);
                ref_real z = back ? L.t + rsag(L.c2, hgt) : rsag(L.c1, hgt);
                CHECK_ABS(hh.point.z, (double)z, 1e-12 * L.size, "%s: parallel hit z = %ssag(%g)",
                          s->name, back ? "t + " : "", (double)hgt);
                CHECK(hh.surface == (back ? LP_SURFACE_BACK : LP_SURFACE_FRONT),
                      "%s: parallel hit surface %d", s->name, hh.surface);
                check_hit(s->name, lens, &L, &f, O, d, 1e-12);
            }
        }
        lp_lens_destroy(lens);
    }
}

/* Accuracy over radii 1 .. 1e9 and flat, positive and negative. */
static void test_radii_accuracy(void)
{
    const double radii[] = {1, 10, 1e3, 1e6, 1e9, INFINITY};
    for (size_t i = 0; i < sizeof radii / sizeof radii[0]; i++) {
        for (int sign = -1; sign <= 1; sign += 2) {
            double R = radii[i];
            double D = fmin(25.0, 1.6 * R);
            double R1 = sign * R, R2 = -sign * R;
            ref_real sagm = isinf(R) ? REF(0.0) : rsag(REF(1.0) / R, D / 2);
            double t = sign > 0 ? (double)(2 * sagm) + 0.2 * D : 0.1 * D;
            ref_lens L;
            ref_init(&L, R1, R2, t, D, 0);
            char name[64];
            snprintf(name, sizeof name, "R1=%g R2=%g t=%g D=%g", R1, R2, t, D);
            frame f = frame_identity();
            lp_error err;
            lp_lens *lens = make_lens(R1, R2, t, D, 0, NULL, &err);
            CHECK(lens != NULL, "%s refused: %s", name, err.message);
            if (!lens)
                continue;
            for (int k = 0; k < 300; k++) {
                int back = k & 1;
                lv3 T;
                cap_target(&L, back, sqrt(urand()) * 0.99, urange(0, 2 * M_PI), &T);
                /* direction within 60 degrees of the axis */
                lp_vec3 dir;
                do {
                    dir = rand_unit();
                } while (fabs(dir.z) < 0.5);
                if ((dir.z < 0) != back)
                    dir = vscale(dir, -1);
                lp_vec3 O = lto(lsub(T, lscale(lfrom(dir), REF(2.0) * L.size)));
                check_hit(name, lens, &L, &f, O, dir, 1e-12);
            }
            lp_lens_destroy(lens);
        }
    }
    /* R = 1e9 agrees with a flat cap up to the sag h^2/(2R) */
    lp_lens *curved = make_lens(1e9, INFINITY, 5, 25, 0, NULL, NULL);
    lp_lens *flat = make_lens(INFINITY, INFINITY, 5, 25, 0, NULL, NULL);
    CHECK(curved && flat, "R=1e9 and flat lenses accepted");
    if (curved && flat) {
        for (int k = 2; k <= 12; k++) {
            double h = k;
            lp_hit hc, hf;
            int g1 = lp_lens_intersect(curved, V(h, 0, -1), V(0, 0, 1), 0.0, INFINITY, &hc);
            int g2 = lp_lens_intersect(flat, V(h, 0, -1), V(0, 0, 1), 0.0, INFINITY, &hf);
            CHECK(g1 && g2, "R=1e9 / flat at h=%g: hits", h);
            if (g1 && g2) {
                double want = h * h / 2e9 + h * h * h * h / (8 * 1e27);
                CHECK_REL(hc.point.z - hf.point.z, want, 1e-6, "R=1e9 vs flat at h=%g: sag h^2/2R", h);
            }
        }
    }
    lp_lens_destroy(curved);
    lp_lens_destroy(flat);
}

/* A ray tangent to a spherical cap: no NaN anywhere. */
static void test_tangent(void)
{
    lp_lens *lens = make_lens(50, -50, 8, 25, 0, NULL, NULL);
    ref_lens L;
    ref_init(&L, 50, -50, 8, 25, 0);
    if (!lens)
        return;
    for (int k = 0; k < 60; k++) {
        int back = k & 1;
        double hgt = urange(0.5, 12.0);
        double a = asin(hgt / 50.0);
        double phi = urange(0, 2 * M_PI);
        /* point on the sphere, tangent direction in the meridional plane,
         * pointing away from the lens (outward in r) */
        lv3 P, dir;
        if (!back) {
            /* front centre (0,0,50): P = C + 50*(sin a, -cos a) */
            P = L3(50 * ref_sin(a) * ref_cos(phi), 50 * ref_sin(a) * ref_sin(phi), 50 - 50 * ref_cos(a));
            /* (cos a, sin a) in (r, z) is perpendicular to the radius
             * (sin a, -cos a): the ray arrives from smaller r and z */
            dir = L3(ref_cos(a) * ref_cos(phi), ref_cos(a) * ref_sin(phi), ref_sin(a));
        } else {
            P = L3(50 * ref_sin(a) * ref_cos(phi), 50 * ref_sin(a) * ref_sin(phi),
                   8 - 50 + 50 * ref_cos(a));
            dir = L3(ref_cos(a) * ref_cos(phi), ref_cos(a) * ref_sin(phi), -ref_sin(a));
        }
        lp_vec3 O = lto(lsub(P, lscale(dir, REF(20.0))));
        lp_vec3 d = lto(dir);
        for (int j = -1; j <= 1; j++) {
            lp_vec3 Oj = vadd(O, vscale(V(cos(phi), sin(phi), 0), j * 1e-9));
            lp_hit h;
            memset(&h, 0, sizeof h);
            int got = lp_lens_intersect(lens, Oj, d, 0.0, INFINITY, &h);
            if (got) {
                CHECK(isfinite(h.t) && vfinite(h.point) && vfinite(h.normal),
                      "tangent ray (k=%d j=%d): non-finite hit", k, j);
                /* an offset of 1e-9 cuts a chord of half-length
                 * sqrt(2*50*1e-9) = 3e-4 */
                CHECK_ABS((double)llen(lsub(lfrom(h.point), P)), 0.0, 1e-3,
                          "tangent ray hit lies at the tangent point");
            }
            lp_ray in;
            memset(&in, 0, sizeof in);
            in.origin = Oj;
            in.dir = d;
            in.lambda_nm = 550;
            in.intensity = 1;
            in.vp = vnorm(vcross(d, V(0.3, 0.5, 0.7)));
            lp_result res;
            lp_result_init(&res);
            lp_trace_args args;
            lp_trace_args_init(&args);
            args.max_depth = 8;
            lp_status st = lp_trace_forward(lens, &in, &args, &res, NULL);
            CHECK(st == LP_OK, "tangent ray trace status %d", (int)st);
            double sum = res.out + res.skipped + res.absorbed_glass + res.absorbed_rim + res.truncated;
            CHECK(isfinite(sum) && isfinite(res.in), "tangent ray bookkeeping finite");
            CHECK_ABS(res.in - sum, 0.0, 1e-12 * fmax(res.in, 1e-300) + 1e-300,
                      "tangent ray bookkeeping");
            for (size_t r = 0; r < res.count; r++) {
                const lp_ray *o = &res.rays[r].ray;
                CHECK(vfinite(o->origin) && vfinite(o->dir) && vfinite(o->vp) &&
                          isfinite(o->intensity) && isfinite(o->op) && isfinite(o->phase),
                      "tangent ray: non-finite output ray");
            }
            lp_result_release(&res);
        }
    }
    lp_lens_destroy(lens);
}

/* Placement: the same lens at position P, axis A (random rotations). */
static void test_placement(void)
{
    for (int rep = 0; rep < 40; rep++) {
        const shape *s = &good_shapes[rep % N_GOOD];
        frame f = frame_make(V(urange(-50, 50), urange(-50, 50), urange(-50, 50)), rand_unit());
        ref_lens L;
        ref_init(&L, s->R1, s->R2, s->t, s->D, s->D2);
        lp_lens *lens = make_lens(s->R1, s->R2, s->t, s->D, s->D2, &f, NULL);
        lp_lens *lens0 = make_lens(s->R1, s->R2, s->t, s->D, s->D2, NULL, NULL);
        CHECK(lens && lens0, "%s placed: accepted", s->name);
        if (!lens || !lens0) {
            lp_lens_destroy(lens);
            lp_lens_destroy(lens0);
            continue;
        }
        for (int k = 0; k < 100; k++) {
            lv3 T;
            int back = k & 1;
            cap_target(&L, back, sqrt(urand()) * 0.98, urange(0, 2 * M_PI), &T);
            lp_vec3 dl = rand_unit();
            if ((dl.z < 0) != back)
                dl.z = -dl.z;
            if (fabs(dl.z) < 0.2)
                continue;
            lp_vec3 Ol = lto(lsub(T, lscale(lfrom(dl), REF(2.0) * L.size)));
            /* world ray: the local ray transformed */
            lp_vec3 Ow = lto(fw_point(&f, lfrom(Ol))), dw = lto(fw_dir(&f, lfrom(dl)));
            lp_hit h0, hw;
            int g0 = lp_lens_intersect(lens0, Ol, dl, 0.0, INFINITY, &h0);
            int gw = lp_lens_intersect(lens, Ow, dw, 0.0, INFINITY, &hw);
            CHECK(g0 == gw, "%s placed: hit %d vs unplaced %d", s->name, gw, g0);
            if (g0 && gw) {
                lv3 pw = fw_point(&f, lfrom(h0.point));
                double scale = L.size + vlen(f.P);
                CHECK_ABS((double)llen(lsub(lfrom(hw.point), pw)) / scale, 0.0, 1e-12,
                          "%s placed: hit point = transformed unplaced hit", s->name);
                worst_place_err = fmax(worst_place_err, (double)llen(lsub(lfrom(hw.point), pw)) / scale);
                CHECK_ABS((double)llen(lsub(lfrom(hw.normal), fw_dir(&f, lfrom(h0.normal)))), 0.0,
                          1e-12, "%s placed: normal transformed", s->name);
                CHECK_ABS(hw.t, h0.t, 1e-12 * scale, "%s placed: t", s->name);
                CHECK(hw.surface == h0.surface, "%s placed: surface", s->name);
            }
            /* and against the reference directly */
            check_hit(s->name, lens, &L, &f, Ow, dw, 1e-12);
        }
        lp_lens_destroy(lens);
        lp_lens_destroy(lens0);
    }
}

static void test_contains_bounds(void)
{
    for (int rep = 0; rep < 3 * (int)N_GOOD; rep++) {
        const shape *s = &good_shapes[rep % N_GOOD];
        frame f = rep < (int)N_GOOD ? frame_identity()
                                    : frame_make(V(urange(-30, 30), urange(-30, 30), urange(-30, 30)),
                                                 rand_unit());
        ref_lens L;
        ref_init(&L, s->R1, s->R2, s->t, s->D, s->D2);
        lp_lens *lens = make_lens(s->R1, s->R2, s->t, s->D, s->D2, &f, NULL);
        if (!lens)
            continue;
        ref_real zmin = ref_fmin(REF(0.0), L.zf), zmax = ref_fmax(L.t, L.zb);
        ref_real rmax = ref_fmax(L.a1, L.a2);
        /* points on the axis */
        if (rep < (int)N_GOOD) {
            CHECK(lp_lens_contains(lens, V(0, 0, s->t / 2)), "%s: contains the centre", s->name);
            CHECK(!lp_lens_contains(lens, V(0, 0, -1e-9)), "%s: not before the front vertex", s->name);
            CHECK(!lp_lens_contains(lens, V(0, 0, s->t + 1e-9)), "%s: not after the back vertex",
                  s->name);
            CHECK(!lp_lens_contains(lens, V(0, 0, 0)), "%s: front vertex is boundary (excluded)",
                  s->name);
            CHECK(!lp_lens_contains(lens, V(0, 0, s->t)), "%s: back vertex is boundary (excluded)",
                  s->name);
            CHECK(!lp_lens_contains(lens, V((double)rmax * 1.001, 0, s->t / 2)),
                  "%s: not outside the rim", s->name);
        }
        int n_in = 0, n_out = 0;
        for (int k = 0; k < 4000; k++) {
            lv3 p = L3(urange(-1.2, 1.2) * rmax, urange(-1.2, 1.2) * rmax,
                       zmin - REF(0.2) * (zmax - zmin) + urand() * REF(1.4) * (zmax - zmin));
            ref_real m;
            int want = ref_inside(&L, p, &m);
            if (m < REF(1e-7) * L.size)
                continue;
            lp_vec3 w = lto(fw_point(&f, p));
            int got = lp_lens_contains(lens, w);
            CHECK(got == want, "%s: contains(local %.9g %.9g %.9g) = %d, want %d", s->name,
                  (double)p.x, (double)p.y, (double)p.z, got, want);
            if (want)
                n_in++;
            else
                n_out++;
        }
        CHECK(n_in > 100 && n_out > 100, "%s: contains sampled both sides (%d in, %d out)", s->name,
              n_in, n_out);
        /* bounds contain sampled surface points */
        lp_vec3 lo, hi;
        lp_lens_bounds(lens, &lo, &hi);
        CHECK(vfinite(lo) && vfinite(hi) && lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z,
              "%s: bounds finite and ordered", s->name);
        double slack = 1e-9 * L.size;
        int outside = 0;
        for (int k = 0; k < 3000; k++) {
            ref_real phi = urange(0, 2 * M_PI);
            lv3 p;
            int which = k % 3;
            if (which < 2) {
                ref_real a = which ? L.a2 : L.a1, r = ref_sqrt(urand()) * a;
                if (k % 10 == 0)
                    r = a;
                ref_real z = which ? L.t + rsag(L.c2, r) : rsag(L.c1, r);
                p = L3(r * ref_cos(phi), r * ref_sin(phi), z);
            } else {
                ref_real u = urand();
                ref_real z = L.zf + u * (L.zb - L.zf);
                ref_real r = L.a1 + u * (L.a2 - L.a1);
                p = L3(r * ref_cos(phi), r * ref_sin(phi), z);
            }
            lv3 w = fw_point(&f, p);
            if (w.x < lo.x - slack || w.x > hi.x + slack || w.y < lo.y - slack ||
                w.y > hi.y + slack || w.z < lo.z - slack || w.z > hi.z + slack)
                outside++;
        }
        CHECK(outside == 0, "%s: %d surface points outside lp_lens_bounds", s->name, outside);
        /* not absurdly loose: within the box of a sphere around the lens */
        double rad = sqrt((double)(2 * rmax * rmax) + pow((double)(zmax - zmin) / 2, 2));
        CHECK(hi.x - lo.x <= 2 * rad + 1 && hi.y - lo.y <= 2 * rad + 1 && hi.z - lo.z <= 2 * rad + 1,
              "%s: bounds too loose", s->name);
        lp_lens_destroy(lens);
    }
    /* conical rim: points just inside/outside the cone */
    ref_lens L;
    ref_init(&L, 50, -50, 8, 30, 20);
    lp_lens *lens = make_lens(50, -50, 8, 30, 20, NULL, NULL);
    if (lens) {
        for (int k = 0; k < 200; k++) {
            ref_real u = urange(0.05, 0.95), phi = urange(0, 2 * M_PI);
            ref_real z = L.zf + u * (L.zb - L.zf), r = L.a1 + u * (L.a2 - L.a1);
            lv3 n = lnorm(L3(ref_cos(phi), ref_sin(phi), -L.k)); /* outward cone normal */
            lv3 p = L3(r * ref_cos(phi), r * ref_sin(phi), z);
            lv3 pin = ladd(p, lscale(n, -REF(1e-6))), pout = ladd(p, lscale(n, REF(1e-6)));
            CHECK(lp_lens_contains(lens, lto(pin)), "cone: point 1e-6 inside the cone is inside");
            CHECK(!lp_lens_contains(lens, lto(pout)), "cone: point 1e-6 outside the cone is outside");
        }
        lp_lens_destroy(lens);
    }
}

/* Re-intersecting from a hit point never returns the same point. */
static void test_no_self_hit(void)
{
    for (int rep = 0; rep < 2 * (int)N_GOOD; rep++) {
        const shape *s = &good_shapes[rep % N_GOOD];
        frame f = rep < (int)N_GOOD ? frame_identity()
                                    : frame_make(V(urange(-30, 30), urange(-30, 30), urange(-30, 30)),
                                                 rand_unit());
        ref_lens L;
        ref_init(&L, s->R1, s->R2, s->t, s->D, s->D2);
        lp_lens *lens = make_lens(s->R1, s->R2, s->t, s->D, s->D2, &f, NULL);
        if (!lens)
            continue;
        const double n = 1.5;
        for (int k = 0; k < 300; k++) {
            lv3 T;
            int back = k & 1;
            cap_target(&L, back, sqrt(urand()) * 0.97, urange(0, 2 * M_PI), &T);
            lp_vec3 dl = rand_unit();
            if ((dl.z < 0) != back)
                dl.z = -dl.z;
            if (fabs(dl.z) < 0.2)
                continue;
            lp_vec3 Ow = lto(fw_point(&f, lsub(T, lscale(lfrom(dl), REF(2.0) * L.size))));
            lp_vec3 dw = lto(fw_dir(&f, lfrom(dl)));
            lp_hit h;
            if (!lp_lens_intersect(lens, Ow, dw, 0.0, INFINITY, &h) || h.surface == LP_SURFACE_RIM)
                continue;
            /* refract into the glass (n=1 -> 1.5) with my own Snell */
            lv3 nl = fl_dir(&f, h.normal);
            lv3 d = lnorm(fl_dir(&f, dw));
            lv3 pl = fl_point(&f, h.point);
            ref_real ci = -ldot(d, nl);
            if (ci < REF(1e-3))
                continue;
            ref_real eta = REF(1.0) / n, ct = ref_sqrt(REF(1.0) - eta * eta * (REF(1.0) - ci * ci));
            lv3 dt = lnorm(ladd(lscale(d, eta), lscale(nl, eta * ci - ct)));
            lp_vec3 dtw = lto(fw_dir(&f, dt));
            lv3 de = ladd(d, lscale(nl, REF(2.0) * ci)); /* external reflection */
            ref_hit r = ref_intersect(&L, pl, dt, REF(1e-9));
            /* (a) the property itself: t_min = 0 from the hit point must
             * not return the hit point again */
            lp_hit h2;
            int g2 = lp_lens_intersect(lens, h.point, dtw, 0.0, INFINITY, &h2);
            CHECK(g2, "%s: refracted ray from a hit point finds no exit", s->name);
            CHECK(!g2 || h2.t > 1e-9, "%s: refracted re-intersection (t_min 0) t=%g (self hit)", s->name,
                  g2 ? h2.t : 0.0);
            lp_hit h4;
            if (lp_lens_intersect(lens, h.point, lto(fw_dir(&f, de)), 0.0, INFINITY, &h4))
                CHECK(h4.t > 1e-9, "%s: external reflection re-hit (t_min 0) t=%g (self hit)", s->name,
                      h4.t);
            /* (b) with a small t_min the next surface is the right one */
            lp_hit h2b;
            int g2b = lp_lens_intersect(lens, h.point, dtw, 1e-9, INFINITY, &h2b);
            CHECK(g2b, "%s: refracted ray (t_min 1e-9) finds no exit", s->name);
            if (!g2b || r.surf < 0)
                continue;
            lv3 pw = fw_point(&f, r.p);
            CHECK_ABS((double)llen(lsub(lfrom(h2b.point), pw)) / L.size, 0.0, 1e-11,
                      "%s: exit point of the refracted ray", s->name);
            /* internal reflection from the exit point */
            lv3 n2 = fl_dir(&f, h2b.normal);
            lv3 dr = ladd(dt, lscale(n2, -REF(2.0) * ldot(dt, n2)));
            lp_hit h3;
            int g3 = lp_lens_intersect(lens, h2b.point, lto(fw_dir(&f, dr)), 0.0, INFINITY, &h3);
            CHECK(g3 && h3.t > 1e-9, "%s: internal reflection re-hit (t_min 0): found %d t=%g", s->name,
                  g3, g3 ? h3.t : 0.0);
            g3 = lp_lens_intersect(lens, h2b.point, lto(fw_dir(&f, dr)), 1e-9, INFINITY, &h3);
            CHECK(g3, "%s: internally reflected ray (t_min 1e-9) finds no surface", s->name);
            ref_hit r3 = ref_intersect(&L, fl_point(&f, h2b.point), lnorm(fl_dir(&f, lto(fw_dir(&f, dr)))),
                                       REF(1e-9));
            if (g3 && r3.surf >= 0)
                CHECK_ABS((double)llen(lsub(lfrom(h3.point), fw_point(&f, r3.p))) / L.size, 0.0, 1e-11,
                          "%s: next point after the internal reflection", s->name);
        }
        lp_lens_destroy(lens);
    }
}

int main(void)
{
    test_accepts();
    test_refuses();
    test_axial_and_parallel();
    test_radii_accuracy();
    test_tangent();
    test_placement();
    test_contains_bounds();
    test_no_self_hit();
    printf("test_geometry: worst hit point error / lens size vs " REF_NAME " reference %.3g, "
           "worst normal error %.3g, worst placed-vs-unplaced %.3g\n",
           worst_hit_err, worst_normal_err, worst_place_err);
    return check_finish("test_geometry");
}
