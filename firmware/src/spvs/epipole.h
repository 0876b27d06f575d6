/*
 * epipole.h - the epipole in the current image from plane plus parallax
 * (paper, section 3.3), and the parallax magnitude.
 *
 * For a point off the plane of H, with e = K(-R c) the image of the target
 * camera centre in the current image (as a signed 3-vector),
 *     (Z_cur / Z_tgt) p_cur = H p_tgt + gamma e,
 *     gamma = (d + n^T X) / (d Z_tgt),
 * so p_cur, H p_tgt and e are collinear.  Under planar motion e = (e_x, 0, e_z)
 * in centred pixels (the epipole lies on the row y = 0), so each off-plane
 * match gives one line through the epipole.  With gamma > 0 (the off-plane
 * points lie between the target camera and the plane, which the controller
 * assumes and DESIGN.md's scenes satisfy) the line also gives the sign of e:
 * e_z > 0 when the target position is in front of the current camera.
 * On the straight line of step 2 the x of the epipole is
 *     e_x / e_z = alpha_x tan(phi - phi_t).
 *
 * Robustness: a 1-point consensus over the candidates (up to
 * SPVS_EPIPOLE_MAX_HYP candidates' directions are hypotheses, each tested
 * against all n <= SPVS_MAX_OFFPLANE), then the median angle of the
 * supporters around the best hypothesis.  Mismatches among the candidates give
 * lines in random directions and find no support.
 */
#ifndef SPVS_EPIPOLE_H
#define SPVS_EPIPOLE_H

#include "spvs/common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    spvs_real e_x_px;   /* x of the epipole, centred pixels (clamped, see below) */
    spvs_real dir_x;    /* signed direction of (e_x, e_z), unit-free, |.| ~ 1    */
    spvs_real dir_z;    /*   dir_z > 0: the target is in front of the camera     */
    spvs_real parallax_px; /* median |p_cur - H p_tgt| over the supporters, px  */
    uint16_t n_support; /* candidates that agree with the estimate              */
} spvs_epipole_t;

/* Clamp for e_x when the epipole is near infinity (robot side-on to the line). */
#define SPVS_EPIPOLE_MAX_PX SPVS_R(20000.0)

/* Caller-owned scratch for one estimate (kept off the stack, which stays
 * small on the MCU). */
typedef struct {
    spvs_real dx[SPVS_MAX_OFFPLANE];
    spvs_real dz[SPVS_MAX_OFFPLANE];
    spvs_real n2[SPVS_MAX_OFFPLANE];
} spvs_epipole_work_t;

/* Estimate the epipole.
 * H:        homography in scaled units (see homography.h).
 * pts:      all points of the frame, scaled units.
 * cand:     indices of the off-plane candidates (n_cand <= SPVS_MAX_OFFPLANE).
 * cos_tol2: squared sine of the largest angle between a candidate's direction
 *           and the hypothesis for it to support it (e.g. 0.01 for ~5.7 deg).
 * min_support: fewer supporters than this is SPVS_E_NO_PARALLAX.
 * support_out: n_cand bytes (or NULL): 1 where the candidate supports.
 * work:     scratch, see spvs_epipole_work_t.
 * Returns SPVS_OK, SPVS_E_ARG or SPVS_E_NO_PARALLAX (too few candidates or
 * supporters, or all candidates on the horizon row). */
SPVS_NODISCARD int spvs_epipole_estimate(const spvs_real H[9],
                                         const spvs_real (*pts)[4],
                                         const uint16_t *cand, uint16_t n_cand,
                                         spvs_real sin_tol2,
                                         uint16_t min_support,
                                         spvs_epipole_t *out,
                                         uint8_t *support_out,
                                         spvs_epipole_work_t *work);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_EPIPOLE_H */
