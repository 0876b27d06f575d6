/*
 * ransac_q.c - RANSAC on fixed-point models (ransac_q.h): the float core's
 * loop (ransac.inc) on int32 models, a uint64 cost and an opaque
 * threshold, with the stopping rule in integers.  No floating point: a
 * confidence is read through its bits (q.h).
 */
#include <string.h>

#include "../core_util.h"
#include "q.h"
#include "ransac_q.h"

/* The log2 table: entry i covers the mantissas m in [1 + i/32, 1 + (i+1)/32)
 * (Q31 [2^31, 2^32)); LOG2_C[i] = round(2^31 / (1 + (i + 1/2) / 32)) so that
 * m LOG2_C[i] 2^-62 = 1 + z with |z| < 1/65, and LOG2_T[i] = -log2(LOG2_C[i]
 * 2^-31) in Q32, rounded (2^-33), for the rounded LOG2_C[i] itself. */
#define LOG2_BITS 5
#define LOG2_N (1 << LOG2_BITS)
static const uint32_t LOG2_C[LOG2_N] = {
    2114445438u, 2051327664u, 1991868891u, 1935759908u, 1882725390u, 1832519380u, 1784921474u,
    1739733588u, 1696777203u, 1655891006u, 1616928864u, 1579758086u, 1544257904u, 1510318170u,
    1477838209u, 1446725826u, 1416896428u, 1388272257u, 1360781718u, 1334358772u, 1308942414u,
    1284476201u, 1260907830u, 1238188770u, 1216273925u, 1195121335u, 1174691910u, 1154949189u,
    1135859120u, 1117389866u, 1099511628u, 1082196484u,
};
static const uint32_t LOG2_T[LOG2_N] = {
    96069026u,   283850911u,  466108992u,  643158981u,  815290272u,  982768791u,  1145839466u,
    1304728379u, 1459644649u, 1610782091u, 1758320683u, 1902427828u, 2043259528u, 2180961373u,
    2315669463u, 2447511201u, 2576606036u, 2703066102u, 2826996790u, 2948497311u, 3067661140u,
    3184576456u, 3299326552u, 3411990165u, 3522641818u, 3631352116u, 3738188006u, 3843213028u,
    3946487551u, 4048068974u, 4148011916u, 4246368396u,
};
/* log2(1 + z) = z (A1 + z (A2 + z (A3 + z (A4 + z A5)))), A_k = (-1)^(k+1) /
 * (k ln 2) in Q30 (rounded): the series cut after z^5 is off by at most
 * |z|^6 / (6 ln 2) < 2^-39 for |z| < 1/65. */
#define LOG2_POLY 5
static const int32_t LOG2_A[LOG2_POLY] = {1549082005, -774541002, 516360668, -387270501,
                                          309816401};
/* z in Q37: |z| < 2^37 / 65 < 2^31 (int32); the products z acc below are
 * below 2^31 2^31 = 2^62. */
#define LOG2_ZQ 37

int64_t spvs_q_log2(uint64_t x)
{
    if (x == 0u) {
        return 0;
    }
    /* x = xn 2^(e - 63) with xn in [2^63, 2^64): m its top 32 bits, lo the
     * rest, so no bit of x is lost. */
    const int e = spvs_q_bitlen64(x) - 1;
    const uint64_t xn = x << (63 - e);
    const uint32_t m = (uint32_t)(xn >> 32);
    const uint32_t lo = (uint32_t)xn;
    if (xn == ((uint64_t)1 << 63)) {
        return (int64_t)e << SPVS_Q_LOGF; /* a power of two: exact */
    }
    const uint32_t i = (m >> (31 - LOG2_BITS)) & (uint32_t)(LOG2_N - 1);
    /* xn LOG2_C[i] 2^-94 = 1 + z with |z| < 1/65: in Q62 m LOG2_C[i] plus
     * (lo LOG2_C[i]) 2^-32 (truncated, 2^-62), below 2^62 (1 + 1/65). */
    const uint64_t p = (uint64_t)m * LOG2_C[i] + (((uint64_t)lo * LOG2_C[i]) >> 32);
    const int64_t zp = (int64_t)p - ((int64_t)1 << 62);
    const int32_t z = (int32_t)spvs_q_rshift_rnd64(zp, 62 - LOG2_ZQ);
    /* Horner in Q30: each step's rounding (2^-31) is scaled by |z| < 2^-6
     * in the result; |acc| < 1.45 (int32 Q30).  Bound: LOG2_POLY - 1 steps. */
    int32_t acc = LOG2_A[LOG2_POLY - 1];
    for (int k = LOG2_POLY - 2; k >= 0; k--) {
        acc = LOG2_A[k] + (int32_t)spvs_q_rshift_rnd64((int64_t)z * acc, LOG2_ZQ);
    }
    /* z acc is Q(37 + 30); to Q32, rounded (2^-33). */
    const int64_t l1z = spvs_q_rshift_rnd64((int64_t)z * acc, LOG2_ZQ + 30 - SPVS_Q_LOGF);
    return ((int64_t)e << SPVS_Q_LOGF) + (int64_t)LOG2_T[i] + l1z;
}

