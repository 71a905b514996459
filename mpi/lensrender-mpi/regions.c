/* regions.c -- the image in square regions (regions.h). */
#include "regions.h"

#define TILE 16

static void set_side(lm_regions *g, int side)
{
    g->side = side;
    g->nx = (g->width - 1) / side + 1;
    g->ny = (g->height - 1) / side + 1;
}

void lm_regions_init(lm_regions *g, int width, int height, int processes, int threads)
{
    int tiles = 1; /* tiles along a side: a power of two */
    g->width = width;
    g->height = height;
    while (tiles * tiles < 4 * threads && tiles < 64)
        tiles *= 2;
    set_side(g, tiles * TILE);
    while (g->side > TILE && lm_regions_count(g) < 8L * processes)
        set_side(g, g->side / 2);
}

long lm_regions_count(const lm_regions *g)
{
    return (long)g->nx * g->ny;
}

void lm_region_rect(const lm_regions *g, long k, int *x0, int *y0, int *x1, int *y1)
{
    int rx = (int)(k % g->nx), ry = (int)(k / g->nx);
    *x0 = rx * g->side;
    *y0 = ry * g->side;
    *x1 = g->width - *x0 > g->side ? *x0 + g->side : g->width;
    *y1 = g->height - *y0 > g->side ? *y0 + g->side : g->height;
}
