/* lens.c -- creating, validating and intersecting a lens. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cap.h"
#include "error.h"
#include "glass_internal.h"
#include "lens_internal.h"
#include "vec3.h"

void lp_lens_desc_init(lp_lens_desc *desc)
{
    if (!desc)
        return;
    memset(desc, 0, sizeof *desc);
    lp_glass_init_constant(&desc->glass, 1.5);
    lp_glass_init_constant(&desc->medium, 1.0);
    desc->axis = v3(0.0, 0.0, 1.0);
}

/* Curvature of a radius: 0 and +-inf are flat. */
static double curvature(double r)
{
    if (r == 0.0 || isinf(r))
        return 0.0;
    return 1.0 / r;
}

static lp_status check_shape(const lp_lens_desc *d, lp_error *err)
{
    if (isnan(d->radius1) || isnan(d->radius2))
        return lp__fail(err, LP_ERROR_INVALID_LENS, "radius %s is NaN",
                        isnan(d->radius1) ? "R1" : "R2");
    if (!isfinite(d->thickness))
        return lp__fail(err, LP_ERROR_INVALID_LENS, "thickness is not a finite number");
    if (!(d->thickness > 0.0))
        return lp__fail(err, LP_ERROR_INVALID_LENS, "thickness %g mm must be > 0",
                        d->thickness);
    if (!isfinite(d->diameter) || !(d->diameter > 0.0))
        return lp__fail(err, LP_ERROR_INVALID_LENS, "diameter D=%g mm must be a finite number > 0",
                        d->diameter);
    if (!isfinite(d->diameter2) || d->diameter2 < 0.0)
        return lp__fail(err, LP_ERROR_INVALID_LENS,
                        "diameter D2=%g mm must be a finite number > 0 (or 0 for D2 = D)",
                        d->diameter2);
    if (!v3_finite(d->position))
        return lp__fail(err, LP_ERROR_INVALID_LENS, "lens position is not finite");
    if (!v3_finite(d->axis) || !(v3_len(d->axis) > 0.0))
        return lp__fail(err, LP_ERROR_INVALID_LENS, "lens axis must be a finite non-zero vector");
    return LP_OK;
}

