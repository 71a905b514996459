/* lanes.h -- the one-ray code's geometry and Fresnel factors, free of
 * branches, for loops over lanes (internal).
 *
 * The lane engines (trace_lanes.c: many forward rays of one wavelength;
 * backward_many.c: one view ray at many wavelengths) keep the state of
 * every lane in arrays and step all lanes at once, in loops the compiler
 * vectorizes.  The functions below are the one-ray code's formulas (cap.h,
 * rim.c, lens.c, interface.c, fresnel.h) with their operations in the same
 * order, so that each lane's numbers are that code's bit for bit, and with
 * its branches turned into selects: every lane computes both sides and
 * keeps one (the files that use them are built with -fno-trapping-math
 * for that).  Flags are ints made of comparisons of doubles and & | only
 * (a select of ints, or an int from memory, stops the vectorizer). */
#ifndef LP_LANES_H
#define LP_LANES_H

#include <math.h>

#include "lens_internal.h"

/* The helpers of the loops over lanes must be inlined, or the loops
 * cannot be vectorized. */
#if defined(__GNUC__)
#define LP__INLINE static inline __attribute__((always_inline))
#else
#define LP__INLINE static inline
#endif

/* The loops over lanes are compiled for the widest vectors of the
 * machine that runs them (AVX-512, AVX2, else the baseline), chosen once
 * when the program loads.  Every copy does the same operations in the
 * same order (the build keeps FP contraction off), so all give the same
 * bits; a build may pin one copy (-DLP__WIDE= for the baseline, or a
 * target attribute) to check it. */
#ifndef LP__WIDE
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define LP__WIDE __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define LP__WIDE
#endif
#endif

/* Lanes per group. */
#define LP__LANES 64

/* A loop over the n lanes of a group, left a loop (not unrolled into
 * lanes of scalar code), so that the vectorizer takes it whole. */
#if defined(__GNUC__)
#define LP__LANE_LOOP(i, n) _Pragma("GCC unroll 1") for (int i = 0; i < (n); i++)
#else
#define LP__LANE_LOOP(i, n) for (int i = 0; i < (n); i++)
#endif

/* The lens as the loops read it (a copy, so that no store to the lanes
 * can be taken to change it). */
typedef struct lp__lane_lens {
    double c[2], z0[2], hh[2], out[2]; /* caps; hh = h^2 (1 + 1e-12) */
    lp__rim r;
    double has_rim; /* 1: r.present, as a number */
    double eps;     /* lens->eps */
    double tol;     /* lp__lens_surface_at's */
    lp_vec3 pos, u, v, w;
} lp__lane_lens;

static inline void lp__lane_lens_of(lp__lane_lens *K, const lp_lens *lens)
{
    for (int s = 0; s < 2; s++) {
        const lp__cap *cap = &lens->cap[s];
        K->c[s] = cap->c;
        K->z0[s] = cap->z0;
        K->hh[s] = cap->h * cap->h * (1.0 + 1e-12);
        K->out[s] = cap->out;
    }
    K->r = lens->rim;
    K->has_rim = lens->rim.present ? 1.0 : 0.0;
    K->eps = lens->eps;
    K->tol = 8.0 * lens->eps;
    K->pos = lens->desc.position;
    K->u = lens->u;
    K->v = lens->v;
    K->w = lens->w;
}

/* lp__to_world_dir, lp__to_world_point */
LP__INLINE lp_vec3 lp__lane_world_dir(const lp__lane_lens *K, lp_vec3 d)
{
    return v3_add(v3_add(v3_scale(K->u, d.x), v3_scale(K->v, d.y)), v3_scale(K->w, d.z));
}

LP__INLINE lp_vec3 lp__lane_world_point(const lp__lane_lens *K, lp_vec3 p)
{
    return v3_add(K->pos, lp__lane_world_dir(K, p));
}

/* lp__cap_on_patch */
LP__INLINE int lp__lane_on_patch(double c, double hh, lp_vec3 x)
{
    double r2 = x.x * x.x + x.y * x.y;
    return !(r2 > hh) & (c * x.z <= 1.0);
}

