/* parse_many -- parse COUNT copies of a scene item, for memory measurement.
 *
 *   parse_many ITEM COUNT MAX_OBJECTS
 *
 * Builds the scene text ITEM x COUNT in memory, parses it as "many.scene"
 * with the given object limit (0: the parser's default), and prints two
 * lines: the number of objects plus lights kept, and the parser's message
 * ("ok" when it accepted the text).  Exit 0 when it could do that, 3 when
 * the text could not be allocated.  test_hostile_scenes runs it through
 * measure_child to bound the parser's peak memory on 10^6 objects. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "parser.h"
#include "scene.h"

int main(int argc, char **argv)
{
    char *end, *text, msg[512];
    long count;
    unsigned long max_objects;
    size_t il;
    rs_scene scene;
    rs_parse_opts opts;

    if (argc != 4) {
        fprintf(stderr, "usage: parse_many ITEM COUNT MAX_OBJECTS\n");
        return 2;
    }
    errno = 0;
    count = strtol(argv[2], &end, 10);
    if (errno || *end || count < 0 || count > 100000000L) {
        fprintf(stderr, "parse_many: bad COUNT '%s'\n", argv[2]);
        return 2;
    }
    max_objects = strtoul(argv[3], &end, 10);
    if (errno || *end) {
        fprintf(stderr, "parse_many: bad MAX_OBJECTS '%s'\n", argv[3]);
        return 2;
    }
    il = strlen(argv[1]);
    text = malloc(il * (size_t)count + 1);
    if (!text)
        return 3;
    for (long i = 0; i < count; i++)
        memcpy(text + il * (size_t)i, argv[1], il);
    text[il * (size_t)count] = '\0';

    rs_parse_opts_init(&opts);
    opts.max_objects = (size_t)max_objects;
    rs_scene_init(&scene);
    if (rs_parse_string(text, "many.scene", &opts, &scene, msg, sizeof msg) == 0)
        snprintf(msg, sizeof msg, "ok");
    printf("%lu\n%s\n", (unsigned long)(scene.n_objects + scene.n_lights), msg);
    rs_scene_free(&scene);
    free(text);
    return 0;
}