lp_status lp_lens_create(const lp_lens_desc *desc, lp_lens **out, lp_error *err)
{
    lp_status st;
    lp_lens *lens;

    if (out)
        *out = NULL;
    if (!desc || !out)
        return lp__fail(err, LP_ERROR_INVALID_ARGUMENT, "lp_lens_create: NULL argument");
    if ((st = check_shape(desc, err)) != LP_OK)
        return st;
    if (desc->uniaxial != 0 && desc->uniaxial != 1)
        return lp__fail(err, LP_ERROR_INVALID_LENS, "uniaxial must be 0 or 1, got %d",
                        desc->uniaxial);
    if ((st = desc->uniaxial ? lp_crystal_check(&desc->crystal, err)
                             : lp_glass_check(&desc->glass, err)) != LP_OK)
        return st;
    if ((st = lp_glass_check(&desc->medium, err)) != LP_OK)
        return st;

    double c1 = curvature(desc->radius1), c2 = curvature(desc->radius2);
    double t = desc->thickness;
    double h1 = 0.5 * desc->diameter;
    double h2 = 0.5 * (desc->diameter2 > 0.0 ? desc->diameter2 : desc->diameter);

    if (c1 != 0.0 && h1 > fabs(desc->radius1))
        return lp__fail(err, LP_ERROR_INVALID_LENS,
                        "front cap diameter %g mm is wider than its sphere (|R1| = %g mm)",
                        2.0 * h1, fabs(desc->radius1));
    if (c2 != 0.0 && h2 > fabs(desc->radius2))
        return lp__fail(err, LP_ERROR_INVALID_LENS,
                        "back cap diameter %g mm is wider than its sphere (|R2| = %g mm)",
                        2.0 * h2, fabs(desc->radius2));

    double scale = fmax(t, fmax(2.0 * h1, 2.0 * h2));
    double tol = 1e-12 * scale;
    /* The axial thickness T(r) = t + sag2(r) - sag1(r) is monotonic in r
     * (its derivative has the sign of c2 - c1), so checking the smaller
     * aperture's edge covers the whole common aperture. */
    double hmin = fmin(h1, h2);
    double t_at_hmin = t + lp__cap_sag(c2, hmin) - lp__cap_sag(c1, hmin);
    if (t_at_hmin < -tol)
        return lp__fail(err, LP_ERROR_INVALID_LENS,
                        "the caps cross before the rim: thickness at r = %g mm is %g mm",
                        hmin, t_at_hmin);
    double z1e = lp__cap_sag(c1, h1);
    double z2e = t + lp__cap_sag(c2, h2);
    double edge = z2e - z1e;
    double slack = 1e-12 * (edge + h1 + h2); /* the rim's */

    lens = calloc(1, sizeof *lens);
    if (!lens)
        return lp__fail(err, LP_ERROR_NO_MEMORY, "out of memory creating a lens");
    lens->desc = *desc;
    lens->desc.diameter2 = 2.0 * h2;
    if (desc->uniaxial)
        lens->desc.crystal.axis = v3_normalize(desc->crystal.axis);
    lens->cap[LP_SURFACE_FRONT] = (lp__cap){c1, 0.0, h1, +1.0};
    lens->cap[LP_SURFACE_BACK] = (lp__cap){c2, t, h2, -1.0};

    if (h1 == h2) {
        if (edge < -tol) {
            free(lens);
            return lp__fail(err, LP_ERROR_INVALID_LENS,
                            "the caps cross before the rim: edge thickness %g mm", edge);
        }
        if (edge > tol) {
            lens->rim = (lp__rim){1, z1e, h1, z2e, h2, 0.0, slack};
        } else {
            lens->rim.present = 0; /* knife edge */
        }
    } else {
        if (!(edge > tol)) {
            free(lens);
            return lp__fail(err, LP_ERROR_INVALID_LENS,
                            "a conical rim (D2 != D) needs a positive edge thickness, got %g mm",
                            edge);
        }
        lens->rim = (lp__rim){1, z1e, h1, z2e, h2, (h2 - h1) / edge, slack};
        /* The cone must stay behind the wider cap between the two edges. */
        for (int i = 1; i < 64; i++) {
            double f = i / 64.0;
            double r = h1 + f * (h2 - h1);
            double zc = z1e + f * edge;
            int bad = h1 > h2 ? zc < lp__cap_sag(c1, r) - tol
                              : zc > t + lp__cap_sag(c2, r) + tol;
            if (bad) {
                free(lens);
                return lp__fail(err, LP_ERROR_INVALID_LENS,
                                "the conical rim cuts through the %s cap at r = %g mm",
                                h1 > h2 ? "front" : "back", r);
            }
        }
    }

    lens->z_min = fmin(0.0, fmin(z1e, z2e));
    lens->z_max = fmax(t, fmax(z1e, z2e));
    lens->h_max = fmax(h1, h2);
    lens->scale = fmax(scale, lens->z_max - lens->z_min);
    lens->eps = 1e-12 * lens->scale;

    lens->w = v3_normalize(desc->axis);
    lens->desc.axis = lens->w;
    lens->u = v3_any_perp(lens->w);
    lens->v = v3_cross(lens->w, lens->u);
    if (desc->uniaxial)
        lens->crystal_axis = lp__to_local_dir(lens, lens->desc.crystal.axis);
    lp__glass_ln_tau(desc->uniaxial ? &lens->desc.crystal.ordinary : &lens->desc.glass,
                     lens->ln_tau);
    {
        double hz = 0.5 * (lens->z_max - lens->z_min);
        double r = sqrt(lens->h_max * lens->h_max + hz * hz) * (1.0 + 1e-9) + 4.0 * lens->eps;
        lens->bound_center = lp__to_world_point(lens, v3(0.0, 0.0, lens->z_min + hz));
        lens->bound_r2 = r * r;
    }
    *out = lens;
    lp__ok(err);
    return LP_OK;
}

void lp_lens_destroy(lp_lens *lens)
{
    free(lens);
}

