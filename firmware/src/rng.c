/*
 * rng.c - the SplitMix-style PRNG of ransac.h: a Weyl sequence with a
 * 32-bit avalanche mix, and a multiply-shift draw below a bound (the
 * bodies are in rng_draw.h, which the RANSAC loop inlines).  Both RANSAC
 * loops take their samples from it, the float one (ransac.c) and the
 * fixed-point one (fixed/ransac_q.c); it sits in a file of its own so that
 * the fixed-point core links it without the float RANSAC.  Integer
 * arithmetic only: the same seed gives the same sequence on every target
 * and in both cores.
 */
#include "rng_draw.h"

void spvs_rng_seed(spvs_rng_t *rng, uint32_t seed)
{
    SPVS_ASSERT(rng != 0);
    rng->state = seed;
}

uint32_t spvs_rng_next(spvs_rng_t *rng)
{
    return spvs_rng_next_inline(rng);
}

uint32_t spvs_rng_below(spvs_rng_t *rng, uint32_t bound)
{
    return spvs_rng_below_inline(rng, bound);
}
