/* test_energy.c -- energy bookkeeping of the forward trace on >= 1e4
 * random rays through random valid lenses of every family (catalog and
 * constant glasses, random media, placements, wavelengths, depths and
 * all three modes), lp_trace_forward_many against single calls,
 * min_weight and LP_SKIP_EXTERNAL_REFLECTION.
 *
 * Checked on every trace: in = out + skipped + absorbed_glass +
 * absorbed_rim + truncated (1e-12 relative), out = the sum of the output
 * intensities, each intensity finite and >= 0, vp unit and perpendicular
 * to dir in polarized mode, 1 <= depth <= max_depth, each output's origin
 * on the cap it names and its direction leaving the glass, the chain's
 * path bits, TIR parts 0/1 on the same ray with phases pi/2 apart
 * (ellipse axes).  A fixed-seed splitmix64 generator makes every failure
 * reproducible; messages carry the seed, lens and ray index.
 *
 * Geometry references (long double) and the Fresnel reflectances are
 * written here; nothing expected comes from the library.
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

/* ------------------------------------------------------------------ */
/* small helpers                                                       */
/* ------------------------------------------------------------------ */

static uint64_t rng_state = 0x1234abcd5678ef01ULL;
static inline uint64_t sm64(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}
static inline double urand(void) { return (double)(sm64() >> 11) * 0x1.0p-53; }
static inline double urange(double a, double b) { return a + (b - a) * urand(); }

