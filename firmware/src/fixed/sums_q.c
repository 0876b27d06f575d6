/*
 * sums_q.c - the fixed-point tie-break cost and the sums of the linear
 * fits, the reference path (points_q.h: spvs_q_pts_cost, spvs_q_pts_sum,
 * spvs_q_lin_move, spvs_q_sum_fast): every point's terms from its exact
 * residuals (sums_q.h).  Built where SPVS_ACCEL is OFF;
 * fixed/accel/sums_fast_q.c adds the integer fast paths.
 */
#include "sums_q.h"

uint64_t spvs_q_pts_cost(const spvs_q_store_t *st, uint16_t n, const int32_t Hq[9],
                         const uint8_t *mask, uint32_t *sat)
{
    uint64_t sum = 0;
    /* Bound: n points. */
    for (uint16_t i = 0; i < n; i++) {
        if (mask[i] && !spvs_q_cost_add(&sum, spvs_q_cost_exact(Hq, &st->v[4u * i], sat), sat)) {
            return UINT64_MAX;
        }
    }
    return sum;
}

int32_t spvs_q_pts_sum(spvs_terms_t kind, const int32_t Hq[9], const spvs_q_store_t *st,
                       const uint8_t *use, uint16_t n, spvs_q_sums_t *out)
{
    if (spvs_q_sums_clear(kind, out) != 0) {
        return -2;
    }
    int32_t used = 0;
    /* Bound: n points. */
    for (uint16_t i = 0; i < n; i++) {
        if (!use[i]) {
            continue;
        }
        const int32_t *p = &st->v[4u * i];
        const int ok = kind == SPVS_T_SAMPSON ? spvs_q_sampson_exact(Hq, p, out)
                                              : spvs_q_sum_exact_point((int)kind, Hq, p, out);
        if (!ok) {
            return -1;
        }
        used++;
    }
    return kind == SPVS_T_FIT_X ? 0 : used;
}

int spvs_q_lin_move(const int32_t Hw[9], const int32_t p[4], int add, spvs_q_sums_t *s)
{
    return spvs_q_lin_move_exact(Hw, p, add ? 0 : 1, s);
}

int spvs_q_sum_fast(spvs_terms_t kind, const spvs_q_store_t *st, const int32_t Hq[9],
                    uint16_t n)
{
    /* No fast path in the reference. */
    (void)kind;
    (void)st;
    (void)Hq;
    (void)n;
    return 0;
}
