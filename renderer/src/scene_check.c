/* scene_check.c -- the rules every scene obeys, stated once (see
 * rs_scene_check in lensrender/scene.h). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#include "lensrender/scene.h"
#include "support/vec.h"

/* Unit to 1e-9 in the squared length. */
static int unit(lp_vec3 v)
{
    return v3_finite(v) && fabs(v.x * v.x + v.y * v.y + v.z * v.z - 1.0) < 1e-9;
}

static int color_fin(rs_color c)
{
    return isfinite(c.r) && isfinite(c.g) && isfinite(c.b);
}

static int broken(char *msg, size_t msg_size, const rs_loc *loc, const char *fmt, ...)
{
    if (msg != NULL && msg_size > 0) {
        va_list ap;
        int n = 0;
        msg[0] = '\0';
        if (loc != NULL)
            n = snprintf(msg, msg_size, "%s:%d:%d: ", loc->file ? loc->file : "<scene>",
                         loc->line, loc->column);
        if (n >= 0 && (size_t)n < msg_size) {
            va_start(ap, fmt);
            vsnprintf(msg + n, msg_size - (size_t)n, fmt, ap);
            va_end(ap);
        }
    }
    return -1;
}

static int finish_ok(const rs_finish *f)
{
    return color_fin(f->ambient) && color_fin(f->emission) && isfinite(f->diffuse) &&
           isfinite(f->brilliance) && isfinite(f->phong) && isfinite(f->phong_size) &&
           f->phong_size > 0.0 && isfinite(f->specular) && isfinite(f->roughness) &&
           f->roughness > 0.0 && color_fin(f->reflection_min) && color_fin(f->reflection_max);
}

/* The geometry of one object; NULL when it keeps the rules, else what. */
static const char *shape_problem(const rs_object *o)
{
    switch (o->type) {
    case RS_OBJ_PLANE:
        return unit(o->u.plane.normal) && isfinite(o->u.plane.distance)
                   ? NULL
                   : "plane: the normal must be a finite unit vector, the distance finite";
    case RS_OBJ_SPHERE:
        return v3_finite(o->u.sphere.center) && isfinite(o->u.sphere.radius) &&
                       o->u.sphere.radius > 0.0
                   ? NULL
                   : "sphere: the centre must be finite, the radius finite and > 0";
    case RS_OBJ_BOX:
        return v3_finite(o->u.box.corner1) && v3_finite(o->u.box.corner2)
                   ? NULL
                   : "box: the corners must be finite";
    case RS_OBJ_DISC:
        return v3_finite(o->u.disc.center) && unit(o->u.disc.normal) &&
                       isfinite(o->u.disc.radius) && o->u.disc.radius > 0.0 &&
                       o->u.disc.hole >= 0.0 && o->u.disc.hole < o->u.disc.radius
                   ? NULL
                   : "disc: centre finite, unit normal, radius > 0 and 0 <= hole < radius";
    case RS_OBJ_LENS: {
        const lp_lens_desc *d = &o->u.lens.desc;
        return !isnan(d->radius1) && !isnan(d->radius2) && isfinite(d->thickness) &&
                       isfinite(d->diameter) && isfinite(d->diameter2) && v3_finite(d->position) &&
                       unit(d->axis)
                   ? NULL
                   : "lens: radii must be numbers, thickness, diameters and position "
                     "finite, the axis a unit vector";
    }
    case RS_OBJ_POLARIZER:
        return v3_finite(o->u.polarizer.center) && unit(o->u.polarizer.normal) &&
                       unit(o->u.polarizer.axis) && isfinite(o->u.polarizer.radius) &&
                       o->u.polarizer.radius > 0.0
                   ? NULL
                   : "polarizer: centre finite, unit normal and axis, radius > 0";
    case RS_OBJ_CYLINDER:
        return v3_finite(o->u.cylinder.base) && v3_finite(o->u.cylinder.cap) &&
                       isfinite(o->u.cylinder.radius) && o->u.cylinder.radius > 0.0
                   ? NULL
                   : "cylinder: ends finite, radius > 0";
    case RS_OBJ_CONE:
        return v3_finite(o->u.cone.base) && v3_finite(o->u.cone.cap) && isfinite(o->u.cone.base_radius) &&
                       isfinite(o->u.cone.cap_radius) && o->u.cone.base_radius >= 0.0 &&
                       o->u.cone.cap_radius >= 0.0
                   ? NULL
                   : "cone: ends finite, radii finite and >= 0";
    case RS_OBJ_TORUS:
        return isfinite(o->u.torus.major) && isfinite(o->u.torus.minor) &&
                       o->u.torus.major > 0.0 && o->u.torus.minor > 0.0
                   ? NULL
                   : "torus: radii finite and > 0";
    case RS_OBJ_CSG:
        return o->u.csg.n_members > 0 && o->u.csg.members != NULL
                   ? NULL
                   : "a CSG object must have members";
    }
    return NULL;
}

