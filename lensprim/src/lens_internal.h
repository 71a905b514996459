/* lens_internal.h -- the lens object and its surfaces (internal).
 *
 * Local frame: axis +z, front vertex at z = 0, back vertex at z = t.
 * A cap is the Spencer & Murty surface c(x^2 + y^2 + (z-z0)^2) - 2(z-z0) = 0
 * through its vertex (0,0,z0), cut to x^2 + y^2 <= h^2 on the branch
 * c(z - z0) <= 1 next to the vertex; c = 0 is the plane z = z0 with no
 * special case.  The rim is x^2 + y^2 = rho(z)^2 with rho linear in z
 * between the two cap edges (a cylinder when both apertures are equal). */
#ifndef LP_LENS_INTERNAL_H
#define LP_LENS_INTERNAL_H

#include "lensprim.h"
#include "vec3.h"

typedef struct lp__cap {
    double c;       /* curvature 1/R, 0 for flat */
    double z0;      /* vertex z */
    double h;       /* aperture radius */
    double out;     /* +1: outward normal is (cx, cy, c(z-z0) - 1) (front);
                       -1: its opposite (back) */
} lp__cap;

typedef struct lp__rim {
    int present;    /* 0 for a knife-edge lens */
    double z_a, rho_a; /* one edge circle */
    double z_b, rho_b; /* the other; z_a < z_b */
    double k;          /* d rho / d z */
    double slack;      /* how far past z_a .. z_b a hit is still taken:
                          1e-12 (z_b - z_a + rho_a + rho_b) */
} lp__rim;

struct lp_lens {
    lp_lens_desc desc;
    lp__cap cap[2];   /* LP_SURFACE_FRONT, LP_SURFACE_BACK */
    lp__rim rim;
    lp_vec3 u, v, w;  /* world directions of local x, y, z */
    double z_min, z_max, h_max; /* local bounding cylinder */
    double scale;     /* a size of the lens, mm */
    double eps;       /* distance below which a hit on ANOTHER surface
                         than the one a ray leaves is ignored */
    lp_vec3 crystal_axis; /* a crystal's optic axis, local, unit */
    lp_vec3 bound_center; /* world centre of a sphere holding the lens */
    double bound_r2;      /* its squared radius, with a margin */
    double ln_tau[LP_GLASS_TABLE_MAX]; /* log of the transmittance table of
                                          the glass traced (a crystal's
                                          ordinary one) */
};

/* A hit in the local frame. */
typedef struct lp__local_hit {
    double t;
    lp_vec3 p;
    lp_vec3 n;      /* outward unit normal */
    int surface;
} lp__local_hit;

/* Sag of a cap of curvature c at radius r: c r^2 / (1 + sqrt(1 - c^2 r^2)). */
double lp__cap_sag(double c, double r);

/* Outward unit normal at a point of the cap (exactly unit on the surface;
 * inline: every node needs one). */
static inline lp_vec3 lp__cap_normal(const lp__cap *cap, lp_vec3 p)
{
    double c = cap->c;
    lp_vec3 n = v3(c * p.x, c * p.y, c * (p.z - cap->z0) - 1.0);
    /* |n| = 1 on the surface; renormalize only to remove rounding */
    return v3_scale(v3_normalize(n), cap->out);
}

/* The smallest t in (t_min, t_max) where p + t d meets the rim, within
 * its z range widened by its slack.  Returns 1 on a hit. */
int lp__rim_intersect(const lp__rim *rim, lp_vec3 p, lp_vec3 d, double t_min,
                      double t_max, double *t);
lp_vec3 lp__rim_normal(const lp__rim *rim, lp_vec3 p);

/* The t_max of the rim's test after a cap's hit at t_cap: a rim hit up to
 * eps beyond it takes the cap's place.  Both meet at the cap's edge
 * circle, where rounding puts either root first; the edge belongs to the
 * opaque rim, so that a ray from outside never "leaves" the glass through
 * a cap there, nor one from inside enters it.  (No cap hit: t_cap is the
 * caller's bound, or +inf in the lanes, and stays so.) */
static inline double lp__rim_t_max(double t_cap, double eps)
{
    return t_cap + eps;
}

/* Whether lp__rim_intersect(rim, p, d, t_min, ...) with t_min >= 0
 * certainly finds nothing because p lies beyond the rim's z range and d
 * leads away from it: a root's z = p.z + s d.z with s > 0 stays on p's
 * side of p.z (rounding is monotonic), so the test refuses every root. */
static inline int lp__rim_beyond(const lp__rim *rim, lp_vec3 p, lp_vec3 d)
{
    return ((d.z <= 0.0) & (p.z < rim->z_a - rim->slack)) |
           ((d.z >= 0.0) & (p.z > rim->z_b + rim->slack)); /* free of branches (lanes.h) */
}

/* Nearest hit of the local ray p + t d, t in (t_min, t_max), with the
 * whole surface.  from_surface is the surface p lies on (LP_SURFACE_NONE
 * for a ray from elsewhere). */
int lp__lens_hit(const lp_lens *lens, lp_vec3 p, lp_vec3 d, int from_surface,
                 double t_min, double t_max, lp__local_hit *hit);

/* The surface the local point p lies on, to within the lens's rounding
 * tolerance (a few 1e-12 of its size), or LP_SURFACE_NONE.  Entry points
 * use it so that a ray starting on the lens (say, one it just emitted)
 * never meets its own origin again. */
int lp__lens_surface_at(const lp_lens *lens, lp_vec3 p);

/* Whether lp_lens_intersect(lens, origin, dir, 0, t_max) certainly
 * returns 0 for every t_max: that call's own arithmetic (the local ray,
 * the surface it leaves, lp__lens_hit) with t_max = INFINITY; with no hit
 * there, there is none below any t_max (every test only narrows).  Where
 * that call would not look at the caps (a ray not finite, of no
 * direction, or away from the lens's bounding sphere) it returns 0
 * anyway, so any answer is right there.  0 where not certain (a ray from
 * no cap). */
int lp__lens_leaves(const lp_lens *lens, lp_vec3 origin, lp_vec3 dir);

/* World <-> local (inline: every node and outgoing ray uses them). */
static inline lp_vec3 lp__to_local_dir(const lp_lens *lens, lp_vec3 d)
{
    return v3(v3_dot(d, lens->u), v3_dot(d, lens->v), v3_dot(d, lens->w));
}
static inline lp_vec3 lp__to_local_point(const lp_lens *lens, lp_vec3 p)
{
    return lp__to_local_dir(lens, v3_sub(p, lens->desc.position));
}
static inline lp_vec3 lp__to_world_dir(const lp_lens *lens, lp_vec3 d)
{
    return v3_add(v3_add(v3_scale(lens->u, d.x), v3_scale(lens->v, d.y)), v3_scale(lens->w, d.z));
}
static inline lp_vec3 lp__to_world_point(const lp_lens *lens, lp_vec3 p)
{
    return v3_add(lens->desc.position, lp__to_world_dir(lens, p));
}

#endif
