/* bvh.c -- a bounding volume hierarchy over a scene's objects.
 *
 * The tree is stored flat, depth first: a node's first child follows it,
 * its second child is at `second`.  Boxes are widened by a relative 1e-9
 * so that rounding in the slab test never loses a hit the object itself
 * would report. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "csg.h"

typedef struct bvh_node {
    double lo[3], hi[3];
    int second;     /* inner: index of the second child; leaf: -1 */
    int axis;       /* inner: the split axis */
    int first, count; /* leaf: obj[first .. first + count) */
} bvh_node;

struct rs_bvh {
    bvh_node *node;
    size_t n_nodes;
    int *obj;         /* object indices, leaves' ranges */
    int *unbounded;   /* objects tried for every ray, in index order */
    size_t n_unbounded;
    size_t n_objects; /* of the scene it was built on */
    double (*box)[6]; /* per object: lo, hi (rs_bvh_may_meet) */
    unsigned char *cull; /* per object: rs_bvh_may_meet tests its box */
};

typedef struct item {
    double lo[3], hi[3], c[3];
    int object;
} item;

static void box_point(double lo[3], double hi[3], lp_vec3 p)
{
    double v[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; k++) {
        lo[k] = v[k] < lo[k] ? v[k] : lo[k];
        hi[k] = v[k] > hi[k] ? v[k] : hi[k];
    }
}

/* The world box of the object-space box with corners a and b under xf. */
static void xf_box(const rs_transform *xf, lp_vec3 a, lp_vec3 b, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (int i = 0; i < 8; i++) {
        lp_vec3 p = {i & 1 ? b.x : a.x, i & 2 ? b.y : a.y, i & 4 ? b.z : a.z};
        box_point(lo, hi, rs_xf_point(xf, p));
    }
}

int rs_object_bounds(const rs_object *o, lp_vec3 *lo_out, lp_vec3 *hi_out)
{
    double lo[3], hi[3];
    lp_vec3 c, a, b;
    double r;

    switch (o->type) {
    case RS_OBJ_SPHERE:
    case RS_OBJ_DISC: /* both inside the cube of half-side r about c */
        c = o->type == RS_OBJ_SPHERE ? o->u.sphere.center : o->u.disc.center;
        r = fabs(o->type == RS_OBJ_SPHERE ? o->u.sphere.radius : o->u.disc.radius);
        a = (lp_vec3){c.x - r, c.y - r, c.z - r};
        b = (lp_vec3){c.x + r, c.y + r, c.z + r};
        xf_box(&o->xf, a, b, lo, hi);
        break;
    case RS_OBJ_BOX:
        xf_box(&o->xf, o->u.box.corner1, o->u.box.corner2, lo, hi);
        break;
    case RS_OBJ_CYLINDER:
    case RS_OBJ_CONE: { /* the hull of two end discs: inside their cubes */
        int cyl = o->type == RS_OBJ_CYLINDER;
        lp_vec3 p0 = cyl ? o->u.cylinder.base : o->u.cone.base;
        lp_vec3 p1 = cyl ? o->u.cylinder.cap : o->u.cone.cap;
        double r0 = fabs(cyl ? o->u.cylinder.radius : o->u.cone.base_radius);
        double r1 = fabs(cyl ? o->u.cylinder.radius : o->u.cone.cap_radius);
        double l2[3], h2[3];
        xf_box(&o->xf, (lp_vec3){p0.x - r0, p0.y - r0, p0.z - r0},
               (lp_vec3){p0.x + r0, p0.y + r0, p0.z + r0}, lo, hi);
        xf_box(&o->xf, (lp_vec3){p1.x - r1, p1.y - r1, p1.z - r1},
               (lp_vec3){p1.x + r1, p1.y + r1, p1.z + r1}, l2, h2);
        for (int k = 0; k < 3; k++) {
            lo[k] = l2[k] < lo[k] ? l2[k] : lo[k];
            hi[k] = h2[k] > hi[k] ? h2[k] : hi[k];
        }
        break;
    }
    case RS_OBJ_TORUS: /* about y: |x|, |z| <= major + minor, |y| <= minor */
        r = fabs(o->u.torus.major) + fabs(o->u.torus.minor);
        a = (lp_vec3){-r, -fabs(o->u.torus.minor), -r};
        b = (lp_vec3){r, fabs(o->u.torus.minor), r};
        xf_box(&o->xf, a, b, lo, hi);
        break;
    case RS_OBJ_POLARIZER:
        c = o->u.polarizer.center;
        r = fabs(o->u.polarizer.radius);
        lo[0] = c.x - r, lo[1] = c.y - r, lo[2] = c.z - r;
        hi[0] = c.x + r, hi[1] = c.y + r, hi[2] = c.z + r;
        break;
    case RS_OBJ_LENS:
        if (!o->lens)
            return 0;
        lp_lens_bounds(o->lens, &a, &b);
        lo[0] = a.x, lo[1] = a.y, lo[2] = a.z;
        hi[0] = b.x, hi[1] = b.y, hi[2] = b.z;
        break;
    case RS_OBJ_CSG: /* from its members' boxes (csg.h) */
        if (!rs_csg_bounds(o, rs_object_bounds, &a, &b))
            return 0;
        lo[0] = a.x, lo[1] = a.y, lo[2] = a.z;
        hi[0] = b.x, hi[1] = b.y, hi[2] = b.z;
        break;
    default:
        return 0; /* planes, and anything without a known finite bound */
    }
    for (int k = 0; k < 3; k++) {
        if (!isfinite(lo[k]) || !isfinite(hi[k]) || !(lo[k] <= hi[k]))
            return 0;
        double pad = 1e-9 * (fabs(lo[k]) + fabs(hi[k]) + (hi[k] - lo[k])) + 1e-300;
        lo[k] -= pad;
        hi[k] += pad;
    }
    *lo_out = (lp_vec3){lo[0], lo[1], lo[2]};
    *hi_out = (lp_vec3){hi[0], hi[1], hi[2]};
    return 1;
}

