/*
 * ransac.c - RANSAC against the estimator interface of ransac.h, and the
 * SplitMix-style PRNG.
 */
#include <math.h>
#include <string.h>

#include "core_util.h"
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

/* spvs_ransac_needed with num = log(1 - confidence) given (spvs_ransac
 * computes it once per run). */
static uint32_t needed_for(spvs_real w, uint16_t s, spvs_real num, uint32_t cap)
{
    if (cap < 1u) {
        cap = 1u;
    }
    spvs_real ws = SPVS_R(1.0);
    for (uint16_t k = 0; k < s; k++) {
        ws *= w;
    }
    if (!(ws > SPVS_R(0.0))) {
        return cap;
    }
    if (ws >= SPVS_R(1.0) - SPVS_REAL_EPS) {
        return 1u;
    }
    spvs_real den = SPVS_LOG(SPVS_R(1.0) - ws);
    if (!(den < SPVS_R(0.0))) {
        return cap;
    }
    spvs_real k = num / den;
    if (!(k < (spvs_real)cap)) {
        return cap;
    }
    uint32_t ki = (uint32_t)k;
    if ((spvs_real)ki < k) {
        ki++;
    }
    return ki < 1u ? 1u : ki;
}

uint32_t spvs_ransac_needed(spvs_real w, uint16_t s, spvs_real confidence,
                            uint32_t cap)
{
    return needed_for(w, s, SPVS_LOG(SPVS_R(1.0) - confidence), cap);
}

/* The arguments of spvs_ransac: SPVS_OK, SPVS_E_ARG or SPVS_E_TOO_FEW. */
static SPVS_ALWAYS_INLINE int check_args(const spvs_estimator_t *est,
                                         const spvs_ransac_opts_t *opts, const spvs_rng_t *rng,
                                         const uint16_t *idx_scratch, const spvs_real *model_out,
                                         const uint8_t *mask_out, const uint8_t *mask_scratch,
                                         const spvs_ransac_stats_t *stats)
{
    if (est == 0 || opts == 0 || rng == 0 || idx_scratch == 0 || model_out == 0 ||
        mask_out == 0 || mask_scratch == 0 || mask_out == mask_scratch || stats == 0 ||
        est->fit == 0 || est->score == 0) {
        return SPVS_E_ARG;
    }
    const uint16_t s = est->sample_size;
    if (s < 1u || s > SPVS_SAMPLE_MAX || opts->max_iters < 1u ||
        opts->max_iters > SPVS_RANSAC_MAX_ITERS ||
        !(opts->confidence > SPVS_R(0.0) && opts->confidence < SPVS_R(1.0)) ||
        !(opts->threshold2 > SPVS_R(0.0))) {
        return SPVS_E_ARG;
    }
    if (est->n < s || est->n < opts->min_inliers) {
        return SPVS_E_TOO_FEW;
    }
    return SPVS_OK;
}

/* Partial Fisher-Yates over idx[0..n): exactly s draws, each without
 * replacement, into sample[0..s). */
static SPVS_ALWAYS_INLINE void draw_sample(spvs_rng_t *rng, uint16_t *idx, uint16_t n,
                                           uint16_t s, uint16_t *sample)
{
    for (uint16_t k = 0; k < s; k++) {
        uint32_t j = k + spvs_rng_below(rng, (uint32_t)(n - k));
        uint16_t t = idx[k];
        idx[k] = idx[j];
        idx[j] = t;
        sample[k] = idx[k];
    }
}

/* The local optimisation of a new best `model` with *cnt inliers (marked in
 * hyp_mask): polish it on its inliers and take the polished model if it has
 * more inliers, or as many at a lower cost (*cost then holds the winner's
 * cost and *cost_known is set).  This hypothesis is the new best either
 * way, so the old best's mask, free_mask, takes the polished model's.
 * Returns 1 when the polished model was taken (its mask in free_mask). */
static SPVS_ALWAYS_INLINE int lo_step(const spvs_estimator_t *est,
                                      const spvs_ransac_opts_t *opts, spvs_real *model,
                                      uint16_t *cnt, const uint8_t *hyp_mask, uint8_t *free_mask,
                                      spvs_real *cost, int *cost_known)
{
    spvs_real polished[SPVS_MODEL_MAX];
    for (int k = 0; k < SPVS_MODEL_MAX; k++) {
        polished[k] = model[k];
    }
    if (est->refine(est->ctx, polished, hyp_mask) != SPVS_OK) {
        return 0;
    }
    uint16_t pcnt = est->score(est->ctx, polished, opts->threshold2, *cnt, free_mask);
    int take = pcnt > *cnt;
    if (pcnt == *cnt && est->cost != 0) {
        *cost = est->cost(est->ctx, model, opts->threshold2);
        spvs_real pcost = est->cost(est->ctx, polished, opts->threshold2);
        *cost_known = 1;
        if (pcost < *cost) {
            take = 1;
            *cost = pcost;
        }
    }
    if (!take) {
        return 0;
    }
    *cnt = pcnt;
    for (int k = 0; k < SPVS_MODEL_MAX; k++) {
        model[k] = polished[k];
    }
    return 1;
}

