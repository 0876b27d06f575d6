/*
 * plane_h.c - the robust planar-motion homography (plane_h.h): the loading
 * of a frame, RANSAC's callbacks, the LO step, the inlier re-selection and
 * the final refit, their flow written once for this core and the
 * fixed-point one in plane_h.inc.  The loops over the points are
 * points.c's.
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

/* ---- the float core's side of plane_h.inc --------------------------------- */

typedef spvs_plane_h_t ph_t;
typedef spvs_real ph_h_t;
typedef spvs_real ph_sums_t;
typedef spvs_real ph_val_t;

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

static int pts_load(spvs_plane_h_t *e, const spvs_match_t *m, uint16_t n, uint16_t n_plane,
                    const uint16_t *order, uint16_t stride)
{
    return spvs_pts_load(&e->pts, e->feat, m, n, n_plane, order, stride) != 0;
}

static int fit_linear(const spvs_plane_h_t *e, const uint8_t *mask, uint16_t m, spvs_real *H)
{
    const spvs_pts_in_t in = source(e);
    return spvs_hf_fit_linear(&in, mask, m, H);
}

static uint16_t pts_score(const spvs_plane_h_t *e, uint16_t n, const spvs_real *H,
                          uint8_t *mask)
{
    return spvs_pts_score(&e->pts, n, H, e->t2, 0, mask);
}

static void pts_row(const spvs_plane_h_t *e, uint16_t i, spvs_real p[4])
{
    spvs_pts_row(&e->pts, i, p);
}

static int lin_move(const spvs_real hw[9], const spvs_real p[4], int add, spvs_real *sums)
{
    return spvs_pts_lin_move(hw, p, add, sums);
}

static int lin_sums(const spvs_plane_h_t *e, const uint8_t *mask, const spvs_real hw[9],
                    spvs_real *sums)
{
    const spvs_pts_in_t in = source(e);
    return spvs_hf_lin_sums(&in, mask, e->n_plane, hw, sums) == SPVS_OK;
}

static int lin_solve(const spvs_real *sums, const spvs_real hw[9], spvs_real H[9])
{
    return spvs_hf_lin_solve(sums, hw, H);
}

static spvs_real lin_cost(const spvs_real *sums)
{
    return sums[SPVS_H_LIN_COST];
}

/* The summed squared Sampson error of the inliers in e->mask under H;
 * SPVS_REAL_MAX when one is behind the camera (always comparable). */
static spvs_real sampson_cost(const spvs_plane_h_t *e, const spvs_real H[9], int *ok)
{
    const spvs_pts_in_t in = source(e);
    spvs_real c;
    *ok = 1;
    return spvs_pts_sum(SPVS_T_SAMPSON, H, &in, e->mask, e->n_plane, &c) < 0 ? SPVS_REAL_MAX : c;
}

static int val_lt(spvs_real a, spvs_real b)
{
    return a < b;
}

static spvs_real *lin_sums_of(spvs_plane_h_t *e)
{
    return e->lin_sums;
}

static spvs_real *h_of(spvs_plane_h_t *e)
{
    return e->H_sc;
}

#include "plane_h.inc"

/* ---- loading a frame ------------------------------------------------------ */

int spvs_plane_h_check(const spvs_match_t *m, uint16_t n)
{
    return frame_size_check(m, n);
}

int spvs_plane_h_load(spvs_plane_h_t *e, const spvs_match_t *m, uint16_t n,
                      const uint16_t *order, uint16_t n_plane)
{
    return load_frame(e, m, n, order, n_plane);
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

/* The LO step (plane_h.inc, lo_step). */
static int est_refine(void *ctx, spvs_real *H, const uint8_t *mask)
{
    return lo_step((spvs_plane_h_t *)ctx, H, mask);
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
    refine_consensus(e, model, st.n_inliers);
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
