/*
 * rng_draw.h - the body of ransac.h's PRNG as static inline functions
 * (private to the core).  rng.c's public functions are these; the RANSAC
 * loop (ransac.inc, in the float and the fixed-point cores) draws its
 * samples through them directly, so that a draw is a few integer
 * instructions in the loop instead of a call into another translation unit.
 */
#ifndef SPVS_RNG_DRAW_H
#define SPVS_RNG_DRAW_H

#include "spvs/ransac.h"

/* A Weyl step followed by a 32-bit avalanche mix: every state gives a
 * well-mixed output and the period is 2^32. */
static inline uint32_t spvs_rng_next_inline(spvs_rng_t *rng)
{
    uint32_t z = (rng->state += 0x9E3779B9u);
    z = (z ^ (z >> 16)) * 0x85EBCA6Bu;
    z = (z ^ (z >> 13)) * 0xC2B2AE35u;
    return z ^ (z >> 16);
}

/* Multiply-shift maps 32 random bits onto [0, bound) with a bias below
 * bound / 2^32, negligible for bound <= SPVS_MAX_MATCHES, and without the
 * unbounded rejection loop of the exact method. */
static inline uint32_t spvs_rng_below_inline(spvs_rng_t *rng, uint32_t bound)
{
    const uint64_t m = (uint64_t)spvs_rng_next_inline(rng) * (uint64_t)bound;
    return (uint32_t)(m >> 32);
}

#endif /* SPVS_RNG_DRAW_H */
