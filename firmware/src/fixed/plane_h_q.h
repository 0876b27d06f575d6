/*
 * plane_h_q.h - the robust planar-motion homography in fixed point: the
 * estimator of plane_h.h (load, 3-point RANSAC with its LO step, the inlier
 * re-selection and the final refit) on the Q store and the Q kernels
 * (private; formats and ranges in docs/FIXED.md).
 *
 * The flow, the bounds and the statuses are plane_h.inc's (shared with
 * plane_h.c); every step is its fixed-point twin:
 *   load      spvs_q_pts_load (points_q.h) in the same spread order;
 *   RANSAC    spvs_q_ransac (ransac_q.h) with spvs_q_solve3, the Q inlier
 *             count and cost, and the LO step's two-stage linear fit
 *             spvs_q_fit_linear (fit_q.h);
 *   reselect  the joint linear fit's BFP sums (spvs_q_pts_sum, SPVS_T_LIN)
 *             solved by spvs_q_lin_solve and moved with spvs_q_lin_move;
 *   refit     SPVS_FINAL_STEPS steps at the current model's weights, each
 *             kept only where it lowers the summed Sampson error (a
 *             spvs_qf_t comparison).
 * H is in scaled units, Q27 (SPVS_QH), h22 = 1.
 */
#ifndef SPVS_FIXED_PLANE_H_Q_H
#define SPVS_FIXED_PLANE_H_Q_H

#include "points_q.h"
#include "spvs/ransac.h"

typedef struct {
    spvs_q_store_t pts;
    /* As spvs_plane_h_t: points 0..n_plane are the plane candidates,
     * feat[i] point i's target-image feature. */
    uint16_t n_pts;
    uint16_t n_plane;
    uint16_t feat[SPVS_MAX_MATCHES];
    /* The estimate: H_cur_tgt in scaled units (Q27), its inliers among the
     * plane candidates and their count. */
    int32_t H[9];
    uint8_t mask[SPVS_MAX_MATCHES];
    uint16_t n_inliers;
    /* Work, as spvs_plane_h_t's. */
    uint16_t idx[SPVS_MAX_MATCHES];
    uint8_t idx_mask[SPVS_MAX_MATCHES];
    uint8_t lo_mask[SPVS_LO_POINTS];
    int32_t lin_hw[9];
    spvs_q_sums_t lin_sums;
    spvs_q_thr_t thr;
} spvs_q_plane_h_t;

/* spvs_plane_h_check: the frame's size and pointer (SPVS_OK,
 * SPVS_E_CAPACITY, SPVS_E_ARG or SPVS_E_TOO_FEW), before anything reads
 * the matches. */
SPVS_NODISCARD int spvs_q_plane_h_check(const spvs_match_t *m, uint16_t n);

/* spvs_plane_h_load on the Q store: the same checks and statuses
 * (SPVS_E_CAPACITY, SPVS_E_ARG, SPVS_E_TOO_FEW, SPVS_E_NONFINITE for a NaN
 * or infinite coordinate, SPVS_E_RANGE for one above SPVS_MAX_COORD_PX or a
 * feature index out of range; where a frame has both, SPVS_E_NONFINITE),
 * the same spread order. */
SPVS_NODISCARD int spvs_q_plane_h_load(spvs_q_plane_h_t *e, const spvs_match_t *m, uint16_t n,
                                       const uint16_t *order, uint16_t n_plane);

/* spvs_plane_h_estimate: t2 is the squared inlier threshold in scaled
 * units (spvs_q_t2_from_real, or the fixed build's own from noise_px);
 * confidence and max_iters as RANSAC's (ransac_q.h).  Returns RANSAC's
 * status; on SPVS_OK e->H, e->mask and e->n_inliers hold the estimate. */
SPVS_NODISCARD int spvs_q_plane_h_estimate(spvs_q_plane_h_t *e, spvs_qf_t t2,
                                           uint32_t confidence_q32, uint32_t max_iters,
                                           spvs_rng_t *rng, uint32_t *iters);

#endif /* SPVS_FIXED_PLANE_H_Q_H */
