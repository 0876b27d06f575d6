/*
 * ransac.h - RANSAC written once against an estimator interface, with a small
 * deterministic PRNG whose state the caller owns.
 *
 * Loop bounds:
 *   hypotheses  <= min(adaptive count for opts->confidence, opts->max_iters),
 *                  and opts->max_iters <= SPVS_RANSAC_MAX_ITERS;
 *   a degenerate sample counts as one hypothesis (no redraw loop);
 *   sampling    is a partial Fisher-Yates over the index array: exactly
 *                  sample_size draws, no retry loop.
 * The adaptive count is ceil(log(1 - confidence) / log(1 - w^s)) with w the
 * best inlier fraction so far and s the sample size.  With a refine callback
 * each new best model with at least 1 / SPVS_LO_MIN_SHARE of the points as
 * inliers is polished on its inliers first (LO-RANSAC), so w reflects the
 * model's true support and the count falls sooner; refine runs at most once
 * per hypothesis.
 */
#ifndef SPVS_RANSAC_H
#define SPVS_RANSAC_H

#include "spvs/common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Largest model (scalars) and sample an estimator may use. */
#define SPVS_MODEL_MAX 9
#define SPVS_SAMPLE_MAX 4

/* SplitMix-style 32-bit generator; same seed, same sequence on every target. */
typedef struct {
    uint32_t state;
} spvs_rng_t;

void spvs_rng_seed(spvs_rng_t *rng, uint32_t seed);
uint32_t spvs_rng_next(spvs_rng_t *rng);
/* Uniform integer in [0, bound), bound >= 1 (multiply-shift, no loop). */
uint32_t spvs_rng_below(spvs_rng_t *rng, uint32_t bound);

/* The estimator RANSAC drives.  `ctx` is the estimator's own data. */
typedef struct {
    uint16_t sample_size; /* points in a minimal sample (<= SPVS_SAMPLE_MAX) */
    uint16_t n;           /* data points                                       */
    void *ctx;
    /* Fit a model to the sample (indices into the data).  Returns SPVS_OK or
     * SPVS_E_DEGENERATE. */
    int (*fit)(void *ctx, const uint16_t *sample, spvs_real *model);
    /* Score a model: count points with squared residual <= threshold2.  When
     * mask is not NULL write 1 for an inlier and 0 otherwise.  May stop
     * early and return a count below `need` once it cannot reach it, or once
     * a statistical test says it will not (a bail-out test; then a model
     * that would have reached `need` is lost now and then, which the
     * estimator keeps rare); the rest of the mask is then meaningless.  A
     * count of at least `need` always comes with a full mask. */
    uint16_t (*score)(void *ctx, const spvs_real *model, spvs_real threshold2,
                      uint16_t need, uint8_t *mask);
    /* Optional (may be NULL): the summed squared residual of the model's
     * inliers, `mask` as score() wrote it for this model (full: a count
     * that ties the best one reached `need`), which breaks ties in the
     * count (lower wins).  Called only when two models tie, so scoring
     * never pays for it.  Without it a tie keeps the earlier model. */
    spvs_real (*cost)(void *ctx, const spvs_real *model, const uint8_t *mask);
    /* Optional (may be NULL): local optimisation of a new best model on its
     * inliers (`mask`, as score() wrote it for this model), in place.
     * Returns SPVS_OK when `model` was replaced.  RANSAC keeps the polished
     * model only if it scores at least as well. */
    int (*refine)(void *ctx, spvs_real *model, const uint8_t *mask);
} spvs_estimator_t;

typedef struct {
    spvs_real threshold2; /* squared inlier threshold, estimator's units        */
    spvs_real confidence; /* in (0, 1), e.g. 0.99                               */
    uint32_t max_iters;   /* cap, 1..SPVS_RANSAC_MAX_ITERS                       */
    uint16_t min_inliers; /* fewer than this is "no consensus"                  */
} spvs_ransac_opts_t;

typedef struct {
    uint32_t iters;      /* hypotheses tried, degenerate ones included        */
    uint32_t degenerate; /* of which degenerate samples                       */
    uint16_t n_inliers;  /* of the best model                                 */
} spvs_ransac_stats_t;

/* Run RANSAC.  Ties in inlier count are broken by the lower summed residual.
 * idx_scratch: n uint16 of caller storage.  model_out: SPVS_MODEL_MAX scalars.
 * mask_out: n bytes, 1 for the best model's inliers.
 * mask_scratch: n bytes of caller storage, not mask_out (the two hold the
 *           best model's and the current hypothesis' inliers in turn, so
 *           the best's mask needs no final scoring pass).
 * Returns SPVS_OK, SPVS_E_ARG (bad options), SPVS_E_TOO_FEW (n < sample_size
 * or n < min_inliers), SPVS_E_DEGENERATE (every sample was degenerate) or
 * SPVS_E_NO_CONSENSUS (best model has fewer than min_inliers inliers). */
SPVS_NODISCARD int spvs_ransac(const spvs_estimator_t *est,
                               const spvs_ransac_opts_t *opts, spvs_rng_t *rng,
                               uint16_t *idx_scratch, spvs_real *model_out,
                               uint8_t *mask_out, uint8_t *mask_scratch,
                               spvs_ransac_stats_t *stats);

/* The adaptive hypothesis count for inlier fraction w (0..1), sample size s
 * and confidence; clamped to [1, cap]. */
uint32_t spvs_ransac_needed(spvs_real w, uint16_t s, spvs_real confidence,
                            uint32_t cap);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_RANSAC_H */
