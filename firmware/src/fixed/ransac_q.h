/*
 * ransac_q.h - RANSAC on fixed-point models (private: not installed, not
 * part of the API; docs/FIXED.md), and its stopping rule in integers.
 *
 * The loop is the float core's (ransac.inc, written once for both): the
 * same samples from the same spvs_rng_t, the same LO-step rule, the same
 * tie-breaks.  Here a model is SPVS_MODEL_MAX int32 entries (the
 * estimator's Q format; Q27 for the homography), the threshold is the
 * estimator's own (an opaque pointer its callbacks read, e.g. a
 * spvs_q_thr_t), the tie-break cost a uint64 (uint64 Q52 from
 * spvs_q_pts_cost), and the adaptive count is computed without floating
 * point (spvs_q_ransac_needed).
 *
 * Loop bounds (as ransac.h):
 *   hypotheses  <= min(adaptive count, opts->max_iters), and
 *                  opts->max_iters <= SPVS_RANSAC_MAX_ITERS;
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
#ifndef SPVS_FIXED_RANSAC_Q_H
#define SPVS_FIXED_RANSAC_Q_H

#include <stdint.h>

#include "spvs/ransac.h"

/* The log terms of the stopping rule: log2 values in Q32 (SPVS_Q_LOGF
 * fractional bits). */
#define SPVS_Q_LOGF 32

/* The estimator RANSAC drives.  `ctx` is the estimator's own data. */
typedef struct {
    uint16_t sample_size; /* points in a minimal sample (<= SPVS_SAMPLE_MAX) */
    uint16_t n;           /* data points                                       */
    void *ctx;
    /* Fit a model to the sample (indices into the data).  Returns SPVS_OK or
     * SPVS_E_DEGENERATE. */
    int (*fit)(void *ctx, const uint16_t *sample, int32_t *model);
    /* Score a model: count points within the threshold `thr` (the
     * estimator's own, opts->thr).  When mask is not NULL write 1 for an
     * inlier and 0 otherwise.  May stop early and return a count below
     * `need` once it cannot reach it, or once a statistical test says it
     * will not (a bail-out test; then a model that would have reached
     * `need` is lost now and then, which the estimator keeps rare); the
     * rest of the mask is then meaningless.  A count of at least `need`
     * always comes with a full mask. */
    uint16_t (*score)(void *ctx, const int32_t *model, const void *thr, uint16_t need,
                      uint8_t *mask);
    /* Optional (may be NULL): the summed squared residual of the model's
     * inliers (`mask`, as score() wrote it for this model, full), which
     * breaks ties in the count (lower wins), as spvs_estimator_t's. */
    uint64_t (*cost)(void *ctx, const int32_t *model, const uint8_t *mask);
    /* Optional (may be NULL): local optimisation of a new best model on its
     * inliers (`mask`, as score() wrote it for this model), in place.
     * Returns SPVS_OK when `model` was replaced.  RANSAC keeps the polished
     * model only if it scores at least as well. */
    int (*refine)(void *ctx, int32_t *model, const uint8_t *mask);
} spvs_q_estimator_t;

typedef struct {
    const void *thr;         /* the inlier threshold, as score() reads it
                                (not NULL)                                  */
    uint32_t confidence_q32; /* confidence 2^-32, 1..2^32 - 1: in (0, 1), as
                                spvs_ransac_opts_t's, e.g. 0.99            */
    uint32_t max_iters;      /* cap, 1..SPVS_RANSAC_MAX_ITERS                */
    uint16_t min_inliers;    /* fewer than this is "no consensus"           */
} spvs_q_ransac_opts_t;

/* The statistics are ransac.h's. */
typedef spvs_ransac_stats_t spvs_q_ransac_stats_t;

