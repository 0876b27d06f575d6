/* rng.c - SplitMix64, uniforms and Box-Muller Gaussians (see rng.h). */
#include "sim/rng.h"

#include <math.h>

#define SIM_GOLDEN 0x9E3779B97F4A7C15ULL

static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

void sim_rng_seed(sim_rng_t *r, uint64_t seed, uint64_t stream)
{
    /* Mixing the stream number through the finaliser before adding it keeps
     * streams of neighbouring seeds from overlapping as shifted copies. */
    r->state = seed ^ mix64(stream * SIM_GOLDEN + 0x632BE59BD9B4E019ULL);
    r->spare = 0.0;
    r->has_spare = 0;
}

uint64_t sim_rng_u64(sim_rng_t *r)
{
    r->state += SIM_GOLDEN;
    return mix64(r->state);
}

double sim_rng_uniform(sim_rng_t *r)
{
    return (double)(sim_rng_u64(r) >> 11) * (1.0 / 9007199254740992.0);
}

double sim_rng_range(sim_rng_t *r, double lo, double hi)
{
    return lo + (hi - lo) * sim_rng_uniform(r);
}

uint32_t sim_rng_below(sim_rng_t *r, uint32_t bound)
{
    uint64_t x = sim_rng_u64(r) >> 32;
    return (uint32_t)((x * (uint64_t)bound) >> 32);
}

double sim_rng_gauss(sim_rng_t *r)
{
    if (r->has_spare) {
        r->has_spare = 0;
        return r->spare;
    }
    /* u1 in (0, 1] so that log(u1) is finite. */
    double u1 = 1.0 - sim_rng_uniform(r);
    double u2 = sim_rng_uniform(r);
    double rad = sqrt(-2.0 * log(u1));
    double ang = 2.0 * 3.14159265358979323846 * u2;
    r->spare = rad * sin(ang);
    r->has_spare = 1;
    return rad * cos(ang);
}
