/* library_path.c -- the include directories (see library_path.h). */
#define _POSIX_C_SOURCE 200809L

#include <sys/stat.h>

#include "library_path.h"

static int is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

size_t rs_library_path(const char *const *user, size_t n, const char **out, size_t cap)
{
    static const char *const defaults[] = {
        RS_POVRAY_INCLUDE_DIR,
#ifdef RS_SHARE_DIR
        RS_SHARE_DIR,
#endif
    };
    size_t k = 0;
    for (size_t i = 0; i < n && k < cap; i++)
        out[k++] = user[i];
    for (size_t i = 0; i < sizeof defaults / sizeof defaults[0] && k < cap; i++)
        if (is_dir(defaults[i]))
            out[k++] = defaults[i];
    return k;
}