/* a before b along the axis (centres, then object index: a strict order,
 * so the tree does not depend on the input's order beyond it). */
static int before(const item *a, const item *b, int axis)
{
    if (a->c[axis] != b->c[axis])
        return a->c[axis] < b->c[axis];
    return a->object < b->object;
}

static void swap_items(item *a, item *b)
{
    item t = *a;
    *a = *b;
    *b = t;
}

/* Reorder items[0..n) so that items[k] is the one a sort along the axis
 * would put there, the ones before it not after it and the ones after it
 * not before it (Hoare's selection, middle pivot). */
static void select_kth(item *items, size_t n, size_t k, int axis)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        swap_items(&items[lo + (hi - lo) / 2], &items[hi]);
        size_t store = lo;
        for (size_t i = lo; i < hi; i++)
            if (before(&items[i], &items[hi], axis))
                swap_items(&items[i], &items[store++]);
        swap_items(&items[store], &items[hi]);
        if (store == k)
            return;
        if (store < k)
            lo = store + 1;
        else
            hi = store - 1;
    }
}

/* Build the subtree of items[0..n) at node index `at`; returns the index
 * after its last node.  The items are split in place at their median
 * along the axis where their centres spread most. */
static size_t build(rs_bvh *b, item *items, size_t n, size_t first, size_t at)
{
    bvh_node *nd = &b->node[at];
    for (int k = 0; k < 3; k++) {
        nd->lo[k] = INFINITY;
        nd->hi[k] = -INFINITY;
    }
    double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            nd->lo[k] = items[i].lo[k] < nd->lo[k] ? items[i].lo[k] : nd->lo[k];
            nd->hi[k] = items[i].hi[k] > nd->hi[k] ? items[i].hi[k] : nd->hi[k];
            clo[k] = items[i].c[k] < clo[k] ? items[i].c[k] : clo[k];
            chi[k] = items[i].c[k] > chi[k] ? items[i].c[k] : chi[k];
        }
    if (n <= RS_BVH_LEAF) {
        nd->second = -1;
        nd->axis = 0;
        nd->first = (int)first;
        nd->count = (int)n;
        for (size_t i = 0; i < n; i++)
            b->obj[first + i] = items[i].object;
        return at + 1;
    }
    int axis = 0;
    for (int k = 1; k < 3; k++)
        if (chi[k] - clo[k] > chi[axis] - clo[axis])
            axis = k;
    size_t half = n / 2;
    select_kth(items, n, half, axis);
    nd->axis = axis;
    nd->first = nd->count = 0;
    size_t next = build(b, items, half, first, at + 1);
    b->node[at].second = (int)next;
    return build(b, items + half, n - half, first + half, next);
}

