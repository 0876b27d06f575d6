/*
 * plane_h_q.c - the robust planar-motion homography in fixed point
 * (plane_h_q.h): the flow of plane_h.inc (written once for both cores) on
 * the Q store and the Q kernels.  The comments of plane_h.inc say why each
 * step is made; here they say only where the fixed-point version differs.
 */
#include <string.h>

#include "../core_util.h"
#include "fit_q.h"
#include "plane_h_q.h"
#include "ransac_q.h"

/* ---- the fixed-point core's side of plane_h.inc ------------------------------ */

typedef spvs_q_plane_h_t ph_t;
typedef int32_t ph_h_t;
typedef spvs_q_sums_t ph_sums_t;
typedef spvs_qf_t ph_val_t;

/* The status of the first bad value in the float core's order (plane_h.c's
 * frame_error: match by match, x_tgt, y_tgt, x_cur, y_cur, each NaN or
 * infinite before out of range, then the feature index), so that a frame
 * with several kinds of bad value gets the float core's status.  Only for
 * a frame the loader refused (bound: n matches). */
static int frame_error(const spvs_match_t *m, uint16_t n)
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

static int pts_load(spvs_q_plane_h_t *e, const spvs_match_t *m, uint16_t n, uint16_t n_plane,
                    const uint16_t *order, uint16_t stride)
{
    return spvs_q_pts_load(&e->pts, e->feat, m, n, n_plane, order, stride) != 0u;
}

static int fit_linear(const spvs_q_plane_h_t *e, const uint8_t *mask, uint16_t m, int32_t *H)
{
    return spvs_q_fit_linear(&e->pts, mask, m, H);
}

static uint16_t pts_score(const spvs_q_plane_h_t *e, uint16_t n, const int32_t *H,
                          uint8_t *mask)
{
    return spvs_q_pts_score(&e->pts, n, H, &e->thr, 0, mask);
}

static void pts_row(const spvs_q_plane_h_t *e, uint16_t i, int32_t p[4])
{
    spvs_q_pts_row(&e->pts, i, p);
}

static int lin_move(const int32_t hw[9], const int32_t p[4], int add, spvs_q_sums_t *sums)
{
    return spvs_q_lin_move(hw, p, add, sums);
}

/* The joint linear fit's BFP sums; usable with at least three points. */
static int lin_sums(const spvs_q_plane_h_t *e, const uint8_t *mask, const int32_t hw[9],
                    spvs_q_sums_t *sums)
{
    return spvs_q_pts_sum(SPVS_T_LIN, hw, &e->pts, mask, e->n_plane, sums) >= 3;
}

static int lin_solve(const spvs_q_sums_t *sums, const int32_t hw[9], int32_t H[9])
{
    return spvs_q_lin_solve(sums, hw, H);
}

static spvs_qf_t lin_cost(const spvs_q_sums_t *sums)
{
    return spvs_q_sums_term(sums, SPVS_H_LIN_COST);
}

/* The summed squared Sampson error of e->mask's inliers under H (scaled
 * units^2); *ok = 0 when one is behind the camera. */
static spvs_qf_t sampson_cost(const spvs_q_plane_h_t *e, const int32_t H[9], int *ok)
{
    spvs_q_sums_t c;
    *ok = spvs_q_pts_sum(SPVS_T_SAMPSON, H, &e->pts, e->mask, e->n_plane, &c) >= 0;
    return spvs_q_sums_term(&c, 0);
}

/* a < b, as !(b <= a). */
static int val_lt(spvs_qf_t a, spvs_qf_t b)
{
    return !spvs_qf_le(b, a);
}

static spvs_q_sums_t *lin_sums_of(spvs_q_plane_h_t *e)
{
    return &e->lin_sums;
}

static int32_t *h_of(spvs_q_plane_h_t *e)
{
    return e->H;
}

#include "../plane_h.inc"

/* ---- loading a frame ------------------------------------------------------ */

int spvs_q_plane_h_check(const spvs_match_t *m, uint16_t n)
{
    return frame_size_check(m, n);
}

int spvs_q_plane_h_load(spvs_q_plane_h_t *e, const spvs_match_t *m, uint16_t n,
                        const uint16_t *order, uint16_t n_plane)
{
    return load_frame(e, m, n, order, n_plane);
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

/* The LO step (plane_h.inc, lo_step). */
static int q_est_refine(void *ctx, int32_t *H, const uint8_t *mask)
{
    return lo_step((spvs_q_plane_h_t *)ctx, H, mask);
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
    refine_consensus(e, model, st.n_inliers);
    return SPVS_OK;
}
