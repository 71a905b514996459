/* translate.h -- a parsed .scene as a POV-Ray 3.7 scene (pov_compare).
 *
 * The translation keeps what POV-Ray can express exactly (camera, lights,
 * planes, spheres, boxes, discs, pigments, finishes, transforms) and
 * writes each lens as CSG through the macro of scenes/lens.inc: the
 * intersection of its two caps (spheres or half-spaces) and a cylinder or
 * cone rim, with a clear lossless dielectric (exact unpolarized Fresnel,
 * conserve_energy, interior on the CSG parent) and an opaque black rim.
 * What POV-Ray cannot express is left out or approximated, and a note
 * says so for each case:
 *   polarizers               left out
 *   coherence                left out (POV-Ray adds intensities)
 *   dispersion               off: ior = n at 587.56 nm (the d line)
 *   absorption               left out (POV-Ray's fade attenuates only
 *                            refracted light, not Beer-Lambert)
 *   monochromatic lights     the line's colour as RGB
 *   blackbody lights         the black body's colour as RGB
 *   light polarization       left out
 * The renderer is then run with the same approximations (see
 * lr_render_opts.no_dispersion) so that the two renders compare like with like. */
#ifndef PC_TRANSLATE_H
#define PC_TRANSLATE_H

#include <stddef.h>
#include <stdio.h>

#include "lensrender/scene.h"

/* The notes pc_translate adds, each at most once and only when the scene
 * has the feature (additions to the original API; the harness and tests
 * may compare against them). */
#define PC_NOTE_POLARIZERS \
    "polarizer objects have no POV-Ray equivalent and were left out"
#define PC_NOTE_COHERENCE \
    "coherence was left out: POV-Ray adds intensities, so there is no interference"
#define PC_NOTE_DISPERSION \
    "dispersion is off: each lens has its index at 587.5618 nm (the d line)"
#define PC_NOTE_ABSORPTION \
    "glass absorption was left out (POV-Ray's fade attenuates only refracted light, " \
    "not Beer-Lambert)"
#define PC_NOTE_MEDIUM \
    "lenses in a medium other than air have ior n_glass/n_medium (exact at their faces; " \
    "POV-Ray has no surrounding medium)"
#define PC_NOTE_LINE_LIGHTS \
    "monochromatic lights were given their line's colour as RGB (linear sRGB of the " \
    "line, Y = luminance of the light's colour, negative components clipped)"
#define PC_NOTE_BLACKBODY_LIGHTS \
    "blackbody lights were given the black body's colour as RGB (Y = luminance of the " \
    "light's colour, negative components clipped)"
#define PC_NOTE_LIGHT_POLARIZATION \
    "light polarization was left out: POV-Ray's lights are unpolarized"

/* POV-Ray's largest max_trace_level; larger values are written as this
 * (with a note). */
#define PC_POV_MAX_TRACE_LEVEL 256

typedef struct pc_notes {
    char **text;     /* owned; one sentence each */
    size_t n, cap;
} pc_notes;

void pc_notes_free(pc_notes *notes);
/* Append a copy of a note (duplicates are not added again). */
int pc_notes_add(pc_notes *notes, const char *text);

typedef struct pc_translate_opts {
    int width, height;      /* for right = x*W/H etc. (already folded) */
    int max_trace_level;    /* written into global_settings; <= 0: the
                               scene's; clamped to 1..256 */
    const char *lens_inc;   /* path written in #include "..." (NULL or "":
                               "lens.inc") */
    int mask;               /* 1: a silhouette scene: only lenses, as opaque
                               white emitters on black, max_trace_level 1 */
} pc_translate_opts;

/* (addition) The magnification pc_translate writes the scene with, for
 * an image of width x height pixels (<= 0: 640 x 480).
 * POV-Ray ignores intersections closer than 1e-4 of its units to a ray's
 * origin and farther than 1e7: in millimetres, an air gap thinner than
 * 0.1 um (the contact zone of Newton's rings) is crossed without seeing
 * its two faces.  Magnifying the scene k times moves both limits down k
 * times.  The factor is the largest power of ten k <= 10^4 with
 * k * E <= 10^6, where E is the larger of the diagonal of the box around
 * everything finite in the scene (camera, lights, lenses, spheres, boxes,
 * discs, polarizers) and the farthest point where a primary ray (every
 * pixel centre) meets a plane: POV-Ray then still sees everything out to
 * 10 E.  1 when that is not possible (a plane seen up to its horizon),
 * the camera is degenerate or the scene is already large.  Magnifying
 * changes nothing else in POV-Ray's image: lights have no distance
 * falloff and no fade is written. */
double pc_pov_scale(const rs_scene *scene, int width, int height);

/* Write the POV-Ray scene for `scene` to `out`.  Notes about what was left
 * out or approximated are appended to `notes` (none in mask mode).
 * Returns 0, or -1 with a message (nothing is written when the scene is
 * refused: a non-finite value, an impossible lens, a glass without an
 * index at the d line, a lens_inc path with '"' or control characters).
 *
 * The scene is written magnified pc_pov_scale() times (see there);
 * POV-Ray's image is the same but for its near and far cut-offs.
 *
 * Translate the scene as parsed (rs_scene_prepare optional, BEFORE
 * rs_scene_freeze_glass): a frozen scene gives the same POV-Ray text but
 * its lenses no longer show dispersion or absorption, so those notes are
 * missing.  Every lens's interior is `ior n_glass(d)/n_medium(d)` at
 * RS_LAMBDA_D_LINE, as rs_scene_freeze_glass(scene, RS_LAMBDA_D_LINE)
 * leaves the renderer.
 *
 * A plane, sphere or box whose inside holds the camera is written turned
 * inside out (plane normal and distance negated, `inverse` for spheres and
 * boxes): the same opaque surface, but POV-Ray no longer thinks the camera
 * (and every lens on its side) is inside it, which would spoil Fresnel at
 * the lens exit faces.  A lens crossing such a surface gets a note. */
int pc_translate(const rs_scene *scene, const pc_translate_opts *opts, FILE *out,
                 pc_notes *notes, char *msg, size_t msg_size);

/* (addition) pc_translate with the magnification given: POV-Ray units per
 * scene unit, > 0 (1: as is), or 0 for pc_pov_scale(scene, opts->width,
 * opts->height), which is what pc_translate uses.  The camera location and look_at, the lights
 * and every object (through its matrix) are magnified; directions,
 * patterns (relative to their objects) and the Lens() arguments (placed
 * by the lens's matrix) are not. */
int pc_translate_scaled(const rs_scene *scene, const pc_translate_opts *opts, double scale,
                        FILE *out, pc_notes *notes, char *msg, size_t msg_size);

#endif
