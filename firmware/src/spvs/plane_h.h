/*
 * plane_h.h - the robust estimate of the plane homography under planar
 * motion: 3-point RANSAC with a local optimisation (LO) step, inlier
 * re-selection and a final Gauss-Newton refit (paper, section 2; the
 * decisions are in docs/ESTIMATION.md).
 *
 *   load      the frame's matches, checked and scaled (pixels /
 *             SPVS_COORD_SCALE), stored in a spread order: the plane
 *             candidates first, the matches the caller knows to be off the
 *             plane after them;
 *   RANSAC    (ransac.h) over the plane candidates with this module's
 *             callbacks: the 3-point solver (homography.h), the inlier
 *             count with a bail-out test, a tie-break cost and the LO step;
 *   reselect  up to SPVS_REFIT_ROUNDS rounds of the joint linear fit on the
 *             inliers and a new inlier set under it, until the set stops
 *             changing;
 *   refit     SPVS_FINAL_STEPS reweighted steps on the final set, kept only
 *             where they lower its summed Sampson error.
 *
 * Error: Sampson's first-order geometric error (Hartley and Zisserman,
 * section 4.2.6) of the planar-motion H, which weighs the noise of both
 * images, against the caller's threshold in pixels; the fits minimise it
 * with the Sampson weights of a reference H (docs/ESTIMATION.md).
 *
 * Bounds: RANSAC's (ransac.h: min(adaptive count, max_iters) hypotheses,
 * each scored once over at most n points, at most one LO step of two
 * linear fits on SPVS_LO_POINTS points each), then SPVS_REFIT_ROUNDS
 * rounds of one 6x6 solve and one pass over the points, and one
 * Gauss-Newton step (two passes).
 *
 * The work struct is plain data the caller owns (it is part of spvs_t);
 * its size does not depend on the point layout (points.c).
 */
#ifndef SPVS_PLANE_H_H
#define SPVS_PLANE_H_H

#include "spvs/common.h"
#include "spvs/ransac.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The sums of the joint linear fit (the re-selection's normal equations),
 * the last of them the summed squared Sampson error at the weights' H. */
#define SPVS_H_LIN_SUMS 25
#define SPVS_H_LIN_COST 24

/* A frame's points, scaled units, in the build's layout (rows or columns:
 * points.h reads them). */
typedef struct {
    spvs_real v[4u * SPVS_MAX_MATCHES];
    /* The largest |x_cur| and |y_cur| of the frame, scaled units: they
     * bound the Sampson error's Jacobian (points.c). */
    spvs_real cur_max[2];
} spvs_point_store_t;

typedef struct {
    spvs_point_store_t pts;
    /* Points 0..n_plane are the plane candidates, n_plane..n_pts the
     * matches the caller knows to be off the plane; feat[i] is point i's
     * target-image feature. */
    uint16_t n_pts;
    uint16_t n_plane;
    uint16_t feat[SPVS_MAX_MATCHES];
    /* The estimate: H_cur_tgt in scaled units, its inliers among the plane
     * candidates (mask[i] = 1) and their count. */
    spvs_real H_sc[9];
    uint8_t mask[SPVS_MAX_MATCHES];
    uint16_t n_inliers;
    /* Work: RANSAC's index scratch (also the load order), the second mask,
     * the LO step's mask over the first SPVS_LO_POINTS points, the joint
     * linear fit's weight model and sums, the squared threshold. */
    uint16_t idx[SPVS_MAX_MATCHES];
    uint8_t idx_mask[SPVS_MAX_MATCHES];
    uint8_t lo_mask[SPVS_LO_POINTS];
    spvs_real lin_hw[9];
    spvs_real lin_sums[SPVS_H_LIN_SUMS];
    spvs_real t2;
} spvs_plane_h_t;

