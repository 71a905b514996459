/* error.h -- filling an lp_error (internal). */
#ifndef LP_ERROR_H
#define LP_ERROR_H

#include "lensprim.h"

/* Fill *err (if non-NULL) with status and a printf-style message; returns
 * status so callers can write `return lp__fail(err, LP_ERROR_..., "...")`. */
lp_status lp__fail(lp_error *err, lp_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Set *err (if non-NULL) to LP_OK with an empty message. */
void lp__ok(lp_error *err);

#endif
