/* catalog_internal.h -- what catalog.c and agf.c share (internal). */
#ifndef LP_CATALOG_INTERNAL_H
#define LP_CATALOG_INTERNAL_H

#include <stddef.h>

#include "lensprim.h"

/* The internal transmittance stored for a reading of 0 ("opaque"), which
 * lp_glass cannot hold (tau must lie in (0, 1]).  Catalogs print tau with
 * three decimals, so a printed 0.000 means tau < 0.0005; the largest value
 * consistent with the reading is used, which keeps the absorption finite
 * and at least as strong as the data say. */
#define LP__TAU_OPAQUE 5e-4

/* A catalog is a growable array of glasses; names are unique under
 * lp__name_equal. */
struct lp_catalog {
    lp_glass *glasses;
    size_t count;
    size_t capacity;
};

/* 1 when a and b are equal ignoring ASCII case, else 0. */
int lp__name_equal(const char *a, const char *b);

/* Add glasses[0..n) to the catalog in order; a glass whose name is already
 * present replaces that entry.  All or nothing: on LP_ERROR_NO_MEMORY the
 * catalog is unchanged. */
lp_status lp__catalog_add(lp_catalog *catalog, const lp_glass *glasses,
                          size_t n, lp_error *err);

#endif
