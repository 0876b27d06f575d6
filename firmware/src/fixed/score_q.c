/*
 * score_q.c - the fixed-point inlier count, the reference path
 * (points_q.h: spvs_q_thr, spvs_q_pts_score): every point decided by
 * point_q.h's q_inlier_ref, the Sampson error on the exact residuals.
 * Built where SPVS_ACCEL is OFF; fixed/accel/score_fast_q.c is the same
 * count with integer filters in front, with the same decisions.
 */
#include "point_q.h"

spvs_q_thr_t spvs_q_thr(spvs_qf_t t2)
{
    /* T and fast are the filters' (fixed/accel/score_fast_q.c). */
    spvs_q_thr_t thr;
    thr.t2 = t2;
    thr.T = 0;
    thr.fast = 0;
    return thr;
}

uint16_t spvs_q_pts_score(const spvs_q_store_t *st, size_t n, const int32_t Hq[9],
                          const spvs_q_thr_t *thr, uint16_t need, uint8_t *mask)
{
    const int32_t max_out = need <= n ? (int32_t)(n - need) : 0;
    /* need > n: the float test's p = 1 (points.inc), as need = n here. */
    const int32_t need_b = need <= n ? (int32_t)need : (int32_t)n;
    int32_t inl = 0;
    /* Bound: n points. */
    for (size_t r = 0; r < n; r++) {
        const int ok = q_inlier_ref(Hq, &st->v[4u * r], thr->t2);
        inl += ok;
        if (mask) {
            mask[r] = (uint8_t)ok;
        }
        /* The count stops once `need` cannot be reached, or at the
         * bail-out test after each whole block of SPVS_SCORE_BLOCK points. */
        const int32_t m = (int32_t)(r + 1);
        if (m - inl > max_out ||
            (m % SPVS_SCORE_BLOCK == 0 && bails(need_b, (int32_t)n, m, inl))) {
            break;
        }
    }
    return (uint16_t)inl;
}