int rs_bvh_build(const rs_scene *scene, rs_bvh **out)
{
    size_t n = scene->n_objects, n_items = 0;
    rs_bvh *b = calloc(1, sizeof *b);
    item *items = calloc(n ? n : 1, sizeof *items);
    *out = NULL;
    if (!b || !items)
        goto fail;
    b->obj = calloc(n ? n : 1, sizeof *b->obj);
    b->unbounded = calloc(n ? n : 1, sizeof *b->unbounded);
    b->node = calloc(n ? 2 * n : 1, sizeof *b->node);
    b->box = calloc(n ? n : 1, sizeof *b->box);
    b->cull = calloc(n ? n : 1, 1);
    if (!b->obj || !b->unbounded || !b->node || !b->box || !b->cull)
        goto fail;
    for (size_t i = 0; i < n; i++) {
        lp_vec3 lo, hi;
        const rs_object *o = &scene->objects[i];
        if (!rs_object_bounds(o, &lo, &hi)) {
            b->unbounded[b->n_unbounded++] = (int)i;
            continue;
        }
        b->cull[i] = o->type == RS_OBJ_LENS || o->type == RS_OBJ_CSG || o->type == RS_OBJ_TORUS ||
                     o->type == RS_OBJ_CYLINDER || o->type == RS_OBJ_CONE;
        double *bx = b->box[i];
        bx[0] = lo.x, bx[1] = lo.y, bx[2] = lo.z, bx[3] = hi.x, bx[4] = hi.y, bx[5] = hi.z;
        item *it = &items[n_items++];
        it->lo[0] = lo.x, it->lo[1] = lo.y, it->lo[2] = lo.z;
        it->hi[0] = hi.x, it->hi[1] = hi.y, it->hi[2] = hi.z;
        for (int k = 0; k < 3; k++)
            it->c[k] = 0.5 * (it->lo[k] + it->hi[k]);
        it->object = (int)i;
    }
    b->n_nodes = n_items ? build(b, items, n_items, 0, 0) : 0;
    b->n_objects = n;
    free(items);
    *out = b;
    return 0;
fail:
    free(items);
    rs_bvh_destroy(b);
    return -1;
}

void rs_bvh_destroy(rs_bvh *b)
{
    if (!b)
        return;
    free(b->node);
    free(b->obj);
    free(b->unbounded);
    free(b->box);
    free(b->cull);
    free(b);
}

int rs_bvh_serves(const rs_bvh *b, const rs_scene *scene)
{
    return b && b->n_objects == scene->n_objects &&
           b->n_objects - b->n_unbounded >= RS_BVH_MIN_BOUNDED;
}

size_t rs_bvh_node_count(const rs_bvh *b) { return b ? b->n_nodes : 0; }
size_t rs_bvh_object_count(const rs_bvh *b) { return b ? b->n_objects : 0; }
size_t rs_bvh_unbounded_count(const rs_bvh *b) { return b ? b->n_unbounded : 0; }

typedef rs_slab_ray slab_ray;

void rs_slab_ray_init(slab_ray *r, lp_vec3 o, lp_vec3 d)
{
    double oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
    for (int k = 0; k < 3; k++) {
        r->o[k] = oo[k];
        r->zero[k] = dd[k] == 0.0;
        r->inv[k] = r->zero[k] ? 0.0 : 1.0 / dd[k];
    }
}

/* Does the segment t in [t0, t1] meet the box lo..hi?  (A direction
 * component 0 makes that slab a containment test.) */
static int slab_box(const slab_ray *r, const double *lo, const double *hi, double t0, double t1)
{
    for (int k = 0; k < 3; k++) {
        if (r->zero[k]) {
            if (r->o[k] < lo[k] || r->o[k] > hi[k])
                return 0;
            continue;
        }
        double a = (lo[k] - r->o[k]) * r->inv[k], b = (hi[k] - r->o[k]) * r->inv[k];
        if (a > b) {
            double s = a;
            a = b;
            b = s;
        }
        t0 = a > t0 ? a : t0;
        t1 = b < t1 ? b : t1;
        if (t0 > t1)
            return 0;
    }
    return 1;
}

