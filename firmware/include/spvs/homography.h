/*
 * homography.h - the planar-motion homography: 3-point minimal solver and the
 * least-squares refit on inliers (paper, section 2, eqs. (2), (4), (5)).
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
 * A point is 4 scalars: x_tgt, y_tgt, x_cur, y_cur.
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

/* The same on the sample idx[0..2] of a larger set of points, read in
 * place: from rows pts[i] = (x_tgt, y_tgt, x_cur, y_cur), or from columns,
 * point i being (cols[0][i], cols[1][i], cols[2][i], cols[3][i]).  The
 * results are the same bits as spvs_h_solve3 on a copy of the three points. */
SPVS_NODISCARD int spvs_h_solve3_rows(const spvs_real (*pts)[4], const uint16_t idx[3],
                                      spvs_real H_out[9]);
SPVS_NODISCARD int spvs_h_solve3_cols(const spvs_real *const cols[4], const uint16_t idx[3],
                                      spvs_real H_out[9]);

/* Squared transfer error in the current image, scaled units squared:
 * |p_cur - dehom(H p_tgt)|^2.  Returns a negative value when H p_tgt has a
 * non-positive third coordinate (the point would be behind the camera). */
spvs_real spvs_h_transfer_err2(const spvs_real H[9], const spvs_real pt[4]);

/* Least-squares refit of H on the points flagged in `use` (nonzero entries),
 * minimising the sum of squared transfer errors in the current image
 * (Gauss-Newton from the given H, reusing the normal matrix of the first
 * step while the steps stay small, rebuilt after a step that halves the
 * cost; stops when a step gains under 1e-4 of the cost or raises it, which
 * is undone).
 * pts: n points, scaled units; use: n flags; H: start value in, result out.
 * max_iters: Gauss-Newton steps at most, clamped to 1..SPVS_REFIT_MAX_ITERS.
 * Returns SPVS_OK, SPVS_E_TOO_FEW (fewer than 3 flagged points) or
 * SPVS_E_DEGENERATE (singular normal equations); on error H is unchanged. */
SPVS_NODISCARD int spvs_h_refit(const spvs_real (*pts)[4], const uint8_t *use,
                                uint16_t n, uint16_t max_iters, spvs_real H[9]);

/* Weighted linear least-squares fit of H on the flagged points, using the
 * block structure: row 3 from the y-equations weighted by 1 / w0^2 (w0 the
 * third coordinate of H p_tgt under the H passed in, so the residual is the
 * y transfer error at w0), then row 1 from the x-equations, whose weighted
 * residual is exactly the x transfer error.  Cheap (two 3x3 solves); used to
 * polish RANSAC hypotheses.  H: weights in, result out.
 * Returns SPVS_OK, SPVS_E_TOO_FEW or SPVS_E_DEGENERATE (H unchanged). */
SPVS_NODISCARD int spvs_h_fit_linear(const spvs_real (*pts)[4], const uint8_t *use,
                                     uint16_t n, spvs_real H[9]);

/* spvs_h_fit_linear and spvs_h_refit on points held in four columns
 * (x_tgt, y_tgt, x_cur, y_cur): point i is (cols[0][i], ..., cols[3][i]).
 * Where SPVS_SIMD_COLUMNS is 1 the sums run on SIMD lanes.  Both layouts
 * give bit-identical results: every sum runs in the same four interleaved
 * lanes (point i in lane i mod 4, each in point order, added pairwise at the
 * end) whatever the layout or target. */
SPVS_NODISCARD int spvs_h_fit_linear_cols(const spvs_real *const cols[4], const uint8_t *use,
                                          uint16_t n, spvs_real H[9]);
SPVS_NODISCARD int spvs_h_refit_cols(const spvs_real *const cols[4], const uint8_t *use,
                                     uint16_t n, uint16_t max_iters, spvs_real H[9]);

