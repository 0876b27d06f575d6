/*
 * rng.h - the simulator's deterministic random numbers: SplitMix64 for the
 * integers, 53-bit uniforms, Box-Muller for Gaussians.  Same seed, same run on
 * every host.
 */
#ifndef SIM_RNG_H
#define SIM_RNG_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    uint64_t state;
    double spare;      /* second Box-Muller value, valid when has_spare */
    int has_spare;
} sim_rng_t;

/* Seed a generator.  `stream` picks an independent sequence for the same seed,
 * so the scene, the target-image noise and the per-frame noise do not change
 * one another when one of them is switched on or off. */
void sim_rng_seed(sim_rng_t *r, uint64_t seed, uint64_t stream);

/* Next 64 random bits (SplitMix64). */
uint64_t sim_rng_u64(sim_rng_t *r);

/* Uniform in [0, 1), 53 random bits. */
double sim_rng_uniform(sim_rng_t *r);

/* Uniform in [lo, hi). */
double sim_rng_range(sim_rng_t *r, double lo, double hi);

/* Uniform integer in [0, bound), bound >= 1 (128-bit multiply-shift). */
uint32_t sim_rng_below(sim_rng_t *r, uint32_t bound);

/* Standard normal (mean 0, standard deviation 1), Box-Muller. */
double sim_rng_gauss(sim_rng_t *r);

#ifdef __cplusplus
}
#endif

#endif /* SIM_RNG_H */
