/* sa_refine.h -- a reference converged pixel by pixel (speed_accuracy).
 *
 * Doubling the wavelengths of the whole image stops at the time budget
 * while a few pixels still change: a dispersed edge, a glass's coloured
 * rim, a bright light seen through a prism, where each pixel catches a
 * band of the spectrum narrower than the wavelength step.  Most pixels
 * have long settled.  sa_refine renders again, with twice the
 * wavelengths, only the pixels not yet calm -- whose colour changed by
 * more than tol in one of their last SA_CALM doublings -- replaces them,
 * and goes on with those: the rule for a converged reference
 * ("doubling changes no pixel by more than tol") applied to each pixel,
 * at the cost of the pixels that need it.  Two doublings in a row, not
 * one, as auto's refinement (RS_REFINE_CALM): a bright light seen
 * through crossed_polarizers' lens changed by 1e-5 from 2048 to 4096
 * wavelengths and by 0.016 from 4096 to 8192 (then 1e-6 to 16384); the
 * reference kept it at 4096, 0.016 off, and auto's render at 16384 was
 * counted wrong there.  A pixel starts with the calm doublings of the
 * given change and, where given, the change before it.  Each pixel keeps its own last change; their RMS
 * over the image stands for the reference's wavelength error as the
 * whole image's last change did.  Every pixel is lr_render_region's,
 * bit for bit what a whole render at its wavelength count gives. */
#ifndef SA_REFINE_H
#define SA_REFINE_H

#include <stddef.h>

#include "support/image.h"

#define SA_CALM 2 /* doublings in a row within tol: a converged pixel */

typedef struct sa_refine_opts {
    const char *scene;  /* the scene file */
    int depth;          /* the reference's depth and cut-off, polarized */
    double cutoff;
    int wavelengths;    /* what *img was rendered with */
    int wavelengths_max; /* no pixel beyond this (<= 16384) */
    double tol;         /* a pixel whose channels all changed by at most
                           this in each of its last SA_CALM doublings
                           has converged */
    double budget;      /* no doubling predicted to take longer (CPU s) */
    double s_per_pixel_wl; /* a first guess of a pixel's cost per
                              wavelength (CPU s) */
    const rs_image *before; /* each pixel's change in the doubling before
                               the last (NULL: not known, as if not calm) */
} sa_refine_opts;

typedef struct sa_refine_stats {
    int wavelengths;  /* the most any pixel reached */
    int levels;       /* doublings run */
    long renders;     /* pixels rendered, over every doubling */
    long left;        /* pixels not calm in SA_CALM doublings */
    double rmse;      /* RMS over every channel of every pixel of its last change */
    double max;       /* the largest channel change of any pixel's last doubling */
    double seconds;   /* CPU seconds of the doublings */
} sa_refine_stats;

/* img: the image at o->wavelengths, refined in place; last: each
 * pixel's change in its last doubling (img minus the image at half the
 * wavelengths, or any estimate of it), updated in place.  Returns 0, or
 * -1 with a message. */
int sa_refine(const sa_refine_opts *o, rs_image *img, rs_image *last, sa_refine_stats *st,
              char *msg, size_t msg_size);

#endif
