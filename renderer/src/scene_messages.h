/* scene_messages.h -- a scene's warnings and #debug text on stderr, for
 * the programs that render scenes from lensrender's command line
 * (lensrender, lensrender-mpi).  Compiled into the programs, not into the
 * renderer's library: it prints. */
#ifndef RS_SCENE_MESSAGES_H
#define RS_SCENE_MESSAGES_H

#include "lensrender/lensrender.h"

/* Each warning as one line "PROGRAM: TEXT", each #debug text as written,
 * in the order the reader gave them; nothing when s is NULL. */
void rs_print_scene_messages(const char *program, const lr_scene *s);

#endif
