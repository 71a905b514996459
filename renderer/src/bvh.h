/* bvh.h -- a bounding volume hierarchy over a scene's objects
 * (renderer-internal).
 *
 * Objects with a finite world bounding box (spheres, boxes, discs,
 * cylinders, cones, tori, lenses, polarizers, CSG objects) go into a binary tree of
 * axis-aligned boxes split at the median of their centres along the
 * widest axis, at most RS_BVH_LEAF objects per leaf; every other object (planes, and any kind
 * of object this file does not know a bound for) is tried for every ray.
 * A ray then visits O(log N) boxes instead of N objects.  Scenes of few
 * objects keep the loop (rs_bvh_serves).
 *
 * The nearest hit is exactly the one a loop over every object finds: an
 * object is intersected with the same arguments, and a tie in t goes to
 * the object of lower index, as in the loop. */
#ifndef RS_BVH_H
#define RS_BVH_H

#include "shapes.h"

#define RS_BVH_LEAF 4

/* Below this many objects with a bound, a loop over every object is
 * cheaper than the tree's boxes (measured: a scene of 3 or 4 objects spent
 * 17 % more instructions in the tree than in the loop). */
#define RS_BVH_MIN_BOUNDED 8

typedef struct rs_bvh rs_bvh;

/* Build over scene->objects (lenses must be created already: their bounds
 * come from lensprim).  Returns 0, or -1 when memory runs out (*out NULL). */
int rs_bvh_build(const rs_scene *scene, rs_bvh **out);
void rs_bvh_destroy(rs_bvh *bvh); /* NULL: no-op */

/* World bounding box of an object; 0 when it has no finite one. */
int rs_object_bounds(const rs_object *o, lp_vec3 *lo, lp_vec3 *hi);

/* Nearest hit of origin + t dir (dir unit), t in (t_min, t_max), skipping
 * object `skip` (-1: none), over the objects the tree was built on.
 * Returns 1 and fills *hit (hit->object set). */
int rs_bvh_intersect(const rs_bvh *bvh, const rs_scene *scene, lp_vec3 origin, lp_vec3 dir,
                     double t_min, double t_max, int skip, rs_hit *hit);

/* Calls fn(ctx, i) for every object i whose bounding box the segment
 * origin + t dir, t in (t_min, t_max), meets (and every unbounded object)
 * until fn returns nonzero; returns that value, or 0.  The order is not
 * the objects' order: fn must not depend on it. */
typedef int (*rs_bvh_visit_fn)(void *ctx, int object);
int rs_bvh_any(const rs_bvh *bvh, lp_vec3 origin, lp_vec3 dir, double t_min, double t_max,
               rs_bvh_visit_fn fn, void *ctx);

/* Whether the scene's searches should go through its tree: one was built
 * on these very objects and it holds at least RS_BVH_MIN_BOUNDED of them. */
int rs_bvh_serves(const rs_bvh *bvh, const rs_scene *scene);

/* A ray prepared for box tests: the origin, the inverse direction and
 * which components of the direction are 0. */
typedef struct rs_slab_ray {
    double o[3], inv[3];
    int zero[3];
} rs_slab_ray;
void rs_slab_ray_init(rs_slab_ray *r, lp_vec3 origin, lp_vec3 dir);

/* Whether origin + t dir, t in [t_min, t_max] (r from them, dir unit), may
 * meet object i of the scene the tree was built on: 0 only when it misses
 * the object's box, kept for the objects whose own test costs more than a
 * box's (lenses, CSG objects, tori, cylinders, cones); 1 for the others.
 * The loops over every object of a small scene ask this first; a hit the
 * object reports always lies in its box. */
int rs_bvh_may_meet(const rs_bvh *bvh, int object, const rs_slab_ray *r, double t_min,
                    double t_max);

/* Whether rs_bvh_may_meet tests object i's box (else it is 1 without
 * reading its ray): a loop may prepare the ray only once one needs it. */
int rs_bvh_culls(const rs_bvh *bvh, int object);

/* Number of tree nodes, of unbounded objects (for tests and benchmarks),
 * and of the scene's objects when it was built. */
size_t rs_bvh_node_count(const rs_bvh *bvh);
size_t rs_bvh_object_count(const rs_bvh *bvh);
size_t rs_bvh_unbounded_count(const rs_bvh *bvh);

#endif
