/* round_shapes.c -- cylinder, cone and torus (see round_shapes.h). */
#include <math.h>

#include "round_shapes.h"

static double dot(lp_vec3 a, lp_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static lp_vec3 sub(lp_vec3 a, lp_vec3 b) { return (lp_vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static lp_vec3 madd(lp_vec3 a, lp_vec3 b, double s)
{
    return (lp_vec3){a.x + s * b.x, a.y + s * b.y, a.z + s * b.z};
}

/* Keep the candidate s if it is nearer than *best. */
static void keep(double s, lp_vec3 ns, double t0, double *best, lp_vec3 *n)
{
    if (s > t0 && s < *best) {
        *best = s;
        *n = ns;
    }
}

int rs_cone_hit(lp_vec3 base, double r1, lp_vec3 cap, double r2, int open, lp_vec3 o,
                lp_vec3 d, double t0, double t1, double *t, lp_vec3 *n)
{
    lp_vec3 ax = sub(cap, base);
    double h = sqrt(dot(ax, ax));
    if (!(h > 0.0))
        return 0;
    ax = (lp_vec3){ax.x / h, ax.y / h, ax.z / h};
    double k = (r2 - r1) / h;
    lp_vec3 w = sub(o, base);
    double ws = dot(w, ax), ds = dot(d, ax);
    lp_vec3 wp = madd(w, ax, -ws), dp = madd(d, ax, -ds);
    double rw = r1 + k * ws;
    double A = dot(dp, dp) - k * k * ds * ds;
    double B = dot(wp, dp) - k * rw * ds;
    double C = dot(wp, wp) - rw * rw;
    double best = t1;
    lp_vec3 bn = {0, 0, 0};

    /* the side: A t^2 + 2 B t + C = 0 */
    double disc = B * B - A * C;
    if (A != 0.0 && disc >= 0.0) {
        double q = -(B + copysign(sqrt(disc), B));
        double roots[2] = {q != 0.0 ? C / q : -B / A, q / A};
        if (q == 0.0)
            roots[1] = roots[0];
        for (int i = 0; i < 2; i++) {
            double s = roots[i], along = ws + s * ds;
            if (!(along >= 0.0 && along <= h) || !(r1 + k * along >= 0.0))
                continue;
            lp_vec3 pp = madd(wp, dp, s);
            keep(s, madd(pp, ax, -(r1 + k * along) * k), t0, &best, &bn);
        }
    }
    /* the end discs */
    if (!open && ds != 0.0) {
        for (int e = 0; e < 2; e++) {
            double r = e ? r2 : r1, plane = e ? h : 0.0;
            if (!(r > 0.0))
                continue;
            double s = (plane - ws) / ds;
            lp_vec3 pp = madd(wp, dp, s);
            if (dot(pp, pp) <= r * r)
                keep(s, e ? ax : (lp_vec3){-ax.x, -ax.y, -ax.z}, t0, &best, &bn);
        }
    }
    if (!(best < t1))
        return 0;
    *t = best;
    *n = bn;
    return 1;
}

static double quartic(const double c[5], double t)
{
    return (((c[4] * t + c[3]) * t + c[2]) * t + c[1]) * t + c[0];
}

int rs_torus_hit(double major, double minor, lp_vec3 o, lp_vec3 d, double t0, double t1,
                 double *t, lp_vec3 *n)
{
    double R2 = major * major, r2 = minor * minor, bound = major + minor;
    double dd = dot(d, d), od = dot(o, d), oo = dot(o, o);
    /* the bounding sphere |p| <= major + minor */
    double disc = od * od - dd * (oo - bound * bound);
    if (!(dd > 0.0) || disc < 0.0)
        return 0;
    double sq = sqrt(disc);
    double lo = (-od - sq) / dd, hi = (-od + sq) / dd;
    /* The samples span the sphere from t0 on, not cut at t1: the hit found
     * does not depend on how near another object is. */
    if (lo < t0)
        lo = t0;
    if (!(lo < hi) || !(lo < t1))
        return 0;
    double a2 = dd, a1 = 2.0 * od, a0 = oo + R2 - r2;
    double b2 = d.x * d.x + d.z * d.z, b1 = 2.0 * (o.x * d.x + o.z * d.z),
           b0 = o.x * o.x + o.z * o.z;
    double c[5] = {a0 * a0 - 4.0 * R2 * b0, 2.0 * a1 * a0 - 4.0 * R2 * b1,
                   a1 * a1 + 2.0 * a2 * a0 - 4.0 * R2 * b2, 2.0 * a2 * a1, a2 * a2};
    double step = minor / 16.0 / sqrt(dd);
    int steps = (int)fmin(4096.0, ceil((hi - lo) / step));
    if (steps < 8)
        steps = 8;
    double prev_t = lo, prev_f = quartic(c, lo);
    for (int i = 1; i <= steps; i++) {
        double s = lo + (hi - lo) * i / steps, f = quartic(c, s);
        if ((prev_f <= 0.0) != (f <= 0.0) && !(prev_t == lo && prev_f == 0.0)) {
            double a = prev_t, b = s, fa = prev_f;
            for (int k = 0; k < 80 && b - a > 1e-15 * (1.0 + fabs(b)); k++) {
                double m = 0.5 * (a + b), fm = quartic(c, m);
                if ((fa <= 0.0) == (fm <= 0.0)) {
                    a = m;
                    fa = fm;
                } else {
                    b = m;
                }
            }
            double root = 0.5 * (a + b);
            if (!(root > t0))
                root = b;
            if (!(root < t1))
                return 0;
            lp_vec3 p = madd(o, d, root);
            double g = dot(p, p) + R2 - r2;
            *t = root;
            *n = (lp_vec3){g * p.x - 2.0 * R2 * p.x, g * p.y, g * p.z - 2.0 * R2 * p.z};
            return 1;
        }
        prev_t = s;
        prev_f = f;
    }
    return 0;
}