/* The fixed-point core's estimator (fixed/plane_h_q.h) and its block
 * floating-point scalar (fixed/q.h): load and estimate are written once
 * (plane_h.inc) and declared for both cores, the float one first.  The Q
 * estimator holds H in Q27 scaled units (h22 = 1). */
typedef struct spvs_q_plane_h spvs_q_plane_h_t;
typedef struct spvs_qf spvs_qf_t;

/* Loads a frame: m[0..n) in centred pixels.  order: NULL when every match
 * is a plane candidate (n_plane = n); else n indices into m, the plane
 * candidates' first (order[0..n_plane), in input order) and the others'
 * after them.  order may be e->idx.  The plane candidates are stored in a
 * spread order, slot k holding the (k stride mod n_plane)-th of them with
 * stride near 0.618 n_plane and coprime with it: matches often come sorted
 * by image position or by object, so mismatches come in runs, and the
 * inlier count's bail-out test needs every stretch of the stored order to
 * look like the whole.
 * Returns spvs_match_list_check's statuses, SPVS_E_NONFINITE (a NaN or
 * infinite coordinate), SPVS_E_RANGE (|coordinate| > SPVS_MAX_COORD_PX or a
 * feature index >= SPVS_MAX_FEATURES) or SPVS_E_TOO_FEW (fewer than
 * SPVS_MIN_INLIERS plane candidates); where a frame has several bad values,
 * the first one's (match by match, each coordinate's NaN before its
 * range), the same in both cores.  Bound: n matches, twice for a bad
 * frame. */
SPVS_NODISCARD int spvs_plane_h_load(spvs_plane_h_t *e, const spvs_match_t *m, uint16_t n,
                                     const uint16_t *order, uint16_t n_plane);
SPVS_NODISCARD int spvs_q_plane_h_load(spvs_q_plane_h_t *e, const spvs_match_t *m, uint16_t n,
                                       const uint16_t *order, uint16_t n_plane);

/* Estimates H on the loaded plane candidates: RANSAC (inlier threshold
 * inlier_px pixels on the Sampson error, confidence in (0, 1), at most max_iters <=
 * SPVS_RANSAC_MAX_ITERS hypotheses, samples drawn from rng), the
 * re-selection and the final refit.  On success e->H_sc, e->mask and
 * e->n_inliers hold the estimate.  *iters: hypotheses tried (also on
 * failure).
 * Returns SPVS_OK, SPVS_E_DEGENERATE (every sample degenerate) or
 * SPVS_E_NO_CONSENSUS (fewer than SPVS_MIN_INLIERS inliers), and
 * SPVS_E_ARG for options out of range.  The Q estimate takes the squared
 * threshold t2 in scaled units (spvs_q_t2_from_real, or the fixed build's
 * own from noise_px) and the confidence in units of 2^-32. */
SPVS_NODISCARD int spvs_plane_h_estimate(spvs_plane_h_t *e, spvs_real inlier_px,
                                         spvs_real confidence, uint32_t max_iters,
                                         spvs_rng_t *rng, uint32_t *iters);
SPVS_NODISCARD int spvs_q_plane_h_estimate(spvs_q_plane_h_t *e, spvs_qf_t t2,
                                           uint32_t confidence_q32, uint32_t max_iters,
                                           spvs_rng_t *rng, uint32_t *iters);

/* Takes H_sc (scaled units, planar form) as the estimate of the loaded
 * frame instead of estimating it: e->mask and e->n_inliers get its inliers
 * among the plane candidates (Sampson error within inlier_px pixels).  Returns SPVS_OK,
 * SPVS_E_DEGENERATE (a non-finite H_sc) or SPVS_E_NO_CONSENSUS (fewer than
 * SPVS_MIN_INLIERS inliers); e->H_sc is set in every case but the first
 * error. */
SPVS_NODISCARD int spvs_plane_h_adopt(spvs_plane_h_t *e, const spvs_real H_sc[9],
                                      spvs_real inlier_px);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_PLANE_H_H */
