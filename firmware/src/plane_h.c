/*
 * plane_h.c - the robust planar-motion homography (plane_h.h): the loading
 * of a frame, RANSAC's callbacks, the LO step, the inlier re-selection and
 * the final refit.  The loops over the points are points.c's.
 */
#include <math.h>
#include <string.h>

#include "core_util.h"
#include "h_fit.h"
#include "spvs/homography.h"
#include "spvs/plane_h.h"

/* The estimator's view of its points for the fits (h_fit.h). */
static spvs_pts_in_t source(const spvs_plane_h_t *e)
{
    const spvs_pts_in_t in = {0, &e->pts};
    return in;
}

void spvs_plane_h_point(const spvs_plane_h_t *e, uint16_t i, spvs_real row[4])
{
    spvs_pts_row(&e->pts, i, row);
}

/* ---- loading a frame ------------------------------------------------------ */

int spvs_plane_h_check(const spvs_match_t *m, uint16_t n)
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

/* The first bad value of a frame, as a status: a non-finite coordinate,
 * one out of range, or a feature index out of range. */
static int frame_error(const spvs_match_t *m, uint16_t n)
{
    const spvs_real lim = (spvs_real)SPVS_MAX_COORD_PX;
    for (uint16_t i = 0; i < n; i++) {
        const spvs_real c[4] = {m[i].x_tgt, m[i].y_tgt, m[i].x_cur, m[i].y_cur};
        for (int j = 0; j < 4; j++) {
            if (!spvs_is_finite(c[j])) {
                return SPVS_E_NONFINITE;
            }
            if (SPVS_FABS(c[j]) > lim) {
                return SPVS_E_RANGE;
            }
        }
        if (m[i].feature >= SPVS_MAX_FEATURES) {
            return SPVS_E_RANGE;
        }
    }
    return SPVS_OK;
}

int spvs_plane_h_load(spvs_plane_h_t *e, const spvs_match_t *m, uint16_t n,
                      const uint16_t *order, uint16_t n_plane)
{
    int rc = spvs_plane_h_check(m, n);
    if (rc != SPVS_OK) {
        return rc;
    }
    if (order == 0) {
        n_plane = n;
    }
    if (n_plane > n) {
        return SPVS_E_ARG;
    }
    /* The copy checks every value without branches; only a bad frame is
     * looked at again, for its status. */
    const uint16_t stride = spvs_pts_spread_stride(n_plane);
    if (spvs_pts_load(&e->pts, e->feat, m, n, n_plane, order, stride) != 0) {
        rc = frame_error(m, n);
        return rc != SPVS_OK ? rc : SPVS_E_RANGE;
    }
    e->n_plane = n_plane;
    e->n_pts = n;
    return n_plane < SPVS_MIN_INLIERS ? SPVS_E_TOO_FEW : SPVS_OK;
}

/* ---- RANSAC's callbacks (ransac.h) ---------------------------------------- */

static int est_fit(void *ctx, const uint16_t *sample, spvs_real *model)
{
    const spvs_plane_h_t *e = (const spvs_plane_h_t *)ctx;
    return spvs_pts_solve3(&e->pts, sample, model);
}

/* The inlier count over all the plane candidates, with the bail-out test
 * (points.h, spvs_pts_score).  For a model as good as `need` the test
 * fails with a probability of about 0.1 % per block; a contaminated
 * sample's model is dropped after 16 to 48 points instead of after
 * n - need outliers. */
static uint16_t est_score(void *ctx, const spvs_real *H, spvs_real t2, uint16_t need,
                          uint8_t *mask)
{
    const spvs_plane_h_t *e = (const spvs_plane_h_t *)ctx;
    return spvs_pts_score(&e->pts, e->n_plane, H, t2, need, mask);
}

/* Tie-break cost of H: its inliers' (mask) squared algebraic residual. */
static spvs_real est_cost(void *ctx, const spvs_real *H, const uint8_t *mask)
{
    const spvs_plane_h_t *e = (const spvs_plane_h_t *)ctx;
    return spvs_pts_cost(&e->pts, e->n_plane, H, mask);
}