/* Run RANSAC.  Ties in inlier count are broken by the lower summed residual.
 * idx_scratch: n uint16 of caller storage.  model_out: SPVS_MODEL_MAX
 * entries.  mask_out: n bytes, 1 for the best model's inliers.
 * mask_scratch: n bytes of caller storage, not mask_out (the two hold the
 *           best model's and the current hypothesis' inliers in turn, so
 *           the best's mask needs no final scoring pass).
 * The adaptive count's log term is spvs_q_log_fail(2^32 - confidence_q32,
 * 32), once per run.
 * Returns SPVS_OK, SPVS_E_ARG (bad options), SPVS_E_TOO_FEW (n < sample_size
 * or n < min_inliers), SPVS_E_DEGENERATE (every sample was degenerate) or
 * SPVS_E_NO_CONSENSUS (best model has fewer than min_inliers inliers). */
SPVS_NODISCARD int spvs_q_ransac(const spvs_q_estimator_t *est, const spvs_q_ransac_opts_t *opts,
                                 spvs_rng_t *rng, uint16_t *idx_scratch, int32_t *model_out,
                                 uint8_t *mask_out, uint8_t *mask_scratch,
                                 spvs_q_ransac_stats_t *stats);

/* log2(x) in Q32 for x >= 1 (0 for x = 0), exact at powers of two (so at
 * n^s for n a power of two): the bit length, a 32-entry table on the
 * next 5 bits and a degree-5 polynomial in the remainder (|z| < 1/65), on
 * all 64 bits of x.  |error| <= 2^-31: 2^-33 each from the table and the
 * last rounding, below 2^-36 from the polynomial's roundings and
 * truncation (measured 2^-32.0 in test_fixed_ransac). */
int64_t spvs_q_log2(uint64_t x);

/* The log term of the stopping rule, -log2(1 - confidence) in Q32, for a
 * failure probability 1 - confidence = fail 2^-frac with 1 <= fail <
 * 2^frac and frac <= 63: frac - log2(fail), at least 1 (|error| <=
 * 2^-31).  0 outside that range. */
uint64_t spvs_q_log_fail(uint64_t fail, uint32_t frac);

/* The log term for the core's scalar confidence, read from its bits: the
 * failure probability 1 - confidence is exact as an integer over 2^63 or a
 * smaller power of two for confidence >= 2^-11 (2^-40 in float); below,
 * the confidence is rounded to a multiple of 2^-63 (a change below 2^-63
 * in log2 units), so |error| <= 2^-31 (spvs_q_log_fail).  The log term of
 * the very scalar the float core reads, where confidence_q32 rounds 1 -
 * confidence
 * to 2^-33 (a change of 2^-33 / ((1 - confidence) ln 2) in log2 units:
 * 1.7e-5 of 16.6 at 0.99999).  Returns 0 and ORs
 * SPVS_Q_NONFINITE (NaN, infinity) or SPVS_Q_SAT (confidence outside
 * (0, 1)) into *sat. */
uint64_t spvs_q_log_fail_real(spvs_real confidence, uint32_t *sat);

/* The adaptive hypothesis count ceil(log_fail / -log2(1 - w^s)) for the
 * inlier fraction w = best_n / n, sample size s <= SPVS_SAMPLE_MAX and
 * log_fail from spvs_q_log_fail; clamped to [1, cap].  spvs_ransac_needed's
 * edge cases: best_n = 0 gives cap, best_n >= n gives 1, s above
 * SPVS_SAMPLE_MAX gives cap.  w^s = best_n^s / n^s is an exact rational
 * (n^s < 2^64), so -log2(1 - w^s) = log2(n^s) - log2(n^s - best_n^s) is two
 * spvs_q_log2 (|error| <= 2^-30 together), and the ratio and its ceiling are
 * one integer division.  The count k before the ceiling is then within
 * (2^-31 + 2^-30 k) k / log_fail of the exact ratio (log_fail in log2
 * units): 1.1e-5 hypotheses at k = 200, confidence 0.9; the ceiling can
 * differ from the exact one only where the exact ratio is that close to an
 * integer.  Bound: s multiplications. */
uint32_t spvs_q_ransac_needed(uint16_t best_n, uint16_t n, uint16_t s, uint64_t log_fail,
                              uint32_t cap);

#endif /* SPVS_FIXED_RANSAC_Q_H */