/* One object and, for a CSG object, each of its members. */
static int object_check(const rs_object *o, size_t index, char *msg, size_t msg_size)
{
    const char *what;
    lp_error err;
    if (o->loc.line < 1 || o->loc.column < 1)
        return broken(msg, msg_size, NULL, "object %zu has no place in a file", index);
    if (!rs_transform_finite(&o->xf) || !rs_transform_finite(&o->pigment.to_pattern))
        return broken(msg, msg_size, &o->loc, "a transform is not finite");
    if (!color_fin(o->pigment.color[0]) || !color_fin(o->pigment.color[1]))
        return broken(msg, msg_size, &o->loc, "a pigment colour is not finite");
    if (!finish_ok(&o->finish))
        return broken(msg, msg_size, &o->loc,
                      "finish: every value must be finite, phong_size and roughness > 0");
    if (!isfinite(o->ior) || !(o->ior > 0.0))
        return broken(msg, msg_size, &o->loc, "interior: ior must be finite and > 0");
    if ((what = shape_problem(o)) != NULL)
        return broken(msg, msg_size, &o->loc, "%s", what);
    if (o->type == RS_OBJ_LENS && o->lens == NULL) {
        /* not created yet: it must be a lens that can exist */
        lp_lens *tmp = NULL;
        if (lp_lens_create(&o->u.lens.desc, &tmp, &err) != LP_OK)
            return broken(msg, msg_size, &o->loc, "lens: %s", err.message);
        lp_lens_destroy(tmp);
    }
    if (o->type == RS_OBJ_CSG)
        for (size_t i = 0; i < o->u.csg.n_members; i++)
            if (object_check(&o->u.csg.members[i], i, msg, msg_size) != 0)
                return -1;
    return 0;
}

int rs_scene_check(const rs_scene *s, char *msg, size_t msg_size)
{
    if (msg != NULL && msg_size > 0)
        msg[0] = '\0';
    if (s == NULL)
        return broken(msg, msg_size, NULL, "no scene");
    for (size_t i = 0; i < s->n_objects; i++)
        if (object_check(&s->objects[i], i, msg, msg_size) != 0)
            return -1;
    for (size_t i = 0; i < s->n_lights; i++) {
        const rs_light *l = &s->lights[i];
        if (!v3_finite(l->position) || !color_fin(l->color) ||
            (l->polarized && !unit(l->polarization)) || !isfinite(l->coherence_length) ||
            l->coherence_length < 0.0)
            return broken(msg, msg_size, &l->loc,
                          "light_source: position and colour finite, polarization a unit "
                          "vector, coherence length finite and >= 0");
    }
    const rs_camera *c = &s->camera;
    if (!v3_finite(c->location) || !v3_finite(c->direction) || !v3_finite(c->right) ||
        !v3_finite(c->up) || !v3_finite(c->sky) || (c->has_look_at && !v3_finite(c->look_at)) ||
        (c->has_angle && !isfinite(c->angle)) || !rs_transform_finite(&c->xf) ||
        !v3_finite(c->focal_point) || !isfinite(c->aperture))
        return broken(msg, msg_size, NULL, "camera: a value is not finite");
    if (!color_fin(s->background) || !color_fin(s->settings.ambient_light))
        return broken(msg, msg_size, NULL, "background or ambient_light is not finite");
    return 0;
}
