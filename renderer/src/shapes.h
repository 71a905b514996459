/* shapes.h -- ray intersection with the scene's objects (renderer-internal). */
#ifndef RS_SHAPES_H
#define RS_SHAPES_H

#include "scene.h"

typedef struct rs_hit {
    double t;        /* distance along the unit direction */
    int object;      /* index in scene->objects */
    lp_vec3 point;   /* world */
    lp_vec3 normal;  /* world, unit, facing against the ray */
    int lens_surface;/* RS_OBJ_LENS: LP_SURFACE_* */
    const rs_object *surface; /* the primitive whose surface was hit: the
                                 object itself, or a CSG's member (its
                                 pigment, finish and ior shade the hit) */
} rs_hit;

/* Nearest hit of origin + t dir (dir unit), t in (t_min, t_max), skipping
 * object `skip` (-1: none).  Returns 1 and fills *hit. */
int rs_scene_intersect(const rs_scene *scene, lp_vec3 origin, lp_vec3 dir, double t_min,
                       double t_max, int skip, rs_hit *hit);

/* Intersect one object; fills t, point, normal (facing the ray) and
 * surface. */
int rs_object_intersect(const rs_object *o, lp_vec3 origin, lp_vec3 dir, double t_min,
                        double t_max, rs_hit *hit);

#endif
