/* test_cone.c -- the cone K of rim-free initial directions.
 *
 * The reference is a chain traced here in ref_real (binary128 where
 * available): Spencer & Murty caps and the cylindrical or conical rim of
 * lens_reference.h, vector Snell at the entry, vector reflection inside.
 * A direction is rim-free when its entry hit is a cap and none of the
 * next dT - 1 internal segments meets the rim.  theta_K is found from it
 * by a scan and a bisection written here, and compared with the library:
 *   - on the axis, in the meridional plane, for five lens shapes
 *     (biconvex, meniscus, flat plate, conical rim, biconcave) and a knife
 *     edge, at depths 1..6, two distances and two glasses: to 1e-6 rad;
 *   - the solid angle against 2 pi (1 - cos theta_K);
 *   - rotational symmetry on the axis: 36 azimuths equal to 1e-9 rad;
 *   - an off-axis point: per azimuth against the reference's bisection
 *     and against brute-force sampling of directions on a fine grid;
 *   - a lens placed in the world, the point given in the world frame;
 *   - the collimated case on a tilted flat plate against the closed form
 *     rho_K = cos(a) (h - (dT - 1) t tan(b)) toward the walk-off and
 *     cos(a) h away from it, sin a = n sin b;
 *   - bad input refused with a message.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "lensprim.h"
#include "ref_real.h"
#include "lens_reference.h"

/* ------------------------------------------------------------------ */
/* the reference chain                                                 */
/* ------------------------------------------------------------------ */

typedef struct {
    ref_lens L;
    ref_real ng, nm;
    int depth;
} ref_case;

/* 1 when O + s d (local, d unit) is rim-free up to rc->depth. */
static int ref_rim_free(const ref_case *rc, lv3 O, lv3 d)
{
    const ref_lens *L = &rc->L;
    ref_hit h = ref_intersect(L, O, d, REF(0.0));
    if (h.surf < 0 || h.surf == LP_SURFACE_RIM)
        return 0;
    lv3 dir;
    if (!lrefract(d, h.n, rc->nm, rc->ng, &dir))
        return 1; /* no internal ray at all */
    for (int k = 1; k < rc->depth; k++) {
        h = ref_intersect(L, h.p, dir, REF(1e-9) * L->size);
        if (h.surf < 0 || h.surf == LP_SURFACE_RIM)
            return 0;
        dir = lreflect(dir, h.n);
    }
    return 1;
}

/* The direction at polar angle th and azimuth ph about axis a. */
static lv3 cone_dir(lv3 a, lv3 e1, lv3 e2, ref_real th, ref_real ph)
{
    lv3 e = ladd(lscale(e1, ref_cos(ph)), lscale(e2, ref_sin(ph)));
    return lnorm(ladd(lscale(a, ref_cos(th)), lscale(e, ref_sin(th))));
}

/* theta_K at one azimuth: first failure on a scan of [0, hi] in `steps`
 * steps, bisected to 1e-13 rad.  *first_bad_step gets the scan bracket. */
static double ref_theta(const ref_case *rc, lv3 P, lv3 a, lv3 e1, lv3 e2, double ph, double hi,
                        int steps, double *lo_out, double *hi_out)
{
    if (!ref_rim_free(rc, P, a)) {
        *lo_out = *hi_out = 0.0;
        return 0.0;
    }
    ref_real good = 0, bad = -1;
    for (int j = 1; j <= steps; j++) {
        ref_real th = (ref_real)hi * j / steps;
        if (!ref_rim_free(rc, P, cone_dir(a, e1, e2, th, ph))) {
            bad = th;
            break;
        }
        good = th;
    }
    if (bad < 0) {
        *lo_out = *hi_out = hi;
        return hi;
    }
    *lo_out = (double)good;
    *hi_out = (double)bad;
    while (bad - good > REF(1e-13)) {
        ref_real mid = (good + bad) / 2;
        if (ref_rim_free(rc, P, cone_dir(a, e1, e2, mid, ph)))
            good = mid;
        else
            bad = mid;
    }
    return (double)good;
}

/* ------------------------------------------------------------------ */

typedef struct {
    const char *name;
    double R1, R2, t, D, D2;
} shape;

