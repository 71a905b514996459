/* test_plate.c -- the multiple-beam ray tree of a lossless plane-parallel
 * plate (Born & Wolf 7.6.1), intensities only.
 *
 * Plate: both caps flat, n = 1.5168, thickness t = 10, diameter 1e4 (the
 * rim is never reached), in air; depth limit 40.  A ray at incidence i
 * refracts to r (sin i = n sin r).  Let R be the reflectance at i from
 * air (Rs or Rp from my formula).  At the internal faces the incidence
 * is r from glass to air, and Fresnel's r'(r) = -r(i) (Stokes), so the
 * internal reflectance is the same R and every crossing transmits
 * T = 1 - R.  The tree is a single chain:
 *   depth 1            external reflection              R
 *   depth 2k+2, k>=0   transmitted: T R^(2k) T          (1-R)^2 R^(2k)
 *   depth 2k+1, k>=1   reflected:   T R^(2k-1) T        (1-R)^2 R^(2k-1)
 * Sum of the transmitted rays: (1-R)^2/(1-R^2) = (1-R)/(1+R); up to depth
 * 40 the sum misses the tail (1-R)^2 R^40/(1-R^2).  The internal ray
 * reflected at node 40 carries T R^39 and is the truncated energy.
 * Geometry: the ray enters at the origin, the k-th transmitted ray
 * leaves at x = (2k+1) t tan r, z = t, the reflected ones at x = 2k t
 * tan r, z = 0; the transmitted direction is the incident one, the
 * reflected one its mirror image; the first transmitted ray is displaced
 * sideways by t sin(i - r)/cos r; successive rays on one side differ in
 * optical path by 2 n t/cos r.
 *
 * Tolerances: each node multiplies the power by a factor computed with a
 * relative rounding of at most ~1e-14 (rp near Brewster's angle loses a
 * couple of digits to cancellation), so a ray of depth d gets
 * max(1e-12, d * 1e-13) relative; positions 1e-10 mm (coordinates up to
 * ~300 mm); directions 1e-14.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "lensprim.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static const double NG = 1.5168, TH = 10.0;
enum { DEPTH = 40 };

static lp_vec3 vec(double x, double y, double z)
{
    lp_vec3 v = {x, y, z};
    return v;
}
static double dot(lp_vec3 a, lp_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static double tol_depth(int d) { return d * 1e-13 > 1e-12 ? d * 1e-13 : 1e-12; }

static void plate_case(const lp_lens *lens, double deg, int pol)
{
    const char *pn = pol ? "p" : "s";
    double th = deg * DEG, ci = cos(th), si = sin(th);
    double sr = si / NG, cr = sqrt(1.0 - sr * sr), tr = sr / cr;
    double rs = (ci - NG * cr) / (ci + NG * cr);
    double rp = (NG * ci - cr) / (NG * ci + cr);
    double R = pol ? rp * rp : rs * rs, T = 1.0 - R;
    lp_vec3 d = vec(si, 0.0, ci), dr = vec(si, 0.0, -ci);

    lp_ray in;
    memset(&in, 0, sizeof in);
    in.origin = vec(-5.0 * si, 0.0, -5.0 * ci);
    in.dir = d;
    in.lambda_nm = 589.0;
    in.intensity = 1.0;
    in.vp = pol ? vec(-ci, 0.0, si) : vec(0.0, 1.0, 0.0);
    lp_trace_args args;
    lp_trace_args_init(&args);
    args.max_depth = DEPTH;
    lp_result res;
    lp_result_init(&res);
    lp_error err;
    memset(&err, 0, sizeof err);
    lp_status st = lp_trace_forward(lens, &in, &args, &res, &err);
    CHECK(st == LP_OK, "%s %g deg: trace: %s", pn, deg, err.message);
    if (st != LP_OK) {
        lp_result_release(&res);
        return;
    }

    const lp_out_ray *by_depth[DEPTH + 1] = {0};
    int count[DEPTH + 1];
    memset(count, 0, sizeof count);
    for (size_t i = 0; i < res.count; i++) {
        int dep = res.rays[i].depth;
        CHECK(dep >= 1 && dep <= DEPTH, "%s %g deg: depth %d out of range", pn, deg, dep);
        if (dep >= 1 && dep <= DEPTH) {
            by_depth[dep] = &res.rays[i];
            count[dep]++;
        }
    }
    CHECK(res.count == DEPTH, "%s %g deg: %zu rays, want one per depth 1..%d", pn, deg,
          res.count, DEPTH);

    double sum_t = 0.0;
    for (int dep = 1; dep <= DEPTH; dep++) {
        CHECK(count[dep] == 1, "%s %g deg: %d rays at depth %d", pn, deg, count[dep], dep);
        if (count[dep] != 1)
            continue;
        const lp_out_ray *o = by_depth[dep];
        const lp_ray *r = &o->ray;
        int transmitted = (dep % 2 == 0);
        double want_i;
        lp_vec3 want_o, want_d;
        if (dep == 1) {
            want_i = R;
            want_o = vec(0, 0, 0);
        } else if (transmitted) {
            int k = (dep - 2) / 2;
            want_i = T * T * pow(R, 2 * k);
            want_o = vec((2 * k + 1) * TH * tr, 0.0, TH);
        } else {
            int k = (dep - 1) / 2;
            want_i = T * T * pow(R, 2 * k - 1);
            want_o = vec(2 * k * TH * tr, 0.0, 0.0);
        }
        want_d = transmitted ? d : dr;
        if (transmitted)
            sum_t += r->intensity;
        CHECK_REL(r->intensity, want_i, tol_depth(dep), "%s %g deg: I at depth %d", pn, deg, dep);
        CHECK(o->kind == (transmitted ? LP_KIND_TRANSMIT : LP_KIND_REFLECT) &&
                  o->surface == (transmitted ? LP_SURFACE_BACK : LP_SURFACE_FRONT) &&
                  o->part == 0,
              "%s %g deg: kind/surface/part at depth %d", pn, deg, dep);
        CHECK_ABS(r->origin.x, want_o.x, 1e-10, "%s %g deg: x at depth %d", pn, deg, dep);
        CHECK_ABS(r->origin.y, want_o.y, 1e-10, "%s %g deg: y at depth %d", pn, deg, dep);
        CHECK_ABS(r->origin.z, want_o.z, 1e-10, "%s %g deg: z at depth %d", pn, deg, dep);
        CHECK_ABS(r->dir.x, want_d.x, 1e-14, "%s %g deg: dir x at depth %d", pn, deg, dep);
        CHECK_ABS(r->dir.y, want_d.y, 1e-14, "%s %g deg: dir y at depth %d", pn, deg, dep);
        CHECK_ABS(r->dir.z, want_d.z, 1e-14, "%s %g deg: dir z at depth %d", pn, deg, dep);
        /* s stays s, p stays p; no TIR, so no extra phase */
        if (pol) {
            CHECK_ABS(r->vp.y, 0.0, 1e-12, "%s %g deg: p stays p at depth %d", pn, deg, dep);
            CHECK_ABS(dot(r->vp, r->dir), 0.0, 1e-12, "%s %g deg: vp.dir at depth %d", pn, deg, dep);
            CHECK_ABS(dot(r->vp, r->vp), 1.0, 1e-12, "%s %g deg: |vp| at depth %d", pn, deg, dep);
        } else {
            CHECK_ABS(fabs(r->vp.y), 1.0, 1e-12, "%s %g deg: s stays s at depth %d", pn, deg, dep);
        }
        CHECK_ABS(r->phase, 0.0, 1e-15, "%s %g deg: phase at depth %d", pn, deg, dep);
        /* optical path between successive rays on one side */
        if (dep >= 3 && count[dep - 2] == 1)
            CHECK_REL(r->op - by_depth[dep - 2]->ray.op, 2.0 * NG * TH / cr, 1e-12,
                      "%s %g deg: op step at depth %d", pn, deg, dep);
    }

    /* lateral displacement of the first transmitted ray */
    if (count[2] == 1) {
        lp_vec3 q = by_depth[2]->ray.origin; /* entry point is the origin */
        double along = dot(q, d);
        lp_vec3 perp = vec(q.x - along * d.x, q.y - along * d.y, q.z - along * d.z);
        double disp = sqrt(dot(perp, perp));
        double want = TH * sin(th - asin(sr)) / cr;
        if (deg == 0.0)
            CHECK_ABS(disp, 0.0, 1e-12, "%s %g deg: no displacement at normal incidence", pn, deg);
        else
            CHECK_REL(disp, want, 1e-12, "%s %g deg: lateral displacement", pn, deg);
    }

    /* sum of the transmitted rays */
    double finite = T * T * (1.0 - pow(R, DEPTH)) / (1.0 - R * R);
    double tail = T * T * pow(R, DEPTH) / (1.0 - R * R);
    CHECK_REL(sum_t, finite, 1e-12, "%s %g deg: sum of transmitted (20 terms)", pn, deg);
    CHECK_ABS(sum_t, (1.0 - R) / (1.0 + R), 1e-12 + tail, "%s %g deg: (1-R)/(1+R)", pn, deg);

    /* energy */
    double sum = 0.0;
    for (size_t i = 0; i < res.count; i++)
        sum += res.rays[i].ray.intensity;
    CHECK_REL(res.in, 1.0, 1e-15, "%s %g deg: in", pn, deg);
    CHECK_REL(res.out, sum, 1e-13, "%s %g deg: out = sum I", pn, deg);
    CHECK_ABS(res.absorbed_glass, 0.0, 1e-15, "%s %g deg: lossless glass", pn, deg);
    CHECK_ABS(res.absorbed_rim, 0.0, 1e-15, "%s %g deg: rim never reached", pn, deg);
    CHECK_ABS(res.skipped, 0.0, 1e-15, "%s %g deg: nothing skipped", pn, deg);
    CHECK_REL(res.truncated, T * pow(R, DEPTH - 1), tol_depth(DEPTH), "%s %g deg: truncated = T R^39",
              pn, deg);
    CHECK_ABS(res.out + res.skipped + res.absorbed_glass + res.absorbed_rim + res.truncated, res.in,
              1e-13, "%s %g deg: bookkeeping", pn, deg);
    lp_result_release(&res);
}

int main(void)
{
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_error err;
    memset(&err, 0, sizeof err);
    lp_lens_desc_init(&desc);
    desc.radius1 = 0.0;
    desc.radius2 = 0.0;
    desc.thickness = TH;
    desc.diameter = 1e4;
    lp_glass_init_constant(&desc.glass, NG);
    lp_status st = lp_lens_create(&desc, &lens, &err);
    CHECK(st == LP_OK, "plate creation: %s", err.message);
    if (st == LP_OK) {
        const double angles[3] = {0.0, 30.0, 60.0};
        for (int a = 0; a < 3; a++)
            for (int pol = 0; pol < 2; pol++)
                plate_case(lens, angles[a], pol);
    }
    lp_lens_destroy(lens);
    return check_finish("test_plate");
}