/* lp__cap_intersect from a point off the cap, t in (t_min, +inf): 1 and
 * *t on a hit.  (Its t_max is applied by the caller: a root the one-ray
 * code refuses for t >= t_max is followed by larger ones only.) */
LP__INLINE int lp__lane_cap_far(double c, double z0, double hh, lp_vec3 p, lp_vec3 d,
                                double t_min, double *t)
{
    lp_vec3 q0 = v3(p.x, p.y, p.z - z0);
    double s0 = -v3_dot(q0, d);
    lp_vec3 q = v3_madd(q0, d, s0);
    double b = c * v3_dot(q, d) - d.z;
    double g = c * v3_dot(q, q) - 2.0 * q.z;
    double disc = b * b - c * g;
    double qq = -(b + copysign(sqrt(disc), b));
    double ra = g / qq, rb = qq / c;
    int va = qq != 0.0, vb = c != 0.0;
    double lo = va ? (vb & (rb < ra) ? rb : ra) : rb;
    double hi = rb < ra ? ra : rb;
    double s1 = s0 + lo, s2 = s0 + hi;
    int real = !(disc < 0.0);
    int ok1 = real & (va | vb) & (s1 > t_min) & (s1 < INFINITY) &
              lp__lane_on_patch(c, hh, v3_madd(q0, d, s1));
    int ok2 = real & va & vb & (s2 > t_min) & (s2 < INFINITY) &
              lp__lane_on_patch(c, hh, v3_madd(q0, d, s2));
    *t = ok1 ? s1 : s2;
    return ok1 | ok2;
}

/* lp__cap_intersect from a point on the cap (on_surface), t > t_min. */
LP__INLINE int lp__lane_cap_self(double c, double z0, double hh, lp_vec3 p, lp_vec3 d,
                                 double t_min, double *t)
{
    lp_vec3 q0 = v3(p.x, p.y, p.z - z0);
    double b = c * v3_dot(q0, d) - d.z;
    double s = -2.0 * b / c;
    *t = s;
    return (c != 0.0) & (s > t_min) & (s < INFINITY) &
           lp__lane_on_patch(c, hh, v3_madd(q0, d, s));
}

/* Could the segment p .. x meet the rim?  lp__rim_intersect refuses
 * every root whose z = p.z + t d.z lies outside the rim's z range (with
 * its slack), and for t between 0 and that of x, z lies between p.z and
 * x.z = p.z + t_x d.z (rounding is monotonic).  So a segment whose ends
 * are both beyond one end of the range cannot: its test is skipped, and
 * the one-ray code's result is the same. */
LP__INLINE int lp__lane_rim_band(const lp__lane_lens *K, lp_vec3 p, lp_vec3 x)
{
    double lo = p.z < x.z ? p.z : x.z, hi = p.z < x.z ? x.z : p.z;
    return !(hi < K->r.z_a - K->r.slack) & !(lo > K->r.z_b + K->r.slack);
}

/* lens.c's inside_rim */
LP__INLINE int lp__lane_inside_rim(const lp__lane_lens *K, lp_vec3 p)
{
    double rho = K->r.rho_a + K->r.k * (p.z - K->r.z_a);
    return (rho > 0.0) & (p.x * p.x + p.y * p.y < rho * rho * (1.0 - 1e-9));
}

/* lp__lens_surface_at(lens, p) != LP_SURFACE_NONE */
LP__INLINE int lp__lane_on_lens(const lp__lane_lens *K, lp_vec3 p)
{
    double tol = K->tol;
    double r2 = p.x * p.x + p.y * p.y;
    double z0 = p.z - K->z0[0], z1 = p.z - K->z0[1];
    double f0 = K->c[0] * (r2 + z0 * z0) - 2.0 * z0;
    double f1 = K->c[1] * (r2 + z1 * z1) - 2.0 * z1;
    double rho = K->r.rho_a + K->r.k * (p.z - K->r.z_a);
    return ((fabs(f0) <= 2.0 * tol) & (r2 <= K->hh[0] + tol) & (K->c[0] * z0 <= 1.0)) |
           ((fabs(f1) <= 2.0 * tol) & (r2 <= K->hh[1] + tol) & (K->c[1] * z1 <= 1.0)) |
           ((K->has_rim != 0.0) & (fabs(sqrt(r2) - rho) <= tol) & (p.z >= K->r.z_a - tol) &
            (p.z <= K->r.z_b + tol));
}

