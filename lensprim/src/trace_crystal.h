/* trace_crystal.h -- tracing through a lens of a uniaxial crystal
 * (internal). */
#ifndef LP_TRACE_CRYSTAL_H
#define LP_TRACE_CRYSTAL_H

#include "trace.h"
#include "uniaxial.h"

/* The crystal and the medium around it at one wavelength. */
typedef struct lp__crystal_optics {
    lp__medium crystal, medium;
    double alpha_o, alpha_e;   /* 1/mm, of the field across / along the axis */
} lp__crystal_optics;

/* Fill *x from the lens and the optics of its ordinary glass; adds the
 * extraordinary glass's extrapolation warning to o->warnings. */
lp_status lp__crystal_optics_at(const lp_lens *lens, lp__optics *o, lp__crystal_optics *x,
                                lp_error *err);

/* Absorption coefficient per mm along the ray of a wave of kind
 * LP__WAVE_O or LP__WAVE_E with real wave vector K. */
double lp__crystal_alpha(const lp__crystal_optics *x, int kind, lp_vec3 K);

/* The forward trace after the entry hit h (not the rim) of the local ray
 * of unit direction d and field E (power |E|^2, already counted in
 * res->in): the tree of o and e rays inside, every outgoing ray. */
lp_status lp__crystal_forward(const lp_lens *lens, lp__optics *o, const lp_trace_args *a,
                              const lp__local_hit *h, lp_vec3 d, const lp__cvec3 *E,
                              const lp__payload *pl, lp_result *res, lp_error *err);

#endif
