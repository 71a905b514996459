/* result.c -- the growable list of outgoing rays and its bookkeeping. */
#include <stdlib.h>
#include <string.h>

#include "result.h"

void lp_result_init(lp_result *r)
{
    if (r)
        memset(r, 0, sizeof *r);
}

void lp_result_clear(lp_result *r)
{
    if (!r)
        return;
    r->count = 0;
    r->in = r->out = r->skipped = r->absorbed_glass = r->absorbed_rim = r->truncated = 0.0;
    r->warnings = 0;
    r->nodes = 0;
}

void lp_result_release(lp_result *r)
{
    if (!r)
        return;
    free(r->rays);
    memset(r, 0, sizeof *r);
}

lp_out_ray *lp__result_grow(lp_result *r)
{
    size_t cap = r->capacity ? 2 * r->capacity : 16;
    lp_out_ray *p = realloc(r->rays, cap * sizeof *p);
    if (!p)
        return NULL;
    r->rays = p;
    r->capacity = cap;
    return &r->rays[r->count++];
}

int lp__result_room(lp_result *r, size_t n)
{
    size_t cap = r->capacity ? r->capacity : 16; /* as lp__result_grow */
    while (cap - r->count < n)
        cap *= 2;
    if (cap == r->capacity)
        return 1;
    lp_out_ray *p = realloc(r->rays, cap * sizeof *p);
    if (!p)
        return 0;
    r->rays = p;
    r->capacity = cap;
    return 1;
}
