/* sa_error.c -- render error against a reference (see sa_error.h). */
#include "sa_error.h"

#include <math.h>

#include "support/colorimetry.h"

int sa_error_measure(const rs_image *img, const rs_image *ref, sa_error *out)
{
    size_t n, visible = 0;
    double mx = 0.0;
    if (img->width != ref->width || img->height != ref->height)
        return -1;
    n = (size_t)img->width * (size_t)img->height;
    for (size_t p = 0; p < n; p++) {
        int vis = 0;
        for (int c = 0; c < 3; c++) {
            double a = img->rgb[3 * p + c], b = ref->rgb[3 * p + c];
            double d = fabs(a - b);
            if (d > mx)
                mx = d;
            if (fabs(rs_srgb_encode(a) - rs_srgb_encode(b)) > 1.0 / 255.0)
                vis = 1;
        }
        visible += (size_t)vis;
    }
    out->rmse = rs_image_rmse(img, ref);
    out->max_abs = mx;
    out->share_visible = n ? (double)visible / (double)n : 0.0;
    return 0;
}
