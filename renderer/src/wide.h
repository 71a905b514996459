/* wide.h -- the renderer's loops over the lanes of a spectral packet,
 * compiled for the widest vectors of the machine that runs them.
 *
 * A function marked RS_WIDE is built three times (AVX-512, AVX2 and the
 * baseline) and one copy is chosen once when the program loads, as the
 * library's lane engine does (lensprim/src/lanes.h).  Its loops apply the
 * same operations to each lane independently (no sums across lanes) and
 * the build keeps FP contraction off, so every copy gives the same bits;
 * the wider ones vectorize loops the baseline cannot (a comparison of
 * doubles made into a byte).  A build may pin the baseline copy
 * (-DRS_WIDE=) to check it. */
#ifndef RS_WIDE_H
#define RS_WIDE_H

#ifndef RS_WIDE
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define RS_WIDE __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define RS_WIDE
#endif
#endif

#endif