static const shape shapes[] = {
    {"biconvex", 50, -50, 8, 25, 0},
    {"meniscus", 30, 60, 6, 25, 0},
    {"flat plate", 0, 0, 5, 20, 0},
    {"conical rim", 40, -60, 12, 30, 22},
    {"biconcave", -40, 40, 3, 25, 0},
    /* sag(3) = 5 - 4 = 1 on both sides: edge thickness exactly 0 */
    {"knife edge", 5, -5, 2, 6, 0},
};

static lp_lens *make(const shape *s, double n, lp_vec3 pos, lp_vec3 axis)
{
    lp_lens_desc d;
    lp_lens_desc_init(&d);
    d.radius1 = s->R1;
    d.radius2 = s->R2;
    d.thickness = s->t;
    d.diameter = s->D;
    d.diameter2 = s->D2;
    lp_glass_init_constant(&d.glass, n);
    d.position = pos;
    d.axis = axis;
    lp_lens *lens = NULL;
    lp_error err;
    lp_status st = lp_lens_create(&d, &lens, &err);
    CHECK(st == LP_OK, "%s: lens refused: %s", s->name, err.message);
    return lens;
}

static void ref_make(ref_case *rc, const shape *s, double n, int depth)
{
    ref_init(&rc->L, s->R1, s->R2, s->t, s->D, s->D2);
    rc->ng = n;
    rc->nm = 1;
    rc->depth = depth;
}

/* On the axis: theta_K against the meridional reference, symmetry, solid
 * angle. */
static void test_on_axis(void)
{
    const double glasses[2] = {1.5168, 1.78472}; /* n_d of N-BK7 and N-SF11 */
    const double dist[2] = {50, 20};
    double worst = 0, worst_sym = 0, worst_omega = 0;
    for (size_t i = 0; i < sizeof shapes / sizeof shapes[0]; i++) {
        for (int g = 0; g < 2; g++) {
            lp_lens *lens = make(&shapes[i], glasses[g], V(0, 0, 0), V(0, 0, 1));
            if (!lens)
                continue;
            for (int di = 0; di < 2; di++) {
                for (int depth = 1; depth <= 6; depth++) {
                    ref_case rc;
                    ref_make(&rc, &shapes[i], glasses[g], depth);
                    lv3 P = L3(0, 0, -dist[di]);
                    double lo, hi;
                    /* meridional plane x = 0: azimuth pi/2 about +z with e1 = x */
                    double want = ref_theta(&rc, P, L3(0, 0, 1), L3(1, 0, 0), L3(0, 1, 0),
                                            M_PI / 2, M_PI / 2, 2000, &lo, &hi);
                    lp_cone_args a;
                    lp_cone_args_init(&a);
                    a.max_depth = depth;
                    a.lambda_nm = 587.56;
                    /* 36 azimuths (the CLI's default) at the deepest dT,
                     * 4 elsewhere: azimuth 90 deg is index n / 4 */
                    int na = depth == 6 ? 36 : 4;
                    double th[36];
                    lp_cone cone;
                    lp_error err;
                    lp_status st = lp_cone_compute(lens, V(0, 0, -dist[di]), &a, (size_t)na, th,
                                                   &cone, &err);
                    CHECK(st == LP_OK, "%s: lp_cone_compute: %s", shapes[i].name, err.message);
                    if (st != LP_OK)
                        continue;
                    /* measured: at most 9.3e-10 rad (the bisection's 1e-9
                     * bracket); 1e-6 is the bound */
                    CHECK_ABS(th[na / 4], want, 1e-6, "%s n=%g z=-%g dT=%d theta_K at 90 deg",
                              shapes[i].name, glasses[g], dist[di], depth);
                    worst = fmax(worst, fabs(th[na / 4] - want));
                    for (int k = 0; k < na; k++) {
                        /* measured: 0 (every azimuth bisects the same
                         * function of theta) */
                        CHECK_ABS(th[k], th[0], 1e-9, "%s dT=%d symmetry at azimuth %d deg",
                                  shapes[i].name, depth, k * 360 / na);
                        worst_sym = fmax(worst_sym, fabs(th[k] - th[0]));
                    }
                    double omega = 2 * M_PI * (1 - cos(want));
                    /* measured: 3.4e-8 relative at most (theta's error
                     * 1e-9 times 2 / theta, theta down to 0.02 rad) */
                    CHECK_REL(cone.solid_angle, omega, 1e-6, "%s dT=%d solid angle",
                              shapes[i].name, depth);
                    worst_omega = fmax(worst_omega, fabs(cone.solid_angle - omega) / omega);
                    CHECK(cone.depth == depth && cone.theta_min <= cone.theta_max &&
                              fabs(cone.theta_max - want) < 1e-6,
                          "%s: summary", shapes[i].name);
                    CHECK(fabs(cone.frame.axis.z - 1) < 1e-15 && fabs(cone.frame.ref.x - 1) < 1e-15,
                          "%s: frame axis +z, ref +x", shapes[i].name);
                    if (i == 2 && depth == 1) {
                        /* the plate at depth 1: the front cap's edge, atan(h / d) */
                        CHECK_ABS(th[0], atan(10.0 / dist[di]), 1e-9, "plate dT=1 edge angle");
                    }
                }
            }
            lp_lens_destroy(lens);
        }
    }
    printf("on axis: worst |theta - ref| %.3g rad, symmetry %.3g rad, solid angle rel %.3g\n",
           worst, worst_sym, worst_omega);
}