/* lp__cap_normal of cap s (0 or 1, a number) at p. */
LP__INLINE lp_vec3 lp__lane_cap_normal(const lp__lane_lens *K, double s, lp_vec3 p)
{
    int b = s == 1.0;
    double c = b ? K->c[1] : K->c[0], z0 = b ? K->z0[1] : K->z0[0];
    double out = b ? K->out[1] : K->out[0];
    lp_vec3 n = v3(c * p.x, c * p.y, c * (p.z - z0) - 1.0);
    return v3_scale(v3_normalize(n), out);
}

/* The next hit (lp__lens_hit, t in (0, +inf)) of a lane at p on cap surf
 * (0 or 1) going along d inside the lens, but for the rim: *t, the hit
 * point *x, and the cap met (0 or 1; -1 for none).  *rim is set when the
 * rim test could change that (then lp__rim_intersect(rim, p, d, eps, *t)
 * decides). */
LP__INLINE double lp__lane_hit_inside(const lp__lane_lens *K, lp_vec3 p, lp_vec3 d, double surf,
                                      double *t, lp_vec3 *x, int *rim)
{
    /* the cap the lane is on (self, from 0), the other one from eps on */
    int on1 = surf == 1.0, off1 = !on1;
    double ts, to;
    int hself = lp__lane_cap_self(on1 ? K->c[1] : K->c[0], on1 ? K->z0[1] : K->z0[0],
                                  on1 ? K->hh[1] : K->hh[0], p, d, 0.0, &ts);
    int hother = lp__lane_cap_far(on1 ? K->c[0] : K->c[1], on1 ? K->z0[0] : K->z0[1],
                                  on1 ? K->hh[0] : K->hh[1], p, d, K->eps, &to);
    int h0 = (on1 & hother) | (off1 & hself), h1 = (on1 & hself) | (off1 & hother);
    double t0 = on1 ? to : ts, t1 = on1 ? ts : to;
    int b1 = h1 & (!h0 | (t1 < t0));
    int cap = h0 | h1;
    double best = b1 ? t1 : (h0 ? t0 : INFINITY);
    *x = v3_madd(p, d, best);
    *t = best;
    *rim = (K->has_rim != 0.0) &
           !(cap & lp__lane_inside_rim(K, p) & lp__lane_inside_rim(K, *x)) &
           ((cap == 0) | lp__lane_rim_band(K, p, *x));
    return cap ? (b1 ? 1.0 : 0.0) : -1.0;
}

/* The hit (lp__lens_hit from outside the lens, t in (0, +inf)) of a ray
 * at p along d, but for the rim: as lp__lane_hit_inside. */
LP__INLINE double lp__lane_hit_outside(const lp__lane_lens *K, lp_vec3 p, lp_vec3 d, double *t,
                                       lp_vec3 *x, int *rim)
{
    double t0, t1;
    int h0 = lp__lane_cap_far(K->c[0], K->z0[0], K->hh[0], p, d, 0.0, &t0);
    int h1 = lp__lane_cap_far(K->c[1], K->z0[1], K->hh[1], p, d, 0.0, &t1);
    int b1 = h1 & (!h0 | (t1 < t0));
    int cap = h0 | h1;
    double best = b1 ? t1 : (h0 ? t0 : INFINITY);
    *x = v3_madd(p, d, best);
    *t = best;
    *rim = (K->has_rim != 0.0) & ((cap == 0) | lp__lane_rim_band(K, p, *x));
    return cap ? (b1 ? 1.0 : 0.0) : -1.0;
}

/* A node's geometry and Fresnel factors (lp__node_setup, lp__fresnel_eval
 * for n1 != n2): light along d meets the surface of outward normal
 * `normal`, from index n1 into n2, eta = n1/n2.  Under total internal
 * reflection (tir) the factors and t are not the one-ray code's: it
 * takes Rs = Rp = 1 and no transmitted wave. */