/* LO step: polish a hypothesis with the weighted linear fit on its inliers
 * among the first SPVS_LO_POINTS points, then once more on the polished
 * model's own inliers among them.  The step only has to lift the count
 * that the stopping rule reads, and the points are in spread order, so the
 * first SPVS_LO_POINTS stand for all of them.  A 3-point model's inliers
 * are those near its sample and it misses the others, so one fit on them
 * lifts the count only part of the way; the second pass takes it the rest.
 * The final model is refitted on every inlier (spvs_plane_h_estimate). */
static int est_refine(void *ctx, spvs_real *H, const uint8_t *mask)
{
    spvs_plane_h_t *e = (spvs_plane_h_t *)ctx;
    const spvs_pts_in_t in = source(e);
    const uint16_t m = e->n_plane < SPVS_LO_POINTS ? e->n_plane : SPVS_LO_POINTS;
    const int rc = spvs_hf_fit_linear(&in, mask, m, H);
    if (rc != SPVS_OK) {
        return rc;
    }
    (void)spvs_pts_score(&e->pts, m, H, e->t2, 0, e->lo_mask);
    /* On failure the fit leaves H as the first pass made it, which is
     * still the polished model. */
    const int rc2 = spvs_hf_fit_linear(&in, e->lo_mask, m, H);
    (void)rc2;
    return SPVS_OK;
}

/* ---- the re-selection ----------------------------------------------------- */

/* Moves the sums from the set `from` to the set `to`: the points flagged in
 * one and not the other added or removed, in point order.  The flags (0 or
 * 1) are compared eight at a time and only the differing bytes of a word
 * visited (most words are equal).  Returns 0 when the sets are the same,
 * 1 when the sums moved, -1 when a point could not be added (w0 <= 0 under
 * hw: the sums are then no longer usable). */
static int lin_follow(const spvs_plane_h_t *e, const spvs_real hw[9], const uint8_t *from,
                      const uint8_t *to, spvs_real sums[SPVS_H_LIN_SUMS])
{
    const uint16_t n = e->n_plane;
    int moved = 0;
    spvs_real p[4];
    /* Bound: n / 8 words, each with at most 8 differing bytes, then fewer
     * than 8 points. */
    uint16_t i0 = 0;
    for (; i0 + 8u <= n; i0 = (uint16_t)(i0 + 8u)) {
        const uint64_t a = spvs_load_le64(from + i0);
        const uint64_t b = spvs_load_le64(to + i0);
        for (uint64_t d = a ^ b; d != 0u; d &= d - 1u) {
            const uint16_t i = (uint16_t)(i0 + spvs_byte_of_lowest(d));
            spvs_pts_row(&e->pts, i, p);
            if (!spvs_pts_lin_move(hw, p, to[i] != 0, sums)) {
                return -1;
            }
            moved = 1;
        }
    }
    for (uint16_t i = i0; i < n; i++) {
        if (from[i] != to[i]) {
            spvs_pts_row(&e->pts, i, p);
            if (!spvs_pts_lin_move(hw, p, to[i] != 0, sums)) {
                return -1;
            }
            moved = 1;
        }
    }
    return moved;
}

/* The summed squared Sampson error of the inliers in e->mask under H;
 * SPVS_REAL_MAX when one is behind the camera. */
static spvs_real sampson_cost(const spvs_plane_h_t *e, const spvs_real H[9])
{
    const spvs_pts_in_t in = source(e);
    spvs_real c;
    return spvs_pts_sum(SPVS_T_SAMPSON, H, &in, e->mask, e->n_plane, &c) < 0 ? SPVS_REAL_MAX : c;
}

/* The final refit on the inliers in e->mask: SPVS_FINAL_STEPS steps, each
 * the joint linear fit with the Sampson weights of the current model
 * (which minimises the Sampson error to first order about it), each kept
 * only where it lowers the summed Sampson error (the current model's comes
 * with the fit's sums).  The re-selection's weights were the RANSAC
 * model's; this takes them at the re-selected model, so that the result is
 * the Sampson fit of the final set.  have_sums: e->lin_sums already hold
 * the sums of the first step (model's, on e->mask). */
static void final_refit(spvs_plane_h_t *e, spvs_real model[9], int have_sums)
{
    const spvs_pts_in_t in = source(e);
    for (int step = 0; step < SPVS_FINAL_STEPS; step++) {
        spvs_real Hn[9];
        if ((!have_sums &&
             spvs_hf_lin_sums(&in, e->mask, e->n_plane, model, e->lin_sums) != SPVS_OK) ||
            spvs_hf_lin_solve(e->lin_sums, model, Hn) != SPVS_OK) {
            break;
        }
        have_sums = 0;
        if (!(sampson_cost(e, Hn) < e->lin_sums[SPVS_H_LIN_COST])) {
            break;
        }
        for (int k = 0; k < 9; k++) {
            model[k] = Hn[k];
        }
    }
}

