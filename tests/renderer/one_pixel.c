/* one_pixel.c -- see one_pixel.h. */
#include "one_pixel.h"

#include <stdio.h>

#include "parser.h"
#include "scene.h"

int one_pixel(const char *text, rs_mode mode, int wavelengths, rs_color *out)
{
    char msg[512] = "";
    rs_scene sc;
    rs_parse_opts po;
    rs_render_opts o;
    rs_integrator *it = NULL;
    int rc = -1;
    rs_scene_init(&sc);
    rs_parse_opts_init(&po);
    po.image_width = po.image_height = 1;
    rs_render_opts_init(&o);
    o.mode = mode;
    if (wavelengths > 0)
        o.wavelengths = wavelengths;
    o.width = o.height = 1;
    if (rs_parse_string(text, "<test>", &po, &sc, msg, sizeof msg) == 0 &&
        rs_scene_prepare(&sc, msg, sizeof msg) == 0 &&
        rs_integrator_create(&sc, &o, &it, msg, sizeof msg) == 0) {
        rs_worker *w = rs_worker_create(it);
        if (w != NULL) {
            rs_integrator_pixel(it, w, 0, 0, out);
            rs_worker_destroy(w);
            rc = 0;
        } else {
            snprintf(msg, sizeof msg, "out of memory for a worker");
        }
        rs_integrator_destroy(it);
    }
    if (rc != 0)
        fprintf(stderr, "one_pixel: %s\n", msg);
    rs_scene_free(&sc);
    return rc;
}
