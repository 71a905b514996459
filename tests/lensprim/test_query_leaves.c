/* test_query_leaves.c -- lp_backward_query_leaves, checked against the
 * lens's geometry by an intersection of the test's own.
 *
 * A query certified as leaving its lens must not meet the lens again: a
 * renderer then leaves the lens out of the query ray's scene test, and a
 * wrong certificate would change a render silently.  For many lens
 * shapes (biconvex, biconcave, meniscus both ways, plano both ways, flat
 * plates, a ball, a biconvex lens and a meniscus with knife edges,
 * biconvex lenses whose edge is 4e-12 and 1e-6 diameters thick, a
 * capsule, conical rims D2 > D and D2 < D, seen from a hemispherical cap,
 * nearly flat, behind a concave cap, deep concave bowls whose queries
 * meet them again, huge radii), placed and tilted at random and once on
 * the world axes, view rays of several kinds (at random, at the cap
 * edges, grazing a cap, at the rim, along the axis, and from points of a
 * cap, of the rim and of a cap's edge, as a renderer's rays that start on
 * the lens) are built by lp_backward_build at 19 wavelengths of a
 * dispersive glass (SF11), in every mode, at depths 1 to 12, and by
 * lp_backward_build_many.
 *
 * For every query certified as leaving:
 *   * lp_lens_intersect(lens, origin, dir, 0, t_max) gives no hit for
 *     t_max = +inf, 1e300 and 10 lens sizes (the documented contract);
 *   * the test's own intersection (long double, in the lens frame built
 *     from the lens's position and axis only: each cap as the sphere or
 *     plane through its vertex cut to its aperture and to the half next
 *     to the vertex, the rim as the cylinder or cone between the two cap
 *     edges) finds no CLEAR hit: a root s > S_MIN of a surface, not the
 *     origin's own root, at a point inside the cap's aperture by a
 *     relative 1e-9 (the rim: inside its z range by 1e-9 lens sizes, at
 *     rho > 0), crossed at |cos| >= 1e-6 to the surface normal.
 *     Margins: a query origin is the library's own intersection point,
 *     within a few 1e-16 lens sizes of its surface, and lp_lens_intersect
 *     by contract ignores hits on another surface closer than 1e-12 lens
 *     sizes; S_MIN = 1e-7 lens sizes is far above both (a transversal
 *     crossing at |cos| >= 1e-6 moves by at most 1e-9 lens sizes for such
 *     an origin error) and below every feature of the shapes tested (the
 *     thinnest, 5e-4 lens sizes) but the edges made thin to probe the
 *     tolerances (4e-12 and 1e-6 diameters) and the knife edges, where
 *     the other cap passes through the origin's neighbourhood by design.
 *     Hits within the margins of a surface but not clear by them are
 *     counted as borderline and printed, not failed (those seen are rays
 *     grazing a flat cap that pass the rim's end by less than 1e-9 lens
 *     sizes: misses).
 * Every query whose ray clearly meets the lens by the test's intersection
 * (certified or not) must have a hit of lp_lens_intersect too: the test's
 * geometry and the library's agree where the certificate says nothing.
 * The share of queries certified, and the share of those that clearly
 * leave (no hit of the test's, clear or borderline) that are certified,
 * are printed per lens: the certificate must not be vacuous.
 * Both builds must give the same queries (bytes) and the same
 * certificate for every query, also for a builder given twice to
 * lp_backward_build_many (it holds its last wavelength's build); a
 * crystal lens certifies nothing, nor does a query index past the last.
 * RAYS_PER_LENS may be raised at compile time for a longer search.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "splitmix.h"
#include "lensprim.h"

#define PI 3.14159265358979323846
#define NWL 19 /* a group of 16 lanes and one of 3 */
#ifndef RAYS_PER_LENS
#define RAYS_PER_LENS 210
#endif

typedef long double ld;

static uint64_t rng = 0x51ee7e1ea7e5ull;
static double uniform(void)
{
    return splitmix_uniform(&rng);
}

static lp_vec3 vec(double x, double y, double z)
{
    lp_vec3 v = {x, y, z};
    return v;
}

static lp_vec3 random_unit(void)
{
    double z = 2.0 * uniform() - 1.0, phi = 2.0 * PI * uniform();
    double r = sqrt(fmax(0.0, 1.0 - z * z));
    return vec(r * cos(phi), r * sin(phi), z);
}

