/* one_pixel.h -- render the single pixel of a 1x1 image of a scene given
 * as text, through the renderer's core (parser, integrator), for tests
 * whose set-up puts everything on one ray. */
#ifndef LP_TEST_ONE_PIXEL_H
#define LP_TEST_ONE_PIXEL_H

#include "integrator.h"

/* Parse text, prepare it and render pixel (0, 0) of a 1x1 image in mode
 * with n wavelengths (n <= 0: the default).  0 on success, else -1 with
 * the message on stderr. */
int one_pixel(const char *text, rs_mode mode, int wavelengths, rs_color *out);

#endif