/* The tie-break between a hypothesis `model` and the best `best` at the
 * same count: the lower cost wins.  Each cost is computed once, when first
 * needed (*cost_known, *best_known). */
static SPVS_ALWAYS_INLINE int wins_tie(const spvs_estimator_t *est, spvs_real t2,
                                       const spvs_real *model, const spvs_real *best,
                                       spvs_real *cost, int *cost_known, spvs_real *best_cost,
                                       int *best_known)
{
    if (!*cost_known) {
        *cost = est->cost(est->ctx, model, t2);
        *cost_known = 1;
    }
    if (!*best_known) {
        *best_cost = est->cost(est->ctx, best, t2);
        *best_known = 1;
    }
    return *cost < *best_cost;
}

int spvs_ransac(const spvs_estimator_t *est, const spvs_ransac_opts_t *opts,
                spvs_rng_t *rng, uint16_t *idx_scratch, spvs_real *model_out,
                uint8_t *mask_out, uint8_t *mask_scratch, spvs_ransac_stats_t *stats)
{
    int rc = check_args(est, opts, rng, idx_scratch, model_out, mask_out, mask_scratch, stats);
    if (rc == SPVS_E_ARG) {
        return rc;
    }
    stats->iters = 0;
    stats->degenerate = 0;
    stats->n_inliers = 0;
    if (rc != SPVS_OK) {
        return rc;
    }
    const uint16_t s = est->sample_size;
    const uint16_t n = est->n;
    for (uint16_t i = 0; i < n; i++) {
        idx_scratch[i] = i;
    }

    spvs_real model[SPVS_MODEL_MAX];
    uint16_t sample[SPVS_SAMPLE_MAX];
    uint16_t best_n = 0;
    /* The best model's tie-break cost, computed at the first tie. */
    spvs_real best_cost = SPVS_R(0.0);
    int best_cost_known = 0;
    int have = 0;
    uint32_t needed = opts->max_iters;
    /* The best model's inliers (complete: a count of at least `need` comes
     * with a full mask) and the hypothesis' scratch mask; the two buffers
     * swap when a hypothesis becomes the best, so no final scoring pass is
     * needed. */
    uint8_t *best_mask = mask_out;
    uint8_t *hyp_mask = mask_scratch;
    /* log(1 - confidence), for the adaptive count. */
    const spvs_real log_fail = SPVS_LOG(SPVS_R(1.0) - opts->confidence);

    /* Bound: needed <= opts->max_iters <= SPVS_RANSAC_MAX_ITERS. */
    for (uint32_t it = 0; it < needed; it++) {
        draw_sample(rng, idx_scratch, n, s, sample);
        stats->iters++;
        if (est->fit(est->ctx, sample, model) != SPVS_OK) {
            stats->degenerate++;
            continue;
        }
        /* Only a new best (whose mask is then complete) uses the mask. */
        uint16_t cnt = est->score(est->ctx, model, opts->threshold2, best_n, hyp_mask);
        spvs_real cost = SPVS_R(0.0);
        int cost_known = 0;
        /* The polished model taken: its mask is then in best_mask. */
        const int polished_taken =
            est->refine != 0 && (cnt > best_n || !have) &&
            (uint32_t)cnt * (uint32_t)SPVS_LO_MIN_SHARE >= (uint32_t)n &&
            lo_step(est, opts, model, &cnt, hyp_mask, best_mask, &cost, &cost_known);
        int better = cnt > best_n || !have;
        /* A tie is broken only between models that make a consensus: below
         * min_inliers the result is a failure whichever model wins, and the
         * cost would be a full pass for nothing (every hypothesis ties when
         * none explains more than its own sample). */
        if (!better && cnt == best_n && best_n >= opts->min_inliers && est->cost != 0) {
            better = wins_tie(est, opts->threshold2, model, model_out, &cost, &cost_known,
                              &best_cost, &best_cost_known);
        }
        if (better) {
            best_n = cnt;
            best_cost = cost;
            best_cost_known = cost_known;
            have = 1;
            for (int k = 0; k < SPVS_MODEL_MAX; k++) {
                model_out[k] = model[k];
            }
            if (!polished_taken) {
                uint8_t *const t = best_mask;
                best_mask = hyp_mask;
                hyp_mask = t;
            }
            uint32_t k_needed =
                needed_for((spvs_real)best_n / (spvs_real)n, s, log_fail, opts->max_iters);
            if (k_needed < needed) {
                needed = k_needed;
            }
        }
    }

    if (!have) {
        return SPVS_E_DEGENERATE;
    }
    if (best_mask != mask_out) {
        memcpy(mask_out, best_mask, n);
    }
    stats->n_inliers = best_n;
    if (stats->n_inliers < opts->min_inliers || stats->n_inliers < s) {
        return SPVS_E_NO_CONSENSUS;
    }
    return SPVS_OK;
}
