/* compare.c -- metrics, silhouettes and the difference map (compare.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compare.h"
#include "support/colorimetry.h"

static float clip01(float v)
{
    if (!(v > 0.0f)) /* NaN too */
        return 0.0f;
    return v < 1.0f ? v : 1.0f;
}

static size_t pixels_of(const rs_image *img)
{
    return (size_t)img->width * (size_t)img->height;
}

int pc_image_clip(const rs_image *img, rs_image *out)
{
    if (!img || !img->rgb || rs_image_create(out, img->width, img->height) != 0)
        return -1;
    for (size_t k = 0; k < 3 * pixels_of(img); k++)
        out->rgb[k] = clip01(img->rgb[k]);
    return 0;
}

double pc_image_luminance(const rs_image *img, size_t p)
{
    const float *c = img->rgb + 3 * p;
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

static double clipped_luminance(const rs_image *img, size_t p)
{
    const float *c = img->rgb + 3 * p;
    return 0.2126 * clip01(c[0]) + 0.7152 * clip01(c[1]) + 0.0722 * clip01(c[2]);
}

static int same_size(const rs_image *a, const rs_image *b)
{
    return a && b && a->rgb && b->rgb && a->width == b->width && a->height == b->height &&
           a->width > 0 && a->height > 0;
}

int pc_compare_images(const rs_image *a, const rs_image *b, pc_metrics *out)
{
    rs_image ca, cb;

    out->rmse = out->psnr = out->ssim = NAN;
    if (!same_size(a, b))
        return -1;
    if (pc_image_clip(a, &ca) != 0)
        return -1;
    if (pc_image_clip(b, &cb) != 0) {
        rs_image_free(&ca);
        return -1;
    }
    out->rmse = rs_image_rmse(&ca, &cb);
    out->psnr = rs_image_psnr(&ca, &cb);
    out->ssim = rs_image_ssim(&ca, &cb);
    rs_image_free(&ca);
    rs_image_free(&cb);
    return 0;
}

unsigned char *pc_mask_from_image(const rs_image *img)
{
    if (!img || !img->rgb)
        return NULL;
    size_t n = pixels_of(img);
    unsigned char *m = malloc(n ? n : 1);
    if (!m)
        return NULL;
    for (size_t p = 0; p < n; p++) {
        const float *c = img->rgb + 3 * p;
        float v = c[0] > c[1] ? c[0] : c[1];
        v = v > c[2] ? v : c[2];
        m[p] = v >= 0.5f;
    }
    return m;
}

/* ---- silhouettes ---- */

/* 1 where m is set and a 4-neighbour inside the image is not. */
static void boundary_of(const unsigned char *m, int w, int h, unsigned char *out)
{
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t p = (size_t)y * (size_t)w + (size_t)x;
            int b = 0;
            if (m[p]) {
                if (x > 0 && !m[p - 1])
                    b = 1;
                else if (x + 1 < w && !m[p + 1])
                    b = 1;
                else if (y > 0 && !m[p - (size_t)w])
                    b = 1;
                else if (y + 1 < h && !m[p + (size_t)w])
                    b = 1;
            }
            out[p] = (unsigned char)b;
        }
}

/* Squared distance from (x, y) to the nearest set pixel of bd, searching
 * square rings of growing Chebyshev radius until no closer pixel can
 * exist.  -1 when bd has no set pixel. */
static void consider(const unsigned char *bd, int w, int h, int x, int y, int dx, int dy,
                     long *best)
{
    int xx = x + dx, yy = y + dy;
    if (xx < 0 || yy < 0 || xx >= w || yy >= h || !bd[(size_t)yy * (size_t)w + (size_t)xx])
        return;
    long d2 = (long)dx * dx + (long)dy * dy;
    if (*best < 0 || d2 < *best)
        *best = d2;
}

static long nearest_sq(const unsigned char *bd, int w, int h, int x, int y)
{
    long best = -1;
    int rmax = w > h ? w : h;
    consider(bd, w, h, x, y, 0, 0, &best);
    for (int r = 1; r <= rmax; r++) {
        if (best >= 0 && (long)r * r >= best)
            break;
        for (int d = -r; d <= r; d++) {
            consider(bd, w, h, x, y, d, -r, &best);  /* top row */
            consider(bd, w, h, x, y, d, r, &best);   /* bottom row */
        }
        for (int d = -r + 1; d <= r - 1; d++) {
            consider(bd, w, h, x, y, -r, d, &best);  /* left column */
            consider(bd, w, h, x, y, r, d, &best);   /* right column */
        }
    }
    return best;
}

