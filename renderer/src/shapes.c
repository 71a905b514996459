/* shapes.c -- planes, spheres, boxes, discs, cylinders, cones, tori,
 * polarizers and lenses (round_shapes.c has the cylinder, cone and torus,
 * csg.c the intersections and differences).
 *
 * Plane, sphere, box and disc are intersected in object space: the world
 * ray is mapped by the inverse transform without renormalizing its
 * direction, so the parameter t is the same in both spaces.  Normals go
 * back by the inverse transpose.  Lenses and polarizers carry their
 * placement in their parameters. */
#include <math.h>

#include "bvh.h"
#include "csg.h"
#include "round_shapes.h"
#include "shapes.h"
#include "support/vec.h"


/* Smallest root of a t^2 + 2 b t + c = 0 in (t0, t1). */
static int quadratic(double a, double b, double c, double t0, double t1, double *t)
{
    double disc = b * b - a * c;
    if (disc < 0.0 || a == 0.0)
        return 0;
    double q = -(b + copysign(sqrt(disc), b));
    double r0 = c / q, r1 = q / a;
    if (q == 0.0)
        r0 = r1;
    if (r0 > r1) {
        double s = r0;
        r0 = r1;
        r1 = s;
    }
    if (r0 > t0 && r0 < t1) {
        *t = r0;
        return 1;
    }
    if (r1 > t0 && r1 < t1) {
        *t = r1;
        return 1;
    }
    return 0;
}

static int disc_hit(lp_vec3 c, lp_vec3 n, double radius, double hole, lp_vec3 o, lp_vec3 d,
                    double t0, double t1, double *t)
{
    double dn = v3_dot(d, n);
    if (dn == 0.0)
        return 0;
    double s = v3_dot(v3_sub(c, o), n) / dn;
    if (!(s > t0 && s < t1))
        return 0;
    lp_vec3 p = v3_sub(v3_madd(o, d, s), c);
    double r2 = v3_dot(p, p);
    if (r2 > radius * radius || r2 < hole * hole)
        return 0;
    *t = s;
    return 1;
}

