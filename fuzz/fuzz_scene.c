/* fuzz_scene.c -- libFuzzer target: the .scene parser on arbitrary bytes.
 *
 * The input is loaded as scene text through the renderer's face (a
 * NUL-terminated copy: an embedded NUL ends the text, as for
 * lr_scene_load_string), then, when it loads, a few primary rays are made
 * and a 4 x 3 image is rendered (1 wavelength, depth 3, one thread).  What
 * the reader builds must keep the scene's rules (lr_scene_check); any
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
        /* What the reader builds keeps the scene's rules (checked once,
         * by the renderer's own check). */
        require(lr_scene_check(s, NULL) == LR_OK);
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
