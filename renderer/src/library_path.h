/* library_path.h -- where #include looks: POV-Ray's Library_Path
 * (renderer-internal).
 *
 * The directories the user gave (-L DIR, +LDIR), in order, then the
 * defaults that exist on this machine: the installed POV-Ray 3.7 include
 * directory (RS_POVRAY_INCLUDE_DIR, so that colors.inc, finish.inc ...
 * are found as POV-Ray finds them) and the project's own share directory
 * (RS_SHARE_DIR, set by the build: where lens.inc is installed). */
#ifndef RS_LIBRARY_PATH_H
#define RS_LIBRARY_PATH_H

#include <stddef.h>

#define RS_POVRAY_INCLUDE_DIR "/usr/share/povray-3.7/include"

/* Fill out[0..cap) with the user's n directories and then the existing
 * defaults; returns how many were written. */
size_t rs_library_path(const char *const *user, size_t n, const char **out, size_t cap);

#endif