/* Off the axis: the frame of the issue (axis to the front vertex, ref
 * the part of +x perpendicular to it), per azimuth against the reference
 * and against brute-force sampling. */
static void test_off_axis(void)
{
    const shape *s = &shapes[0];
    const double n = 1.5168;
    lp_lens *lens = make(s, n, V(0, 0, 0), V(0, 0, 1));
    if (!lens)
        return;
    const lp_vec3 pts[2] = {{3, -2, -40}, {9, 4, -25}};
    double worst = 0;
    int bf_checked = 0;
    for (int pi = 0; pi < 2; pi++) {
        lp_vec3 P = pts[pi];
        lv3 a = lnorm(L3(-P.x, -P.y, -P.z));
        lv3 e1 = lnorm(lsub(L3(1, 0, 0), lscale(a, a.x)));
        lv3 e2 = lcross(a, e1);
        for (int depth = 1; depth <= 6; depth += 1) {
            ref_case rc;
            ref_make(&rc, s, n, depth);
            lp_cone_args args;
            lp_cone_args_init(&args);
            args.max_depth = depth;
            enum { NA = 12 };
            double th[NA];
            lp_cone cone;
            lp_error err;
            lp_status st = lp_cone_compute(lens, P, &args, NA, th, &cone, &err);
            CHECK(st == LP_OK, "off-axis lp_cone_compute: %s", err.message);
            if (st != LP_OK)
                continue;
            double omega = 0;
            for (int k = 0; k < NA; k++) {
                double ph = 2 * M_PI * k / NA, lo, hi;
                double want = ref_theta(&rc, lfrom(P), a, e1, e2, ph, M_PI / 2, 2000, &lo, &hi);
                /* measured: at most 8.6e-10 rad */
                CHECK_ABS(th[k], want, 1e-6, "point %d dT=%d azimuth %d: theta_K", pi, depth,
                          k * 30);
                worst = fmax(worst, fabs(th[k] - want));
                omega += (1 - cos(want)) * 2 * M_PI / NA;
                /* brute force: every direction on a 5e-4 rad grid below
                 * theta_K is rim-free, the next grid point above the
                 * first failure is not */
                if (depth % 2 == 0) {
                    int all = 1;
                    double step = 5e-4;
                    for (double t = 0; t < th[k] - 1e-7; t += step)
                        all &= ref_rim_free(&rc, lfrom(P), cone_dir(a, e1, e2, t, ph));
                    CHECK(all, "point %d dT=%d azimuth %d: a sampled direction below "
                               "theta_K=%.9f is not rim-free", pi, depth, k * 30, th[k]);
                    CHECK(!ref_rim_free(&rc, lfrom(P), cone_dir(a, e1, e2, th[k] + 1e-7, ph)),
                          "point %d dT=%d azimuth %d: the direction just past theta_K is "
                          "rim-free", pi, depth, k * 30);
                    bf_checked++;
                }
            }
            CHECK_REL(cone.solid_angle, omega, 1e-6, "point %d dT=%d solid angle", pi, depth);
            CHECK(cone.theta_max - cone.theta_min > 1e-3,
                  "point %d dT=%d: off the axis the cone is not circular (%.6f..%.6f)", pi,
                  depth, cone.theta_min, cone.theta_max);
            CHECK(fabs(cone.frame.axis.x - (double)a.x) < 1e-15 &&
                      fabs(cone.frame.ref.x - (double)e1.x) < 1e-15 &&
                      fabs(cone.frame.ref.z - (double)e1.z) < 1e-15,
                  "point %d: frame", pi);
        }
    }
    printf("off axis: worst |theta - ref| %.3g rad; %d azimuths brute-forced\n", worst,
           bf_checked);
    lp_lens_destroy(lens);
}

