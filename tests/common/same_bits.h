/* same_bits.h -- lensprim results compared bit for bit, for the tests of
 * entry points whose contract is "exactly what the one-at-a-time call
 * gives" (tolerance 0: every double compared as bytes, no padding). */
#ifndef LP_TEST_SAME_BITS_H
#define LP_TEST_SAME_BITS_H

#include <string.h>

#include "lensprim.h"

/* The same outgoing ray, field by field. */
static inline int same_out_ray(const lp_out_ray *a, const lp_out_ray *b)
{
    const lp_ray *x = &a->ray, *y = &b->ray;
    return memcmp(&x->origin, &y->origin, sizeof x->origin) == 0 &&
           memcmp(&x->dir, &y->dir, sizeof x->dir) == 0 &&
           memcmp(&x->lambda_nm, &y->lambda_nm, sizeof(double)) == 0 &&
           memcmp(&x->intensity, &y->intensity, sizeof(double)) == 0 &&
           memcmp(&x->vp, &y->vp, sizeof x->vp) == 0 && x->kphi == y->kphi &&
           memcmp(&x->op, &y->op, sizeof(double)) == 0 &&
           memcmp(&x->phase, &y->phase, sizeof(double)) == 0 && x->ch == y->ch &&
           a->depth == b->depth && a->kind == b->kind && a->surface == b->surface &&
           a->part == b->part && a->path == b->path && a->waves == b->waves;
}

/* The same bookkeeping and number of rays. */
static inline int same_books(const lp_result *a, const lp_result *b)
{
    return memcmp(&a->in, &b->in, sizeof(double)) == 0 &&
           memcmp(&a->out, &b->out, sizeof(double)) == 0 &&
           memcmp(&a->skipped, &b->skipped, sizeof(double)) == 0 &&
           memcmp(&a->absorbed_glass, &b->absorbed_glass, sizeof(double)) == 0 &&
           memcmp(&a->absorbed_rim, &b->absorbed_rim, sizeof(double)) == 0 &&
           memcmp(&a->truncated, &b->truncated, sizeof(double)) == 0 &&
           a->warnings == b->warnings && a->nodes == b->nodes && a->count == b->count;
}

#endif
