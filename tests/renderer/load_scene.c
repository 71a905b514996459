/* load_scene.c -- see load_scene.h. */
#include "load_scene.h"

#include <stdio.h>

#include "library_path.h"
#include "parser.h"

int load_scene(rs_scene *sc, const char *path, const char *text, const char *name, int w, int h)
{
    char msg[1024] = "";
    rs_parse_opts po;
    const char *dirs[4];
    rs_parse_opts_init(&po);
    po.image_width = w;
    po.image_height = h;
    po.include_dirs = dirs; /* colors.inc and lens.inc, as lensrender finds them */
    po.n_include_dirs = rs_library_path(NULL, 0, dirs, sizeof dirs / sizeof *dirs);
    if ((path ? rs_parse_file(path, &po, sc, msg, sizeof msg)
              : rs_parse_string(text, name, &po, sc, msg, sizeof msg)) != 0 ||
        rs_scene_prepare(sc, msg, sizeof msg) != 0) {
        fprintf(stderr, "%s: %s\n", path ? path : name, msg);
        return -1;
    }
    return 0;
}
