/* coherence.h -- where the light of a coherent source starts its optical
 * path, and the power that a bundle of rays delivers at the pixel
 * (renderer-internal).
 *
 * The physics (README, "Interference"): two beams interfere only when
 * they come from the same source point, and then with the optical path
 * difference of the real paths from that point to the image point.  The
 * integrator traces each beam back from the pixel until it meets a source
 * (an emitting or diffusing surface, or the background at infinity); the
 * last segment of the beam, from the last surface the light crossed to the
 * source, is its "wavelet".  A bundle ray's op is the optical path from
 * the start of its wavelet to the camera, without the wavelet itself.
 *
 * For a pair of beams of one source the wavelets are joined to ONE common
 * source point: the midpoint S of the two points where the beams met the
 * source, each wavelet replaced by a spherical wavelet from S, so the pair
 * differs by
 *     D = op_a - op_b + |S - o_a| - |S - o_b|
 * (o the start of a wavelet).  For the background (a source at infinity)
 * S recedes along the mean direction u of the two wavelets, a plane wave:
 *     D = op_a - op_b - u.(o_a - o_b).
 * By Fermat's principle the optical path is stationary, so this is the
 * difference of the real paths from S to first order in the beams'
 * separation; it does not depend on where the world origin is, on the
 * camera distance, or on glass that both beams cross.  Beams that met the
 * source on different objects (a diffusing surface is a rough scatterer:
 * its points are mutually incoherent, each carrying its light's temporal
 * coherence) add as intensities.
 *
 * Each emitted ray gets ch = (wavelet index << 32) | (2 source + half):
 * the low half is the coherence channel (one per source and half of
 * natural light), the high half indexes the worker's wavelet table. */
#ifndef RS_COHERENCE_H
#define RS_COHERENCE_H

#include <stddef.h>
#include <stdint.h>

#include "lensprim.h"

/* The last segment of a traced beam, towards its source. */
typedef struct rs_wavelet {
    lp_vec3 o;      /* where it starts: the last surface the light crossed
                       (or the camera) */
    lp_vec3 d;      /* unit direction from o towards the source */
    lp_vec3 s;      /* where it meets the source (finite sources) */
    int finite;     /* 0: the background, at infinity along d */
    int emitter;    /* the object the source point lies on; -1: background */
} rs_wavelet;

typedef struct rs_wavelets {
    rs_wavelet *w;
    size_t n, cap;
} rs_wavelets;

/* Append a wavelet; its index, or -1 when out of memory (or when the
 * table would outgrow 2^32 entries). */
long rs_wavelets_push(rs_wavelets *t, const rs_wavelet *w);
void rs_wavelets_free(rs_wavelets *t);

/* The ch of a ray of source `source`, half `half`, leaving wavelet `index`
 * (inline: every emitted ray has one). */
static inline uint64_t rs_coherence_ch(long index, int source, int half)
{
    return ((uint64_t)index << 32) | (2u * (uint64_t)source + (uint64_t)half);
}

/* Rays a crystal lens splits into o and e rays.  The rays one lens hit
 * returns on queries of one depth and kind, grown from one channel, come
 * from that source: their wavelets are joined to a common source point
 * like any pair's, and they are mutually coherent whatever the source's
 * `coherent` setting (natural white light gives the interference colours
 * of a crystal); different source points (emitters) and the two halves
 * of natural light still add as intensities.  rs_coherence_split marks
 * such a ray: bit 31 of ch set, bits 16-30 a number of the group (the lens
 * hit's number `hit`, the depth and kind of its query), the source and
 * half in bits 0-15, the wavelet index kept.  Channels of a split group
 * are coherent with coherence length 0 (infinite) unless their source is
 * coherent.  Valid when 2 * sources < 2^16. */
#define RS_COHERENCE_MAX_SOURCES 32768
uint64_t rs_coherence_split(uint64_t ch, uint64_t hit, int depth, int transmit);

/* What the pixel receives from rays *r[0..n) of one wavelength (nm, in
 * air), ray i of intensity I[i] (its own intensity field unused): rays
 * of different channels, or of a channel that is not coherent, add as
 * intensities; two rays of one coherent channel (coherent[src]) add
 * as amplitudes sqrt(I) vp exp(i(2 pi op/lambda - pi kphi + phase)) with
 * their path difference D taken as above and the visibility
 * gamma = exp(-(D/L)^2) of the source's coherence length L = coherence[src]
 * (gamma = 1 for L = 0: infinite):
 *     P = sum_i I_i + sum_{i<j} 2 gamma_ij sqrt(I_i I_j) (vp_i.vp_j) cos(phi_i - phi_j).
 * Negative totals (rounding) are returned as 0. */
double rs_coherent_power(const lp_ray *const *r, const double *I, size_t n, const rs_wavelets *t,
                         const unsigned char *coherent, const double *coherence,
                         int n_sources, double lambda_nm);

#endif
