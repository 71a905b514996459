/* csg.c -- intersection, difference and union as solids (see csg.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "csg.h"
#include "support/vec.h"


/* Inside a cone (a cylinder when r1 = r2) from base to cap, in object
 * space: between the end planes and within the radius there. */
static int inside_cone(lp_vec3 base, double r1, lp_vec3 cap, double r2, lp_vec3 p)
{
    lp_vec3 ax = v3_sub(cap, base), w = v3_sub(p, base);
    double h2 = v3_dot(ax, ax);
    if (!(h2 > 0.0))
        return 0;
    double s = v3_dot(w, ax) / h2, r = r1 + (r2 - r1) * s;
    lp_vec3 q = v3_madd(w, ax, -s);
    return s > 0.0 && s < 1.0 && v3_dot(q, q) < r * r;
}

/* A primitive's inside in its object space (POV-Ray's: an open cylinder
 * or cone is as solid as a closed one). */
static int inside_primitive(const rs_object *o, lp_vec3 p)
{
    switch (o->type) {
    case RS_OBJ_PLANE:
        return v3_dot(o->u.plane.normal, p) < o->u.plane.distance;
    case RS_OBJ_SPHERE: {
        lp_vec3 d = v3_sub(p, o->u.sphere.center);
        return v3_dot(d, d) < o->u.sphere.radius * o->u.sphere.radius;
    }
    case RS_OBJ_BOX: {
        lp_vec3 a = o->u.box.corner1, b = o->u.box.corner2;
        return p.x > fmin(a.x, b.x) && p.x < fmax(a.x, b.x) && p.y > fmin(a.y, b.y) &&
               p.y < fmax(a.y, b.y) && p.z > fmin(a.z, b.z) && p.z < fmax(a.z, b.z);
    }
    case RS_OBJ_CYLINDER:
        return inside_cone(o->u.cylinder.base, o->u.cylinder.radius, o->u.cylinder.cap,
                           o->u.cylinder.radius, p);
    case RS_OBJ_CONE:
        return inside_cone(o->u.cone.base, o->u.cone.base_radius, o->u.cone.cap,
                           o->u.cone.cap_radius, p);
    case RS_OBJ_TORUS: {
        double rho = sqrt(p.x * p.x + p.z * p.z) - o->u.torus.major;
        return rho * rho + p.y * p.y < o->u.torus.minor * o->u.torus.minor;
    }
    default:
        return 0; /* discs, lenses, polarizers: no inside */
    }
}

int rs_object_inside(const rs_object *o, lp_vec3 p)
{
    int in;
    if (o->type != RS_OBJ_CSG) {
        if (o->type == RS_OBJ_DISC || o->type == RS_OBJ_LENS || o->type == RS_OBJ_POLARIZER)
            return 0;
        in = inside_primitive(o, rs_xf_inv_point(&o->xf, p));
        return in != o->inverse;
    }
    const rs_object *m = o->u.csg.members;
    size_t n = o->u.csg.n_members;
    switch (o->u.csg.op) {
    case RS_CSG_UNION:
        in = 0;
        for (size_t i = 0; i < n && !in; i++)
            in = rs_object_inside(&m[i], p);
        break;
    case RS_CSG_INTERSECTION:
        in = n > 0;
        for (size_t i = 0; i < n && in; i++)
            in = rs_object_inside(&m[i], p);
        break;
    default: /* difference */
        in = n > 0 && rs_object_inside(&m[0], p);
        for (size_t i = 1; i < n && in; i++)
            in = !rs_object_inside(&m[i], p);
        break;
    }
    return in != o->inverse;
}

int rs_csg_intersect(const rs_object *o, lp_vec3 origin, lp_vec3 dir, double t_min,
                     double t_max, rs_hit *hit)
{
    double best = t_max;
    int found = 0;
    for (size_t i = 0; i < o->u.csg.n_members; i++) {
        const rs_object *m = &o->u.csg.members[i];
        double t = t_min;
        /* the member's crossings in order, up to the nearest found so far:
         * each root is found again exactly from the same ray, so t_min =
         * the last root (exclusive) moves on to the next one */
        for (int k = 0; k < RS_CSG_MAX_CROSSINGS; k++) {
            rs_hit h;
            if (!rs_object_intersect(m, origin, dir, t, best, &h))
                break;
            t = h.t;
            double e = RS_CSG_STEP * (1.0 + sqrt(v3_dot(h.point, h.point)));
            if (rs_object_inside(o, v3_madd(h.point, dir, -e)) !=
                rs_object_inside(o, v3_madd(h.point, dir, e))) {
                *hit = h;
                best = h.t;
                found = 1;
                break;
            }
        }
    }
    return found;
}

