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
#include "spvs/plane_h.h"
#include "spvs/ransac.h"

struct spvs_q_plane_h {
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
};

#endif /* SPVS_FIXED_PLANE_H_Q_H */
