/* scene.c -- the scene's lifetime: defaults, freeing, and creating the
 * lensprim lenses once parsing is done. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "csg.h"
#include "scene.h"

void rs_scene_init(rs_scene *scene)
{
    rs_camera *c = &scene->camera;
    rs_settings *s = &scene->settings;

    memset(scene, 0, sizeof *scene);

    /* POV-Ray's camera defaults. */
    c->location = (lp_vec3){ 0.0, 0.0, 0.0 };
    c->direction = (lp_vec3){ 0.0, 0.0, 1.0 };
    c->right = (lp_vec3){ 1.33, 0.0, 0.0 };
    c->up = (lp_vec3){ 0.0, 1.0, 0.0 };
    c->sky = (lp_vec3){ 0.0, 1.0, 0.0 };
    c->look_at = (lp_vec3){ 0.0, 0.0, 1.0 };
    c->has_look_at = 0;
    c->angle = 0.0;
    c->has_angle = 0;
    rs_transform_identity(&c->xf);
    c->has_xf = 0;
    c->focal_point = (lp_vec3){ 0.0, 0.0, 0.0 };
    c->aperture = 0.0;
    c->blur_samples = 0;

    scene->background = (rs_color){ 0.0, 0.0, 0.0 };

    s->max_trace_level = 5;
    s->adc_bailout = 1.0 / 255.0;
    s->ambient_light = (rs_color){ 1.0, 1.0, 1.0 };
    s->assumed_gamma = 1.0;
    s->coherent = 0;

    scene->objects = NULL;
    scene->lights = NULL;
    scene->files = NULL;
    scene->catalog = NULL;
    scene->bvh = NULL;
}

void rs_scene_free(rs_scene *scene)
{
    if (scene == NULL)
        return;
    for (size_t i = 0; i < scene->n_objects; i++) {
        lp_lens_destroy(scene->objects[i].lens);
        rs_object_release(&scene->objects[i]);
    }
    free(scene->objects);
    free(scene->lights);
    for (size_t i = 0; i < scene->n_files; i++)
        free(scene->files[i]);
    free(scene->files);
    for (size_t i = 0; i < scene->n_messages; i++)
        free(scene->messages[i].text);
    free(scene->messages);
    lp_catalog_destroy(scene->catalog);
    rs_bvh_destroy(scene->bvh);
    rs_scene_init(scene);
}

int rs_scene_add_message(rs_scene *scene, rs_message_kind kind, const char *text)
{
    size_t n = strlen(text);
    char *copy = malloc(n + 1);
    rs_message *a;
    if (copy == NULL)
        return -1;
    memcpy(copy, text, n + 1);
    a = realloc(scene->messages, (scene->n_messages + 1) * sizeof *a);
    if (a == NULL) {
        free(copy);
        return -1;
    }
    scene->messages = a;
    scene->messages[scene->n_messages].kind = kind;
    scene->messages[scene->n_messages].text = copy;
    scene->n_messages++;
    return 0;
}

static int prep_error(char *msg, size_t msg_size, const rs_loc *loc, const char *fmt, ...)
{
    if (msg != NULL && msg_size > 0) {
        va_list ap;
        int n = snprintf(msg, msg_size, "%s:%d:%d: ",
                         loc->file ? loc->file : "<scene>", loc->line, loc->column);
        if (n >= 0 && (size_t)n < msg_size) {
            va_start(ap, fmt);
            vsnprintf(msg + n, msg_size - (size_t)n, fmt, ap);
            va_end(ap);
        }
    }
    return -1;
}

/* (Re)build the scene's bounding volume hierarchy. */
static int build_bvh(rs_scene *scene, char *msg, size_t msg_size)
{
    rs_bvh_destroy(scene->bvh);
    scene->bvh = NULL;
    if (rs_bvh_build(scene, &scene->bvh) != 0) {
        if (msg != NULL && msg_size > 0)
            snprintf(msg, msg_size, "out of memory building the scene's bounding volumes");
        return -1;
    }
    return 0;
}

/* Resolve catalog glass names and create every lens.  A lens created by
 * an earlier call is replaced, so the call may be repeated after the
 * descriptions change.  The catalog is created here when the caller has
 * not set one (a caller may create it first to load AGF files into it). */
int rs_scene_prepare(rs_scene *scene, char *msg, size_t msg_size)
{
    lp_error err;

    if (msg != NULL && msg_size > 0)
        msg[0] = '\0';
    if (scene == NULL)
        return -1;
    for (size_t i = 0; i < scene->n_objects; i++) {
        rs_object *o = &scene->objects[i];
        if (o->type != RS_OBJ_LENS)
            continue;
        lp_lens_destroy(o->lens);
        o->lens = NULL;
        if (o->u.lens.glass_name[0] != '\0') {
            if (scene->catalog == NULL) {
                if (lp_catalog_create(&scene->catalog, &err) != LP_OK)
                    return prep_error(msg, msg_size, &o->loc,
                                      "lens: cannot create the glass catalog: %s", err.message);
            }
            if (lp_catalog_find(scene->catalog, o->u.lens.glass_name,
                                &o->u.lens.desc.glass, &err) != LP_OK)
                return prep_error(msg, msg_size, &o->loc, "lens: glass \"%s\": %s",
                                  o->u.lens.glass_name, err.message);
        }
        if (lp_lens_create(&o->u.lens.desc, &o->lens, &err) != LP_OK) {
            o->lens = NULL;
            return prep_error(msg, msg_size, &o->loc, "lens: %s", err.message);
        }
    }
    return build_bvh(scene, msg, msg_size);
}

int rs_scene_freeze_glass(rs_scene *scene, double lambda_nm, char *msg, size_t msg_size)
{
    lp_error err;

    if (msg != NULL && msg_size > 0)
        msg[0] = '\0';
    if (scene == NULL)
        return -1;
    for (size_t i = 0; i < scene->n_objects; i++) {
        rs_object *o = &scene->objects[i];
        if (o->type != RS_OBJ_LENS || o->lens == NULL)
            continue;
        lp_lens_desc *d = &o->u.lens.desc;
        double ng = lp_glass_index(&d->glass, lambda_nm);
        double nm = lp_glass_index(&d->medium, lambda_nm);
        if (!isfinite(ng) || !isfinite(nm))
            return prep_error(msg, msg_size, &o->loc, "lens: no index at %g nm", lambda_nm);
        lp_glass_init_constant(&d->glass, ng);
        lp_glass_init_constant(&d->medium, nm);
        if (d->uniaxial) {
            double no = lp_glass_index(&d->crystal.ordinary, lambda_nm);
            double ne = lp_glass_index(&d->crystal.extraordinary, lambda_nm);
            if (!isfinite(no) || !isfinite(ne))
                return prep_error(msg, msg_size, &o->loc, "lens: no crystal index at %g nm",
                                  lambda_nm);
            lp_crystal_init_constant(&d->crystal, no, ne, d->crystal.axis);
        }
        o->u.lens.glass_name[0] = '\0';
        lp_lens_destroy(o->lens);
        o->lens = NULL;
        if (lp_lens_create(d, &o->lens, &err) != LP_OK) {
            o->lens = NULL;
            return prep_error(msg, msg_size, &o->loc, "lens: %s", err.message);
        }
    }
    return build_bvh(scene, msg, msg_size);
}
