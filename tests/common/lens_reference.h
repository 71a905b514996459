/* lens_reference.h -- an independent reference for the lens tests.
 *
 * Shared by the property tests (energy, reciprocity, rim): a fixed-seed
 * PRNG (splitmix64), small vector helpers, a reference lens in ref_real
 * (binary128 where available, see ref_real.h; Spencer & Murty caps,
 * cylinder/cone rim) with its own intersector and inside test written
 * from the geometry alone, and random valid lenses of every classical
 * family.  Nothing here calls the code under test except to create the
 * lens the reference describes.  Include after check.h and lensprim.h. */
#ifndef LP_TEST_LENS_REFERENCE_H
#define LP_TEST_LENS_REFERENCE_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lensprim.h"
#include "ref_real.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

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

typedef struct { ref_real x, y, z; } lv3;
static lv3 L3(ref_real x, ref_real y, ref_real z) { lv3 v = {x, y, z}; return v; }
static inline lv3 ladd(lv3 a, lv3 b) { return L3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline lv3 lsub(lv3 a, lv3 b) { return L3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline lv3 lscale(lv3 a, ref_real s) { return L3(a.x * s, a.y * s, a.z * s); }
static inline ref_real ldot(lv3 a, lv3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline ref_real llen(lv3 a) { return ref_sqrt(ldot(a, a)); }
static inline lv3 lnorm(lv3 a) { return lscale(a, REF(1.0) / llen(a)); }
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
/* local -> world, in ref_real */
static inline lv3 fw_point(const frame *f, lv3 p)
{
    return L3((ref_real)f->P.x + f->e1.x * p.x + f->e2.x * p.y + f->A.x * p.z,
              (ref_real)f->P.y + f->e1.y * p.x + f->e2.y * p.y + f->A.y * p.z,
              (ref_real)f->P.z + f->e1.z * p.x + f->e2.z * p.y + f->A.z * p.z);
}
static inline lv3 fw_dir(const frame *f, lv3 d)
{
    return L3(f->e1.x * d.x + f->e2.x * d.y + f->A.x * d.z,
              f->e1.y * d.x + f->e2.y * d.y + f->A.y * d.z,
              f->e1.z * d.x + f->e2.z * d.y + f->A.z * d.z);
}
/* world -> local, in ref_real */
static inline lv3 fl_point(const frame *f, lp_vec3 w)
{
    lv3 d = L3((ref_real)w.x - f->P.x, (ref_real)w.y - f->P.y, (ref_real)w.z - f->P.z);
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
/* reference lens geometry, ref_real, local frame                      */
/* ------------------------------------------------------------------ */

typedef struct {
    ref_real c1, c2, t, a1, a2, zf, zb, k;
    int rim;
    double size;
} ref_lens;

static inline ref_real curv(double R)
{
    return (R == 0.0 || isinf(R)) ? REF(0.0) : REF(1.0) / (ref_real)R;
}
/* sag(h) = R - sign(R) sqrt(R^2 - h^2), written without cancellation:
 * c h^2 / (1 + sqrt(1 - c^2 h^2)), c = 1/R (0 for flat). */
static inline ref_real rsag(ref_real c, ref_real h)
{
    return c * h * h / (REF(1.0) + ref_sqrt(REF(1.0) - c * c * h * h));
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
    double zmin = (double)ref_fmin(REF(0.0), L->zf), zmax = (double)ref_fmax(t, L->zb);
    L->size = fmax(fmax(D, D2), zmax - zmin);
    L->rim = (L->zb - L->zf) > REF(1e-12) * L->size;
    L->k = L->rim ? (L->a2 - L->a1) / (L->zb - L->zf) : REF(0.0);
}

typedef struct {
    ref_real s;
    lv3 p, n;
    int surf;
} ref_hit;


static inline void consider(ref_hit *best, ref_real s, lv3 p, lv3 n, int surf)
{
    if (best->surf < 0 || s < best->s) {
        best->s = s;
        best->p = p;
        best->n = n;
        best->surf = surf;
    }
}

/* Nearest surface hit of O + s d, s > smin (d unit). surf -1: none. */
static inline ref_hit ref_intersect(const ref_lens *L, lv3 O, lv3 d, ref_real smin)
{
    ref_hit best;
    best.surf = -1;
    best.s = 0;
    for (int side = 0; side < 2; side++) {
        ref_real c = side ? L->c2 : L->c1, z0 = side ? L->t : REF(0.0), a = side ? L->a2 : L->a1;
        ref_real Z = O.z - z0;
        ref_real A = c, B = c * (O.x * d.x + O.y * d.y + Z * d.z) - d.z;
        ref_real C = c * (O.x * O.x + O.y * O.y + Z * Z) - REF(2.0) * Z;
        ref_real r[2];
        int nr = ref_quad_roots(A, B, C, r);
        for (int i = 0; i < nr; i++) {
            if (!(r[i] > smin))
                continue;
            lv3 p = ladd(O, lscale(d, r[i]));
            if (p.x * p.x + p.y * p.y > a * a)
                continue;
            if (c * (p.z - z0) >= REF(1.0))
                continue;
            /* outward normal: front +grad G1, back -grad G2 */
            lv3 g = L3(c * p.x, c * p.y, c * (p.z - z0) - REF(1.0));
            lv3 n = lnorm(side ? lscale(g, -REF(1.0)) : g);
            consider(&best, r[i], p, n, side ? LP_SURFACE_BACK : LP_SURFACE_FRONT);
        }
    }
    if (L->rim) {
        ref_real R0 = L->a1 + L->k * (O.z - L->zf);
        ref_real A = d.x * d.x + d.y * d.y - L->k * L->k * d.z * d.z;
        ref_real B = O.x * d.x + O.y * d.y - R0 * L->k * d.z;
        ref_real C = O.x * O.x + O.y * O.y - R0 * R0;
        ref_real r[2];
        int nr = ref_quad_roots(A, B, C, r);
        for (int i = 0; i < nr; i++) {
            if (!(r[i] > smin))
                continue;
            lv3 p = ladd(O, lscale(d, r[i]));
            if (p.z < L->zf || p.z > L->zb)
                continue;
            ref_real rr = L->a1 + L->k * (p.z - L->zf);
            lv3 n = lnorm(L3(p.x, p.y, -rr * L->k));
            consider(&best, r[i], p, n, LP_SURFACE_RIM);
        }
    }
    return best;
}

/* Inside test with a margin (a lower bound-ish of the distance to the
 * boundary, vertical for the caps). */
static inline int ref_inside(const ref_lens *L, lv3 p, ref_real *margin)
{
    ref_real r = ref_sqrt(p.x * p.x + p.y * p.y);
    ref_real rmax = ref_fmax(L->a1, L->a2);
    if (r >= rmax) {
        *margin = r - rmax;
        return 0;
    }
    ref_real lower, upper;
    if (r <= L->a1)
        lower = rsag(L->c1, r);
    else
        lower = L->zf + (r - L->a1) / L->k; /* cone, a2 > a1 */
    if (r <= L->a2)
        upper = L->t + rsag(L->c2, r);
    else
        upper = L->zf + (r - L->a1) / L->k; /* cone, a1 > a2 */
    ref_real m = ref_fmin(ref_fabs(p.z - lower), ref_fabs(p.z - upper));
    m = ref_fmin(m, rmax - r);
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
    ref_real phi = urange(0, 2 * M_PI);
    if (which == 2 && L->rim) {
        ref_real u = urand();
        ref_real z = L->zf + u * (L->zb - L->zf), r = L->a1 + u * (L->a2 - L->a1);
        return L3(r * ref_cos(phi), r * ref_sin(phi), z);
    }
    int back = which == 1;
    ref_real a = back ? L->a2 : L->a1, r = ref_sqrt(urand()) * a;
    ref_real z = back ? L->t + rsag(L->c2, r) : rsag(L->c1, r);
    return L3(r * ref_cos(phi), r * ref_sin(phi), z);
}

/* Reflection and refraction of ref_real directions. */
static inline lv3 lcross(lv3 a, lv3 b)
{
    return L3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

static inline lv3 lreflect(lv3 d, lv3 n) { return ladd(d, lscale(n, -2 * ldot(d, n))); }

static inline int lrefract(lv3 d, lv3 n, ref_real n1, ref_real n2, lv3 *out)
{
    lv3 m = ldot(d, n) < 0 ? n : lscale(n, -1); /* toward the incident side */
    ref_real ci = -ldot(d, m), eta = n1 / n2;
    ref_real st2 = eta * eta * (1 - ci) * (1 + ci);
    if (st2 >= 1)
        return 0;
    ref_real ct = ref_sqrt(1 - st2);
    *out = lnorm(ladd(lscale(d, eta), lscale(m, eta * ci - ct)));
    return 1;
}

/* The internal chain of one ray through a lens, node by node, in ref_real
 * (test_rim, test_reciprocity): the path the paper's model follows (enter,
 * then reflect at every cap node), stopped at the rim, a miss or
 * REF_CHAIN_MAX nodes. */
#define REF_CHAIN_MAX 24
typedef struct {
    int n;                                   /* cap nodes 1..n */
    lv3 p[REF_CHAIN_MAX + 2], nrm[REF_CHAIN_MAX + 2], din[REF_CHAIN_MAX + 2], drefl[REF_CHAIN_MAX + 2], dtran[REF_CHAIN_MAX + 2];
    int surf[REF_CHAIN_MAX + 2], tir[REF_CHAIN_MAX + 2], good[REF_CHAIN_MAX + 2];
    ref_real seg[REF_CHAIN_MAX + 2];                  /* internal length node k-1 -> k */
    ref_real cosi[REF_CHAIN_MAX + 2];
    int rim_depth;                           /* node index of the rim, 0 none */
    lv3 rim_p;                               /* where the chain meets the rim */
    ref_real rim_cos;                        /* |cos| of incidence on the rim */
    int leak;
} ref_cap_chain;

/* The chain of the ray O + s d (d unit) into a lens of index ng in a medium
 * nm.  good[k] marks a well-conditioned node: away from the cap's edge
 * circle, not grazing, not near the critical angle. */
static inline void ref_build_cap_chain(const ref_lens *L, ref_real ng, ref_real nm, lv3 O, lv3 d,
                                   ref_cap_chain *c)
{
    memset(c, 0, sizeof *c);
    ref_hit h = ref_intersect(L, O, d, REF(0.0));
    if (h.surf < 0)
        return;
    if (h.surf == LP_SURFACE_RIM) {
        c->rim_depth = 1;
        c->rim_p = h.p;
        c->rim_cos = ref_fabs(ldot(d, h.n));
        return;
    }
    lv3 dir = d;
    ref_real n1 = nm, n2 = ng;
    ref_real edge_m = REF(1e-6) * L->size;
    for (int k = 1; k <= REF_CHAIN_MAX; k++) {
        c->n = k;
        c->p[k] = h.p;
        c->nrm[k] = h.n;
        c->surf[k] = h.surf;
        c->din[k] = dir;
        ref_real ci = ref_fabs(ldot(dir, h.n));
        c->cosi[k] = ci;
        c->drefl[k] = lreflect(dir, h.n);
        c->tir[k] = !lrefract(dir, h.n, n1, n2, &c->dtran[k]);
        /* conditioning: away from the cap's edge circle, not grazing, not
         * near the critical angle */
        ref_real a = h.surf == LP_SURFACE_BACK ? L->a2 : L->a1;
        ref_real r = ref_sqrt(h.p.x * h.p.x + h.p.y * h.p.y);
        ref_real x = (n1 / n2) * ref_sqrt((1 - ci) * (1 + ci)); /* sin of refraction */
        int good = r < a - edge_m && ci > REF(0.02) && ref_fabs(x - 1) > REF(1e-3);
        if (!c->tir[k])
            good = good && ref_sqrt((1 - x) * (1 + x)) > REF(0.02);
        c->good[k] = good;
        lv3 next;
        if (k == 1) {
            if (c->tir[1])
                return;
            next = c->dtran[1];
            n1 = ng;
            n2 = nm;
        } else {
            next = c->drefl[k];
        }
        h = ref_intersect(L, h.p, next, REF(1e-9) * L->size);
        if (h.surf < 0) {
            c->leak = 1;
            return;
        }
        if (h.surf == LP_SURFACE_RIM) {
            c->rim_depth = k + 1;
            c->rim_p = h.p;
            c->rim_cos = ref_fabs(ldot(next, h.n));
            return;
        }
        c->seg[k + 1] = h.s;
        dir = next;
    }
}

#endif
