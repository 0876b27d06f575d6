/*
 * h_fit.h - homography.c's fits on either point source (private to the
 * core): the public API of homography.h reads rows the caller gives, the
 * estimator (plane_h.c) its point store (points.h).
 */
#ifndef SPVS_H_FIT_H
#define SPVS_H_FIT_H

#include "points.h"

/* 3-point solver on points given as coordinate k of sample point i at
 * pc[k][idx[i] * is] (homography.c). */
SPVS_NODISCARD int spvs_h_solve3_strided(const spvs_real *const pc[4], const uint16_t idx[3],
                                         uint32_t is, spvs_real H_out[9]);

/* ---- the fits, on either point source (homography.c) ------------------- */

/* spvs_h_fit_linear (homography.h) on a point source. */
SPVS_NODISCARD int spvs_hf_fit_linear(const spvs_pts_in_t *in, const uint8_t *use, uint16_t n,
                                      spvs_real H[9]);

/* Joint linear fit at fixed weights, kept as sums that follow the set.
 *
 * Rows 1 and 3 of H at once by least squares on the algebraic residuals
 * eps = (x_cur h3 . p - h1 . p, y_cur h3 . p - y_tgt), which are linear in
 * them, each match weighted by (J J^T)^-1 at a fixed weight model Hw, J
 * the residuals' Jacobian in the match's four coordinates (h_point.inc):
 * near Hw, eps^T (J J^T)^-1 eps is the match's squared Sampson error, so
 * the fit minimises the Sampson error about Hw.  The fit is solved as a step from Hw,
 * whose residuals the sums hold, so that rounding in the sums only scales
 * the step.  Its normal equations are SPVS_H_LIN_SUMS sums of per-point
 * terms that depend only on the point and Hw: when the flagged set changes
 * by a few points they are moved by adding and removing those points'
 * terms (spvs_pts_lin_move).
 *
 * spvs_hf_lin_sums: the sums over the flagged points.  Returns SPVS_OK,
 *   SPVS_E_TOO_FEW (fewer than 3) or SPVS_E_DEGENERATE (a flagged point
 *   has w0 <= SPVS_W_EPS); on error sums is unchanged.
 * spvs_hf_lin_solve: the fit of the sums (made with Hw) as H: Hw with rows
 *   1 and 3 moved by the solution.  Returns SPVS_OK, or SPVS_E_DEGENERATE
 *   (normal matrix not positive definite, or a non-finite result; H
 *   unchanged). */
SPVS_NODISCARD int spvs_hf_lin_sums(const spvs_pts_in_t *in, const uint8_t *use, uint16_t n,
                                    const spvs_real Hw[9], spvs_real sums[SPVS_H_LIN_SUMS]);
SPVS_NODISCARD int spvs_hf_lin_solve(const spvs_real sums[SPVS_H_LIN_SUMS], const spvs_real Hw[9],
                                     spvs_real H[9]);

#endif /* SPVS_H_FIT_H */
