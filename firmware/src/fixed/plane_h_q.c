/*
 * plane_h_q.c - the robust planar-motion homography in fixed point
 * (plane_h_q.h): plane_h.c's flow on the Q store and the Q kernels.  The
 * comments of plane_h.c say why each step is made; here they say only
 * where the fixed-point version differs.
 */
#include <string.h>

#include "../core_util.h"
#include "fit_q.h"
#include "plane_h_q.h"
#include "ransac_q.h"

/* ---- loading a frame ------------------------------------------------------ */

int spvs_q_plane_h_check(const spvs_match_t *m, uint16_t n)
{
    if (n > SPVS_MAX_MATCHES) {
        return SPVS_E_CAPACITY;
    }
    if (m == 0 && n > 0) {
        return SPVS_E_ARG;
    }
    if (n < 3u) {
        return SPVS_E_TOO_FEW;
    }
    return SPVS_OK;
}

/* The status of the first bad value in the float core's order (plane_h.c's
 * frame_error: match by match, x_tgt, y_tgt, x_cur, y_cur, each NaN or
 * infinite before out of range, then the feature index), so that a frame
 * with several kinds of bad value gets the float core's status.  Only for
 * a frame the loader refused (bound: n matches). */
static int q_frame_error(const spvs_match_t *m, uint16_t n)
{
    for (uint16_t i = 0; i < n; i++) {
        const spvs_real c[4] = {m[i].x_tgt, m[i].y_tgt, m[i].x_cur, m[i].y_cur};
        for (int j = 0; j < 4; j++) {
            const spvs_q_ieee_t v = spvs_q_real_parts(c[j]);
            if (v.nonfinite) {
                return SPVS_E_NONFINITE;
            }
            /* |c| > SPVS_MAX_COORD_PX, an integer: its nearest integer is
             * above it, or equal to it with the magnitude rounded down. */
            uint32_t sat = 0;
            int below = 0;
            const int32_t r = spvs_q_from_ieee(v, 0, &sat, &below);
            const int64_t a = r < 0 ? -(int64_t)r : r;
            if (sat != 0u || a > SPVS_MAX_COORD_PX || (a == SPVS_MAX_COORD_PX && below)) {
                return SPVS_E_RANGE;
            }
        }
        if (m[i].feature >= SPVS_MAX_FEATURES) {
            return SPVS_E_RANGE;
        }
    }
    return SPVS_OK;
}

int spvs_q_plane_h_load(spvs_q_plane_h_t *e, const spvs_match_t *m, uint16_t n,
                        const uint16_t *order, uint16_t n_plane)
{
    const int rc = spvs_q_plane_h_check(m, n);
    if (rc != SPVS_OK) {
        return rc;
    }
    if (order == 0) {
        n_plane = n;
    }
    if (n_plane > n) {
        return SPVS_E_ARG;
    }
    const uint16_t stride = spvs_pts_spread_stride(n_plane);
    const uint32_t bad = spvs_q_pts_load(&e->pts, e->feat, m, n, n_plane, order, stride);
    if (bad != 0u) {
        const int first = q_frame_error(m, n);
        return first != SPVS_OK ? first : SPVS_E_RANGE;
    }
    e->n_plane = n_plane;
    e->n_pts = n;
    return n_plane < SPVS_MIN_INLIERS ? SPVS_E_TOO_FEW : SPVS_OK;
}

/* ---- RANSAC's callbacks (ransac_q.h) -------------------------------------- */

static int q_est_fit(void *ctx, const uint16_t *sample, int32_t *model)
{
    const spvs_q_plane_h_t *e = (const spvs_q_plane_h_t *)ctx;
    return spvs_q_solve3(&e->pts, sample, model);
}

static uint16_t q_est_score(void *ctx, const int32_t *H, const void *thr, uint16_t need,
                          uint8_t *mask)
{
    const spvs_q_plane_h_t *e = (const spvs_q_plane_h_t *)ctx;
    return spvs_q_pts_score(&e->pts, e->n_plane, H, (const spvs_q_thr_t *)thr, need, mask);
}

/* The tie-break cost; a saturated sum (above 2^12 scaled units^2, far
 * beyond any consensus's) compares as the largest, which it is. */
static uint64_t q_est_cost(void *ctx, const int32_t *H, const uint8_t *mask)
{
    const spvs_q_plane_h_t *e = (const spvs_q_plane_h_t *)ctx;
    uint32_t sat = 0;
    return spvs_q_pts_cost(&e->pts, e->n_plane, H, mask, &sat);
}

/* plane_h.c's est_refine: two linear fits on the first SPVS_LO_POINTS
 * points, the second on the first one's inliers. */
static int q_est_refine(void *ctx, int32_t *H, const uint8_t *mask)
{
    spvs_q_plane_h_t *e = (spvs_q_plane_h_t *)ctx;
    const uint16_t m = e->n_plane < SPVS_LO_POINTS ? e->n_plane : SPVS_LO_POINTS;
    const int rc = spvs_q_fit_linear(&e->pts, mask, m, H);
    if (rc != SPVS_OK) {
        return rc;
    }
    (void)spvs_q_pts_score(&e->pts, m, H, &e->thr, 0, e->lo_mask);
    const int rc2 = spvs_q_fit_linear(&e->pts, e->lo_mask, m, H);
    (void)rc2;
    return SPVS_OK;
}

/* ---- the re-selection ----------------------------------------------------- */

/* plane_h.c's lin_follow: the sums moved from the set `from` to `to`.
 * Returns 0 (the same sets), 1 (moved) or -1 (a point behind the camera
 * under hw: the sums are no longer usable). */
