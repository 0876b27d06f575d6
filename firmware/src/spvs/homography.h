/*
 * homography.h - the planar-motion homography: 3-point minimal solver, the
 * linear fit, the inverse and the pixel scaling (paper, section 2, eqs. (2),
 * (4), (5)).
 *
 * Under planar motion H_cur_tgt = [[h11 h12 h13],[0 1 0],[h31 h32 h33]]
 * (eq. 4), stored row-major in 9 scalars with H[4] = h22 = 1 and H[3] = H[5] = 0.
 * Six unknowns, so three matches fix it.  Each match gives
 *     y_cur * (h31 x_tgt + h32 y_tgt + h33) = y_tgt                 (row 3)
 *     x_cur * (h31 x_tgt + h32 y_tgt + h33) = h11 x_tgt + h12 y_tgt + h13
 * so the 6x6 system is block triangular: the three y-equations give row 3, then
 * the x-equations give row 1 with the same 3x3 matrix [x_tgt y_tgt 1].
 *
 * Points passed to these functions are in the core's scaled units (pixels
 * divided by SPVS_COORD_SCALE); an isotropic scaling keeps the (0,1,0) row.
 * A point is a row of 4 scalars: x_tgt, y_tgt, x_cur, y_cur.  The robust
 * estimator built on these (RANSAC, LO step, inlier re-selection) is
 * plane_h.h.
 */
#ifndef SPVS_HOMOGRAPHY_H
#define SPVS_HOMOGRAPHY_H

#include "spvs/common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Index of each entry of H in the row-major array. */
enum { SPVS_H11 = 0, SPVS_H12 = 1, SPVS_H13 = 2, SPVS_H22 = 4,
       SPVS_H31 = 6, SPVS_H32 = 7, SPVS_H33 = 8 };

/* Solve H from three matches (minimal solver).
 * pts:   3 points (x_tgt, y_tgt, x_cur, y_cur), scaled units.
 * H_out: 9 scalars, planar form, h22 = 1.
 * Returns SPVS_OK, or SPVS_E_DEGENERATE when the target points are (nearly)
 * collinear, a y-equation carries no information (all on the horizon), or the
 * solution is non-finite or maps a sample point behind the camera. */
SPVS_NODISCARD int spvs_h_solve3(const spvs_real pts[3][4], spvs_real H_out[9]);

/* Squared transfer error in the current image, scaled units squared:
 * |p_cur - dehom(H p_tgt)|^2.  Returns a negative value when H p_tgt has a
 * non-positive third coordinate (the point would be behind the camera). */
spvs_real spvs_h_transfer_err2(const spvs_real H[9], const spvs_real pt[4]);

/* Weighted linear least-squares fit of H on the points flagged in `use`
 * (nonzero entries), using the block structure: row 3 from the y-equations
 * weighted by 1 / w0^2 (w0 the third coordinate of H p_tgt under the H
 * passed in, so the residual is the y transfer error at w0), then row 1 from
 * the x-equations, whose weighted residual is exactly the x transfer error.
 * Cheap (two 3x3 solves).
 * pts: n points, scaled units; use: n flags; H: weights in, result out.
 * Returns SPVS_OK, SPVS_E_TOO_FEW (fewer than 3 flagged points) or
 * SPVS_E_DEGENERATE (a flagged point behind the camera under the weights,
 * or a singular system); on error H is unchanged. */
SPVS_NODISCARD int spvs_h_fit_linear(const spvs_real (*pts)[4], const uint8_t *use,
                                     uint16_t n, spvs_real H[9]);

/* H^-1 normalised to h22 = 1 (the inverse of a planar-motion H has the
 * same form).  Returns SPVS_OK, or SPVS_E_DEGENERATE when
 * |h11 h33 - h13 h31| <= 1e-9 (Hi unchanged). */
SPVS_NODISCARD int spvs_h_inverse(const spvs_real H[9], spvs_real Hi[9]);

/* Convert H between scaled units and pixels: H_px = S H_scaled S^-1 with
 * S = diag(s, s, 1), so h13 *= s and h31, h32 /= s.  scale = SPVS_COORD_SCALE
 * goes from scaled to pixels, 1/SPVS_COORD_SCALE back. */
void spvs_h_rescale(spvs_real H[9], spvs_real scale);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_HOMOGRAPHY_H */
