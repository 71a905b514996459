/* auto_settings.h -- what `--mode auto --tolerance E` renders a scene with
 * (renderer-internal).
 *
 * E is the RMSE of linear RGB allowed against the scene's converged
 * reference (polarized, wavelengths and depth enough that doubling either
 * changes nothing, no branch cut-off).  The choice -- light model,
 * wavelength count, depth and cut-off -- splits E into budgets and keeps
 * each error source inside its own:
 *
 *   model       polarized when the scene needs it (a polarizer, a
 *               polarized light, a coherent light or global coherence: an
 *               unpolarized model is wrong there by the whole effect);
 *               otherwise fresnel when its measured departure from the
 *               polarized model on the probe pixels is within 30 % of E.
 *   wavelengths the midpoint rule's error falls as N^-p (p between 0.5
 *               and 1) where dispersion puts steps into the integrand over
 *               wavelength, and is 0 without dispersion and pigment
 *               colours; the probe pixels are rendered at 4, 8, 16, 32
 *               and 64 wavelengths: the errors of 4..32 are measured (the
 *               changes up to 64 plus the extrapolated rest), p comes
 *               from the changes 16->32->64, and beyond 64 the error is
 *               extrapolated as N^-p.  N is the least that keeps it
 *               within what the other budgets leave of E (at most 1024).
 *   cut-off     an error budget, not a fixed weight: a branch is dropped
 *               when the radiance it can still carry -- its bound on the
 *               path's power transmittance (the library's per-branch
 *               bound) times the brightest radiance anything in the scene
 *               sends -- is below 10 % of E; where light is coherent a
 *               branch of weight w changes a pixel by up to 2 sqrt(w)
 *               through interference, and the weight budget is squared.
 *   depth       deep enough that what the depth limit drops is the cut-off
 *               budget's business: 16 levels for E >= 1e-3, 32 below.
 *
 * The probe pixels are about one in 64 of the
 * image (at least 48 through glass and 16 elsewhere, each group weighted
 * by its share of the image): 124 wavelength samples (plus 32 for
 * fresnel) per probe pixel, a fraction of the render.  Nothing here renders the reference.
 *
 * No printing, no global state.  The caller's --depth, --wavelengths and
 * --cutoff, when given, are kept and the rest chosen around them. */
#ifndef RS_AUTO_SETTINGS_H
#define RS_AUTO_SETTINGS_H

#include <stddef.h>

#include "integrator.h"
#include "scene.h"

#define RS_AUTO_TOLERANCE_DEFAULT 1e-3

typedef struct rs_auto_request {
    double tolerance;  /* E > 0 */
    int width, height; /* the image */
    int depth;         /* > 0: fixed by the user */
    int wavelengths;   /* > 0: fixed by the user */
    double cutoff;     /* >= 0: fixed by the user (a weight) */
} rs_auto_request;

/* Choose.  out gets mode, wavelengths, depth, cutoff, width and height;
 * why gets one line (no newline) saying what was chosen and why.  The
 * scene must be prepared.  Returns 0, or -1 with a message (out of
 * memory, a camera that cannot be set up). */
int rs_auto_choose(const rs_scene *scene, const rs_auto_request *req, rs_render_opts *out,
                   char *why, size_t why_size, char *msg, size_t msg_size);

#endif
