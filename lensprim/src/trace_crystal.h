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

/* Backward tracing through a crystal: the state an lp_backward keeps
 * for it (trace_crystal_backward.c). */
typedef struct lp__xback lp__xback;

void lp__xback_free(lp__xback *x);
/* 1 when the last build was through a crystal (x may be NULL). */
int lp__xback_active(const lp__xback *x);
void lp__xback_deactivate(lp__xback *x);
size_t lp__xback_query_count(const lp__xback *x);
const lp_query *lp__xback_queries(const lp__xback *x);
int lp__xback_rim_depth(const lp__xback *x);

/* Build the view ray's tree after its entry hit h (not the rim), local
 * unit direction d; *xp is created on first use.  args are resolved. */
lp_status lp__crystal_build(lp__xback **xp, const lp_lens *lens, const lp__optics *optics,
                            const lp_trace_args *args, lp_vec3 d, const lp__local_hit *h,
                            lp_error *err);

/* Gather as lp_backward_gather. */
lp_status lp__crystal_gather(const lp__xback *x, size_t q, const lp_ray *bundle, size_t n,
                             lp_result *out, lp_error *err);

#endif