int pc_compare_masks(const unsigned char *a, const unsigned char *b, int width, int height,
                     pc_geometry *out)
{
    memset(out, 0, sizeof *out);
    out->worst_x = out->worst_y = out->worst_mask = -1;
    out->iou = out->max_boundary_px = NAN;
    if (!a || !b || width < 1 || height < 1)
        return -1;
    size_t n = (size_t)width * (size_t)height, inter = 0, uni = 0;
    for (size_t p = 0; p < n; p++) {
        out->area_a += a[p] != 0;
        out->area_b += b[p] != 0;
        inter += a[p] && b[p];
        uni += a[p] || b[p];
        out->flipped += (a[p] != 0) != (b[p] != 0);
    }
    out->iou = uni ? (double)inter / (double)uni : 1.0;

    unsigned char *ba = malloc(n), *bb = malloc(n);
    if (!ba || !bb) {
        free(ba);
        free(bb);
        return -1;
    }
    boundary_of(a, width, height, ba);
    boundary_of(b, width, height, bb);
    size_t na = 0, nb = 0;
    for (size_t p = 0; p < n; p++) {
        na += ba[p];
        nb += bb[p];
    }
    if (na == 0 && nb == 0) {
        out->max_boundary_px = 0.0;
    } else if (na == 0 || nb == 0) {
        out->max_boundary_px = INFINITY;
    } else {
        long worst = 0;
        for (int which = 0; which < 2; which++) {
            const unsigned char *from = which ? bb : ba, *to = which ? ba : bb;
            for (int y = 0; y < height; y++)
                for (int x = 0; x < width; x++) {
                    size_t p = (size_t)y * (size_t)width + (size_t)x;
                    if (!from[p] || to[p])
                        continue; /* on both boundaries: distance 0 */
                    long d2 = nearest_sq(to, width, height, x, y);
                    if (d2 > worst) {
                        worst = d2;
                        out->worst_x = x;
                        out->worst_y = y;
                        out->worst_mask = which;
                    }
                }
        }
        out->max_boundary_px = sqrt((double)worst);
    }
    free(ba);
    free(bb);
    return 0;
}

/* ---- the difference map ---- */

/* Control points of the ramp, sRGB-encoded; lightness rises along it. */
static const struct {
    double t, r, g, b;
} ramp_points[] = {
    {0.00, 0.00, 0.00, 0.00}, {0.15, 0.10, 0.06, 0.36}, {0.35, 0.42, 0.09, 0.50},
    {0.55, 0.78, 0.20, 0.32}, {0.75, 0.96, 0.52, 0.12}, {0.90, 0.98, 0.82, 0.26},
    {1.00, 1.00, 1.00, 0.85},
};

void pc_ramp(double t, float rgb[3])
{
    size_t n = sizeof ramp_points / sizeof ramp_points[0], k = 1;
    if (!(t > 0.0))
        t = 0.0;
    if (t > 1.0)
        t = 1.0;
    while (k + 1 < n && t > ramp_points[k].t)
        k++;
    double u = (t - ramp_points[k - 1].t) / (ramp_points[k].t - ramp_points[k - 1].t);
    double e[3] = {ramp_points[k - 1].r + u * (ramp_points[k].r - ramp_points[k - 1].r),
                   ramp_points[k - 1].g + u * (ramp_points[k].g - ramp_points[k - 1].g),
                   ramp_points[k - 1].b + u * (ramp_points[k].b - ramp_points[k - 1].b)};
    for (int c = 0; c < 3; c++)
        rgb[c] = (float)rs_srgb_decode(e[c]);
}

static int cmp_double(const void *pa, const void *pb)
{
    double a = *(const double *)pa, b = *(const double *)pb;
    return (a > b) - (a < b);
}

/* The smallest of 1, 2, 5 x 10^k that is >= v (v > 0). */
static double nice_ceil(double v)
{
    double p = pow(10.0, floor(log10(v)));
    static const double steps[] = {1.0, 2.0, 5.0, 10.0};
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; i++)
        if (steps[i] * p >= v * (1.0 - 1e-12))
            return steps[i] * p;
    return 10.0 * p;
}

int pc_diff_map(const rs_image *a, const rs_image *b, rs_image *out, double *scale,
                double *max_diff)
{
    if (!same_size(a, b))
        return -1;
    size_t n = pixels_of(a);
    double *d = malloc(n * sizeof *d), *sorted = malloc(n * sizeof *sorted);
    if (!d || !sorted || rs_image_create(out, a->width, a->height) != 0) {
        free(d);
        free(sorted);
        return -1;
    }
    double mx = 0.0;
    for (size_t p = 0; p < n; p++) {
        d[p] = fabs(clipped_luminance(a, p) - clipped_luminance(b, p));
        sorted[p] = d[p];
        if (d[p] > mx)
            mx = d[p];
    }
    qsort(sorted, n, sizeof *sorted, cmp_double);
    size_t q = (size_t)floor(0.999 * (double)(n - 1));
    double s = sorted[q];
    s = nice_ceil(s > 1e-4 ? s : 1e-4);
    for (size_t p = 0; p < n; p++)
        pc_ramp(d[p] / s, out->rgb + 3 * p);
    *scale = s;
    if (max_diff)
        *max_diff = mx;
    free(d);
    free(sorted);
    return 0;
}

int pc_worst_pixel_find(const rs_image *a, const rs_image *b, pc_worst_pixel *out)
{
    memset(out, 0, sizeof *out);
    if (!same_size(a, b))
        return -1;
    size_t n = pixels_of(a), best = 0;
    double bd = -1.0;
    for (size_t p = 0; p < n; p++) {
        double d = fabs(clipped_luminance(a, p) - clipped_luminance(b, p));
        if (d > bd) {
            bd = d;
            best = p;
        }
    }
    out->x = (int)(best % (size_t)a->width);
    out->y = (int)(best / (size_t)a->width);
    out->a = clipped_luminance(a, best);
    out->b = clipped_luminance(b, best);
    out->diff = bd;
    return 0;
}