/* Re-selects the inliers of `model` until the set stops changing (bound:
 * SPVS_REFIT_ROUNDS rounds): each round solves the joint linear fit on the
 * set in use and takes the inliers of its H as the next set, kept while
 * the count does not fall.  The fit's weights stay those of the RANSAC
 * model, so its sums follow the set by the points that enter or leave it
 * (lin_follow) instead of another pass.  On return e->mask holds the set
 * and *n_inl its count.  Returns 1 when no round changed the model (the
 * first fit failed or lost inliers): e->lin_sums are then still the sums of
 * `model` on e->mask, which the final refit starts from. */
static int reselect(spvs_plane_h_t *e, spvs_real model[9], uint16_t *n_inl)
{
    const spvs_pts_in_t in = source(e);
    /* The set in use and the next one, swapped each round. */
    uint8_t *cur = e->mask;
    uint8_t *next = e->idx_mask;
    spvs_real *const hw = e->lin_hw;
    spvs_real *const sums = e->lin_sums;
    for (int k = 0; k < 9; k++) {
        hw[k] = model[k];
    }
    if (spvs_hf_lin_sums(&in, cur, e->n_plane, hw, sums) != SPVS_OK) {
        return 0;
    }
    int unchanged = 1;
    for (int round = 0; round < SPVS_REFIT_ROUNDS; round++) {
        spvs_real Hr[9];
        if (spvs_hf_lin_solve(sums, hw, Hr) != SPVS_OK) {
            break;
        }
        const uint16_t n_new = spvs_pts_score(&e->pts, e->n_plane, Hr, e->t2, 0, next);
        if (n_new < *n_inl) {
            break;
        }
        unchanged = 0;
        for (int k = 0; k < 9; k++) {
            model[k] = Hr[k];
        }
        /* The model is now the fit on cur; the sums move to next. */
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
    return unchanged;
}

int spvs_plane_h_estimate(spvs_plane_h_t *e, spvs_real inlier_px, spvs_real confidence,
                          uint32_t max_iters, spvs_rng_t *rng, uint32_t *iters)
{
    SPVS_ASSERT(e != 0 && rng != 0 && iters != 0);
    const spvs_real t = inlier_px * (SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
    e->t2 = t * t;
    spvs_estimator_t est = {3u, e->n_plane, e, est_fit, est_score, est_cost, est_refine};
    spvs_ransac_opts_t opts = {e->t2, confidence, max_iters, SPVS_MIN_INLIERS};
    spvs_ransac_stats_t st;
    spvs_real model[SPVS_MODEL_MAX];
    int rc = spvs_ransac(&est, &opts, rng, e->idx, model, e->mask, e->idx_mask, &st);
    *iters = st.iters;
    if (rc != SPVS_OK) {
        return rc;
    }
    uint16_t n_inl = st.n_inliers;
    const int have_sums = reselect(e, model, &n_inl);
    final_refit(e, model, have_sums);
    for (int k = 0; k < 9; k++) {
        e->H_sc[k] = model[k];
    }
    e->n_inliers = n_inl;
    return SPVS_OK;
}

int spvs_plane_h_adopt(spvs_plane_h_t *e, const spvs_real H_sc[9], spvs_real inlier_px)
{
    SPVS_ASSERT(e != 0 && H_sc != 0);
    if (!spvs_finite3x2(H_sc, H_sc + 6)) {
        return SPVS_E_DEGENERATE;
    }
    for (int k = 0; k < 9; k++) {
        e->H_sc[k] = H_sc[k];
    }
    e->H_sc[3] = SPVS_R(0.0);
    e->H_sc[4] = SPVS_R(1.0);
    e->H_sc[5] = SPVS_R(0.0);
    const spvs_real t = inlier_px * (SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
    e->t2 = t * t;
    e->n_inliers = spvs_pts_score(&e->pts, e->n_plane, e->H_sc, e->t2, 0, e->mask);
    return e->n_inliers < SPVS_MIN_INLIERS ? SPVS_E_NO_CONSENSUS : SPVS_OK;
}