static int slab_hit(const slab_ray *r, const bvh_node *nd, double t0, double t1)
{
    return slab_box(r, nd->lo, nd->hi, t0, t1);
}

int rs_bvh_culls(const rs_bvh *b, int i)
{
    return b && i >= 0 && (size_t)i < b->n_objects && b->cull[i];
}

int rs_bvh_may_meet(const rs_bvh *b, int i, const slab_ray *r, double t_min, double t_max)
{
    if (!rs_bvh_culls(b, i))
        return 1;
    return slab_box(r, b->box[i], b->box[i] + 3, t_min, t_max);
}

/* nextafter(x, +infinity), inline for the common finite x > 0. */
static double next_up(double x)
{
    if (!(x > 0.0) || !(x < INFINITY))
        return nextafter(x, INFINITY);
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    u++;
    memcpy(&x, &u, sizeof x);
    return x;
}

/* Try object i against the best hit so far: a nearer hit, or an equally
 * near one of a lower index, replaces it. */
static void try_object(const rs_scene *scene, int i, lp_vec3 origin, lp_vec3 dir, double t_min,
                       rs_hit *best, int *found)
{
    rs_hit h;
    /* an equally near hit counts only for a lower index than the best's */
    double t_lim = *found && i < best->object ? next_up(best->t) : best->t;
    if (!rs_object_intersect(&scene->objects[i], origin, dir, t_min, t_lim, &h))
        return;
    if (*found && !(h.t < best->t || (h.t == best->t && i < best->object)))
        return;
    h.object = i;
    *best = h;
    *found = 1;
}

int rs_bvh_intersect(const rs_bvh *b, const rs_scene *scene, lp_vec3 origin, lp_vec3 dir,
                     double t_min, double t_max, int skip, rs_hit *hit)
{
    rs_hit best;
    int found = 0, stack[128], sp = 0;
    slab_ray r;

    best.t = t_max;
    best.object = -1;
    for (size_t u = 0; u < b->n_unbounded; u++)
        if (b->unbounded[u] != skip)
            try_object(scene, b->unbounded[u], origin, dir, t_min, &best, &found);
    if (b->n_nodes > 0) {
        rs_slab_ray_init(&r, origin, dir);
        stack[sp++] = 0;
    }
    while (sp > 0) {
        const bvh_node *nd = &b->node[stack[--sp]];
        if (!slab_hit(&r, nd, t_min, best.t))
            continue;
        if (nd->second < 0) {
            for (int k = 0; k < nd->count; k++) {
                int i = b->obj[nd->first + k];
                if (i != skip)
                    try_object(scene, i, origin, dir, t_min, &best, &found);
            }
            continue;
        }
        /* Visit the child on the ray's side of the split first. */
        int near = (int)(nd - b->node) + 1, far = nd->second;
        if (r.inv[nd->axis] < 0.0) {
            int s = near;
            near = far;
            far = s;
        }
        if (sp + 2 > (int)(sizeof stack / sizeof stack[0]))
            break; /* cannot happen: median splits keep the depth below 64 */
        stack[sp++] = far;
        stack[sp++] = near;
    }
    if (found)
        *hit = best;
    return found;
}

int rs_bvh_any(const rs_bvh *b, lp_vec3 origin, lp_vec3 dir, double t_min, double t_max,
               rs_bvh_visit_fn fn, void *ctx)
{
    int stack[128], sp = 0, v;
    slab_ray r;

    for (size_t u = 0; u < b->n_unbounded; u++)
        if ((v = fn(ctx, b->unbounded[u])) != 0)
            return v;
    if (b->n_nodes > 0) {
        rs_slab_ray_init(&r, origin, dir);
        stack[sp++] = 0;
    }
    while (sp > 0) {
        const bvh_node *nd = &b->node[stack[--sp]];
        if (!slab_hit(&r, nd, t_min, t_max))
            continue;
        if (nd->second < 0) {
            for (int k = 0; k < nd->count; k++)
                if ((v = fn(ctx, b->obj[nd->first + k])) != 0)
                    return v;
            continue;
        }
        if (sp + 2 > (int)(sizeof stack / sizeof stack[0]))
            break;
        stack[sp++] = nd->second;
        stack[sp++] = (int)(nd - b->node) + 1;
    }
    return 0;
}