static int lin_follow(const spvs_q_plane_h_t *e, const int32_t hw[9], const uint8_t *from,
                      const uint8_t *to, spvs_q_sums_t *sums)
{
    const uint16_t n = e->n_plane;
    int moved = 0;
    int32_t p[4];
    /* Bound: n / 8 words, each with at most 8 differing bytes, then fewer
     * than 8 points. */
    uint16_t i0 = 0;
    for (; i0 + 8u <= n; i0 = (uint16_t)(i0 + 8u)) {
        const uint64_t a = spvs_load_le64(from + i0);
        const uint64_t b = spvs_load_le64(to + i0);
        for (uint64_t d = a ^ b; d != 0u; d &= d - 1u) {
            const uint16_t i = (uint16_t)(i0 + spvs_byte_of_lowest(d));
            spvs_q_pts_row(&e->pts, i, p);
            if (!spvs_q_lin_move(hw, p, to[i] != 0, sums)) {
                return -1;
            }
            moved = 1;
        }
    }
    for (uint16_t i = i0; i < n; i++) {
        if (from[i] != to[i]) {
            spvs_q_pts_row(&e->pts, i, p);
            if (!spvs_q_lin_move(hw, p, to[i] != 0, sums)) {
                return -1;
            }
            moved = 1;
        }
    }
    return moved;
}

/* plane_h.c's reselect on the Q kernels. */
static void reselect(spvs_q_plane_h_t *e, int32_t model[9], uint16_t *n_inl)
{
    uint8_t *cur = e->mask;
    uint8_t *next = e->idx_mask;
    int32_t *const hw = e->lin_hw;
    spvs_q_sums_t *const sums = &e->lin_sums;
    memcpy(hw, model, 9 * sizeof hw[0]);
    if (spvs_q_pts_sum(SPVS_T_LIN, hw, &e->pts, cur, e->n_plane, sums) < 3) {
        return;
    }
    for (int round = 0; round < SPVS_REFIT_ROUNDS; round++) {
        int32_t Hr[9];
        if (spvs_q_lin_solve(sums, hw, Hr) != SPVS_OK) {
            break;
        }
        const uint16_t n_new = spvs_q_pts_score(&e->pts, e->n_plane, Hr, &e->thr, 0, next);
        if (n_new < *n_inl) {
            break;
        }
        memcpy(model, Hr, sizeof Hr);
        const int moved = lin_follow(e, hw, cur, next, sums);
        if (moved < 0) {
            break;
        }
        uint8_t *const was = cur;
        cur = next;
        next = was;
        *n_inl = n_new;
        if (moved == 0) {
            break;
        }
    }
    if (cur != e->mask) {
        memcpy(e->mask, cur, e->n_plane);
    }
}

/* ---- the final refit ------------------------------------------------------ */

/* The summed squared Sampson error of e->mask's inliers under H (scaled
 * units^2); *ok = 0 when one is behind the camera. */
static spvs_qf_t sampson_cost(const spvs_q_plane_h_t *e, const int32_t H[9], int *ok)
{
    spvs_q_sums_t c;
    *ok = spvs_q_pts_sum(SPVS_T_SAMPSON, H, &e->pts, e->mask, e->n_plane, &c) >= 0;
    return spvs_q_sums_term(&c, 0);
}

/* plane_h.c's final_refit; the step is kept only where its Sampson cost is
 * below the current model's, which the LIN sums carry as term
 * SPVS_H_LIN_COST. */
static void final_refit(spvs_q_plane_h_t *e, int32_t model[9])
{
    for (int step = 0; step < SPVS_FINAL_STEPS; step++) {
        int32_t Hn[9];
        if (spvs_q_pts_sum(SPVS_T_LIN, model, &e->pts, e->mask, e->n_plane, &e->lin_sums) < 3 ||
            spvs_q_lin_solve(&e->lin_sums, model, Hn) != SPVS_OK) {
            break;
        }
        int ok = 0;
        const spvs_qf_t cn = sampson_cost(e, Hn, &ok);
        const spvs_qf_t c0 = spvs_q_sums_term(&e->lin_sums, SPVS_H_LIN_COST);
        /* cn < c0, as !(c0 <= cn). */
        if (!ok || spvs_qf_le(c0, cn)) {
            break;
        }
        memcpy(model, Hn, sizeof Hn);
    }
}

int spvs_q_plane_h_estimate(spvs_q_plane_h_t *e, spvs_qf_t t2, uint32_t confidence_q32,
                            uint32_t max_iters, spvs_rng_t *rng, uint32_t *iters)
{
    SPVS_ASSERT(e != 0 && rng != 0 && iters != 0);
    e->thr = spvs_q_thr(t2);
    spvs_q_estimator_t est = {3u,        e->n_plane,  e,         q_est_fit,
                              q_est_score, q_est_cost, q_est_refine};
    spvs_q_ransac_opts_t opts = {&e->thr, confidence_q32, max_iters, SPVS_MIN_INLIERS};
    spvs_q_ransac_stats_t st;
    int32_t model[SPVS_MODEL_MAX];
    const int rc = spvs_q_ransac(&est, &opts, rng, e->idx, model, e->mask, e->idx_mask, &st);
    *iters = st.iters;
    if (rc != SPVS_OK) {
        return rc;
    }
    uint16_t n_inl = st.n_inliers;
    reselect(e, model, &n_inl);
    final_refit(e, model);
    memcpy(e->H, model, sizeof e->H);
    e->n_inliers = n_inl;
    return SPVS_OK;
}