static lp_vec3 V(double x, double y, double z) { lp_vec3 v = {x, y, z}; return v; }
static inline lp_vec3 vadd(lp_vec3 a, lp_vec3 b) { return V(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline lp_vec3 vsub(lp_vec3 a, lp_vec3 b) { return V(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline lp_vec3 vscale(lp_vec3 a, double s) { return V(a.x * s, a.y * s, a.z * s); }
static inline double vdot(lp_vec3 a, lp_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline lp_vec3 vcross(lp_vec3 a, lp_vec3 b)
{
    return V(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double vlen(lp_vec3 a) { return sqrt(vdot(a, a)); }
static inline lp_vec3 vnorm(lp_vec3 a) { return vscale(a, 1.0 / vlen(a)); }
static inline int vfinite(lp_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

static inline lp_vec3 rand_unit(void)
{
    for (;;) {
        lp_vec3 v = V(urange(-1, 1), urange(-1, 1), urange(-1, 1));
        double l = vlen(v);
        if (l > 0.1 && l <= 1.0)
            return vscale(v, 1.0 / l);
    }
}

typedef struct { long double x, y, z; } lv3;
static lv3 L3(long double x, long double y, long double z) { lv3 v = {x, y, z}; return v; }
static inline lv3 ladd(lv3 a, lv3 b) { return L3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline lv3 lsub(lv3 a, lv3 b) { return L3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline lv3 lscale(lv3 a, long double s) { return L3(a.x * s, a.y * s, a.z * s); }
static inline long double ldot(lv3 a, lv3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline long double llen(lv3 a) { return sqrtl(ldot(a, a)); }
static inline lv3 lnorm(lv3 a) { return lscale(a, 1.0L / llen(a)); }
static inline lv3 lfrom(lp_vec3 a) { return L3(a.x, a.y, a.z); }
static inline lp_vec3 lto(lv3 a) { return V((double)a.x, (double)a.y, (double)a.z); }

/* A placement: world = P + e1*x + e2*y + A*z (A = the lens axis). */
typedef struct { lp_vec3 P, e1, e2, A; } frame;

static inline frame frame_make(lp_vec3 P, lp_vec3 A)
{
    frame f;
    f.P = P;
    f.A = vnorm(A);
    lp_vec3 h = fabs(f.A.x) < 0.6 ? V(1, 0, 0) : (fabs(f.A.y) < 0.6 ? V(0, 1, 0) : V(0, 0, 1));
    f.e1 = vnorm(vcross(f.A, h));
    f.e2 = vcross(f.A, f.e1);
    return f;
}
static inline frame frame_identity(void) { return frame_make(V(0, 0, 0), V(0, 0, 1)); }
/* local -> world, in long double */
static inline lv3 fw_point(const frame *f, lv3 p)
{
    return L3((long double)f->P.x + f->e1.x * p.x + f->e2.x * p.y + f->A.x * p.z,
              (long double)f->P.y + f->e1.y * p.x + f->e2.y * p.y + f->A.y * p.z,
              (long double)f->P.z + f->e1.z * p.x + f->e2.z * p.y + f->A.z * p.z);
}
static inline lv3 fw_dir(const frame *f, lv3 d)
{
    return L3(f->e1.x * d.x + f->e2.x * d.y + f->A.x * d.z,
              f->e1.y * d.x + f->e2.y * d.y + f->A.y * d.z,
              f->e1.z * d.x + f->e2.z * d.y + f->A.z * d.z);
}
/* world -> local, in long double */
static inline lv3 fl_point(const frame *f, lp_vec3 w)
{
    lv3 d = L3((long double)w.x - f->P.x, (long double)w.y - f->P.y, (long double)w.z - f->P.z);
    return L3(d.x * f->e1.x + d.y * f->e1.y + d.z * f->e1.z,
              d.x * f->e2.x + d.y * f->e2.y + d.z * f->e2.z,
              d.x * f->A.x + d.y * f->A.y + d.z * f->A.z);
}
static inline lv3 fl_dir(const frame *f, lp_vec3 w)
{
    lv3 d = lfrom(w);
    return L3(d.x * f->e1.x + d.y * f->e1.y + d.z * f->e1.z,
              d.x * f->e2.x + d.y * f->e2.y + d.z * f->e2.z,
              d.x * f->A.x + d.y * f->A.y + d.z * f->A.z);
}

static inline int has_word(const char *msg, const char *word)
{
    size_t n = strlen(word);
    for (const char *p = msg; *p; p++) {
        size_t i = 0;
        while (i < n && p[i] && (p[i] | 0x20) == (word[i] | 0x20))
            i++;
        if (i == n)
            return 1;
    }
    return 0;
}

/* ------------------------------------------------------------------ */
/* reference lens geometry, long double, local frame                   */
/* ------------------------------------------------------------------ */

typedef struct {
    long double c1, c2, t, a1, a2, zf, zb, k;
    int rim;
    double size;
} ref_lens;

static inline long double curv(double R) { return (R == 0.0 || isinf(R)) ? 0.0L : 1.0L / (long double)R; }
/* sag(h) = R - sign(R) sqrt(R^2 - h^2), written without cancellation:
 * c h^2 / (1 + sqrt(1 - c^2 h^2)), c = 1/R (0 for flat). */
static inline long double rsag(long double c, long double h)
{
    return c * h * h / (1.0L + sqrtl(1.0L - c * c * h * h));
}

static inline void ref_init(ref_lens *L, double R1, double R2, double t, double D, double D2)
{
    L->c1 = curv(R1);
    L->c2 = curv(R2);
    L->t = t;
    L->a1 = D / 2;
    L->a2 = (D2 > 0 ? D2 : D) / 2;
    L->zf = rsag(L->c1, L->a1);
    L->zb = t + rsag(L->c2, L->a2);
    double zmin = (double)fminl(0.0L, L->zf), zmax = (double)fmaxl(t, L->zb);
    L->size = fmax(fmax(D, D2), zmax - zmin);
    L->rim = (L->zb - L->zf) > 1e-12L * L->size;
    L->k = L->rim ? (L->a2 - L->a1) / (L->zb - L->zf) : 0.0L;
}

typedef struct {
    long double s;
    lv3 p, n;
    int surf;
} ref_hit;

/* roots of A s^2 + 2 B s + C = 0 (stable form) */
static inline int quad_roots(long double A, long double B, long double C, long double r[2])
{
    if (A == 0.0L) {
        if (B == 0.0L)
            return 0;
        r[0] = -C / (2.0L * B);
        return 1;
    }
    long double disc = B * B - A * C;
    if (disc < 0.0L)
        return 0;
    long double q = -(B + copysignl(sqrtl(disc), B));
    if (q == 0.0L) {
        r[0] = 0.0L;
        return 1;
    }
    r[0] = q / A;
    r[1] = C / q;
    return 2;
}

static inline void consider(ref_hit *best, long double s, lv3 p, lv3 n, int surf)
{
    if (best->surf < 0 || s < best->s) {
        best->s = s;
        best->p = p;
        best->n = n;
        best->surf = surf;
    }
}

/* Nearest surface hit of O + s d, s > smin (d unit). surf -1: none. */
static inline ref_hit ref_intersect(const ref_lens *L, lv3 O, lv3 d, long double smin)
{
    ref_hit best;
    best.surf = -1;
    best.s = 0;
    for (int side = 0; side < 2; side++) {
        long double c = side ? L->c2 : L->c1, z0 = side ? L->t : 0.0L, a = side ? L->a2 : L->a1;
        long double Z = O.z - z0;
        long double A = c, B = c * (O.x * d.x + O.y * d.y + Z * d.z) - d.z;
        long double C = c * (O.x * O.x + O.y * O.y + Z * Z) - 2.0L * Z;
        long double r[2];
        int nr = quad_roots(A, B, C, r);
        for (int i = 0; i < nr; i++) {
            if (!(r[i] > smin))
                continue;
            lv3 p = ladd(O, lscale(d, r[i]));
            if (p.x * p.x + p.y * p.y > a * a)
                continue;
            if (c * (p.z - z0) >= 1.0L)
                continue;
            /* outward normal: front +grad G1, back -grad G2 */
            lv3 g = L3(c * p.x, c * p.y, c * (p.z - z0) - 1.0L);
            lv3 n = lnorm(side ? lscale(g, -1.0L) : g);
            consider(&best, r[i], p, n, side ? LP_SURFACE_BACK : LP_SURFACE_FRONT);
        }
    }
    if (L->rim) {
        long double R0 = L->a1 + L->k * (O.z - L->zf);
        long double A = d.x * d.x + d.y * d.y - L->k * L->k * d.z * d.z;
        long double B = O.x * d.x + O.y * d.y - R0 * L->k * d.z;
        long double C = O.x * O.x + O.y * O.y - R0 * R0;
        long double r[2];
        int nr = quad_roots(A, B, C, r);
        for (int i = 0; i < nr; i++) {
            if (!(r[i] > smin))
                continue;
            lv3 p = ladd(O, lscale(d, r[i]));
            if (p.z < L->zf || p.z > L->zb)
                continue;
            long double rr = L->a1 + L->k * (p.z - L->zf);
            lv3 n = lnorm(L3(p.x, p.y, -rr * L->k));
            consider(&best, r[i], p, n, LP_SURFACE_RIM);
        }
    }
    return best;
}

/* Inside test with a margin (a lower bound-ish of the distance to the
 * boundary, vertical for the caps). */
static inline int ref_inside(const ref_lens *L, lv3 p, long double *margin)
{
    long double r = sqrtl(p.x * p.x + p.y * p.y);
    long double rmax = fmaxl(L->a1, L->a2);
    if (r >= rmax) {
        *margin = r - rmax;
        return 0;
    }
    long double lower, upper;
    if (r <= L->a1)
        lower = rsag(L->c1, r);
    else
        lower = L->zf + (r - L->a1) / L->k; /* cone, a2 > a1 */
    if (r <= L->a2)
        upper = L->t + rsag(L->c2, r);
    else
        upper = L->zf + (r - L->a1) / L->k; /* cone, a1 > a2 */
    long double m = fminl(fabsl(p.z - lower), fabsl(p.z - upper));
    m = fminl(m, rmax - r);
    *margin = m;
    return p.z > lower && p.z < upper;
}

/* ------------------------------------------------------------------ */
/* random valid lenses of every family                                 */
/* ------------------------------------------------------------------ */

typedef struct {
    double R1, R2, t, D, D2;
    int family;
} rshape;

static const char *const family_names[] = {
    "biconvex",       "plano-convex",    "convex-plano", "positive meniscus", "negative meniscus",
    "meniscus (R<0)", "plano-concave",   "concave-plano", "biconcave",        "flat plate",
    "knife edge",     "cone narrowing", "cone widening"};

/* sag of a cap of radius R at height h (double; 0 for flat) */
static inline double dsag(double R, double h)
{
    if (R == 0.0 || isinf(R))
        return 0.0;
    return h * h / (R * (1.0 + sqrt(1.0 - (h / R) * (h / R))));
}

/* a radius magnitude with a/|R| in [0.1, 0.95] */
static inline double rad_for(double a) { return a / urange(0.1, 0.95); }

static inline void random_shape(rshape *s)
{
    int fam = (int)(sm64() % 13);
    double D = urange(5, 50), a = D / 2;
    double edge = urand() < 0.1 ? urange(0.005, 0.05) : urange(0.3, 0.3 * D);
    double R1 = INFINITY, R2 = INFINITY, D2 = 0, x, y;
    s->family = fam;
    switch (fam) {
    case 0: R1 = rad_for(a); R2 = -rad_for(a); break;
    case 1: R1 = rad_for(a); R2 = INFINITY; break;
    case 2: R1 = 0; R2 = -rad_for(a); break;
    case 3: x = rad_for(a); y = rad_for(a); R1 = fmin(x, y); R2 = fmax(x, y); break;
    case 4: x = rad_for(a); y = rad_for(a); R1 = fmax(x, y); R2 = fmin(x, y); break;
    case 5: R1 = -rad_for(a); R2 = -rad_for(a); break;
    case 6: R1 = -rad_for(a); R2 = INFINITY; break;
    case 7: R1 = -INFINITY; R2 = rad_for(a); break;
    case 8: R1 = -rad_for(a); R2 = rad_for(a); break;
    case 9: R1 = (sm64() & 1) ? 0.0 : INFINITY; R2 = (sm64() & 1) ? 0.0 : -INFINITY; break;
    case 10: {
        /* exact knife edges: sag(3) = 5 - 4 = 1 for R = 5 and 3.75 - 2.25
         * = 1.5 for R = 3.75, scaled by powers of two (exact) */
        double sc = ldexp(1.0, (int)(sm64() % 5) - 1);
        int v = (int)(sm64() % 3);
        s->D = 6 * sc;
        s->D2 = 0;
        s->R1 = 5 * sc;
        s->R2 = v == 0 ? -5 * sc : (v == 1 ? -3.75 * sc : INFINITY);
        s->t = (v == 0 ? 2 : (v == 1 ? 2.5 : 1)) * sc;
        return;
    }
    case 11:
        R1 = rad_for(a);
        D2 = D * urange(0.5, 0.9);
        R2 = urand() < 0.3 ? INFINITY : -rad_for(D2 / 2);
        break;
    case 12: {
        D2 = D * urange(1.1, 1.6);
        R2 = -rad_for(D2 / 2);
        int v = (int)(sm64() % 3);
        R1 = v == 0 ? rad_for(a) : (v == 1 ? INFINITY : -rad_for(a));
        break;
    }
    }
    double a2 = (D2 > 0 ? D2 : D) / 2;
    s->R1 = R1;
    s->R2 = R2;
    s->D = D;
    s->D2 = D2;
    s->t = fmax(dsag(R1, a) - dsag(R2, a2), 0.0) + edge;
}

static inline lp_lens *make_lens_g(const rshape *s, const lp_glass *glass, const lp_glass *medium,
                                   const frame *f)
{
    lp_lens_desc desc;
    lp_lens_desc_init(&desc);
    desc.radius1 = s->R1;
    desc.radius2 = s->R2;
    desc.thickness = s->t;
    desc.diameter = s->D;
    desc.diameter2 = s->D2;
    if (glass)
        desc.glass = *glass;
    if (medium)
        desc.medium = *medium;
    desc.position = f->P;
    desc.axis = f->A;
    lp_lens *lens = NULL;
    lp_error err;
    lp_status st = lp_lens_create(&desc, &lens, &err);
    CHECK(st == LP_OK, "valid %s lens R1=%.17g R2=%.17g t=%.17g D=%.17g D2=%.17g refused: %s",
          family_names[s->family], s->R1, s->R2, s->t, s->D, s->D2, err.message);
    return st == LP_OK ? lens : NULL;
}

static const char *const builtin_names[] = {"N-BK7", "N-SF11", "F2",  "N-BAK4",
                                            "N-SF6", "FUSED-SILICA", "CAF2"};

/* A random glass: a catalog glass (absorbing) or a constant 1.3..2.0. */
static inline void random_glass(lp_glass *g)
{
    if (sm64() & 1) {
        const char *name = builtin_names[sm64() % (sizeof builtin_names / sizeof builtin_names[0])];
        lp_error err;
        lp_status st = lp_glass_builtin(name, g, &err);
        CHECK(st == LP_OK, "lp_glass_builtin(\"%s\"): %s", name, err.message);
        if (st == LP_OK)
            return;
    }
    lp_glass_init_constant(g, urange(1.3, 2.0));
}

static inline void random_medium(lp_glass *g)
{
    lp_glass_init_constant(g, (sm64() & 1) ? 1.0 : urange(1.0, 1.4));
}

/* A random point on (or near) the lens surface, local frame. */
static inline lv3 random_surface_point(const ref_lens *L, int which)
{
    long double phi = urange(0, 2 * M_PI);
    if (which == 2 && L->rim) {
        long double u = urand();
        long double z = L->zf + u * (L->zb - L->zf), r = L->a1 + u * (L->a2 - L->a1);
        return L3(r * cosl(phi), r * sinl(phi), z);
    }
    int back = which == 1;
    long double a = back ? L->a2 : L->a1, r = sqrtl(urand()) * a;
    long double z = back ? L->t + rsag(L->c2, r) : rsag(L->c1, r);
    return L3(r * cosl(phi), r * sinl(phi), z);
}

/* ------------------------------------------------------------------ */
/* Fresnel, written here (Born & Wolf), long double                    */
/* ------------------------------------------------------------------ */

/* Reflectances at incidence cosine ci from n1 into n2; 1, 1 under TIR. */
static void fresnel_R(long double ci, long double n1, long double n2, long double *Rs,
                      long double *Rp, long double *ct_out)
{
    long double st2 = (n1 / n2) * (n1 / n2) * (1 - ci) * (1 + ci);
    if (st2 >= 1) {
        *Rs = *Rp = 1;
        *ct_out = -1;
        return;
    }
    long double ct = sqrtl(1 - st2);
    long double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    long double rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    *Rs = rs * rs;
    *Rp = rp * rp;
    *ct_out = ct;
}

/* ------------------------------------------------------------------ */

static const uint64_t SEED = 0x5eed0000c0ffeeULL;
static char ctx[256];
static long n_rays_total, n_hits_total, n_leaks, n_tir_pairs, n_rim_rays, n_truncated_rays;
static double worst_balance;

/* distance-like residual of a point from a cap surface (local) */
static long double cap_residual(const ref_lens *L, lv3 p, int back)
{
    long double c = back ? L->c2 : L->c1, z0 = back ? L->t : 0.0L;
    long double Z = p.z - z0;
    long double G = c * (p.x * p.x + p.y * p.y + Z * Z) - 2 * Z;
    long double g = 2 * sqrtl(c * c * (p.x * p.x + p.y * p.y) + (c * Z - 1) * (c * Z - 1));
    return fabsl(G) / g;
}

static lv3 cap_normal(const ref_lens *L, lv3 p, int back)
{
    long double c = back ? L->c2 : L->c1, z0 = back ? L->t : 0.0L;
    lv3 g = L3(c * p.x, c * p.y, c * (p.z - z0) - 1.0L);
    return lnorm(back ? lscale(g, -1.0L) : g);
}

/* expected path bits of the single chain through a lens: node 1 a
 * refraction in, nodes 2..d-1 internal reflections, node d a refraction
 * out; depth 1 is the external reflection */
static uint64_t chain_path(int d) { return d == 1 ? 1u : (((uint64_t)1 << (d - 1)) - 2); }

typedef struct {
    int robust;      /* the reference hit is far from edges and not grazing */
    int surf;        /* its surface */
    long double cos_i;
    lv3 n;           /* local outward normal at the hit */
} ref_entry;

static ref_entry classify(const ref_lens *L, lv3 O, lv3 d)
{
    ref_entry e;
    ref_hit h = ref_intersect(L, O, d, 0.0L);
    e.surf = h.surf;
    e.robust = 0;
    e.cos_i = 0;
    if (h.surf < 0)
        return e;
    e.n = h.n;
    e.cos_i = -ldot(d, h.n);
    long double m = 1e-7L * L->size;
    int ok = e.cos_i > 1e-3L;
    if (h.surf == LP_SURFACE_RIM) {
        ok = ok && h.p.z - L->zf > m && L->zb - h.p.z > m;
    } else {
        long double a = h.surf == LP_SURFACE_BACK ? L->a2 : L->a1;
        ok = ok && sqrtl(h.p.x * h.p.x + h.p.y * h.p.y) < a - m;
    }
    e.robust = ok;
    return e;
}

/* All the per-trace properties. */
static void check_trace(const ref_lens *L, const frame *f, const lp_glass *glass, const lp_ray *in,
                        const lp_trace_args *args, const lp_result *res, const ref_entry *ent)
{
    double I = in->intensity;
    double sum = res->out + res->skipped + res->absorbed_glass + res->absorbed_rim + res->truncated;
    n_rays_total++;
    if (res->warnings & LP_WARN_LEAK)
        n_leaks++;
    CHECK(isfinite(res->in) && isfinite(sum), "%s: bookkeeping not finite", ctx);
    CHECK(res->in >= 0 && res->out >= 0 && res->skipped >= 0 && res->absorbed_glass >= 0 &&
              res->absorbed_rim >= 0 && res->truncated >= 0,
          "%s: negative bookkeeping entry (in %g out %g skip %g glass %g rim %g trunc %g)", ctx,
          res->in, res->out, res->skipped, res->absorbed_glass, res->absorbed_rim, res->truncated);
    if (res->in > 0) {
        n_hits_total++;
        double e = fabs(res->in - sum) / res->in;
        if (e > worst_balance)
            worst_balance = e;
        CHECK_REL(sum, res->in, 1e-12, "%s: in = out + skipped + glass + rim + truncated", ctx);
    } else {
        CHECK(res->count == 0 && sum == 0, "%s: in = 0 but %zu rays / sum %g", ctx, res->count, sum);
    }
    if (res->truncated > 0)
        n_truncated_rays++;
    if (res->absorbed_rim > 0)
        n_rim_rays++;
    if (ent->robust) {
        CHECK_REL(res->in, I, 1e-15, "%s: in = the ray's intensity (robust hit)", ctx);
        if (ent->surf == LP_SURFACE_RIM) {
            CHECK(res->count == 0, "%s: a ray hitting the rim from outside gave %zu rays", ctx,
                  res->count);
            CHECK_REL(res->absorbed_rim, I, 1e-15, "%s: rim hit from outside: absorbed_rim = in", ctx);
        }
    }
    if (glass->n_tau == 0)
        CHECK(res->absorbed_glass <= 1e-15 * res->in, "%s: lossless glass absorbed %g", ctx,
              res->absorbed_glass);
    if (!L->rim && !(res->warnings & LP_WARN_LEAK))
        CHECK(res->absorbed_rim == 0, "%s: knife-edge lens (no rim) absorbed %g at the rim", ctx,
              res->absorbed_rim);

    /* per output ray */
    double out_sum = 0;
    int entry_surface = -1;
    for (size_t i = 0; i < res->count; i++)
        if (res->rays[i].depth == 1)
            entry_surface = res->rays[i].surface;
    if (entry_surface < 0 && ent->robust && ent->surf != LP_SURFACE_RIM)
        entry_surface = ent->surf;
    int per_depth[LP_MAX_DEPTH + 2] = {0};
    int part_mask[LP_MAX_DEPTH + 2] = {0};
    for (size_t i = 0; i < res->count; i++) {
        const lp_out_ray *o = &res->rays[i];
        const lp_ray *r = &o->ray;
        out_sum += r->intensity;
        CHECK(vfinite(r->origin) && vfinite(r->dir) && vfinite(r->vp) && isfinite(r->intensity) &&
                  isfinite(r->op) && isfinite(r->phase),
              "%s: output ray %zu not finite", ctx, i);
        CHECK(r->intensity >= 0, "%s: output ray %zu intensity %g < 0", ctx, i, r->intensity);
        CHECK(r->intensity <= I * (1 + 1e-12), "%s: output ray %zu intensity %g > input %g", ctx, i,
              r->intensity, I);
        CHECK(o->depth >= 1 && o->depth <= args->max_depth, "%s: depth %d outside 1..%d", ctx,
              o->depth, args->max_depth);
        CHECK(o->part == 0 || o->part == 1, "%s: part %d", ctx, o->part);
        CHECK(o->kind == LP_KIND_REFLECT || o->kind == LP_KIND_TRANSMIT, "%s: kind %d", ctx,
              (int)o->kind);
        CHECK(o->surface == LP_SURFACE_FRONT || o->surface == LP_SURFACE_BACK,
              "%s: output surface %d", ctx, o->surface);
        CHECK_ABS(vlen(r->dir), 1.0, 1e-12, "%s: |dir|", ctx);
        CHECK(r->lambda_nm == in->lambda_nm && r->ch == in->ch, "%s: lambda/ch not copied", ctx);
        CHECK(r->op >= in->op - 1e-12, "%s: op %g decreased below the input's %g", ctx, r->op, in->op);
        if (args->mode == LP_MODE_POLARIZED) {
            CHECK_ABS(vlen(r->vp), 1.0, 1e-9, "%s: |vp|", ctx);
            CHECK_ABS(vdot(r->vp, r->dir), 0.0, 1e-9, "%s: vp . dir", ctx);
        }
        if (o->depth >= 1 && o->depth <= LP_MAX_DEPTH) {
            per_depth[o->depth]++;
            part_mask[o->depth] |= 1 << (o->part & 1);
            CHECK(o->path == chain_path(o->depth), "%s: depth %d path %#llx, want %#llx", ctx,
                  o->depth, (unsigned long long)o->path, (unsigned long long)chain_path(o->depth));
        }
        if (o->depth == 1) {
            CHECK(o->kind == LP_KIND_REFLECT, "%s: depth-1 ray is not a reflection", ctx);
            CHECK_ABS(r->op, in->op, 1e-12, "%s: depth-1 reflection adds no optical path", ctx);
        }
        if (entry_surface >= 0 && o->depth >= 2)
            CHECK(o->kind == (o->surface == entry_surface ? LP_KIND_REFLECT : LP_KIND_TRANSMIT),
                  "%s: depth %d kind %d leaving surface %d (entered %d)", ctx, o->depth, (int)o->kind,
                  o->surface, entry_surface);
        /* the origin lies on the named cap and the ray leaves the glass */
        if (o->surface == LP_SURFACE_FRONT || o->surface == LP_SURFACE_BACK) {
            int back = o->surface == LP_SURFACE_BACK;
            lv3 p = fl_point(f, r->origin);
            long double a = back ? L->a2 : L->a1;
            CHECK(cap_residual(L, p, back) <= 1e-9L * L->size, "%s: ray %zu origin %.3Lg off its cap",
                  ctx, i, cap_residual(L, p, back));
            CHECK(sqrtl(p.x * p.x + p.y * p.y) <= a * (1 + 1e-9L), "%s: ray %zu origin outside the cap",
                  ctx, i);
            lv3 n = cap_normal(L, p, back);
            CHECK(ldot(fl_dir(f, r->dir), n) >= -1e-9L, "%s: ray %zu points into the glass", ctx, i);
        }
    }
    if (res->count)
        CHECK_REL(out_sum, res->out, 1e-12, "%s: out = sum of output intensities", ctx);
    else
        CHECK(res->out == 0, "%s: out %g with no rays", ctx, res->out);
    for (int d = 1; d <= args->max_depth && d <= LP_MAX_DEPTH; d++) {
        CHECK(per_depth[d] <= 2, "%s: %d rays at depth %d (one chain, at most two TIR parts)", ctx,
              per_depth[d], d);
        if (per_depth[d] == 2)
            CHECK(part_mask[d] == 3, "%s: two rays at depth %d are not parts 0 and 1", ctx, d);
    }
    /* TIR pairs: the same ray, parts 0/1 along the ellipse axes, so
     * their total phases differ by pi/2 modulo pi */
    for (size_t i = 0; i < res->count; i++) {
        const lp_out_ray *p1 = &res->rays[i];
        if (p1->part != 1)
            continue;
        const lp_out_ray *p0 = NULL;
        for (size_t j = 0; j < res->count; j++)
            if (res->rays[j].part == 0 && res->rays[j].depth == p1->depth &&
                res->rays[j].kind == p1->kind && res->rays[j].path == p1->path)
                p0 = &res->rays[j];
        CHECK(p0 != NULL, "%s: part 1 at depth %d without its part 0", ctx, p1->depth);
        if (!p0)
            continue;
        n_tir_pairs++;
        CHECK(p0->surface == p1->surface &&
                  vlen(vsub(p0->ray.origin, p1->ray.origin)) <= 1e-12 * L->size &&
                  vlen(vsub(p0->ray.dir, p1->ray.dir)) <= 1e-12,
              "%s: TIR parts at depth %d are not the same ray", ctx, p1->depth);
        if (args->mode == LP_MODE_POLARIZED) {
            double I0 = p0->ray.intensity, I1 = p1->ray.intensity;
            if (fmin(I0, I1) > 1e-9 * (I0 + I1)) {
                double dphi = 2 * M_PI * (p1->ray.op - p0->ray.op) / in->lambda_nm * 1e6 -
                              M_PI * (p1->ray.kphi - p0->ray.kphi) + (p1->ray.phase - p0->ray.phase);
                double m = fmod(dphi, M_PI);
                if (m < 0)
                    m += M_PI;
                CHECK_ABS(m, M_PI / 2, 1e-9, "%s: TIR parts' phase difference mod pi (ellipse axes)",
                          ctx);
            }
        }
    }
}

static void make_ray(lp_ray *in, lp_vec3 origin, lp_vec3 dir)
{
    memset(in, 0, sizeof *in);
    in->origin = origin;
    in->dir = dir;
    lp_vec3 vp;
    do {
        vp = rand_unit();
    } while (vlen(vcross(vp, dir)) < 0.1);
    in->vp = vp;
    in->lambda_nm = urange(380, 780);
    in->intensity = urange(0.1, 10);
    in->op = urange(0, 5);
    in->kphi = (int)(sm64() % 4);
    in->phase = urange(-3, 3);
    in->ch = sm64();
}

/* A random ray aimed near a random lens point, from outside. */
static void random_ray(const ref_lens *L, const frame *f, lp_ray *in)
{
    int which = (int)(sm64() % 10);
    lv3 T;
    if (which < 4)
        T = random_surface_point(L, 0);
    else if (which < 8)
        T = random_surface_point(L, 1);
    else
        T = random_surface_point(L, 2);
    if (sm64() % 4 == 0) /* some misses and grazing rays */
        T = ladd(T, lscale(lfrom(rand_unit()), 0.05L * L->size * urand()));
    lp_vec3 dir = rand_unit();
    lv3 O = lsub(T, lscale(lfrom(dir), 2.0L * L->size));
    make_ray(in, lto(fw_point(f, O)), lto(fw_dir(f, lfrom(dir))));
}

static void test_random_bookkeeping(void)
{
    const int n_lenses = 200, rays_per_lens = 60;
    int fam_count[13] = {0};
    long mode_count[3] = {0};
    lp_result res;
    lp_result_init(&res);
    printf("test_energy: seed %#llx, %d lenses x %d rays\n", (unsigned long long)SEED, n_lenses,
           rays_per_lens);
    for (int li = 0; li < n_lenses; li++) {
        rng_state = SEED + (uint64_t)li * 0x2545F4914F6CDD1DULL;
        rshape s;
        random_shape(&s);
        fam_count[s.family]++;
        lp_glass glass, medium;
        random_glass(&glass);
        random_medium(&medium);
        frame f = frame_make(V(urange(-100, 100), urange(-100, 100), urange(-100, 100)), rand_unit());
        ref_lens L;
        ref_init(&L, s.R1, s.R2, s.t, s.D, s.D2);
        lp_lens *lens = make_lens_g(&s, &glass, &medium, &f);
        if (!lens)
            continue;
        for (int ri = 0; ri < rays_per_lens; ri++) {
            snprintf(ctx, sizeof ctx, "[seed %#llx lens %d (%s, %s in n=%g) ray %d]",
                     (unsigned long long)SEED, li, family_names[s.family], glass.name,
                     lp_glass_index(&medium, 550), ri);
            lp_ray in;
            random_ray(&L, &f, &in);
            lp_trace_args args;
            lp_trace_args_init(&args);
            args.mode = (lp_mode)(sm64() % 3);
            args.max_depth = 1 + (int)(sm64() % 20);
            mode_count[args.mode]++;
            lv3 Ol = fl_point(&f, in.origin), dl = lnorm(fl_dir(&f, in.dir));
            ref_entry ent = classify(&L, Ol, dl);
            lp_error err;
            lp_status st = lp_trace_forward(lens, &in, &args, &res, &err);
            CHECK(st == LP_OK, "%s: trace status %d: %s", ctx, (int)st, err.message);
            if (st != LP_OK)
                continue;
            check_trace(&L, &f, &glass, &in, &args, &res, &ent);
        }
        lp_lens_destroy(lens);
    }
    lp_result_release(&res);
    printf("test_energy: %ld rays, %ld hit the lens, %ld reached the rim, %ld truncated, %ld TIR part "
           "pairs, %ld with LP_WARN_LEAK; worst balance %.3g\n",
           n_rays_total, n_hits_total, n_rim_rays, n_truncated_rays, n_tir_pairs, n_leaks,
           worst_balance);
    printf("test_energy: modes polarized %ld fresnel %ld schlick %ld; families:", mode_count[0],
           mode_count[1], mode_count[2]);
    for (int i = 0; i < 13; i++)
        printf(" %s=%d", family_names[i], fam_count[i]);
    printf("\n");
    CHECK(n_rays_total >= 10000, "at least 1e4 rays traced (%ld)", n_rays_total);
    CHECK(n_hits_total >= 5000, "enough rays hit a lens (%ld)", n_hits_total);
    CHECK(n_rim_rays > 100 && n_truncated_rays > 100 && n_tir_pairs > 10,
          "the sample reaches the rim, truncation and TIR");
}

/* lp_trace_forward_many == single calls */
static void test_many(void)
{
    rng_state = SEED ^ 0x77;
    for (int rep = 0; rep < 4; rep++) {
        rshape s;
        random_shape(&s);
        lp_glass glass, medium;
        random_glass(&glass);
        random_medium(&medium);
        frame f = frame_make(V(urange(-10, 10), urange(-10, 10), urange(-10, 10)), rand_unit());
        ref_lens L;
        ref_init(&L, s.R1, s.R2, s.t, s.D, s.D2);
        lp_lens *lens = make_lens_g(&s, &glass, &medium, &f);
        if (!lens)
            continue;
        enum { N = 1000 };
        static lp_ray rays[N];
        static size_t offsets[N + 1];
        for (int i = 0; i < N; i++)
            random_ray(&L, &f, &rays[i]);
        lp_trace_args args;
        lp_trace_args_init(&args);
        args.mode = (lp_mode)(rep % 3);
        args.max_depth = 4 + 3 * rep;
        lp_result many, one;
        lp_result_init(&many);
        lp_result_init(&one);
        lp_error err;
        lp_status st = lp_trace_forward_many(lens, rays, N, &args, &many, offsets, &err);
        CHECK(st == LP_OK, "forward_many status %d: %s", (int)st, err.message);
        if (st != LP_OK) {
            lp_lens_destroy(lens);
            continue;
        }
        double in = 0, out = 0, skipped = 0, ag = 0, ar = 0, tr = 0, worst = 0;
        int mismatches = 0;
        CHECK(offsets[0] == 0 && offsets[N] == many.count, "forward_many offsets span the rays");
        for (int i = 0; i < N; i++) {
            lp_trace_forward(lens, &rays[i], &args, &one, NULL);
            in += one.in;
            out += one.out;
            skipped += one.skipped;
            ag += one.absorbed_glass;
            ar += one.absorbed_rim;
            tr += one.truncated;
            size_t n = offsets[i + 1] - offsets[i];
            if (n != one.count) {
                mismatches++;
                continue;
            }
            for (size_t k = 0; k < n; k++) {
                const lp_out_ray *a = &many.rays[offsets[i] + k], *b = &one.rays[k];
                if (a->depth != b->depth || a->kind != b->kind || a->surface != b->surface ||
                    a->part != b->part || a->path != b->path || a->ray.kphi != b->ray.kphi ||
                    a->ray.ch != b->ray.ch) {
                    mismatches++;
                    continue;
                }
                double e = fabs(a->ray.intensity - b->ray.intensity) / fmax(b->ray.intensity, 1e-300);
                e = fmax(e, vlen(vsub(a->ray.origin, b->ray.origin)) / L.size);
                e = fmax(e, vlen(vsub(a->ray.dir, b->ray.dir)));
                e = fmax(e, vlen(vsub(a->ray.vp, b->ray.vp)));
                e = fmax(e, fabs(a->ray.op - b->ray.op) / fmax(1, fabs(b->ray.op)));
                e = fmax(e, fabs(a->ray.phase - b->ray.phase));
                if (b->ray.intensity == 0 && a->ray.intensity == 0)
                    e = fmax(e, 0);
                if (e > worst)
                    worst = e;
            }
        }
        CHECK(mismatches == 0, "forward_many rep %d: %d rays differ from single calls", rep, mismatches);
        CHECK_ABS(worst, 0.0, 1e-14, "forward_many rep %d: ray fields vs single calls", rep);
        CHECK_REL(many.in, in, 1e-12, "forward_many: in = sum of single calls");
        CHECK_REL(many.out, out, 1e-12, "forward_many: out = sum of single calls");
        CHECK_ABS(many.skipped - skipped, 0.0, 1e-12 * in, "forward_many: skipped");
        CHECK_ABS(many.absorbed_glass - ag, 0.0, 1e-12 * in, "forward_many: absorbed_glass");
        CHECK_ABS(many.absorbed_rim - ar, 0.0, 1e-12 * in, "forward_many: absorbed_rim");
        CHECK_ABS(many.truncated - tr, 0.0, 1e-12 * in, "forward_many: truncated");
        CHECK_REL(many.out + many.skipped + many.absorbed_glass + many.absorbed_rim + many.truncated,
                  many.in, 1e-12, "forward_many: summed bookkeeping balances");
        /* an invalid ray (vp parallel to dir) is reported by index */
        rays[5].vp = rays[5].dir;
        memset(&err, 0, sizeof err);
        st = lp_trace_forward_many(lens, rays, N, &args, &many, offsets, &err);
        CHECK(st != LP_OK, "forward_many with vp parallel to dir at ray 5 accepted");
        CHECK(has_word(err.message, "5"), "forward_many error message \"%s\" names ray 5", err.message);
        lp_result_release(&many);
        lp_result_release(&one);
        lp_lens_destroy(lens);
    }
}

/* min_weight stops the chain early; the bookkeeping still balances. */
static void test_min_weight(void)
{
    lp_lens_desc desc;
    lp_lens_desc_init(&desc);
    desc.radius1 = 50;
    desc.radius2 = -50;
    desc.thickness = 8;
    desc.diameter = 25;
    lp_glass_init_constant(&desc.glass, 1.5);
    lp_lens *lens = NULL;
    CHECK(lp_lens_create(&desc, &lens, NULL) == LP_OK, "min_weight lens");
    if (!lens)
        return;
    for (int k = 0; k < 20; k++) {
        lp_ray in;
        lp_vec3 d = vnorm(V(urange(-0.05, 0.05), urange(-0.05, 0.05), 1));
        make_ray(&in, V(urange(-3, 3), urange(-3, 3), -20), d);
        in.op = 0;
        lp_trace_args args;
        lp_trace_args_init(&args);
        args.mode = (lp_mode)(k % 3);
        args.max_depth = 20;
        lp_result full, cut;
        lp_result_init(&full);
        lp_result_init(&cut);
        lp_trace_forward(lens, &in, &args, &full, NULL);
        args.min_weight = 1e-3;
        lp_trace_forward(lens, &in, &args, &cut, NULL);
        int dfull = 0, dcut = 0;
        for (size_t i = 0; i < full.count; i++)
            dfull = full.rays[i].depth > dfull ? full.rays[i].depth : dfull;
        for (size_t i = 0; i < cut.count; i++)
            dcut = cut.rays[i].depth > dcut ? cut.rays[i].depth : dcut;
        /* near-normal: internal power after j internal reflections is
         * ~ 0.96 * 0.04^j, below 1e-3 from j = 3 on: the chain ends by
         * depth 5, while without a cut it runs to depth 20 */
        CHECK(dfull == 20, "min_weight 0: chain reaches max_depth 20 (got %d)", dfull);
        CHECK(dcut >= 2 && dcut <= 6, "min_weight 1e-3: chain stops early (depth %d)", dcut);
        CHECK(cut.count < full.count, "min_weight 1e-3: fewer rays (%zu vs %zu)", cut.count, full.count);
        CHECK_REL(cut.out + cut.skipped + cut.absorbed_glass + cut.absorbed_rim + cut.truncated, cut.in,
                  1e-12, "min_weight 1e-3: bookkeeping");
        CHECK_REL(cut.in, in.intensity, 1e-15, "min_weight: in");
        CHECK(cut.truncated > 0 && cut.truncated < 2e-3 * cut.in,
              "min_weight 1e-3: truncated %g is the cut branch (< 2e-3 in)", cut.truncated / cut.in);
        /* every ray of the cut trace is a ray of the full trace */
        int missing = 0;
        for (size_t i = 0; i < cut.count; i++) {
            int found = 0;
            for (size_t j = 0; j < full.count && !found; j++)
                found = full.rays[j].depth == cut.rays[i].depth &&
                        full.rays[j].part == cut.rays[i].part &&
                        fabs(full.rays[j].ray.intensity - cut.rays[i].ray.intensity) <=
                            1e-12 * full.rays[j].ray.intensity;
            missing += !found;
        }
        CHECK(missing == 0, "min_weight: %d rays of the cut trace are not in the full trace", missing);
        lp_result_release(&full);
        lp_result_release(&cut);
    }
    lp_lens_destroy(lens);
}

/* LP_SKIP_EXTERNAL_REFLECTION: the depth-1 ray goes to `skipped`; its
 * intensity follows Fresnel's equations (computed here). */
static void test_skip_external(void)
{
    rng_state = SEED ^ 0x5151;
    int checked_fresnel = 0;
    for (int rep = 0; rep < 40; rep++) {
        rshape s;
        random_shape(&s);
        lp_glass glass, medium;
        double ng = urange(1.3, 2.0), nm = (rep & 1) ? 1.0 : urange(1.0, 1.4);
        lp_glass_init_constant(&glass, ng);
        lp_glass_init_constant(&medium, nm);
        frame f = frame_make(V(urange(-10, 10), urange(-10, 10), urange(-10, 10)), rand_unit());
        ref_lens L;
        ref_init(&L, s.R1, s.R2, s.t, s.D, s.D2);
        lp_lens *lens = make_lens_g(&s, &glass, &medium, &f);
        if (!lens)
            continue;
        for (int ri = 0; ri < 30; ri++) {
            snprintf(ctx, sizeof ctx, "[skip-external rep %d ray %d, %s]", rep, ri,
                     family_names[s.family]);
            lp_ray in;
            random_ray(&L, &f, &in);
            lp_trace_args args;
            lp_trace_args_init(&args);
            args.mode = (lp_mode)(ri % 3);
            args.max_depth = 6;
            lp_result a, b;
            lp_result_init(&a);
            lp_result_init(&b);
            lp_trace_forward(lens, &in, &args, &a, NULL);
            args.flags = LP_SKIP_EXTERNAL_REFLECTION;
            lp_trace_forward(lens, &in, &args, &b, NULL);
            double r1 = 0;
            size_t n1 = 0;
            const lp_out_ray *refl = NULL;
            for (size_t i = 0; i < a.count; i++)
                if (a.rays[i].depth == 1) {
                    r1 += a.rays[i].ray.intensity;
                    n1++;
                    refl = &a.rays[i];
                }
            for (size_t i = 0; i < b.count; i++)
                CHECK(b.rays[i].depth != 1, "%s: depth-1 ray present despite the flag", ctx);
            CHECK(b.count + n1 == a.count, "%s: flag removed %zu rays, want %zu", ctx,
                  a.count - b.count, n1);
            CHECK_ABS(b.skipped - a.skipped, r1, 1e-12 * fmax(a.in, 1e-300),
                      "%s: skipped = the depth-1 intensity", ctx);
            CHECK_REL(b.in, a.in, 1e-15, "%s: in unchanged by the flag", ctx);
            if (b.in > 0)
                CHECK_REL(b.out + b.skipped + b.absorbed_glass + b.absorbed_rim + b.truncated, b.in,
                          1e-12, "%s: bookkeeping with the flag", ctx);
            /* Fresnel at the entry node, computed here */
            lv3 Ol = fl_point(&f, in.origin), dl = lnorm(fl_dir(&f, in.dir));
            ref_entry ent = classify(&L, Ol, dl);
            if (refl && ent.robust && ent.surf != LP_SURFACE_RIM && ent.cos_i > 0.01L) {
                long double Rs, Rp, ct;
                fresnel_R(ent.cos_i, nm, ng, &Rs, &Rp, &ct);
                long double R;
                if (args.mode == LP_MODE_POLARIZED) {
                    lv3 v = fl_dir(&f, in.vp);
                    v = lnorm(lsub(v, lscale(dl, ldot(v, dl))));
                    lv3 sx = L3(dl.y * ent.n.z - dl.z * ent.n.y, dl.z * ent.n.x - dl.x * ent.n.z,
                                dl.x * ent.n.y - dl.y * ent.n.x);
                    long double as2 = llen(sx) > 1e-9L ? powl(ldot(v, lnorm(sx)), 2) : 1.0L;
                    R = Rs * as2 + Rp * (1 - as2);
                } else if (args.mode == LP_MODE_FRESNEL) {
                    R = (Rs + Rp) / 2;
                } else {
                    long double R0 = powl((nm - ng) / (nm + ng), 2);
                    long double c = nm <= ng ? ent.cos_i : ct;
                    R = ct < 0 ? 1.0L : R0 + (1 - R0) * powl(1 - c, 5);
                }
                CHECK_ABS(r1 / in.intensity, (double)R, 1e-12 + 1e-10 * (double)R,
                          "%s: depth-1 reflectance vs Fresnel (mode %d)", ctx, (int)args.mode);
                lv3 dr = ladd(dl, lscale(ent.n, 2 * ent.cos_i));
                CHECK_ABS((double)llen(lsub(fl_dir(&f, refl->ray.dir), dr)), 0.0, 1e-12,
                          "%s: depth-1 direction = mirror of the incident", ctx);
                checked_fresnel++;
            }
            lp_result_release(&a);
            lp_result_release(&b);
        }
        lp_lens_destroy(lens);
    }
    CHECK(checked_fresnel > 200, "depth-1 Fresnel checked on %d rays", checked_fresnel);
}

int main(void)
{
    test_random_bookkeeping();
    test_many();
    test_min_weight();
    test_skip_external();
    return check_finish("test_energy");
}
