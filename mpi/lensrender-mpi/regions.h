/* regions.h -- an image cut into the square regions that lensrender-mpi
 * hands out, one work item each.
 *
 * Regions are side x side pixels (smaller at the right and bottom edges),
 * numbered row by row from the top left.  The side is a multiple of the
 * renderer's 16-pixel tile, chosen for two balances: inside a process,
 * at least 4 tiles per thread (so its threads finish together); across
 * processes, at least 8 regions per process (so a process that finishes
 * early takes more), the second winning when they disagree, down to one
 * tile.  Which region a pixel is in changes nothing of its value (the
 * renderer's determinism), so neither does the side. */
#ifndef LRMPI_REGIONS_H
#define LRMPI_REGIONS_H

typedef struct lm_regions {
    int width, height, side;
    int nx, ny; /* regions across and down */
} lm_regions;

/* The regions of a width x height image (both >= 1) for `processes`
 * processes of `threads` threads each (both >= 1). */
void lm_regions_init(lm_regions *g, int width, int height, int processes, int threads);

/* The number of regions, nx * ny. */
long lm_regions_count(const lm_regions *g);

/* Region k's pixels x0 <= i < x1, y0 <= j < y1 (0 <= k < count). */
void lm_region_rect(const lm_regions *g, long k, int *x0, int *y0, int *x1, int *y1);

#endif
