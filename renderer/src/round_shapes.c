/* round_shapes.c -- cylinder, cone and torus (see round_shapes.h). */
#include <math.h>

#include "round_shapes.h"
#include "support/vec.h"


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
    lp_vec3 ax = v3_sub(cap, base);
    double h = sqrt(v3_dot(ax, ax));
    if (!(h > 0.0))
        return 0;
    ax = (lp_vec3){ax.x / h, ax.y / h, ax.z / h};
    double k = (r2 - r1) / h;
    lp_vec3 w = v3_sub(o, base);
    double ws = v3_dot(w, ax), ds = v3_dot(d, ax);
    lp_vec3 wp = v3_madd(w, ax, -ws), dp = v3_madd(d, ax, -ds);
    double rw = r1 + k * ws;
    double A = v3_dot(dp, dp) - k * k * ds * ds;
    double B = v3_dot(wp, dp) - k * rw * ds;
    double C = v3_dot(wp, wp) - rw * rw;
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
            lp_vec3 pp = v3_madd(wp, dp, s);
            keep(s, v3_madd(pp, ax, -(r1 + k * along) * k), t0, &best, &bn);
        }
    }
    /* the end discs */
    if (!open && ds != 0.0) {
        for (int e = 0; e < 2; e++) {
            double r = e ? r2 : r1, plane = e ? h : 0.0;
            if (!(r > 0.0))
                continue;
            double s = (plane - ws) / ds;
            lp_vec3 pp = v3_madd(wp, dp, s);
            if (v3_dot(pp, pp) <= r * r)
                keep(s, e ? ax : (lp_vec3){-ax.x, -ax.y, -ax.z}, t0, &best, &bn);
        }
    }
    if (!(best < t1))
        return 0;
    *t = best;
    *n = bn;
    return 1;
}

/* c[0] + c[1] t + ... + c[deg] t^deg */
static double poly(const double *c, int deg, double t)
{
    double v = c[deg];
    for (int i = deg - 1; i >= 0; i--)
        v = v * t + c[i];
    return v;
}

/* The root of the polynomial in (a, b) where its sign changes (fa, fb the
 * values at the ends), by bisection to the last bit. */
static double bisect(const double *c, int deg, double a, double b, double fa)
{
    for (int k = 0; k < 200; k++) {
        double m = 0.5 * (a + b);
        if (!(m > a && m < b))
            break;
        double fm = poly(c, deg, m);
        if ((fa <= 0.0) == (fm <= 0.0)) {
            a = m;
            fa = fm;
        } else {
            b = m;
        }
    }
    return 0.5 * (a + b);
}

/* The roots in (lo, hi] where the sign changes, ascending, into r (at most
 * deg): between consecutive roots of the derivative the polynomial is
 * monotonic, so each such piece holds at most one, found by bisection.  A
 * ray that dips into a surface by any amount is caught this way (the dip's
 * bottom is a root of the derivative), where sampling would step over it;
 * a root of even order (an exact tangent) changes no sign and is not one. */
static int sign_changes(const double *c, int deg, double lo, double hi, double *r)
{
    double d[4], cut[6];
    int n = 0, nc = 0;
    if (deg == 1) {
        if (c[1] == 0.0)
            return 0;
        double t = -c[0] / c[1];
        if (t > lo && t <= hi)
            r[n++] = t;
        return n;
    }
    for (int i = 1; i <= deg; i++)
        d[i - 1] = i * c[i];
    cut[nc++] = lo;
    nc += sign_changes(d, deg - 1, lo, hi, cut + 1);
    cut[nc++] = hi;
    double fa = poly(c, deg, lo);
    for (int i = 0; i + 1 < nc; i++) {
        double a = cut[i], b = cut[i + 1], fb = poly(c, deg, b);
        if (b > a && (fa <= 0.0) != (fb <= 0.0))
            r[n++] = bisect(c, deg, a, b, fa);
        fa = fb;
    }
    return n;
}

int rs_torus_hit(double major, double minor, lp_vec3 o, lp_vec3 d, double t0, double t1,
                 double *t, lp_vec3 *n)
{
    double R2 = major * major, r2 = minor * minor, bound = major + minor;
    double dd = v3_dot(d, d), od = v3_dot(o, d), oo = v3_dot(o, o);
    /* the bounding sphere |p| <= major + minor */
    double disc = od * od - dd * (oo - bound * bound);
    if (!(dd > 0.0) || disc < 0.0)
        return 0;
    double sq = sqrt(disc);
    double lo = (-od - sq) / dd, hi = (-od + sq) / dd;
    /* The roots are isolated over the sphere from t0 on, not cut at t1:
     * the hit found does not depend on how near another object is. */
    if (lo < t0)
        lo = t0;
    if (!(lo < hi) || !(lo < t1))
        return 0;
    /* the quartic in s = t - lo, from the point where the ray enters the
     * bounding sphere (no cancellation from a far origin) */
    lp_vec3 q = v3_madd(o, d, lo);
    double qd = v3_dot(q, d), qq = v3_dot(q, q);
    double a2 = dd, a1 = 2.0 * qd, a0 = qq + R2 - r2;
    double b2 = d.x * d.x + d.z * d.z, b1 = 2.0 * (q.x * d.x + q.z * d.z),
           b0 = q.x * q.x + q.z * q.z;
    double c[5] = {a0 * a0 - 4.0 * R2 * b0, 2.0 * a1 * a0 - 4.0 * R2 * b1,
                   a1 * a1 + 2.0 * a2 * a0 - 4.0 * R2 * b2, 2.0 * a2 * a1, a2 * a2};
    double roots[4];
    int nr = sign_changes(c, 4, 0.0, hi - lo, roots);
    for (int i = 0; i < nr; i++) {
        double root = lo + roots[i];
        if (!(root > t0 && root < t1))
            continue;
        lp_vec3 p = v3_madd(o, d, root);
        double g = v3_dot(p, p) + R2 - r2;
        *t = root;
        *n = (lp_vec3){g * p.x - 2.0 * R2 * p.x, g * p.y, g * p.z - 2.0 * R2 * p.z};
        return 1;
    }
    return 0;
}