typedef struct lp__lane_node {
    lp_vec3 nn;        /* the normal facing the incident side */
    double ci, ct;     /* cosines of incidence and refraction */
    double a, b, c, d; /* n1 ci, n2 ct, n2 ci, n1 ct */
    double is, ip;     /* 1/(a + b), 1/(c + d) */
    double rs, rp;     /* amplitude reflection coefficients */
    double ts, tp;     /* power-normalized transmission amplitudes */
    int tir;
    lp_vec3 t, r;      /* transmitted and reflected directions */
} lp__lane_node;

/* lp__lane_node_at but for the last step: g->t and g->r are left to be
 * normalized (v3_normalize), so that a loop over lanes can do that apart. */
LP__INLINE void lp__lane_node_raw(double n1, double n2, double eta, lp_vec3 d, lp_vec3 normal,
                                  lp__lane_node *g)
{
    double dn = v3_dot(d, normal);
    double adn = fabs(dn);
    g->nn = dn > 0.0 ? v3_neg(normal) : normal;
    double ci = adn < 1.0 ? adn : 1.0;
    double sin2_i = (1.0 - ci) * (1.0 + ci);
    double cos2_t = 1.0 - eta * eta * sin2_i;
    /* no interface at all where the indices are equal: the light goes on
     * (fresnel.h's lp__fresnel_eval: cos t = cos i, ts = tp = 1) */
    int same = n1 == n2;
    double ct = same ? ci : sqrt(cos2_t);
    g->ci = ci;
    g->ct = ct;
    g->tir = !same & (cos2_t < 0.0);
    g->a = n1 * ci, g->b = n2 * ct;
    g->c = n2 * ci, g->d = n1 * ct;
    g->is = 1.0 / (g->a + g->b), g->ip = 1.0 / (g->c + g->d);
    g->rs = (g->a - g->b) * g->is;
    g->rp = (g->c - g->d) * g->ip;
    double gg = 2.0 * sqrt(g->a * g->b); /* 2 sqrt(n1 ci n2 ct) */
    g->ts = same ? 1.0 : gg * g->is;
    g->tp = same ? 1.0 : gg * g->ip;
    g->t = v3_madd(v3_scale(d, eta), g->nn, eta * ci - ct);
    g->r = v3_madd(d, g->nn, 2.0 * ci);
}

LP__INLINE void lp__lane_node_at(double n1, double n2, double eta, lp_vec3 d, lp_vec3 normal,
                                 lp__lane_node *g)
{
    lp__lane_node_raw(n1, n2, eta, d, normal, g);
    g->t = v3_normalize(g->t);
    g->r = v3_normalize(g->r);
}

/* The law of a node: the mode, and for Schlick's the cosine it takes
 * (lp__schlick: the refracted one when n1 > n2).  A constant of each
 * copy of the loops, so that each is free of branches. */
enum { LP__LAW_POLARIZED, LP__LAW_FRESNEL, LP__LAW_SCHLICK_CI, LP__LAW_SCHLICK_CT };

/* The power reflectance of an unpolarized mode (lp__node_reflectance):
 * Schlick's (schlick set) with r0 = ((n1 - n2)/(n1 + n2))^2 and the
 * refracted cosine when use_ct (n1 > n2), or (Rs + Rp)/2; 1 under total
 * internal reflection. */
LP__INLINE double lp__lane_reflectance(int schlick, double r0, int use_ct, const lp__lane_node *g)
{
    double R;
    if (schlick) {
        double m = 1.0 - (use_ct ? g->ct : g->ci);
        double m2 = m * m;
        R = r0 + (1.0 - r0) * m2 * m2 * m;
    } else {
        R = 0.5 * (g->rs * g->rs + g->rp * g->rp);
    }
    return g->tir ? 1.0 : R;
}

/* Schlick's r0 of an interface (lp__schlick's). */
static inline double lp__lane_schlick_r0(double n1, double n2)
{
    double r0 = (n1 - n2) / (n1 + n2);
    return r0 * r0;
}

#endif
