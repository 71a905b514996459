/* montage.h -- side_by_side.png: our render | POV-Ray's | the difference
 * map, each panel labelled (pov_compare).
 *
 * Layout, for panels of W x H pixels: three panels in a row with a gap
 * of 4 black pixels between them, a label strip above each and a caption
 * strip below.  Text is drawn with a built-in 5 x 7 pixel font (upper
 * case letters, digits and . , - + ( ) : = / % _ | and space; lower case
 * is drawn as upper case, anything else as '?'), scaled 2x when the
 * panels are at least 240 pixels wide.  Under the difference panel the
 * strip shows the colour ramp from 0 to diff_scale.
 *
 * The montage is built as linear RGB and written as an 8-bit sRGB PNG by
 * rs_png_write.  Nothing here prints; no global state. */
#ifndef PC_MONTAGE_H
#define PC_MONTAGE_H

#include <stddef.h>

#include "support/image.h"

typedef struct pc_montage_args {
    const rs_image *ours;     /* linear RGB; clipped to [0, 1] when drawn */
    const rs_image *povray;   /* same size */
    const rs_image *diff;     /* the map of pc_diff_map, same size */
    const char *ours_label;   /* e.g. "OURS (FRESNEL)" */
    const char *povray_label; /* e.g. "POV-RAY 3.7" */
    const char *diff_label;   /* e.g. "DIFFERENCE" */
    const char *ours_caption; /* under our panel (may be NULL), e.g. metrics */
    const char *povray_caption;
    double diff_scale;        /* the value at the top of the ramp */
} pc_montage_args;

/* Build the montage into *out (overwritten).  Returns 0, or -1 (images
 * missing or of different sizes, out of memory). */
int pc_montage_build(const pc_montage_args *args, rs_image *out);

/* Build and write it to path.  Returns 0, or -1 with a message. */
int pc_montage_write(const char *path, const pc_montage_args *args, char *msg, size_t msg_size);

/* Draw text with the built-in font, top-left corner at (x, y), each font
 * pixel a scale x scale block of colour rgb (linear).  Clipped to the
 * image.  Returns the width drawn in pixels. */
int pc_draw_text(rs_image *img, int x, int y, int scale, const char *text, const float rgb[3]);

/* The width in pixels text would take at this scale. */
int pc_text_width(const char *text, int scale);

#endif
