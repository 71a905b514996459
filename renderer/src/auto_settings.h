/* auto_settings.h -- what `--mode auto --tolerance E` renders a scene with
 * (renderer-internal).
 *
 * E is the RMSE of linear RGB allowed against the scene's converged
 * reference (polarized, wavelengths and depth enough that doubling either
 * changes nothing, no branch cut-off).  The choice -- light model,
 * wavelength count, depth and cut-off -- reads the scene first and
 * measures on a small probe only what the scene alone cannot tell; E is
 * split into budgets, each error source kept inside its own:
 *
 *   model       polarized when the scene needs it, read from the scene:
 *               a polarizer, a crystal lens (its o and e rays part the
 *               light by polarization), a polarized light, a coherent
 *               light or global coherence -- an unpolarized model is
 *               wrong there by the whole effect.  Otherwise fresnel when
 *               its departure from polarized, measured on the probe, is
 *               within half of E.
 *   cut-off     an error budget, not a fixed weight.  Its floor comes from
 *               the library's per-branch bounds: below it no dropped branch
 *               can carry more than 10 % of E (bound on the path's power
 *               transmittance x the brightest radiance in the scene; where
 *               light is coherent a branch of weight w changes a pixel by
 *               up to 2 sqrt(w) through interference, so the weight budget
 *               is squared).  Most dropped branches carry far less than
 *               their bound (they see a dark background), so cut-offs from
 *               0.01 down by tens are measured on the probe and the first
 *               whose change to the next, doubled, is within 20 % of E
 *               stands; the floor ends the ladder.  Coherent scenes take
 *               the floor: interference makes a faint branch matter.
 *   wavelengths a ladder 4, 8, 16 ... on the probe, in the chosen model and
 *               cut-off: the first N whose change to 2N, doubled, fits in
 *               what the model and cut-off leave of E (at most 16384,
 *               what lensrender takes).
 *               Without dispersion the first rung stands; through
 *               dispersive glass the integrand over wavelength has a step
 *               at every edge a pixel's spectrum crosses and the error
 *               falls only as N^-0.5..N^-1.  Only the ladder's rungs are
 *               chosen: counts between them are not measured, and the
 *               error is not monotone in N.
 *   depth       16 levels, or the scene's max_trace_level when larger:
 *               the cut-off, not the depth, ends lens trees; the depth
 *               limit matters only where light is not attenuated (TIR
 *               traps, mirror pairs).
 *
 * The probe: a pilot first -- the middle pixel of every 2 x 2 cell (every
 * pixel of an image under 4 x 192 pixels; larger cells past 4096), in rgb,
 * or polarized at one wavelength where the scene needs that model -- marks
 * the brightest and (rgb) the most saturated pixels, 6 of each or one in
 * 64 of the pilot's, each standing for its cell: a regular subsample
 * misses the few pixels that carry most of an error (a cut-off's dropped
 * branch under a bright highlight, a wavelength count's error on a
 * saturated colour).  The marked pixels are in every probe render; then
 * one in 4 of the other pixels whose camera ray meets a lens (through
 * polarizers, which are thin sheets) and one in 32 of the rest (at least
 * 24 and 8, at most 1024 of each, lens pixels at most one in 16 of the
 * image), each group weighted by its share of the image; a subsampled
 * group's mean square is taken one standard error high (polariscope at
 * 16 x 12, E = 1e-4: without it the probe under-counted the change 16 ->
 * 32 wavelengths and auto stopped at 16, 1.0e-4 off).  Its cost,
 * wavelength samples summed over its renders (a pilot pixel in rgb counts
 * one), is returned; at 32 x 24 it is measured 0.38-0.56 of the chosen
 * render's where that is cheap, less at larger sizes.  Nothing here renders
 * the reference.
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
 * *probe_samples (when not NULL) the probe's cost: its pixels times
 * their wavelengths, summed over its renders (a render of the image
 * costs width x height x wavelengths of them);
 * why gets one line (no newline) saying what was chosen and why.  The
 * scene must be prepared.  Returns 0, or -1 with a message (out of
 * memory, a camera that cannot be set up). */
int rs_auto_choose(const rs_scene *scene, const rs_auto_request *req, rs_render_opts *out,
                   double *probe_samples, char *why, size_t why_size, char *msg,
                   size_t msg_size);

#endif