uint64_t spvs_q_log_fail(uint64_t fail, uint32_t frac)
{
    if (frac > 63u || fail < 1u || fail >= ((uint64_t)1 << frac)) {
        return 0u;
    }
    const int64_t l = ((int64_t)frac << SPVS_Q_LOGF) - spvs_q_log2(fail);
    /* At least 1: a confidence too small for Q32 still asks for one
     * hypothesis, and 0 stays the invalid value. */
    return l < 1 ? 1u : (uint64_t)l;
}

uint64_t spvs_q_log_fail_real(spvs_real confidence, uint32_t *sat)
{
    const spvs_q_ieee_t c = spvs_q_real_parts(confidence);
    if (c.nonfinite) {
        *sat |= SPVS_Q_NONFINITE;
        return 0u;
    }
    /* confidence = mant 2^exp2; in (0, 1) exactly when mant > 0, not
     * negative and mant < 2^-exp2 (then exp2 < 0). */
    if (c.neg || c.mant == 0u || c.exp2 >= 0 ||
        (c.exp2 > -64 && c.mant >= ((uint64_t)1 << (uint32_t)-c.exp2))) {
        *sat |= SPVS_Q_SAT;
        return 0u;
    }
    uint32_t frac = (uint32_t)-c.exp2;
    uint64_t mant = c.mant;
    if (frac > 63u) {
        /* confidence < 2^53 2^-64 = 2^-11: rounded to a multiple of 2^-63,
         * which moves -log2(1 - confidence) (about confidence / ln 2) by
         * less than 2^-63, far below the result's 2^-32. */
        const uint32_t r = frac - 63u; /* >= 1 */
        mant = r > 63u ? 0u : (mant >> r) + ((mant >> (r - 1u)) & 1u);
        frac = 63u;
        if (mant == 0u) {
            return 1u;
        }
    }
    return spvs_q_log_fail(((uint64_t)1 << frac) - mant, frac);
}

uint32_t spvs_q_ransac_needed(uint16_t best_n, uint16_t n, uint16_t s, uint64_t log_fail,
                              uint32_t cap)
{
    if (cap < 1u) {
        cap = 1u;
    }
    if (best_n == 0u || s > SPVS_SAMPLE_MAX) {
        return cap;
    }
    if (best_n >= n) {
        return 1u;
    }
    /* n^s and best_n^s exact: below 2^(16 s) <= 2^64.  Bound: s <=
     * SPVS_SAMPLE_MAX. */
    uint64_t ns = 1u;
    uint64_t bs = 1u;
    for (uint16_t k = 0; k < s; k++) {
        ns *= n;
        bs *= best_n;
    }
    if (ns == bs) {
        return 1u; /* s = 0: w^s = 1 */
    }
    /* -log2(1 - w^s) in Q32; where the two logs' errors meet (1 - w^s so
     * close to 1 that the difference is not positive) the count is the cap,
     * as in float when 1 - w^s rounds to 1. */
    const int64_t den = spvs_q_log2(ns) - spvs_q_log2(ns - bs);
    if (den <= 0) {
        return cap;
    }
    const uint64_t q = log_fail / (uint64_t)den;
    if (q >= cap) {
        return cap;
    }
    uint32_t k = (uint32_t)q;
    if (q * (uint64_t)den < log_fail) {
        k++;
    }
    return k < 1u ? 1u : k;
}

/* The fixed-point instance of the loop (ransac.inc). */
#define RT_MODEL int32_t
#define RT_COST uint64_t
#define RT_COST_ZERO 0u
#define RT_LOGF uint64_t
#define RT_EST spvs_q_estimator_t
#define RT_OPTS spvs_q_ransac_opts_t
#define RT_THRESHOLD(o) ((o)->thr)
#define RT_OPTS_OK(o) ((o)->thr != 0 && (o)->confidence_q32 > 0u)
/* -log2(1 - confidence) in Q32. */
#define RT_LOG_FAIL(o) spvs_q_log_fail(((uint64_t)1 << 32) - (o)->confidence_q32, 32u)
#define RT_NEEDED(best_n, n, s, log_fail, cap)                                                 \
    spvs_q_ransac_needed((best_n), (n), (s), (log_fail), (cap))
#include "../ransac.inc"

int spvs_q_ransac(const spvs_q_estimator_t *est, const spvs_q_ransac_opts_t *opts,
                  spvs_rng_t *rng, uint16_t *idx_scratch, int32_t *model_out, uint8_t *mask_out,
                  uint8_t *mask_scratch, spvs_q_ransac_stats_t *stats)
{
    return ransac_loop(est, opts, rng, idx_scratch, model_out, mask_out, mask_scratch, stats);
}
