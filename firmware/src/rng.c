/*
 * rng.c - the SplitMix-style PRNG of ransac.h: a Weyl sequence with a
 * 32-bit avalanche mix, and a multiply-shift draw below a bound.  Both
 * RANSAC loops take their samples from it, the float one (ransac.c) and
 * the fixed-point one (fixed/ransac_q.c); it sits in a file of its own so
 * that the fixed-point core links it without the float RANSAC.  Integer
 * arithmetic only: the same seed gives the same sequence on every target
 * and in both cores.
 */
#include "spvs/ransac.h"

void spvs_rng_seed(spvs_rng_t *rng, uint32_t seed)
{
    SPVS_ASSERT(rng != 0);
    rng->state = seed;
}

uint32_t spvs_rng_next(spvs_rng_t *rng)
{
    /* A Weyl step followed by a 32-bit avalanche mix: every state gives a
     * well-mixed output and the period is 2^32. */
    uint32_t z = (rng->state += 0x9E3779B9u);
    z = (z ^ (z >> 16)) * 0x85EBCA6Bu;
    z = (z ^ (z >> 13)) * 0xC2B2AE35u;
    return z ^ (z >> 16);
}

uint32_t spvs_rng_below(spvs_rng_t *rng, uint32_t bound)
{
    /* Multiply-shift maps 32 random bits onto [0, bound) with a bias below
     * bound / 2^32, negligible for bound <= SPVS_MAX_MATCHES, and without the
     * unbounded rejection loop of the exact method. */
    uint64_t m = (uint64_t)spvs_rng_next(rng) * (uint64_t)bound;
    return (uint32_t)(m >> 32);
}