/* Joint linear fit at fixed weights, kept as sums that follow the set.
 *
 * Rows 1 and 3 of H at once by least squares on the x- and y-equations
 * above, each divided by w0 = h3w . p_tgt, the third coordinate under a
 * fixed weight model Hw (near the solution w / w0 is near 1, so the
 * residuals are close to the transfer errors).  The fit is solved as a step
 * from Hw, whose residuals the sums hold, so that float rounding in the
 * sums only scales the step.  Its normal equations are SPVS_H_LIN_SUMS sums
 * over the flagged points of terms that depend only on the point and Hw:
 * when the flagged set changes by a few points they are updated by adding
 * and removing those points' terms instead of summed again.  Their normal
 * matrix is the Gauss-Newton one of spvs_h_refit with the measured
 * (x_cur, y_cur) in place of the predicted and w0 in place of w, which
 * spvs_h_refit_lin uses near the solution.
 *
 * spvs_h_lin_sums: the sums over the flagged points (rows or columns, the
 *   same bits either way, as in spvs_h_refit_cols).  Returns SPVS_OK,
 *   SPVS_E_TOO_FEW (fewer than 3 flagged points) or SPVS_E_DEGENERATE (a
 *   flagged point has w0 <= 1e-6); on error sums is unchanged.
 * spvs_h_lin_update: adds (add != 0) or removes point pt's terms.  Returns
 *   SPVS_OK, or SPVS_E_DEGENERATE when pt has w0 <= 1e-6 (sums unchanged).
 * spvs_h_lin_solve: the fit of the sums (made with Hw) as H: Hw with rows 1
 *   and 3 moved by the solution.  Returns SPVS_OK, or SPVS_E_DEGENERATE
 *   (normal matrix not positive definite, or a non-finite result; H
 *   unchanged).
 * spvs_h_refit_lin: spvs_h_refit whose first Gauss-Newton step takes the
 *   normal matrix of `sums` (made on the same flagged points) and sums only
 *   the gradient and the cost at H: 7 terms per point instead of 25. */
#define SPVS_H_LIN_SUMS 24
SPVS_NODISCARD int spvs_h_lin_sums(const spvs_real (*pts)[4], const uint8_t *use, uint16_t n,
                                   const spvs_real Hw[9], spvs_real sums[SPVS_H_LIN_SUMS]);
SPVS_NODISCARD int spvs_h_lin_sums_cols(const spvs_real *const cols[4], const uint8_t *use,
                                        uint16_t n, const spvs_real Hw[9],
                                        spvs_real sums[SPVS_H_LIN_SUMS]);
SPVS_NODISCARD int spvs_h_lin_update(const spvs_real Hw[9], const spvs_real pt[4], int add,
                                     spvs_real sums[SPVS_H_LIN_SUMS]);
SPVS_NODISCARD int spvs_h_lin_solve(const spvs_real sums[SPVS_H_LIN_SUMS], const spvs_real Hw[9],
                                    spvs_real H[9]);
SPVS_NODISCARD int spvs_h_refit_lin(const spvs_real (*pts)[4], const uint8_t *use, uint16_t n,
                                    uint16_t max_iters, const spvs_real sums[SPVS_H_LIN_SUMS],
                                    spvs_real H[9]);
SPVS_NODISCARD int spvs_h_refit_lin_cols(const spvs_real *const cols[4], const uint8_t *use,
                                         uint16_t n, uint16_t max_iters,
                                         const spvs_real sums[SPVS_H_LIN_SUMS], spvs_real H[9]);

/* Convert H between scaled units and pixels: H_px = S H_scaled S^-1 with
 * S = diag(s, s, 1), so h13 *= s and h31, h32 /= s.  scale = SPVS_COORD_SCALE
 * goes from scaled to pixels, 1/SPVS_COORD_SCALE back. */
void spvs_h_rescale(spvs_real H[9], spvs_real scale);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_HOMOGRAPHY_H */
