/* compare.h -- how far two renders of one scene are apart (pov_compare).
 *
 * Images are rs_images of linear RGB.  Every comparison first clips both
 * images to [0, 1] (POV-Ray clips at 1 when it writes its PNG, and a
 * render above 1 would otherwise be punished for light POV-Ray cannot
 * store), then uses image.h's RMSE, PSNR (peak 1) and SSIM.
 *
 * Silhouettes are binary masks, one byte per pixel (1 = lens, 0 = not),
 * row 0 at the top, pixel (x, y) at mask[y * width + x].  Their geometry
 * is compared by
 *   IoU                |A and B| / |A or B| (1 when both are empty);
 *   boundary distance  the symmetric Hausdorff distance, in pixels, between
 *                      the two masks' boundary pixel sets: the largest
 *                      distance from a boundary pixel of either mask to
 *                      the nearest boundary pixel of the other.  A boundary
 *                      pixel is a set pixel with a 4-neighbour inside the
 *                      image that is not set (the image's own edge is not
 *                      a boundary).  0 for identical masks; INFINITY when
 *                      one mask has a boundary and the other none.
 *   flipped pixels     pixels set in exactly one of the two masks.
 * A silhouette shifted by less than a pixel gives a distance of 1.
 *
 * Nothing here prints; no global state. */
#ifndef PC_COMPARE_H
#define PC_COMPARE_H

#include <stddef.h>

#include "support/image.h"

typedef struct pc_metrics {
    double rmse;
    double psnr;   /* dB; INFINITY for identical (clipped) images */
    double ssim;
} pc_metrics;

/* Metrics between a and b after clipping both to [0, 1] (NaN counts as 0).
 * Returns 0, or -1 (sizes differ, an image is empty, out of memory) with
 * every field NAN. */
int pc_compare_images(const rs_image *a, const rs_image *b, pc_metrics *out);

/* A copy of img with every value clipped to [0, 1] (NaN -> 0) into *out
 * (overwritten).  Returns 0 or -1 (out of memory, empty input). */
int pc_image_clip(const rs_image *img, rs_image *out);

/* Luminance 0.2126 R + 0.7152 G + 0.0722 B of pixel index p (= y*w + x). */
double pc_image_luminance(const rs_image *img, size_t p);

/* A binary mask of img: 1 where the pixel's largest channel is >= 0.5.
 * Returns a malloc'ed width*height array (free() it) or NULL. */
unsigned char *pc_mask_from_image(const rs_image *img);

typedef struct pc_geometry {
    double iou;              /* in [0, 1] */
    double max_boundary_px;  /* symmetric Hausdorff distance, pixels */
    size_t area_a, area_b;   /* set pixels of each mask */
    size_t flipped;          /* pixels set in exactly one mask */
    /* Where the largest boundary distance occurs: a boundary pixel of the
     * mask (0 = a, 1 = b) whose nearest boundary pixel in the other mask is
     * farthest; -1 when there is none (distance 0 or infinite). */
    int worst_x, worst_y, worst_mask;
} pc_geometry;

/* Compare two width x height masks.  Returns 0, or -1 on a bad size or
 * when out of memory. */
int pc_compare_masks(const unsigned char *a, const unsigned char *b, int width, int height,
                     pc_geometry *out);

/* The difference map of a and b (same size): per pixel the absolute
 * difference of the clipped luminances |Y(a) - Y(b)|, mapped through a
 * perceptual colour ramp (black, deep blue, purple, red, orange, yellow,
 * white: lightness rises monotonically) over [0, scale], into *out as
 * linear RGB (overwritten).  scale is a "nice" number (1, 2 or 5 times a
 * power of ten) at or above the 99.9th percentile of the differences, at
 * least 1e-4, and is returned in *scale.  *max_diff (may be NULL) gets
 * the largest difference.  Returns 0 or -1. */
int pc_diff_map(const rs_image *a, const rs_image *b, rs_image *out, double *scale,
                double *max_diff);

/* The ramp itself: the linear RGB colour of t in [0, 1] (clamped). */
void pc_ramp(double t, float rgb[3]);

/* Where two images differ most: the pixel of largest |Y(a) - Y(b)| after
 * clipping, its value in each image (luminance) and the difference.
 * Returns 0, or -1 for different sizes. */
typedef struct pc_worst_pixel {
    int x, y;
    double a, b, diff;
} pc_worst_pixel;
int pc_worst_pixel_find(const rs_image *a, const rs_image *b, pc_worst_pixel *out);

#endif
