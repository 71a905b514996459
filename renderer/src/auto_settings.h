/* auto_settings.h -- what `--mode auto --tolerance E` renders a scene with
 * (renderer-internal).
 *
 * E is the RMSE of linear RGB allowed against the scene's converged
 * reference (polarized, wavelengths and depth enough that doubling either
 * changes nothing, no branch cut-off).  Auto takes the candidate of least
 * cost whose error, estimated on a small probe of the image, is within E.
 * The candidates are the sweep's grid (speed_accuracy): every light model
 * the scene allows x wavelengths 4, 8, 16 ... 16384 x depth 4, 8, 16 and
 * 32 (or the scene's max_trace_level when larger) x cut-off 1e-2, 1e-3,
 * 1e-4, 1e-6 and, from depth 16 on, 1e-8 ... 1e-12, down to a floor.
 *
 *   models      polarized only where the scene needs it: a polarizer, a
 *               crystal lens (its o and e rays part the light by
 *               polarization), a polarized light, a coherent light or
 *               global coherence -- an unpolarized model is wrong there by
 *               the whole effect.  Otherwise rgb, schlick, fresnel and
 *               polarized, each priced and measured.
 *   cut-off     its floor comes from the library's per-branch bounds:
 *               below it no dropped branch can carry more than 10 % of E
 *               (bound on the path's power transmittance x the brightest
 *               radiance in the scene; where light is coherent a branch of
 *               weight w changes a pixel by up to 2 sqrt(w) through
 *               interference, so the weight budget is squared).  The
 *               deepest tree T* (the largest depth, the grid's cut-off at
 *               or below the floor) is the probe's reference for the
 *               tree, counted 0.1 E off.  A tree whose probe would cost
 *               more than 64 x the cheapest tree's is not probed (its
 *               render stops there, or is not started where the two
 *               looser trees of its depth foretell 4 x that): under
 *               coherent light the floor is squared, and the faint
 *               branches of a scene of many surfaces cost thousands of
 *               times the main rays (microscope.scene, ten surfaces and a
 *               crystal, depth 32 at 4 wavelengths: 192 pixels 0.05 s at
 *               cut-off 1e-2, 1.1 s at 1e-4, 45 s at 1e-6; at E = 1e-3
 *               its probe first rendered depth 32 at 1e-10 and had not
 *               ended in 12 minutes at 64 x 48).  T* is then the dearest
 *               tree probed, and auto's line says that what the fainter
 *               branches add is not in the estimate.  The chart's scenes
 *               stay within 2.5 x at E = 1e-4 (64 x 48), but polariscope
 *               (52 x) and newtons_rings (641 x: 2 of its 20 trees not
 *               probed at 1e-3, the same choice).
 *
 * The estimate of a candidate (model m, N wavelengths, tree T) is made of
 * measured parts, each an RMS difference over the probe:
 *
 *   e = sqrt(e_wl(N)^2 + e_model(m)^2) + e_tree(T)
 *
 * The wavelength and model parts add in quadrature: a too coarse
 * wavelength grid errs in sign with the grid (its error changes sign
 * from one count to the next), the unpolarized laws' error is the same
 * at every count, and over an image the two are uncorrelated -- measured
 * on the chart's references at 128 x 96, depth 16, cut-off 1e-3: fresnel
 * at 64 wavelengths against the reference 9.3e-4, 9.6e-4, 9.7e-4
 * (conical_rim, default, meniscus) where polarized at 64 is 7.3e-4,
 * 7.9e-4, 7.8e-4 and fresnel at 512 (its model's error) 6.0e-4, 5.3e-4,
 * 5.7e-4: in quadrature 9.4e-4, 9.5e-4, 9.7e-4; summed 1.3e-3 to 1.4e-3.
 * The tree's part (light the dropped branches would have carried: it
 * only darkens) adds linearly, the triangle inequality's bound.
 *
 *   e_wl(N)     the ladder: the probe rendered in the ladder's model
 *               (fresnel, or polarized where it is the only one) at the
 *               cheapest tree within E / 4 of T*, at 4, 8, 16 ...
 *               wavelengths; the top rung's error is taken as its last
 *               change and e_wl(N) is N's difference from the top plus
 *               it.  Over the whole image that sum is about twice the
 *               error: the errors of successive counts are uncorrelated
 *               where a lens disperses (each grid meets a pixel's
 *               spectral steps elsewhere, and the error halves per
 *               doubling), so a change is sqrt(5) / 2 of the coarser
 *               count's error and sqrt(5) times the finer's
 *               (default.scene at 128 x 96, polarized, depth 16, cut-off
 *               1e-3, against 2048 wavelengths: 2.8e-3, 1.9e-3, 7.9e-4 at
 *               16, 32, 64, the change 32 -> 64 2.1e-3, the changes 16 ->
 *               32 -> 64 at cos -0.58).  The sum is kept: its margin is
 *               what covers the probe's sampling of a heavy-tailed error.
 *               Summed in quadrature instead (the law of cosines at the
 *               changes' measured cosine), auto went over E where it had
 *               met it on 2 of the chart's 36 (scene, E): desk_lamp at 1e-3,
 *               1.08e-3 (fresnel at 16 wavelengths, whose wavelength part
 *               the probe measured 5.1e-4 where it is 8.9e-4: 10 of the
 *               12288 pixels carry 48 % of its squared error, 40 carry
 *               88 %, and the probe has 42 of the 1350 lens pixels) and
 *               plano_convex at 1e-4, 1.29e-4 (depth 8, whose tree part
 *               the probe measured 5.2e-5 where it is 1.2e-4).  The
 *               error is not monotone in N (a pixel's spectrum has
 *               steps), so each rung is measured, none extrapolated.
 *               The ladder climbs until the top's change is within
 *               E / 8, or, once some candidate
 *               meets E, while its next rung would cost the probe at most
 *               5 % of that candidate's render.
 *   e_tree(T)   T's difference from T*, both in rgb (or polarized at 4
 *               wavelengths where the scene needs it), plus 0.1 E.
 *   e_model(m)  m's difference from polarized at 4 wavelengths and the
 *               ladder's tree.
 *   rgb         (no wavelengths) its difference from the ladder's top
 *               plus the top's own error, in quadrature with the top's
 *               model part, plus the top's tree part.
 *
 * Per pixel, where it helps: a candidate may refine its wavelengths
 * (rs_render_opts.refine_tol): a pixel whose spectral packet split at a
 * dispersive lens is rendered again at 2N, 4N ... until two doublings in
 * a row change no channel by more than tau, or at the ladder's top count
 * (refine_max); the rest keep N.  Each rung N is tried with tau = E / 8
 * ... 8 E, each replayed on the probe's rungs (the probe's own split
 * pixels stepping up them by the same rule): its e_wl is the replayed
 * probe's difference from the top plus the top's error, its cost the
 * rung's plus what the replayed renders again cost.  tau sqrt(s) <= E
 * (s the share of the image that split): a pixel is left within about
 * tau of its converged value, which bounds what the refined pixels add
 * whatever the probe saw -- a looser tau let the few pixels a coarse grid
 * gets most wrong, which the probe's ~100 pixels miss, through (at
 * 8 E: default.scene 1.08e-4 and meniscus 1.01e-4 against E = 1e-4).
 * Two doublings, not one: a band of wavelengths that a lens sends
 * elsewhere, narrower than two grids' spacing, can leave them equal
 * (default.scene at 128 x 96: two pixels 4e-4 apart at 4 and 8
 * wavelengths, 0.4 at 16).  Past the top, a pixel whose last doubling
 * still changed a channel by more than E sqrt(pixels) / 4 -- one that
 * alone would take 1/16 of the image's squared error, and so there are
 * at most 16 of them in an image within E -- goes on doubling up to
 * 16384 (refine_outlier, refine_limit): such pixels are too few for any
 * probe to meet (crossed_polarizers at 128 x 96, E = 1e-3: 8 pixels of a
 * light seen through the lens, 0.065 off at 1024 wavelengths, were 1.1e-3
 * RMS over the image by themselves; past the top, 6.0e-4 for the whole
 * image).
 *
 * Costs are deterministic: every probe render counts its work
 * (rs_worker_work) and prices it (rs_work_cost); a candidate's cost is
 * predicted from the ladder's rung, scaled by its tree's and its model's
 * measured cost ratios.  The choice never depends on the machine.
 *
 * The probe: a pilot first -- one pixel in every cell of a grid of about
 * 1/256 of the image (at least 192 pixels: every pixel of a small image),
 * in rgb, or polarized at one wavelength where the scene needs that model
 * -- marks the cells of the brightest and (rgb) the most saturated
 * pixels, 6 of each or one in 64 of the pilot's, each cell standing in the
 * probe by a scrambled pixel of its own: a regular subsample misses the
 * few pixels that carry most of an error (a cut-off's dropped branch
 * under a bright highlight, a wavelength count's error on a saturated
 * colour), and the pilot's extreme pixel itself would weigh its cell high.
 * The marked pixels are in every probe render; then a scrambled one in
 * 32 of the other pixels whose camera ray meets a lens (through
 * polarizers, which are thin sheets) and one in 256 of the rest (at least
 * 24 and 8, lens pixels at most one in 128 of the image; a regular stride
 * aliases with the image's edges), each group weighted by its share of
 * the image; a subsampled group's mean square is taken one standard
 * error high.  At 128 x 96 that is about 100 pixels, and the probe costs
 * 9-40 % of the chosen render at E = 1e-2, less at smaller E and at
 * larger sizes.  Nothing here renders the reference.
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

/* What the choice costs, in rs_work_cost's units: the probe's renders
 * (spent), and the chosen render of the whole image (predicted). */
typedef struct rs_auto_cost {
    double probe, render;
} rs_auto_cost;

/* Choose.  out gets mode, wavelengths, depth, cutoff, width and height;
 * *cost (when not NULL) the probe's cost and the chosen render's; why gets
 * one line (no newline) saying what was chosen and why.  The scene must
 * be prepared.  Returns 0, or -1 with a message (out of memory, a camera
 * that cannot be set up). */
int rs_auto_choose(const rs_scene *scene, const rs_auto_request *req, rs_render_opts *out,
                   rs_auto_cost *cost, char *why, size_t why_size, char *msg, size_t msg_size);

#endif
