/* render_check.h -- whole renders for the tests that check them against
 * closed-form optics (test_render_physics, test_interference): load a
 * scene, render (the masked pixels of) a picture through the tile
 * scheduler, read pixels, and locate an extremum by a least-squares
 * parabola. */
#ifndef RENDER_CHECK_H
#define RENDER_CHECK_H

#include "integrator.h"
#include "scene.h"

typedef struct picture {
    int w, h;
    double *rgb; /* 3 per pixel, row-major from the top */
} picture;

/* Parse text (or the file at path when text is NULL) into sc, which the
 * caller has set up with rs_scene_init and releases with rs_scene_free;
 * w x h is the image size the scene sees (image_width, image_height).
 * 0, or -1 with the message on stderr. */
int rc_load_scene(rs_scene *sc, const char *text, const char *path, int w, int h);

/* Render (the masked pixels of; mask NULL: all) a w x h picture of sc into
 * *pic (allocated here; the caller frees pic->rgb).  depth <= 0 and
 * cutoff < 0 take the scene's settings, wavelengths <= 0 the default.
 * 0, or -1 with the message on stderr. */
int rc_render(const rs_scene *sc, rs_mode mode, int w, int h, int depth, double cutoff,
              int wavelengths, const unsigned char *mask, picture *pic);

double rc_px(const picture *p, int i, int j, int c);
/* Rec. 709 luminance of pixel (i, j). */
double rc_luminance(const picture *p, int i, int j);

/* The vertex (*xv, *yv) of the least-squares parabola through (x[k],
 * y[k]), k = 0..n-1 (n >= 3); 0, or -1 when the points do not make a
 * parabola opening upwards (no minimum).  yv may be NULL. */
int rc_parabola_min(const double *x, const double *y, int n, double *xv, double *yv);

#endif
