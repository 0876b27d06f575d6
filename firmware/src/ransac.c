/*
 * ransac.c - RANSAC against the estimator interface of ransac.h.  The
 * SplitMix-style PRNG it draws samples with is in rng.c.
 */
#include <math.h>
#include <string.h>

#include "core_util.h"
#include "spvs/ransac.h"

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

/* The float instance of the loop: ransac.inc, written once for this scalar
 * and for the fixed-point models (fixed/ransac_q.c). */
#define RT_MODEL spvs_real
#define RT_COST spvs_real
#define RT_COST_ZERO SPVS_R(0.0)
#define RT_LOGF spvs_real
#define RT_EST spvs_estimator_t
#define RT_OPTS spvs_ransac_opts_t
#define RT_THRESHOLD(o) ((o)->threshold2)
#define RT_OPTS_OK(o)                                                                          \
    ((o)->confidence > SPVS_R(0.0) && (o)->confidence < SPVS_R(1.0) &&                         \
     (o)->threshold2 > SPVS_R(0.0))
/* log(1 - confidence). */
#define RT_LOG_FAIL(o) SPVS_LOG(SPVS_R(1.0) - (o)->confidence)
#define RT_NEEDED(best_n, n, s, log_fail, cap)                                                 \
    needed_for((spvs_real)(best_n) / (spvs_real)(n), (s), (log_fail), (cap))
#include "ransac.inc"

int spvs_ransac(const spvs_estimator_t *est, const spvs_ransac_opts_t *opts, spvs_rng_t *rng,
                uint16_t *idx_scratch, spvs_real *model_out, uint8_t *mask_out,
                uint8_t *mask_scratch, spvs_ransac_stats_t *stats)
{
    return ransac_loop(est, opts, rng, idx_scratch, model_out, mask_out, mask_scratch, stats);
}