/* The same lens placed in the world: the world point gives the local
 * point's cone. */
static void test_world_frame(void)
{
    const shape *s = &shapes[1];
    lp_vec3 pos = V(10, -5, 30), axis = vnorm(V(0.3, -0.2, 1));
    lp_lens *local = make(s, 1.6, V(0, 0, 0), V(0, 0, 1));
    lp_lens *world = make(s, 1.6, pos, axis);
    if (!local || !world)
        goto out;
    frame f = frame_make(pos, axis);
    /* the library's local x is its own choice: find the world point of a
     * local point on the axis (any frame works there) */
    lp_vec3 Pl = V(0, 0, -35);
    lp_vec3 Pw = vadd(pos, vscale(f.A, -35));
    lp_cone_args a;
    lp_cone_args_init(&a);
    a.max_depth = 4;
    double t1[8], t2[8];
    lp_cone c1, c2;
    lp_status st1 = lp_cone_compute(local, Pl, &a, 8, t1, &c1, NULL);
    a.frame = LP_FRAME_WORLD;
    lp_status st2 = lp_cone_compute(world, Pw, &a, 8, t2, &c2, NULL);
    CHECK(st1 == LP_OK && st2 == LP_OK, "world frame cone computed");
    for (int k = 0; k < 8; k++)
        /* measured: 5e-10 (the world transform's rounding moves the
         * bisection by one bracket at most) */
        CHECK_ABS(t2[k], t1[k], 2e-9, "world frame azimuth %d", k);
    CHECK(vlen(vsub(c2.frame.axis, f.A)) < 1e-12 && vlen(vsub(c2.frame.apex, Pw)) < 1e-12 &&
              fabs(vdot(c2.frame.ref, f.A)) < 1e-12,
          "world frame: axis along the lens axis, apex the point");
    int free_ray = -1;
    lp_status st = lp_rim_free(world, Pw, f.A, &a, &free_ray, NULL);
    CHECK(st == LP_OK && free_ray == 1, "lp_rim_free on the world axis");
    st = lp_rim_free(world, Pw, vscale(f.A, -1), &a, &free_ray, NULL);
    CHECK(st == LP_OK && free_ray == 0, "lp_rim_free: a ray away from the lens has no tree");
out:
    lp_lens_destroy(local);
    lp_lens_destroy(world);
}

/* The collimated case on a tilted flat plate: each internal segment moves
 * the ray by t tan(b) along the plane of incidence, so the rays that stay
 * off the rim for dT - 1 segments start at most h - (dT - 1) t tan(b) from
 * the axis on the walk-off side; in the plane perpendicular to the beam
 * that is cos(a) times as far. */
static void test_beam_plate(void)
{
    const double h = 10, t = 5, n = 1.5168;
    const shape plate = {"plate", 0, 0, t, 2 * h, 0};
    lp_lens *lens = make(&plate, n, V(0, 0, 0), V(0, 0, 1));
    if (!lens)
        return;
    double worst = 0;
    for (int ai = 0; ai < 3; ai++) {
        double alpha = (double[]){0.0, 0.3, 0.9}[ai];
        double beta = asin(sin(alpha) / n);
        lp_vec3 d = V(sin(alpha), 0, cos(alpha));
        for (int depth = 1; depth <= 6; depth++) {
            lp_cone_args a;
            lp_cone_args_init(&a);
            a.max_depth = depth;
            double r[4];
            lp_beam_region reg;
            lp_error err;
            lp_status st = lp_beam_region_compute(lens, d, &a, 4, r, &reg, &err);
            CHECK(st == LP_OK, "beam: %s", err.message);
            if (st != LP_OK)
                continue;
            double walk = (depth - 1) * t * tan(beta);
            double want0 = cos(alpha) * (h - walk), want2 = cos(alpha) * h;
            if (walk > h) /* even the ray through the vertex meets the rim */
                want0 = want2 = 0;
            /* azimuth 0 is +x's part perpendicular to the beam: toward the
             * walk-off.  measured: 6.4e-10 mm */
            CHECK_ABS(r[0], want0, 1e-6, "beam a=%g dT=%d rho_K toward the walk-off", alpha,
                      depth);
            CHECK_ABS(r[2], want2, 1e-6, "beam a=%g dT=%d rho_K away from it", alpha, depth);
            worst = fmax(worst, fmax(fabs(r[0] - want0), fabs(r[2] - want2)));
            if (alpha == 0.0)
                CHECK_ABS(reg.area, M_PI * h * h, 1e-6 * h * h, "normal beam: area pi h^2");
            CHECK(vlen(vsub(reg.frame.axis, d)) < 1e-15, "beam frame axis");
        }
    }
    printf("beam on a plate: worst |rho - closed form| %.3g mm\n", worst);
    lp_lens_destroy(lens);
}

