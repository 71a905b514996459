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
 * rs_scene_freeze_glass) so that the two renders compare like with like. */
#ifndef PC_TRANSLATE_H
#define PC_TRANSLATE_H

#include <stddef.h>
#include <stdio.h>

#include "scene.h"

typedef struct pc_notes {
    char **text;     /* owned; one sentence each */
    size_t n, cap;
} pc_notes;

void pc_notes_free(pc_notes *notes);
/* Append a copy of a note (duplicates are not added again). */
int pc_notes_add(pc_notes *notes, const char *text);

typedef struct pc_translate_opts {
    int width, height;      /* for right = x*W/H etc. (already folded) */
    int max_trace_level;    /* written into global_settings */
    const char *lens_inc;   /* path written in #include "..." */
    int mask;               /* 1: a silhouette scene: only lenses, as opaque
                               white emitters on black, max_trace_level 1 */
} pc_translate_opts;

/* Write the POV-Ray scene for `scene` to `out`.  Notes about what was left
 * out or approximated are appended to `notes`.  Returns 0, or -1 with a
 * message. */
int pc_translate(const rs_scene *scene, const pc_translate_opts *opts, FILE *out,
                 pc_notes *notes, char *msg, size_t msg_size);

#endif