static lp_vec3 vmin(lp_vec3 a, lp_vec3 b)
{
    return (lp_vec3){fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z)};
}

static lp_vec3 vmax(lp_vec3 a, lp_vec3 b)
{
    return (lp_vec3){fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z)};
}

/* A member's box; none for an inverted one (it reaches infinity). */
static int member_box(const rs_object *m, rs_bounds_fn member_bounds, lp_vec3 *lo, lp_vec3 *hi)
{
    return !m->inverse && member_bounds(m, lo, hi);
}

int rs_csg_bounds(const rs_object *o, rs_bounds_fn member_bounds, lp_vec3 *lo, lp_vec3 *hi)
{
    const rs_object *m = o->u.csg.members;
    size_t n = o->u.csg.n_members;
    lp_vec3 a = {0, 0, 0}, b = {0, 0, 0}, ma, mb;
    int have = 0;

    if (o->inverse || n == 0)
        return 0;
    if (o->u.csg.op == RS_CSG_DIFFERENCE) {
        if (!member_box(&m[0], member_bounds, &a, &b))
            return 0;
        *lo = a;
        *hi = b;
        return 1;
    }
    /* an intersection: the common part of the boxes there are; a union:
     * the hull of all of them */
    int inter = o->u.csg.op == RS_CSG_INTERSECTION;
    for (size_t i = 0; i < n; i++) {
        if (!member_box(&m[i], member_bounds, &ma, &mb)) {
            if (inter)
                continue;
            return 0;
        }
        if (!have) {
            a = ma;
            b = mb;
            have = 1;
            continue;
        }
        a = inter ? vmax(a, ma) : vmin(a, ma);
        b = inter ? vmin(b, mb) : vmax(b, mb);
    }
    if (!have)
        return 0;
    if (!(a.x <= b.x && a.y <= b.y && a.z <= b.z)) /* an empty intersection: a point */
        b = a;
    *lo = a;
    *hi = b;
    return 1;
}

int rs_object_copy(rs_object *dst, const rs_object *src)
{
    *dst = *src;
    if (src->type != RS_OBJ_CSG || src->u.csg.n_members == 0)
        return 0;
    size_t n = src->u.csg.n_members;
    rs_object *m = calloc(n, sizeof *m);
    dst->u.csg.members = NULL;
    dst->u.csg.n_members = 0;
    if (m == NULL)
        return -1;
    for (size_t i = 0; i < n; i++) {
        if (rs_object_copy(&m[i], &src->u.csg.members[i]) != 0) {
            for (size_t j = 0; j < i; j++)
                rs_object_release(&m[j]);
            free(m);
            return -1;
        }
    }
    dst->u.csg.members = m;
    dst->u.csg.n_members = n;
    return 0;
}

void rs_object_release(rs_object *o)
{
    if (o->type != RS_OBJ_CSG)
        return;
    for (size_t i = 0; i < o->u.csg.n_members; i++)
        rs_object_release(&o->u.csg.members[i]);
    free(o->u.csg.members);
    o->u.csg.members = NULL;
    o->u.csg.n_members = 0;
}

size_t rs_object_node_count(const rs_object *o)
{
    size_t n = 1;
    if (o->type == RS_OBJ_CSG)
        for (size_t i = 0; i < o->u.csg.n_members; i++)
            n += rs_object_node_count(&o->u.csg.members[i]);
    return n;
}

static void inherit(rs_object *o, const rs_object *tex, const rs_object *interior)
{
    if (o->has_texture)
        tex = o;
    if (o->has_interior)
        interior = o;
    if (o->type == RS_OBJ_CSG) {
        for (size_t i = 0; i < o->u.csg.n_members; i++)
            inherit(&o->u.csg.members[i], tex, interior);
        return;
    }
    if (tex != NULL && tex != o) {
        o->pigment = tex->pigment;
        o->finish = tex->finish;
    }
    if (interior != NULL && interior != o)
        o->ior = interior->ior;
}

void rs_csg_inherit(rs_object *o)
{
    if (o->type == RS_OBJ_CSG)
        inherit(o, NULL, NULL);
}