void lp_lens_get_desc(const lp_lens *lens, lp_lens_desc *out)
{
    if (lens && out)
        *out = lens->desc;
}

double lp_lens_edge_thickness(const lp_lens *lens)
{
    if (!lens)
        return NAN;
    return lens->rim.present ? lens->rim.z_b - lens->rim.z_a : 0.0;
}

void lp_lens_bounds(const lp_lens *lens, lp_vec3 *lo, lp_vec3 *hi)
{
    lp_vec3 a = v3(INFINITY, INFINITY, INFINITY), b = v3(-INFINITY, -INFINITY, -INFINITY);
    if (!lens)
        return;
    for (int i = 0; i < 8; i++) {
        lp_vec3 c = v3(i & 1 ? lens->h_max : -lens->h_max, i & 2 ? lens->h_max : -lens->h_max,
                       i & 4 ? lens->z_max : lens->z_min);
        lp_vec3 w = lp__to_world_point(lens, c);
        a = v3(fmin(a.x, w.x), fmin(a.y, w.y), fmin(a.z, w.z));
        b = v3(fmax(b.x, w.x), fmax(b.y, w.y), fmax(b.z, w.z));
    }
    if (lo)
        *lo = a;
    if (hi)
        *hi = b;
}

/* Is the local point p strictly inside the rim's solid cone (or
 * cylinder) r < rho(z), by a relative margin far above rounding?  That
 * solid is convex, so a segment between two such points cannot cross the
 * rim, and its intersection test can be skipped. */
static int inside_rim(const lp__rim *rim, lp_vec3 p)
{
    double rho = rim->rho_a + rim->k * (p.z - rim->z_a);
    return rho > 0.0 && p.x * p.x + p.y * p.y < rho * rho * (1.0 - 1e-9);
}

int lp__lens_hit(const lp_lens *lens, lp_vec3 p, lp_vec3 d, int from_surface,
                 double t_min, double t_max, lp__local_hit *hit)
{
    double best = t_max, t;
    int surface = LP_SURFACE_NONE;
    /* A ray leaving a surface ignores hits on the others closer than eps. */
    double t_other = from_surface == LP_SURFACE_NONE ? t_min : lp__max(t_min, lens->eps);

    for (int s = LP_SURFACE_FRONT; s <= LP_SURFACE_BACK; s++) {
        int self = s == from_surface;
        if (lp__cap_intersect(&lens->cap[s], p, d, self, self ? t_min : t_other, best, &t)) {
            best = t;
            surface = s;
        }
    }
    lp_vec3 x = v3_madd(p, d, best);
    /* The rim's test is skipped where it cannot find a hit: a segment
     * between two cap points inside the rim's solid, or a ray meeting no
     * cap that leaves the rim's z range behind. */
    const lp__rim *rim = &lens->rim;
    int rim_possible =
        rim->present && (surface == LP_SURFACE_NONE
                             ? !(t_other >= 0.0 && lp__rim_beyond(rim, p, d))
                             : !(from_surface != LP_SURFACE_NONE && inside_rim(rim, p) &&
                                 inside_rim(rim, x)));
    double t_rim = surface == LP_SURFACE_NONE ? best : lp__rim_t_max(best, lens->eps);
    if (rim_possible && lp__rim_intersect(rim, p, d, t_other, t_rim, &t)) {
        best = t;
        surface = LP_SURFACE_RIM;
        x = v3_madd(p, d, best);
    }
    if (surface == LP_SURFACE_NONE)
        return 0;
    hit->t = best;
    hit->p = x;
    hit->surface = surface;
    hit->n = surface == LP_SURFACE_RIM ? lp__rim_normal(rim, hit->p)
                                       : lp__cap_normal(&lens->cap[surface], hit->p);
    return 1;
}

