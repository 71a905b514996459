/* sa_error.h -- the error of a render against a reference (speed_accuracy).
 *
 * Both images hold linear RGB of the same size.  rmse is the root mean
 * square difference over every channel of every pixel (rs_image_rmse);
 * max_abs the largest absolute channel difference; share_visible the
 * fraction of pixels in which some channel differs by more than 1/255
 * once both are encoded by the sRGB curve (values clipped to [0, 1] as an
 * 8-bit PNG would be), i.e. pixels whose PNG may differ visibly. */
#ifndef SA_ERROR_H
#define SA_ERROR_H

#include "support/image.h"

typedef struct sa_error {
    double rmse, max_abs, share_visible;
} sa_error;

/* Returns 0, or -1 when the sizes differ. */
int sa_error_measure(const rs_image *img, const rs_image *ref, sa_error *out);

#endif
