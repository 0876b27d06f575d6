/*
 * solve3_q.c - the 3-point minimal solver of the planar-motion H in fixed
 * point (points_q.h, spvs_q_solve3; docs/FIXED.md).
 */
#include "../core_util.h"
#include "points_q.h"

/* SPVS_W_EPS (1e-6) in Q53, rounded down. */
#define W_EPS_Q53 ((int64_t)9007199254)

/* ---- the 3-point solver ----------------------------------------------------- */

/* DET_EPS of homography.c (1e-7) in Q52, rounded up, and as a spvs_qf_t
 * (1801439851 2^-54: 1e-7 with its mantissa rounded up to 31 bits). */
#define Q_DET_EPS_Q52 ((int64_t)450359963)
static const spvs_qf_t Q_DET_EPS = {0x6B5FCA6B, -54};

/* c as a spvs_qf_t, from a Q26 coordinate difference (int32) or a Q52
 * product (int64): exact inputs, one rounding to 31 bits. */
static spvs_qf_t qf_q26(int64_t c)
{
    return spvs_qf_from_i64(c, -SPVS_QC);
}

/* The sum a0 b0 + a1 b1 + a2 b2 of spvs_qf_t values. */
static spvs_qf_t qf_dot3(const spvs_qf_t a[3], const spvs_qf_t b[3])
{
    return spvs_qf_add(spvs_qf_add(spvs_qf_mul(a[0], b[0]), spvs_qf_mul(a[1], b[1])),
                       spvs_qf_mul(a[2], b[2]));
}

int spvs_q_solve3(const spvs_q_store_t *st, const uint16_t idx[3], int32_t Hq[9])
{
    const int32_t *p[3];
    for (int i = 0; i < 3; i++) {
        p[i] = &st->v[4u * idx[i]];
    }
    /* The cofactors of P, rows (x_tgt, y_tgt, 1) (homography.c,
     * spvs_h_solve3_strided): differences exact in int32 (< 2^31), the
     * 2 x 2 minors exact in int64 Q52 (< 2^61), det(P) their sum (< 2^63). */
    int64_t c[3][3];
    for (int i = 0; i < 3; i++) {
        const int32_t *a = p[(i + 1) % 3], *b = p[(i + 2) % 3];
        c[i][0] = (int64_t)a[1] - b[1];
        c[i][1] = (int64_t)b[0] - a[0];
        c[i][2] = (int64_t)a[0] * b[1] - (int64_t)b[0] * a[1];
    }
    const int64_t det_p = c[0][2] + c[1][2] + c[2][2];
    if (spvs_q_abs64(det_p) <= (uint64_t)Q_DET_EPS_Q52) {
        return SPVS_E_DEGENERATE;
    }
    /* Row 3 solves P h3 = w with w_i = y_tgt / y_cur (as float's adj(P)
     * adj(D) y_tgt / det(D P), D = diag(y_cur), with det(D) divided out);
     * det(D P) = y_cur0 y_cur1 y_cur2 det(P) must pass float's test. */
    uint32_t sat = 0;
    const spvs_qf_t dp = spvs_qf_from_i64(det_p, -2 * SPVS_QC);
    spvs_qf_t dy = dp;
    spvs_qf_t w[3];
    for (int i = 0; i < 3; i++) {
        const spvs_qf_t v = qf_q26(p[i][3]);
        dy = spvs_qf_mul(dy, v);
        w[i] = spvs_qf_mul(qf_q26(p[i][1]), spvs_qf_recip(v, &sat));
    }
    if (p[0][3] == 0 || p[1][3] == 0 || p[2][3] == 0 ||
        spvs_qf_le(dy.m < 0 ? spvs_qf_neg(dy) : dy, Q_DET_EPS)) {
        return SPVS_E_DEGENERATE;
    }
    const spvs_qf_t idp = spvs_qf_recip(dp, &sat);
    spvs_qf_t cc[3][3];
    for (int i = 0; i < 3; i++) {
        cc[i][0] = qf_q26(c[i][0]);
        cc[i][1] = qf_q26(c[i][1]);
        cc[i][2] = spvs_qf_from_i64(c[i][2], -2 * SPVS_QC);
    }
    int32_t h[9] = {0, 0, 0, 0, (int32_t)1 << SPVS_QH, 0, 0, 0, 0};
    for (int j = 0; j < 3; j++) {
        const spvs_qf_t col[3] = {cc[0][j], cc[1][j], cc[2][j]};
        h[6 + j] = spvs_qf_to_q32(spvs_qf_mul(qf_dot3(col, w), idp), SPVS_QH, &sat);
    }
    /* An entry outside (-16, 16) is outside the kernels' range: no
     * consensus keeps such a model (docs/FIXED.md). */
    if (sat != 0) {
        return SPVS_E_DEGENERATE;
    }
    /* Row 1 solves P h1 = x_cur w with w = h3 . p_tgt (exact in Q53); a
     * plane point seen by both cameras has w > 0. */
    spvs_qf_t bx[3];
    for (int i = 0; i < 3; i++) {
        const int64_t wi = (int64_t)h[6] * p[i][0] + (int64_t)h[7] * p[i][1] +
                           (int64_t)h[8] * ((int64_t)1 << SPVS_QC);
        if (wi <= W_EPS_Q53) {
            return SPVS_E_DEGENERATE;
        }
        bx[i] = spvs_qf_mul(qf_q26(p[i][2]), spvs_qf_from_i64(wi, -53));
    }
    for (int j = 0; j < 3; j++) {
        const spvs_qf_t col[3] = {cc[0][j], cc[1][j], cc[2][j]};
        h[j] = spvs_qf_to_q32(spvs_qf_mul(qf_dot3(col, bx), idp), SPVS_QH, &sat);
    }
    if (sat != 0) {
        return SPVS_E_DEGENERATE;
    }
    for (int k = 0; k < 9; k++) {
        Hq[k] = h[k];
    }
    return SPVS_OK;
}
