/* plot.h -- a tiny line-plot renderer onto an rs_image (tools-internal).
 *
 * One call draws one complete chart (frame, grid, ticks, tick labels,
 * title, axis labels, optional vertical marker lines, the series and a
 * legend) into a rectangle of an image, so several charts can share one
 * picture.  Text uses a built-in 5x7 bitmap font (printable ASCII plus
 * the UTF-8 characters degree sign, theta and lambda), drawn at an
 * integer scale; lines are anti-aliased (coverage from the exact distance
 * to each segment, composited in linear light).
 *
 * Colours are given as 0xRRGGBB in sRGB, as on the web; the image holds
 * linear RGB (rs_png_write encodes it back to sRGB).
 *
 * No state: every function works only on its arguments. */
#ifndef ML_PLOT_H
#define ML_PLOT_H

#include <stddef.h>

#include "support/image.h"

typedef enum pl_dash {
    PL_SOLID = 0,
    PL_DASHED,
    PL_DOTTED
} pl_dash;

/* One line.  Points whose x or y is not finite -- or whose y <= 0 on a
 * logarithmic axis -- break the line there.  Parts outside the data
 * rectangle are clipped.  n == 0 makes a legend-only entry (e.g. a key
 * for a line style); label == NULL keeps the line out of the legend. */
typedef struct pl_series {
    const char *label;
    const double *x, *y;
    size_t n;
    unsigned color;  /* 0xRRGGBB, sRGB */
    pl_dash dash;
    double width;    /* line width in pixels; <= 0: 2 */
} pl_series;

/* A vertical reference line at data x (dashed grey), labelled at the top
 * of the data rectangle. */
typedef struct pl_marker {
    double x;
    const char *label;
} pl_marker;

typedef enum pl_corner {
    PL_LEGEND_NONE = 0,
    PL_LEGEND_TOP_LEFT,
    PL_LEGEND_TOP_RIGHT,
    PL_LEGEND_BOTTOM_LEFT,
    PL_LEGEND_BOTTOM_RIGHT,
    PL_LEGEND_LEFT,  /* vertically centred */
    PL_LEGEND_RIGHT
} pl_corner;

typedef struct pl_chart {
    const char *title;    /* may be NULL */
    const char *xlabel;   /* may be NULL */
    const char *ylabel;   /* may be NULL; drawn rotated */
    double xmin, xmax;    /* xmin < xmax */
    double ymin, ymax;    /* ymin < ymax; both > 0 when ylog */
    int ylog;             /* 1: log10 y axis, ticks at the decades */
    double xstep, ystep;  /* major tick spacing (linear axes); <= 0: automatic */
    int yticks_percent;   /* 1: append '%' to the y tick labels */
    pl_corner legend;
    int legend_columns;   /* <= 0: 1 */
    const pl_marker *markers;
    size_t n_markers;
    int text_scale;       /* font scale; <= 0: 2 (10x14 pixel glyphs) */
} pl_chart;

/* Fill the whole image with one colour. */
void pl_fill(rs_image *img, unsigned color);

/* Draw text with its top-left corner at (x, y) at the given scale (>= 1).
 * '\n' starts a new line.  Characters outside the font draw as '?'.
 * Pixels outside the image are skipped. */
void pl_text(rs_image *img, int x, int y, int scale, unsigned color, const char *text);

/* Width in pixels of the longest line of text at the given scale. */
int pl_text_width(const char *text, int scale);

/* Draw a chart into the rectangle (x, y, w, h) of img.  Returns 0, or -1
 * with a one-line message (an invalid range, a rectangle too small for
 * the frame, no memory). */
int pl_draw(rs_image *img, int x, int y, int w, int h, const pl_chart *chart,
            const pl_series *series, size_t n_series, char *msg, size_t msg_size);

#endif
