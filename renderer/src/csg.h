/* csg.h -- constructive solid geometry: intersection, difference, and a
 * union inside them (renderer-internal).
 *
 * A CSG object (RS_OBJ_CSG) owns its members: primitives with an inside
 * (plane, sphere, box, cylinder, cone, torus) or CSG objects again, each
 * with its transforms folded into its own placement.  As in POV-Ray, a
 * point is inside
 *   a union         when it is inside any member,
 *   an intersection when it is inside every member,
 *   a difference    when it is inside the first member and in none of the
 *                   others,
 * and `inverse` swaps inside and outside of a primitive or of a CSG.
 *
 * The surface of a CSG object is where a ray passes from outside to
 * inside or back: among the crossings of the members' surfaces, in order
 * along the ray, the first at which the CSG's inside test differs a short
 * step RS_CSG_STEP (relative to the point's distance from the origin)
 * before and after the crossing.  So two members sharing a face (a drill
 * flush with the face it opens) leave no skin, a ray along a tangent or a
 * face meets nothing there, and solids thinner than that step vanish.
 * The normal is the member's, turned against the ray (an opaque surface
 * is lit from the side it is seen from, so a subtracted member's flipped
 * normal needs no flip of its own). */
#ifndef RS_CSG_H
#define RS_CSG_H

#include "shapes.h"

/* The inside test's step across a crossing: RS_CSG_STEP * (1 + |p|). */
#define RS_CSG_STEP 1e-9

/* Crossings of one member's surface looked at per ray (a torus has at
 * most 4, a cone 4, a box 2; the torus's sampling may report a crossing
 * twice). */
#define RS_CSG_MAX_CROSSINGS 32

/* Is the world point p inside the object?  Primitives with an inside and
 * CSG objects; `inverse` swapped.  Discs, lenses and polarizers: 0. */
int rs_object_inside(const rs_object *o, lp_vec3 p);

/* The nearest crossing of the CSG object's surface by origin + t dir (dir
 * unit), t in (t_min, t_max); 1 and *hit (t, point, normal against the
 * ray, surface = the member primitive), or 0. */
int rs_csg_intersect(const rs_object *o, lp_vec3 origin, lp_vec3 dir, double t_min,
                     double t_max, rs_hit *hit);

/* A world box holding the CSG object, from its members' boxes given by
 * member_bounds (which returns 0 for a member without a finite box): an
 * intersection's box is the intersection of its members' boxes (members
 * without one do not restrict it), a difference's is its first member's,
 * a union's the union of its members'; an inverted CSG has none.  Returns
 * 1 and the box, or 0 when there is no finite one. */
typedef int (*rs_bounds_fn)(const rs_object *o, lp_vec3 *lo, lp_vec3 *hi);
int rs_csg_bounds(const rs_object *o, rs_bounds_fn member_bounds, lp_vec3 *lo, lp_vec3 *hi);

/* Deep copy of any object (a CSG's members are copied too) into *dst.
 * Returns 0, or -1 when memory runs out (*dst then owns nothing). */
int rs_object_copy(rs_object *dst, const rs_object *src);

/* Free what an object owns (a CSG's members); the object stays valid and
 * owns nothing.  Other objects own nothing: a no-op. */
void rs_object_release(rs_object *o);

/* Number of objects in the tree (1 for a primitive). */
size_t rs_object_node_count(const rs_object *o);

/* POV-Ray's texture rule, applied once the object is final: every member
 * without a pigment, finish or texture of its own takes its nearest CSG
 * ancestor's, and every member without an interior the nearest one's
 * that has one. */
void rs_csg_inherit(rs_object *o);

#endif
