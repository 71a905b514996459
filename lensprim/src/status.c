/* status.c -- status codes, their strings, and filling lp_error. */
#include <stdarg.h>
#include <stdio.h>

#include "error.h"

const char *lp_status_string(lp_status status)
{
    switch (status) {
    case LP_OK: return "ok";
    case LP_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case LP_ERROR_INVALID_LENS: return "invalid lens";
    case LP_ERROR_INVALID_GLASS: return "invalid glass";
    case LP_ERROR_UNKNOWN_GLASS: return "unknown glass";
    case LP_ERROR_UNSUPPORTED: return "unsupported";
    case LP_ERROR_PARSE: return "parse error";
    case LP_ERROR_IO: return "input/output error";
    case LP_ERROR_NO_MEMORY: return "out of memory";
    case LP_ERROR_RANGE: return "out of range";
    }
    return "unknown status";
}

lp_status lp__fail(lp_error *err, lp_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        err->status = status;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
    }
    return status;
}

void lp__ok(lp_error *err)
{
    if (err) {
        err->status = LP_OK;
        err->message[0] = '\0';
    }
}
