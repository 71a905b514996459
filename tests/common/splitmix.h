/* splitmix.h -- the tests' seeded random numbers: SplitMix64 (Steele, Lea
 * and Flood 2014; Vigna's constants), the same sequence on every machine,
 * the state the caller's. */
#ifndef LP_TEST_SPLITMIX_H
#define LP_TEST_SPLITMIX_H

#include <stdint.h>

/* The next number of the sequence of *state, uniform in [0, 1) with 53
 * random bits. */
static inline double splitmix_uniform(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (z >> 11) * (1.0 / 9007199254740992.0);
}

#endif