static void test_bad_input(void)
{
    lp_lens *lens = make(&shapes[0], 1.5, V(0, 0, 0), V(0, 0, 1));
    if (!lens)
        return;
    lp_cone_args a;
    double th[4];
    lp_cone c;
    lp_error err;
    lp_cone_args_init(&a);
    struct {
        lp_vec3 p;
        const char *word;
    } pts[] = {{{0, 0, 0}, "vertex"}, {{0, 0, 4}, "inside"}, {{NAN, 0, -10}, "finite"},
               {{0, INFINITY, -10}, "finite"}};
    for (size_t i = 0; i < sizeof pts / sizeof pts[0]; i++) {
        memset(&err, 0, sizeof err);
        lp_status st = lp_cone_compute(lens, pts[i].p, &a, 4, th, &c, &err);
        CHECK(st == LP_ERROR_INVALID_ARGUMENT && has_word(err.message, pts[i].word),
              "bad point %zu: status %d message '%s'", i, (int)st, err.message);
    }
    lp_cone_args b = a;
    b.max_depth = 0;
    CHECK(lp_cone_compute(lens, V(0, 0, -10), &b, 4, th, &c, &err) == LP_ERROR_INVALID_ARGUMENT &&
              has_word(err.message, "depth"),
          "depth 0 refused: %s", err.message);
    b = a;
    b.tolerance = 0;
    CHECK(lp_cone_theta(lens, V(0, 0, -10), 0, &b, th, &err) == LP_ERROR_INVALID_ARGUMENT,
          "tolerance 0 refused");
    b = a;
    b.scan_steps = 0;
    CHECK(lp_cone_theta(lens, V(0, 0, -10), 0, &b, th, &err) == LP_ERROR_INVALID_ARGUMENT,
          "scan_steps 0 refused");
    b = a;
    b.lambda_nm = -1;
    CHECK(lp_cone_theta(lens, V(0, 0, -10), 0, &b, th, &err) == LP_ERROR_INVALID_ARGUMENT,
          "negative wavelength refused");
    CHECK(lp_cone_theta(lens, V(0, 0, -10), NAN, &a, th, &err) == LP_ERROR_INVALID_ARGUMENT,
          "NaN azimuth refused");
    CHECK(lp_cone_compute(lens, V(0, 0, -10), &a, 0, th, &c, &err) == LP_ERROR_INVALID_ARGUMENT,
          "no azimuths refused");
    CHECK(lp_cone_compute(NULL, V(0, 0, -10), &a, 4, th, &c, &err) == LP_ERROR_INVALID_ARGUMENT,
          "NULL lens refused");
    double r[4];
    lp_beam_region reg;
    CHECK(lp_beam_region_compute(lens, V(0, 0, 0), &a, 4, r, &reg, &err) ==
              LP_ERROR_INVALID_ARGUMENT,
          "zero beam direction refused");
    int f;
    CHECK(lp_rim_free(lens, V(0, 0, -10), V(0, 0, 0), &a, &f, &err) == LP_ERROR_INVALID_ARGUMENT,
          "zero ray direction refused");
    /* NULL args: the defaults (dT 5) */
    CHECK(lp_cone_theta(lens, V(0, 0, -10), 0, NULL, th, &err) == LP_OK && th[0] > 0.1,
          "NULL args: defaults");
    /* a point behind the lens looks through the back cap */
    CHECK(lp_cone_theta(lens, V(0, 0, 40), 0, &a, th, &err) == LP_OK && th[0] > 0.1,
          "a point behind the lens: %s", err.message);
    lp_lens_destroy(lens);
}

int main(void)
{
    printf("reference arithmetic: %s\n", REF_NAME);
    test_on_axis();
    test_off_axis();
    test_world_frame();
    test_beam_plate();
    test_bad_input();
    return check_finish("test_cone");
}
