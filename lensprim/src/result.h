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

/* Room for n more rays, so that that many can be appended at
 * &r->rays[r->count++] without a check; 0 when memory runs out (nothing
 * changed). */
int lp__result_room(lp_result *r, size_t n);

static inline int lp__result_reserve(lp_result *r, size_t n)
{
    return r->capacity - r->count >= n ? 1 : lp__result_room(r, n);
}

#endif
