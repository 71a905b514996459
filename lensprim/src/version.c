/* version.c -- the library's version, as built. */
#include "lensprim.h"

#define LP_STR_(x) #x
#define LP_STR(x) LP_STR_(x)

int lp_version_number(void)
{
    return LP_VERSION_NUMBER;
}

const char *lp_version_string(void)
{
    return LP_STR(LP_VERSION_MAJOR) "." LP_STR(LP_VERSION_MINOR) "." LP_STR(LP_VERSION_PATCH);
}
