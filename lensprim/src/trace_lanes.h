/* trace_lanes.h -- the lane engine: a group of forward rays of one
 * wavelength through a glass lens, in lockstep (internal).
 *
 * Through a glass (not crystal) lens a forward ray's tree is a chain:
 * node 1 reflects a ray out and refracts one in; every later node sends
 * one ray out and reflects the other on.  The rays of a group walk their
 * chains together, one node per step for all of them, in loops over the
 * lanes that the compiler vectorizes; a lane that leaves (a miss, the
 * rim, the depth, the weight cut) is masked off.  A lane that meets
 * anything rare -- total internal reflection, normal incidence, a start
 * on the lens, a chain that loses its way -- is handed back, and that
 * ray is traced from its start by the one-ray code.  Every operation is
 * the one-ray code's, in the same order, so a ray the engine traces gives
 * the same outgoing rays and sums, bit for bit. */
#ifndef LP_TRACE_LANES_H
#define LP_TRACE_LANES_H

#include "trace.h"

/* The helpers of the loops over lanes must be inlined, or the loops
 * cannot be vectorized. */
#if defined(__GNUC__)
#define LP__INLINE static inline __attribute__((always_inline))
#else
#define LP__INLINE static inline
#endif

/* The loops over lanes are compiled for the widest vectors of the
 * machine that runs them (AVX-512, AVX2, else the baseline), chosen once
 * when the program loads.  Every copy does the same operations in the
 * same order (the build keeps FP contraction off), so all give the same
 * bits. */
#ifndef LP__WIDE /* a build may pin one copy (-DLP__WIDE=) to check it */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define LP__WIDE __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define LP__WIDE
#endif
#endif

/* Rays per group. */
#define LP__LANES 64

/* A group's rays, checked and in the lens frame. */
typedef struct lp__lane_in {
    const double *px, *py, *pz; /* origins */
    const double *dx, *dy, *dz; /* unit directions */
    const double *vx, *vy, *vz; /* unit field directions, perpendicular */
    const double *intensity;    /* finite, >= 0 */
    const double *op;           /* optical paths so far */
    const double *take;         /* 1: the engine may trace the ray, 0: not */
} lp__lane_in;

typedef struct lp__lanes lp__lanes;

/* Scratch for groups traced to depth max_depth at most; NULL when memory
 * runs out.  lp__lanes_destroy(NULL) is a no-op. */
lp__lanes *lp__lanes_create(int max_depth);
void lp__lanes_destroy(lp__lanes *L);

/* Trace rays 0..m-1 (m <= LP__LANES) of a group at the optics o with the
 * resolved args a (a->max_depth no deeper than L's).  Nothing is added
 * to a result yet: see lp__lanes_emit. */
void lp__lanes_run(lp__lanes *L, const lp_lens *lens, const lp__optics *o,
                   const lp_trace_args *a, const lp__lane_in *in, size_t m);

/* 1 when the last run traced ray j (its results wait for lp__lanes_emit);
 * 0 when the ray was not taken or was handed back (lp__trace_checked
 * traces it). */
int lp__lanes_traced(const lp__lanes *L, size_t j);

/* Add ray j's outgoing rays and sums to res, exactly as lp__trace_checked
 * would for the ray of that intensity and payload pl with the same args:
 * the flags and the filter are applied here, in the order of the one-ray
 * code.  Returns LP_ERROR_NO_MEMORY or LP_OK. */
lp_status lp__lanes_emit(const lp__lanes *L, size_t j, const lp_lens *lens,
                         const lp_trace_args *a, double intensity, const lp__payload *pl,
                         lp_result *res, lp_error *err);

#endif