int rs_object_intersect(const rs_object *ob, lp_vec3 origin, lp_vec3 dir, double t_min,
                        double t_max, rs_hit *hit)
{
    double t;
    lp_vec3 n_obj;

    if (ob->type == RS_OBJ_CSG)
        return rs_csg_intersect(ob, origin, dir, t_min, t_max, hit);
    hit->surface = ob;
    if (ob->type == RS_OBJ_LENS) {
        lp_hit h;
        if (!ob->lens || !lp_lens_intersect(ob->lens, origin, dir, t_min, t_max, &h))
            return 0;
        hit->t = h.t;
        hit->point = h.point;
        hit->normal = v3_dot(h.normal, dir) > 0.0 ? (lp_vec3){-h.normal.x, -h.normal.y, -h.normal.z}
                                                : h.normal;
        hit->lens_surface = h.surface;
        return 1;
    }
    if (ob->type == RS_OBJ_POLARIZER) {
        const lp_vec3 c = ob->u.polarizer.center, n = ob->u.polarizer.normal;
        if (!disc_hit(c, n, ob->u.polarizer.radius, 0.0, origin, dir, t_min, t_max, &t))
            return 0;
        hit->t = t;
        hit->point = v3_madd(origin, dir, t);
        hit->normal = v3_dot(n, dir) > 0.0 ? (lp_vec3){-n.x, -n.y, -n.z} : n;
        hit->lens_surface = LP_SURFACE_NONE;
        return 1;
    }

    lp_vec3 o = rs_xf_inv_point(&ob->xf, origin), d = rs_xf_inv_dir(&ob->xf, dir);
    switch (ob->type) {
    case RS_OBJ_PLANE: {
        lp_vec3 n = ob->u.plane.normal;
        double dn = v3_dot(d, n);
        if (dn == 0.0)
            return 0;
        t = (ob->u.plane.distance * v3_dot(n, n) - v3_dot(o, n)) / dn;
        if (!(t > t_min && t < t_max))
            return 0;
        n_obj = n;
        break;
    }
    case RS_OBJ_SPHERE: {
        lp_vec3 oc = v3_sub(o, ob->u.sphere.center);
        double r = ob->u.sphere.radius;
        if (!quadratic(v3_dot(d, d), v3_dot(oc, d), v3_dot(oc, oc) - r * r, t_min, t_max, &t))
            return 0;
        n_obj = v3_sub(v3_madd(o, d, t), ob->u.sphere.center);
        break;
    }
    case RS_OBJ_BOX: {
        lp_vec3 a = ob->u.box.corner1, b = ob->u.box.corner2;
        double lo[3] = {fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z)};
        double hi[3] = {fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z)};
        double oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
        double tn = -INFINITY, tf = INFINITY;
        int an = -1, af = -1;
        for (int k = 0; k < 3; k++) {
            if (dd[k] == 0.0) {
                if (oo[k] < lo[k] || oo[k] > hi[k])
                    return 0;
                continue;
            }
            double t1 = (lo[k] - oo[k]) / dd[k], t2 = (hi[k] - oo[k]) / dd[k];
            if (t1 > t2) {
                double s = t1;
                t1 = t2;
                t2 = s;
            }
            if (t1 > tn) {
                tn = t1;
                an = k;
            }
            if (t2 < tf) {
                tf = t2;
                af = k;
            }
        }
        if (tn > tf)
            return 0;
        int axis;
        if (tn > t_min && tn < t_max) {
            t = tn;
            axis = an;
        } else if (tf > t_min && tf < t_max) {
            t = tf;
            axis = af;
        } else {
            return 0;
        }
        if (axis < 0)
            return 0;
        n_obj = (lp_vec3){axis == 0, axis == 1, axis == 2};
        break;
    }
    case RS_OBJ_DISC:
        if (!disc_hit(ob->u.disc.center, ob->u.disc.normal, ob->u.disc.radius, ob->u.disc.hole,
                      o, d, t_min, t_max, &t))
            return 0;
        n_obj = ob->u.disc.normal;
        break;
    case RS_OBJ_CYLINDER:
        if (!rs_cone_hit(ob->u.cylinder.base, ob->u.cylinder.radius, ob->u.cylinder.cap,
                         ob->u.cylinder.radius, ob->u.cylinder.open, o, d, t_min, t_max, &t,
                         &n_obj))
            return 0;
        break;
    case RS_OBJ_CONE:
        if (!rs_cone_hit(ob->u.cone.base, ob->u.cone.base_radius, ob->u.cone.cap,
                         ob->u.cone.cap_radius, ob->u.cone.open, o, d, t_min, t_max, &t, &n_obj))
            return 0;
        break;
    case RS_OBJ_TORUS:
        if (!rs_torus_hit(ob->u.torus.major, ob->u.torus.minor, o, d, t_min, t_max, &t, &n_obj))
            return 0;
        break;
    default:
        return 0;
    }
    lp_vec3 n = v3_unit_or_self(rs_xf_normal(&ob->xf, n_obj));
    hit->t = t;
    hit->point = v3_madd(origin, dir, t);
    hit->normal = v3_dot(n, dir) > 0.0 ? (lp_vec3){-n.x, -n.y, -n.z} : n;
    hit->lens_surface = LP_SURFACE_NONE;
    return 1;
}

int rs_scene_intersect(const rs_scene *scene, lp_vec3 origin, lp_vec3 dir, double t_min,
                       double t_max, int skip, rs_hit *hit)
{
    int found = 0;
    rs_hit h;
    rs_slab_ray r;
    if (rs_bvh_serves(scene->bvh, scene))
        return rs_bvh_intersect(scene->bvh, scene, origin, dir, t_min, t_max, skip, hit);
    int boxes = scene->bvh && rs_bvh_object_count(scene->bvh) == scene->n_objects, ready = 0;
    for (size_t i = 0; i < scene->n_objects; i++) {
        if ((int)i == skip)
            continue;
        if (boxes && rs_bvh_culls(scene->bvh, (int)i)) { /* the ray for boxes, once needed */
            if (!ready)
                rs_slab_ray_init(&r, origin, dir);
            ready = 1;
            if (!rs_bvh_may_meet(scene->bvh, (int)i, &r, t_min, t_max))
                continue;
        }
        if (rs_object_intersect(&scene->objects[i], origin, dir, t_min, t_max, &h)) {
            h.object = (int)i;
            *hit = h;
            t_max = h.t;
            found = 1;
        }
    }
    return found;
}
