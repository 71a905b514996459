/* scene_messages.c -- a scene's messages on stderr (scene_messages.h). */
#include <stdio.h>

#include "scene_messages.h"

void rs_print_scene_messages(const char *program, const lr_scene *s)
{
    for (size_t k = 0; s && k < lr_scene_message_count(s); k++) {
        lr_message_kind kind;
        const char *text = lr_scene_message(s, k, &kind);
        if (kind == LR_MESSAGE_DEBUG)
            fputs(text, stderr);
        else
            fprintf(stderr, "%s: %s\n", program, text);
    }
}
