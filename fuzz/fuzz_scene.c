/* fuzz_scene.c -- libFuzzer target: the .scene parser on arbitrary bytes.
 *
 * The input is loaded as scene text through the renderer's face (a
 * NUL-terminated copy: an embedded NUL ends the text, as for
 * lr_scene_load_string), then, when it loads, a few primary rays are made
 * and a 4 x 3 image is rendered (1 wavelength, depth 3, one thread).  What the parser stores must
 * be finite, with unit normals and positive sizes (parser.h); any
 * crash, sanitizer report, leak, hang or runaway allocation is a bug; a
 * refusal must come with a "<fuzz>:LINE:COL: ..." message.  #include is
 * off (no file is read), and a parse reads at most 10^5 tokens and makes
 * at most 2000 objects, so that endless #while loops and macro calls end
 * in milliseconds. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lensrender/lensrender.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void require(int cond)
{
    if (!cond)
        abort();
}

static int fin(lp_vec3 v)
{
    return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
}

static int unit(lp_vec3 v)
{
    return fin(v) && fabs(v.x * v.x + v.y * v.y + v.z * v.z - 1.0) < 1e-9;
}

static int xf_ok(const rs_transform *xf)
{
    for (int i = 0; i < 3; i++) {
        if (!isfinite(xf->t[i]) || !isfinite(xf->inv_t[i]))
            return 0;
        for (int j = 0; j < 3; j++)
            if (!isfinite(xf->m[i][j]) || !isfinite(xf->inv_m[i][j]))
                return 0;
    }
    return 1;
}

/* The invariants parser.h promises for a parsed scene. */
static void check_scene(const rs_scene *s)
{
    for (size_t i = 0; i < s->n_objects; i++) {
        const rs_object *o = &s->objects[i];
        require(o->loc.line >= 1 && o->loc.column >= 1);
        require(xf_ok(&o->xf) && xf_ok(&o->pigment.to_pattern));
        switch (o->type) {
        case RS_OBJ_PLANE:
            require(unit(o->u.plane.normal) && isfinite(o->u.plane.distance));
            break;
        case RS_OBJ_SPHERE:
            require(fin(o->u.sphere.center) && isfinite(o->u.sphere.radius) &&
                    o->u.sphere.radius > 0.0);
            break;
        case RS_OBJ_BOX:
            require(fin(o->u.box.corner1) && fin(o->u.box.corner2));
            break;
        case RS_OBJ_DISC:
            require(fin(o->u.disc.center) && unit(o->u.disc.normal) &&
                    isfinite(o->u.disc.radius) && o->u.disc.radius > 0.0 &&
                    o->u.disc.hole >= 0.0 && o->u.disc.hole < o->u.disc.radius);
            break;
        case RS_OBJ_LENS: {
            const lp_lens_desc *d = &o->u.lens.desc;
            require(!isnan(d->radius1) && !isnan(d->radius2));
            require(isfinite(d->thickness) && isfinite(d->diameter) &&
                    isfinite(d->diameter2) && fin(d->position) && unit(d->axis));
            break;
        }
        case RS_OBJ_POLARIZER:
            require(fin(o->u.polarizer.center) && unit(o->u.polarizer.normal) &&
                    unit(o->u.polarizer.axis) && isfinite(o->u.polarizer.radius) &&
                    o->u.polarizer.radius > 0.0);
            break;
        case RS_OBJ_CYLINDER:
            require(fin(o->u.cylinder.base) && fin(o->u.cylinder.cap) &&
                    isfinite(o->u.cylinder.radius) && o->u.cylinder.radius > 0.0);
            break;
        case RS_OBJ_CONE:
            require(fin(o->u.cone.base) && fin(o->u.cone.cap) &&
                    isfinite(o->u.cone.base_radius) && isfinite(o->u.cone.cap_radius) &&
                    o->u.cone.base_radius >= 0.0 && o->u.cone.cap_radius >= 0.0);
            break;
        case RS_OBJ_TORUS:
            require(isfinite(o->u.torus.major) && isfinite(o->u.torus.minor) &&
                    o->u.torus.major > 0.0 && o->u.torus.minor > 0.0);
            break;
        }
        require(isfinite(o->finish.phong) && isfinite(o->finish.phong_size) &&
                o->finish.phong_size > 0.0 && isfinite(o->finish.roughness) &&
                o->finish.roughness > 0.0 && isfinite(o->ior) && o->ior > 0.0);
    }
    for (size_t i = 0; i < s->n_lights; i++) {
        const rs_light *l = &s->lights[i];
        require(fin(l->position));
        require(!l->polarized || unit(l->polarization));
        require(isfinite(l->coherence_length) && l->coherence_length >= 0.0);
    }
    require(xf_ok(&s->camera.xf));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    lr_load_opts opts;
    lr_scene *scene = NULL;
    lr_error err;

    if (text == NULL)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    lr_load_opts_init(&opts);
    opts.no_include = 1;       /* no file is opened */
    opts.max_tokens = 100000;  /* loops and macro recursion end fast */
    opts.max_objects = 2000;
    if (lr_scene_load_string(text, "<fuzz>", &opts, &scene, &err) != LR_OK) {
        /* A refusal must say where: "<fuzz>:LINE:COL: ..." */
        require(err.status == LR_ERROR_NO_MEMORY || strncmp(err.message, "<fuzz>:", 7) == 0);
    } else {
        const rs_scene *s = lr_scene_description(scene);
        lr_render_opts ro;
        lr_renderer *r = NULL;
        float rgb[3 * 4 * 3];
        require(s != NULL);
        check_scene(s);
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < 4; i++) {
                lp_vec3 o, d;
                if (lr_camera_ray(&s->camera, 4, 3, i + 0.5, j + 0.5, &o, &d, NULL) == LR_OK)
                    require(fin(o) && unit(d));
            }
        lr_render_opts_init(&ro);
        ro.width = 4;
        ro.height = 3;
        ro.wavelengths = 1;
        ro.depth = 3;
        ro.threads = 1;
        if (lr_renderer_create(scene, &ro, &r, &err) == LR_OK)
            require(lr_render_image(r, rgb, NULL, NULL, &err) == LR_OK);
        lr_renderer_free(r);
    }
    lr_scene_free(scene);
    free(text);
    return 0;
}