/* ---- The test's own lens geometry (long double, from the desc) ---- */

typedef struct ld3 {
    ld x, y, z;
} ld3;

static ld3 l3(lp_vec3 v)
{
    ld3 r = {v.x, v.y, v.z};
    return r;
}
static ld3 l3sub(ld3 a, ld3 b)
{
    ld3 r = {a.x - b.x, a.y - b.y, a.z - b.z};
    return r;
}
static ld3 l3madd(ld3 a, ld3 b, ld s)
{
    ld3 r = {a.x + s * b.x, a.y + s * b.y, a.z + s * b.z};
    return r;
}
static ld l3dot(ld3 a, ld3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static ld3 l3unit(ld3 a)
{
    ld n = sqrtl(l3dot(a, a));
    ld3 r = {a.x / n, a.y / n, a.z / n};
    return r;
}

typedef struct geom {
    ld3 pos, w;        /* front vertex, unit axis */
    ld c[2], z0[2], h[2];
    int rim;           /* 0: knife edge (the caps meet) */
    ld za, zb, ra, rb, k;
    ld scale;
} geom;

/* sag of a sphere of curvature c at radius r, as the height of the cap
 * above its vertex: R - sqrt(R^2 - r^2) written without cancellation */
static ld sag(ld c, ld r)
{
    return c * r * r / (1.0L + sqrtl(1.0L - c * c * r * r));
}

static ld curv(double R)
{
    return (R == 0.0 || isinf(R)) ? 0.0L : 1.0L / (ld)R;
}

static void geom_of(const lp_lens_desc *d, geom *g)
{
    g->pos = l3(d->position);
    g->w = l3unit(l3(d->axis));
    g->c[0] = curv(d->radius1);
    g->c[1] = curv(d->radius2);
    g->z0[0] = 0.0L;
    g->z0[1] = d->thickness;
    g->h[0] = 0.5L * d->diameter;
    g->h[1] = 0.5L * (d->diameter2 > 0.0 ? d->diameter2 : d->diameter);
    g->za = sag(g->c[0], g->h[0]);
    g->zb = d->thickness + sag(g->c[1], g->h[1]);
    g->ra = g->h[0];
    g->rb = g->h[1];
    ld zlo = fminl(0.0L, fminl(g->za, g->zb)), zhi = fmaxl(d->thickness, fmaxl(g->za, g->zb));
    g->scale = fmaxl(zhi - zlo, 2.0L * fmaxl(g->h[0], g->h[1]));
    g->rim = g->zb - g->za > 1e-9L * g->scale;
    g->k = g->rim ? (g->rb - g->ra) / (g->zb - g->za) : 0.0L;
}

#define S_MIN_REL 1e-7L
#define EDGE_REL 1e-9L
#define COS_MIN 1e-6L

typedef struct verdict {
    int clear, border; /* clear hits, borderline hits */
    int surface;       /* of the first clear hit */
    ld s;
} verdict;

static void note(verdict *v, int clear, int surface, ld s)
{
    if (clear) {
        if (!v->clear || s < v->s)
            v->s = s, v->surface = surface;
        v->clear++;
    } else {
        v->border++;
    }
}

/* Roots of a s^2 + 2 b s + g = 0 (a may be 0), in roots[], count returned. */
static int quad(ld a, ld b, ld g, ld roots[2])
{
    if (a == 0.0L) {
        if (b == 0.0L)
            return 0;
        roots[0] = -g / (2.0L * b);
        return 1;
    }
    ld disc = b * b - a * g;
    if (disc < 0.0L)
        return 0;
    ld q = -(b + copysignl(sqrtl(disc), b));
    if (q == 0.0L) {
        roots[0] = 0.0L;
        return 1;
    }
    roots[0] = g / q;
    roots[1] = q / a;
    return 2;
}

/* Every hit of the ray o + s d (world, d unit) with the lens, s > 0. */
static verdict meet(const geom *G, lp_vec3 ow, lp_vec3 dw, int from)
{
    verdict v = {0, 0, -1, 0.0L};
    ld3 o = l3(ow), d = l3unit(l3(dw));
    ld s_min = S_MIN_REL * G->scale;
    /* caps: c |x|^2 - 2 x.w = 0 with x relative to the vertex */
    for (int c = 0; c < 2; c++) {
        ld3 q = l3sub(l3sub(o, G->pos), (ld3){G->z0[c] * G->w.x, G->z0[c] * G->w.y,
                                             G->z0[c] * G->w.z});
        ld cc = G->c[c];
        ld b = cc * l3dot(q, d) - l3dot(d, G->w);
        ld g = cc * l3dot(q, q) - 2.0L * l3dot(q, G->w);
        ld roots[2];
        int n = quad(cc, b, g, roots);
        int own = -1; /* the origin's own root on its own cap */
        if (c == from && n > 0) /* the root nearest 0 */
            own = n == 2 && fabsl(roots[1]) < fabsl(roots[0]) ? 1 : 0;
        for (int i = 0; i < n; i++) {
            ld s = roots[i];
            if (i == own || !(s > 0.0L))
                continue;
            ld3 x = l3madd(q, d, s);
            ld z = l3dot(x, G->w), r2 = l3dot(x, x) - z * z;
            ld hh = G->h[c] * G->h[c];
            if (!(r2 <= hh * (1.0L + 1e-9L)) || !(cc * z <= 1.0L + 1e-9L))
                continue; /* off the patch */
            ld3 n3 = l3madd((ld3){-G->w.x, -G->w.y, -G->w.z}, x, cc);
            ld cosv = fabsl(l3dot(n3, d)) / sqrtl(l3dot(n3, n3));
            int clear = s > s_min && r2 <= hh * (1.0L - 2e-9L) && cc * z <= 1.0L - 1e-9L &&
                        cosv >= COS_MIN;
            if (s > s_min || clear)
                note(&v, clear, c, s);
        }
    }
    if (G->rim) {
        ld3 p = l3sub(o, G->pos);
        ld pz = l3dot(p, G->w), dz = l3dot(d, G->w);
        ld3 pp = l3madd(p, G->w, -pz), dp = l3madd(d, G->w, -dz);
        ld rho = G->ra + G->k * (pz - G->za);
        ld A = l3dot(dp, dp) - G->k * G->k * dz * dz;
        ld B = l3dot(pp, dp) - G->k * rho * dz;
        ld C = l3dot(pp, pp) - rho * rho;
        ld roots[2];
        int n = quad(A, B, C, roots);
        ld m = EDGE_REL * G->scale;
        for (int i = 0; i < n; i++) {
            ld s = roots[i];
            if (!(s > s_min))
                continue;
            ld z = pz + s * dz;
            ld rz = G->ra + G->k * (z - G->za);
            if (z < G->za - m || z > G->zb + m || rz < 0.0L)
                continue;
            ld3 xp = l3madd(pp, dp, s);
            /* normal: the gradient of r^2 - rho(z)^2 */
            ld3 n3 = l3madd(xp, G->w, -G->k * rz);
            ld nn = sqrtl(l3dot(n3, n3));
            ld cosv = nn > 0.0L ? fabsl(l3dot(n3, d)) / nn : 0.0L;
            int clear = z >= G->za + m && z <= G->zb - m && rz > m && cosv >= COS_MIN;
            note(&v, clear, 2, s);
        }
    }
    return v;
}

/* ---- The lenses ---- */

typedef struct shape {
    const char *name;
    double R1, R2, t, D, D2;
    double knife; /* >= 0: t is set so that the edge thickness is this
                     many diameters (0: a knife edge); < 0: t as given */
} shape;

static const shape shapes[] = {
    {"biconvex", 20, -20, 5, 12, 0, -1},
    {"biconcave", -15, 15, 2, 10, 0, -1},
    {"deep biconcave", -6, 6, 1, 10, 0, -1},
    {"positive meniscus", 10, 25, 4, 12, 0, -1},
    {"negative meniscus", 25, 10, 2, 12, 0, -1},
    {"steep meniscus", 6.5, 7, 3, 12, 0, -1},
    {"plano-convex", 15, 0, 4, 12, 0, -1},
    {"convex-plano", INFINITY, -15, 4, 12, 0, -1},
    {"plano-concave", 0, 12, 3, 12, 0, -1},
    {"flat plate", 0, 0, 3, 20, 0, -1},
    {"thin flat disc", 0, 0, 0.05, 20, 0, -1},
    {"ball (knife edge)", 5, -5, 10, 10, 0, -1},
    {"capsule (two hemispheres)", 5, -5, 12, 10, 0, -1},
    {"knife-edge biconvex", 20, -20, 0, 12, 0, 0},
    {"knife-edge meniscus", 10, 25, 0, 12, 0, 0},
    {"edge 4e-12 D (caps within tolerance)", 20, -20, 0, 12, 0, 4e-12},
    {"edge 1e-6 D", 20, -20, 0, 12, 0, 1e-6},
    {"cone D2 > D, hemisphere front", 5, 0, 8, 10, 20, -1},
    {"cone D2 < D, hemisphere back", 0, -5, 8, 20, 10, -1},
    {"cone D2 > D biconvex", 30, -40, 6, 12, 16, -1},
    {"cone D2 < D meniscus", 12, 30, 5, 16, 10, -1},
    {"concave hemisphere bowl", -5, 0, 1, 10, 0, -1},
    {"concave bowl both sides", -5, 5, 1, 10, 0, -1},
    {"concave bowl, cone D2 > D", -5, 0, 1, 10, 14, -1},
    {"flat cone D2 < D (near annulus)", 0, 0, 0.01, 20, 10, -1},
    {"flat cone D2 > D (near annulus)", 0, 0, 0.01, 10, 20, -1},
    {"cone D2 > D, concave back", 8, -40, 3, 10, 12, -1},
    {"huge radii", 1e9, -1e12, 3, 10, 0, -1},
    {"huge radii, cone", 1e12, 1e9, 3, 10, 14, -1},
    {"huge and flat", 1e15, 0, 2, 10, 0, -1},
    {"thin long-radius", 1000, -1000, 0.05, 10, 0, -1},
};
#define N_SHAPES (sizeof shapes / sizeof shapes[0])

/* A point of the lens frame (x, y, z) in the world, with the test's own
 * frame (any two axes perpendicular to w will do: the lens is round). */
typedef struct frame {
    lp_vec3 pos, u, v, w;
} frame;

static frame frame_of(const lp_lens_desc *d)
{
    frame f;
    double n = sqrt(d->axis.x * d->axis.x + d->axis.y * d->axis.y + d->axis.z * d->axis.z);
    f.pos = d->position;
    f.w = vec(d->axis.x / n, d->axis.y / n, d->axis.z / n);
    lp_vec3 a = fabs(f.w.x) < 0.6 ? vec(1, 0, 0) : vec(0, 1, 0);
    /* u = a - (a.w) w, normalized; v = w x u */
    double aw = a.x * f.w.x + a.y * f.w.y + a.z * f.w.z;
    lp_vec3 u = vec(a.x - aw * f.w.x, a.y - aw * f.w.y, a.z - aw * f.w.z);
    double un = sqrt(u.x * u.x + u.y * u.y + u.z * u.z);
    f.u = vec(u.x / un, u.y / un, u.z / un);
    f.v = vec(f.w.y * f.u.z - f.w.z * f.u.y, f.w.z * f.u.x - f.w.x * f.u.z,
              f.w.x * f.u.y - f.w.y * f.u.x);
    return f;
}

static lp_vec3 to_world(const frame *f, double x, double y, double z)
{
    return vec(f->pos.x + x * f->u.x + y * f->v.x + z * f->w.x,
               f->pos.y + x * f->u.y + y * f->v.y + z * f->w.y,
               f->pos.z + x * f->u.z + y * f->v.z + z * f->w.z);
}

static lp_vec3 dir_world(const frame *f, double x, double y, double z)
{
    return vec(x * f->u.x + y * f->v.x + z * f->w.x, x * f->u.y + y * f->v.y + z * f->w.y,
               x * f->u.z + y * f->v.z + z * f->w.z);
}

static double sag_d(double c, double r)
{
    return c * r * r / (1.0 + sqrt(1.0 - c * c * r * r));
}

static double curv_d(double R)
{
    return (R == 0.0 || isinf(R)) ? 0.0 : 1.0 / R;
}

/* A view ray of kind `kind` at the lens: origin *o, direction *d. */
static void view_ray(const lp_lens_desc *ds, const frame *f, int kind, lp_vec3 *o, lp_vec3 *d)
{
    double c1 = curv_d(ds->radius1), c2 = curv_d(ds->radius2);
    double h1 = 0.5 * ds->diameter;
    double h2 = 0.5 * (ds->diameter2 > 0.0 ? ds->diameter2 : ds->diameter);
    double za = sag_d(c1, h1), zb = ds->thickness + sag_d(c2, h2);
    double hm = fmax(h1, h2), zlo = fmin(0.0, fmin(za, zb));
    double zhi = fmax(ds->thickness, fmax(za, zb));
    double L = 3.0 * fmax(2.0 * hm, zhi - zlo);
    double phi = 2.0 * PI * uniform();
    double x, y, z;
    lp_vec3 dl = random_unit();
    switch (kind) {
    case 0: { /* anywhere in the bounding cylinder */
        double r = 1.05 * hm * sqrt(uniform());
        x = r * cos(phi), y = r * sin(phi), z = zlo + (zhi - zlo) * uniform();
        break;
    }
    case 1: { /* a cap's edge circle */
        int s = uniform() < 0.5;
        double h = s ? h2 : h1;
        x = h * cos(phi), y = h * sin(phi), z = s ? zb : za;
        break;
    }
    case 2: { /* a point of a cap, grazing it */
        int s = uniform() < 0.5;
        double c = s ? c2 : c1, h = s ? h2 : h1;
        double r = h * sqrt(uniform());
        x = r * cos(phi), y = r * sin(phi), z = (s ? ds->thickness : 0.0) + sag_d(c, r);
        /* the normal c (x, y, z - z0) - (0, 0, 1), a tangent t, and a tilt */
        double nx = c * x, ny = c * y, nz = c * (z - (s ? ds->thickness : 0.0)) - 1.0;
        double nn = sqrt(nx * nx + ny * ny + nz * nz);
        nx /= nn, ny /= nn, nz /= nn;
        double dn = dl.x * nx + dl.y * ny + dl.z * nz;
        double tx = dl.x - dn * nx, ty = dl.y - dn * ny, tz = dl.z - dn * nz;
        double tn = sqrt(tx * tx + ty * ty + tz * tz);
        static const double tilt[] = {0.0, 1e-9, -1e-9, 1e-6, -1e-6, 1e-3, -1e-3, 0.05};
        double e = tilt[(int)(uniform() * 8.0) & 7];
        dl = vec(tx / tn + e * nx, ty / tn + e * ny, tz / tn + e * nz);
        break;
    }
    case 3: { /* the rim */
        double fz = uniform();
        x = (h1 + fz * (h2 - h1)) * cos(phi), y = (h1 + fz * (h2 - h1)) * sin(phi);
        z = za + fz * (zb - za);
        break;
    }
    case 5:   /* from a point of a cap (the renderer's rays from a lens) */
    case 6: { /* from a point of the rim or a cap edge */
        int s = uniform() < 0.5;
        if (kind == 5) {
            double c = s ? c2 : c1, h = s ? h2 : h1;
            double r = h * sqrt(uniform());
            x = r * cos(phi), y = r * sin(phi), z = (s ? ds->thickness : 0.0) + sag_d(c, r);
        } else {
            double fz = uniform() < 0.3 ? (double)s : uniform();
            x = (h1 + fz * (h2 - h1)) * cos(phi), y = (h1 + fz * (h2 - h1)) * sin(phi);
            z = za + fz * (zb - za);
        }
        lp_vec3 dw = dir_world(f, dl.x, dl.y, dl.z);
        *o = to_world(f, x, y, z);
        *d = dw;
        return;
    }
    default: { /* near the axis, nearly along it */
        double r = 0.3 * hm * sqrt(uniform());
        x = r * cos(phi), y = r * sin(phi), z = 0.5 * ds->thickness;
        double e = uniform() < 0.5 ? 0.0 : 0.02 * uniform();
        dl = vec(e * cos(phi + 1.0), e * sin(phi + 1.0), uniform() < 0.5 ? 1.0 : -1.0);
        break;
    }
    }
    lp_vec3 dw = dir_world(f, dl.x, dl.y, dl.z);
    double n = sqrt(dw.x * dw.x + dw.y * dw.y + dw.z * dw.z);
    dw = vec(dw.x / n, dw.y / n, dw.z / n);
    lp_vec3 tw = to_world(f, x, y, z);
    *o = vec(tw.x - L * dw.x, tw.y - L * dw.y, tw.z - L * dw.z);
    *d = dw;
}

static int same_q(const lp_query *a, const lp_query *b)
{
    return memcmp(&a->origin, &b->origin, sizeof a->origin) == 0 &&
           memcmp(&a->dir, &b->dir, sizeof a->dir) == 0 && a->depth == b->depth &&
           a->surface == b->surface;
}

static long n_met, n_queries, n_certified, n_free, n_free_certified, n_border, n_wrong;

static void test_lens(const shape *sh, int placed)
{
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_error err;
    lp_lens_desc_init(&desc);
    desc.radius1 = sh->R1;
    desc.radius2 = sh->R2;
    desc.diameter = sh->D;
    desc.diameter2 = sh->D2;
    desc.thickness = sh->t;
    if (sh->knife >= 0.0) { /* the edge thickness: t - sag1(h) + sag2(h) */
        double h = 0.5 * sh->D;
        desc.thickness = sag_d(curv_d(sh->R1), h) - sag_d(curv_d(sh->R2), h) + sh->knife * sh->D;
    }
    static const double b[3] = {1.73759695, 0.313747346, 1.89878101}; /* SF11 */
    static const double c[3] = {0.013188707, 0.0623068142, 155.23629};
    lp_glass_init_sellmeier(&desc.glass, "SF11", b, c);
    if (placed) {
        desc.position = vec(100.0 * uniform() - 50.0, 100.0 * uniform() - 50.0,
                            100.0 * uniform() - 50.0);
        desc.axis = random_unit();
    }
    if (lp_lens_create(&desc, &lens, &err) != LP_OK) {
        CHECK(0, "%s: lens not created: %s", sh->name, err.message);
        return;
    }
    if (sh->knife == 0.0)
        CHECK(lp_lens_edge_thickness(lens) == 0.0, "%s: a knife edge", sh->name);
    geom G;
    geom_of(&desc, &G);
    frame F = frame_of(&desc);

    lp_backward *one[NWL], *many[NWL];
    double wl[NWL];
    for (int k = 0; k < NWL; k++) {
        wl[k] = 400.0 + 20.0 * k;
        if (lp_backward_create(&one[k], &err) != LP_OK ||
            lp_backward_create(&many[k], &err) != LP_OK)
            abort();
    }
    long q0 = n_queries, c0 = n_certified, f0 = n_free, fc0 = n_free_certified, b0 = n_border;
    static const int depths[] = {1, 3, 8, 12};
    static const lp_mode modes[] = {LP_MODE_FRESNEL, LP_MODE_POLARIZED, LP_MODE_SCHLICK};
    int reported = 0;
    for (int ri = 0; ri < RAYS_PER_LENS; ri++) {
        lp_vec3 o, d;
        view_ray(&desc, &F, ri % 7, &o, &d);
        lp_trace_args a;
        lp_trace_args_init(&a);
        a.max_depth = depths[ri % 4];
        a.mode = modes[ri % 3];
        int st_many = lp_backward_build_many(many, NWL, lens, o, d, wl, &a, &err);
        for (int k = 0; k < NWL; k++) {
            int st_one = lp_backward_build(one[k], lens, o, d, wl[k], &a, &err);
            CHECK(st_one == st_many, "%s ray %d: statuses", sh->name, ri);
            if (st_one != LP_OK || st_many != LP_OK)
                continue;
            size_t nq = lp_backward_query_count(one[k]);
            CHECK(nq == lp_backward_query_count(many[k]), "%s ray %d wl %d: query counts",
                  sh->name, ri, k);
            if (nq != lp_backward_query_count(many[k]))
                continue;
            const lp_query *qa = lp_backward_queries(one[k]), *qb = lp_backward_queries(many[k]);
            CHECK(!lp_backward_query_leaves(one[k], nq) && !lp_backward_query_leaves(many[k], nq),
                  "%s: a query past the last is not certified", sh->name);
            for (size_t j = 0; j < nq; j++) {
                int la = lp_backward_query_leaves(one[k], j);
                int lb = lp_backward_query_leaves(many[k], j);
                CHECK(same_q(&qa[j], &qb[j]), "%s ray %d wl %d query %zu: the same query",
                      sh->name, ri, k, j);
                CHECK(la == lb, "%s ray %d wl %d query %zu: certificates %d (one) %d (many)",
                      sh->name, ri, k, j, la, lb);
                CHECK(la == 0 || la == 1, "%s: a certificate is 0 or 1, got %d", sh->name, la);
                n_queries++;
                verdict v = meet(&G, qa[j].origin, qa[j].dir, qa[j].surface);
                int is_free = v.clear == 0 && v.border == 0;
                n_free += is_free;
                n_free_certified += is_free && la;
                if (v.clear) { /* the test's intersection agrees with the library's */
                    lp_hit hh;
                    n_met++;
                    CHECK(lp_lens_intersect(lens, qa[j].origin, qa[j].dir, 0.0, INFINITY, &hh),
                          "%s ray %d wl %d query %zu: the test meets surface %d at s = %.17Lg, "
                          "lp_lens_intersect nothing",
                          sh->name, ri, k, j, v.surface, v.s);
                }
                if (!la)
                    continue;
                n_certified++;
                n_border += v.border > 0;
                lp_hit h;
                static const double tmax[] = {INFINITY, 1e300, 10.0};
                for (int ti = 0; ti < 3; ti++) {
                    double tm = ti == 2 ? 10.0 * (double)G.scale : tmax[ti];
                    CHECK(!lp_lens_intersect(lens, qa[j].origin, qa[j].dir, 0.0, tm, &h),
                          "%s ray %d wl %d query %zu: certified, but lp_lens_intersect hits "
                          "surface %d at t = %.17g",
                          sh->name, ri, k, j, h.surface, h.t);
                }
                if (v.clear) {
                    n_wrong++;
                    CHECK(0,
                          "%s ray %d wl %d query %zu: certified, but the ray meets surface %d "
                          "at s = %.17Lg",
                          sh->name, ri, k, j, v.surface, v.s);
                    if (reported++ < 3)
                        fprintf(stderr,
                                "  reproducer: R1 %.17g R2 %.17g t %.17g D %.17g D2 %.17g pos "
                                "(%.17g %.17g %.17g) axis (%.17g %.17g %.17g)\n"
                                "  view ray o (%.17g %.17g %.17g) d (%.17g %.17g %.17g) "
                                "lambda %g mode %d depth %d\n"
                                "  query origin (%.17g %.17g %.17g) dir (%.17g %.17g %.17g) "
                                "surface %d depth %d\n",
                                desc.radius1, desc.radius2, desc.thickness, desc.diameter,
                                desc.diameter2, desc.position.x, desc.position.y,
                                desc.position.z, desc.axis.x, desc.axis.y, desc.axis.z, o.x,
                                o.y, o.z, d.x, d.y, d.z, wl[k], (int)a.mode, a.max_depth,
                                qa[j].origin.x, qa[j].origin.y, qa[j].origin.z, qa[j].dir.x,
                                qa[j].dir.y, qa[j].dir.z, qa[j].surface, qa[j].depth);
                }
            }
        }
        if (ri % 4 == 0) { /* a builder given twice holds its last wavelength's build */
            lp_backward *dup[3] = {many[0], many[1], many[0]};
            double dwl[3] = {wl[0], wl[1], wl[NWL - 1]};
            lp_trace_args a2 = a;
            a2.min_weight = ri % 8 == 0 ? 1e-3 : 0.0; /* some candidates dropped */
            int s1 = lp_backward_build_many(dup, 3, lens, o, d, dwl, &a2, &err);
            int s2 = lp_backward_build(one[0], lens, o, d, wl[NWL - 1], &a2, &err);
            CHECK(s1 == s2, "%s ray %d: a builder given twice: statuses", sh->name, ri);
            if (s1 == LP_OK && s2 == LP_OK) {
                size_t nq = lp_backward_query_count(one[0]);
                int same = nq == lp_backward_query_count(many[0]);
                for (size_t q = 0; same && q < nq; q++)
                    same = same_q(&lp_backward_queries(one[0])[q],
                                  &lp_backward_queries(many[0])[q]) &&
                           lp_backward_query_leaves(one[0], q) ==
                               lp_backward_query_leaves(many[0], q);
                CHECK(same, "%s ray %d: a builder given twice: its last build's queries and "
                      "certificates", sh->name, ri);
            }
        }
    }
    long nq = n_queries - q0, nc = n_certified - c0, nf = n_free - f0,
         nfc = n_free_certified - fc0;
    printf("%-32s %s: %6ld queries, %5.1f%% certified; of %6ld that clearly leave %5.1f%% "
           "certified; %ld certified borderline\n",
           sh->name, placed ? "placed" : "on axes", nq, nq ? 100.0 * nc / nq : 0.0, nf,
           nf ? 100.0 * nfc / nf : 0.0, n_border - b0);
    for (int k = 0; k < NWL; k++) {
        lp_backward_destroy(one[k]);
        lp_backward_destroy(many[k]);
    }
    lp_lens_destroy(lens);
}

/* A crystal lens certifies nothing. */
static void test_crystal(void)
{
    lp_lens_desc desc;
    lp_lens *lens = NULL;
    lp_backward *bw = NULL;
    lp_error err;
    lp_lens_desc_init(&desc);
    desc.radius1 = 20.0;
    desc.radius2 = -20.0;
    desc.thickness = 5.0;
    desc.diameter = 12.0;
    desc.uniaxial = 1;
    lp_crystal_init_constant(&desc.crystal, 1.658, 1.486, vec(0.3, 0.5, 0.8));
    lp_backward *bw2[3] = {NULL, NULL, NULL};
    if (lp_lens_create(&desc, &lens, &err) != LP_OK || lp_backward_create(&bw, &err) != LP_OK ||
        lp_backward_create(&bw2[0], &err) != LP_OK || lp_backward_create(&bw2[1], &err) != LP_OK ||
        lp_backward_create(&bw2[2], &err) != LP_OK) {
        CHECK(0, "crystal lens");
        return;
    }
    frame F = frame_of(&desc);
    size_t total = 0, certified = 0;
    for (int ri = 0; ri < 200; ri++) {
        lp_vec3 o, d;
        view_ray(&desc, &F, ri % 5, &o, &d);
        lp_trace_args a;
        lp_trace_args_init(&a);
        a.max_depth = 4;
        if (lp_backward_build(bw, lens, o, d, 550.0, &a, &err) != LP_OK)
            continue;
        size_t nq = lp_backward_query_count(bw);
        for (size_t j = 0; j <= nq; j++)
            certified += lp_backward_query_leaves(bw, j) != 0;
        total += nq;
        /* and through lp_backward_build_many */
        lp_backward *many[3] = {bw2[0], bw2[1], bw2[2]};
        static const double wl[3] = {450.0, 550.0, 650.0};
        if (lp_backward_build_many(many, 3, lens, o, d, wl, &a, &err) != LP_OK)
            continue;
        for (int k = 0; k < 3; k++) {
            nq = lp_backward_query_count(many[k]);
            for (size_t j = 0; j <= nq; j++)
                certified += lp_backward_query_leaves(many[k], j) != 0;
            total += nq;
        }
    }
    for (int k = 0; k < 3; k++)
        lp_backward_destroy(bw2[k]);
    CHECK(total > 0, "crystal: some queries");
    CHECK(certified == 0, "crystal: %zu of %zu queries certified", certified, total);
    printf("%-32s: %6zu queries, none certified\n", "crystal biconvex", total);
    lp_backward_destroy(bw);
    lp_lens_destroy(lens);
}

int main(void)
{
    for (size_t s = 0; s < N_SHAPES; s++) {
        test_lens(&shapes[s], 0);
        test_lens(&shapes[s], 1);
    }
    test_crystal();
    printf("all: %ld queries, %.1f%% certified; %ld meet the lens again clearly; of %ld that "
           "clearly leave %.1f%% certified; %ld certified with a borderline hit, %ld certified "
           "with a clear hit\n",
           n_queries, 100.0 * n_certified / (double)n_queries, n_met, n_free,
           100.0 * n_free_certified / (double)n_free, n_border, n_wrong);
    CHECK(n_met > 100, "the test's intersection finds queries that meet their lens: %ld", n_met);
    CHECK(n_certified > n_queries / 10, "the certificate is not vacuous: %ld of %ld",
          n_certified, n_queries);
    return check_finish("test_query_leaves");
}