int lp__lens_surface_at(const lp_lens *lens, lp_vec3 p)
{
    double tol = 8.0 * lens->eps;
    double r2 = p.x * p.x + p.y * p.y;
    for (int s = LP_SURFACE_FRONT; s <= LP_SURFACE_BACK; s++) {
        const lp__cap *cap = &lens->cap[s];
        double z = p.z - cap->z0;
        /* |grad F| = 2 on the surface, so |F|/2 is the distance to first order */
        double f = cap->c * (r2 + z * z) - 2.0 * z;
        if (fabs(f) <= 2.0 * tol && r2 <= cap->h * cap->h * (1.0 + 1e-12) + tol &&
            cap->c * z <= 1.0)
            return s;
    }
    if (lens->rim.present) {
        const lp__rim *rim = &lens->rim;
        double rho = rim->rho_a + rim->k * (p.z - rim->z_a);
        if (fabs(sqrt(r2) - rho) <= tol && p.z >= rim->z_a - tol && p.z <= rim->z_b + tol)
            return LP_SURFACE_RIM;
    }
    return LP_SURFACE_NONE;
}

/* The ray origin + t d (d unit, world) in the local frame: *p and *dl,
 * and the surface the origin lies on. */
static inline int local_ray(const lp_lens *lens, lp_vec3 origin, lp_vec3 d, lp_vec3 *p,
                            lp_vec3 *dl)
{
    *p = lp__to_local_point(lens, origin);
    *dl = lp__to_local_dir(lens, d);
    return lp__lens_surface_at(lens, *p);
}

int lp_lens_intersect(const lp_lens *lens, lp_vec3 origin, lp_vec3 dir, double t_min,
                      double t_max, lp_hit *hit)
{
    lp__local_hit h;
    if (!lens || !hit || !v3_finite(origin) || !v3_finite(dir) || isnan(t_min) || isnan(t_max))
        return 0;
    lp_vec3 d = v3_normalize(dir);
    if (d.x == 0.0 && d.y == 0.0 && d.z == 0.0)
        return 0;
    /* A ray from outside the bounding sphere that misses it, or leaves
     * it, cannot meet the lens. */
    lp_vec3 oc = v3_sub(origin, lens->bound_center);
    double b = v3_dot(oc, d), c = v3_dot(oc, oc) - lens->bound_r2;
    if (c > 0.0 && (b > 0.0 || b * b < c))
        return 0;
    lp_vec3 p, dl;
    int from = local_ray(lens, origin, d, &p, &dl);
    if (!lp__lens_hit(lens, p, dl, from, t_min, t_max, &h))
        return 0;
    hit->t = h.t;
    hit->point = v3_madd(origin, d, h.t);
    hit->normal = lp__to_world_dir(lens, h.n);
    hit->surface = h.surface;
    return 1;
}

int lp__lens_leaves(const lp_lens *lens, lp_vec3 origin, lp_vec3 dir)
{
    lp__local_hit h;
    lp_vec3 p, dl;
    int from = local_ray(lens, origin, v3_normalize(dir), &p, &dl);
    if (from != LP_SURFACE_FRONT && from != LP_SURFACE_BACK)
        return 0;
    return !lp__lens_hit(lens, p, dl, from, 0.0, INFINITY, &h);
}

int lp_lens_contains(const lp_lens *lens, lp_vec3 point)
{
    if (!lens || !v3_finite(point))
        return 0;
    lp_vec3 p = lp__to_local_point(lens, point);
    if (!(p.z > lens->z_min && p.z < lens->z_max))
        return 0;
    double r2 = p.x * p.x + p.y * p.y;
    const lp__cap *f = &lens->cap[LP_SURFACE_FRONT], *b = &lens->cap[LP_SURFACE_BACK];
    /* behind the front cap: c1(r^2 + z^2) - 2z < 0; before the back cap:
     * c2(r^2 + (z-t)^2) - 2(z-t) > 0 */
    if (!(f->c * (r2 + p.z * p.z) - 2.0 * p.z < 0.0))
        return 0;
    double zb = p.z - b->z0;
    if (!(b->c * (r2 + zb * zb) - 2.0 * zb > 0.0))
        return 0;
    double rho;
    if (lens->rim.present) {
        const lp__rim *rim = &lens->rim;
        rho = rim->rho_a + rim->k * (p.z - rim->z_a);
        rho = fmin(rho, lens->h_max);
    } else {
        rho = f->h;
    }
    return r2 < rho * rho;
}
