/* result.h -- appending to an lp_result (internal). */
#ifndef LP_RESULT_H
#define LP_RESULT_H

#include "lensprim.h"

/* A slot for one more ray in a full result: the array grown, or NULL
 * when memory runs out. */
lp_out_ray *lp__result_grow(lp_result *r);

/* A slot for one more ray, or NULL when memory runs out. */
static inline lp_out_ray *lp__result_push(lp_result *r)
{
    if (r->count == r->capacity)
        return lp__result_grow(r);
    return &r->rays[r->count++];
}

#endif
