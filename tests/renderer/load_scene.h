/* load_scene.h -- read and prepare a scene, from a file or from text, for
 * an image of w x h pixels, with the include directories lensrender
 * uses (colors.inc, lens.inc), through the renderer's core. */
#ifndef LP_TEST_LOAD_SCENE_H
#define LP_TEST_LOAD_SCENE_H

#include "scene.h"

/* The file at path, or when path is NULL the text (named name in
 * messages), into sc (rs_scene_init'ed).  0 on success, else -1 with the
 * message on stderr. */
int load_scene(rs_scene *sc, const char *path, const char *text, const char *name, int w, int h);

#endif
