/*
 * fit_q.h - the solves of the estimator's linear fits in fixed point
 * (private: not installed, not part of the API; formats and ranges in
 * docs/FIXED.md).
 *
 * The twins of homography.c's spvs_hf_fit_linear and spvs_hf_lin_solve
 * (h_fit.h) on the Q store and the block floating-point sums of
 * spvs_q_pts_sum (points_q.h).  The normal matrices' entries span 40 bits
 * or more (x^2, x and 1 times weights that scale as 1 / w^2), so no one Q
 * format holds them: each system N x = b is equilibrated first by powers
 * of two, N'' = P N P with P = diag(2^-h_i) and N''_ii in [1/2, 2), in
 * Q30 int32; the right side is normalised once into int32 with one block
 * exponent.  The 3 x 3 systems are solved by their adjugate (cofactors
 * exact in int64, one reciprocal of the determinant), the 6 x 6 by a
 * Cholesky factor in Q30 with int64 accumulations and substitutions in
 * int32 blocks; the solution's entries are rounded to Q27 (SPVS_QH).
 * No spvs_qf_t arithmetic.
 *
 * Statuses are float's, with two differences, both documented at their
 * tests: a pivot of the exactly equilibrated matrix D N D,
 * D = diag(N)^-1/2, below 2^-20 (N not positive definite in the
 * precision kept; float's tests are |det| > 1e-7 for the 3 x 3 systems,
 * which is also made here, and a pivot above 1e-12 (1 + N_ii) for the
 * 6 x 6) is SPVS_E_DEGENERATE, and so is an entry of the result outside
 * (-16, 16) (the Q27 range of H; float returns such an H).
 * Only terms 0-8 (SPVS_T_FIT_Y, SPVS_T_FIT_X) or 0-23 (SPVS_T_LIN) of the
 * sums are read: term 24 of SPVS_T_LIN (the Sampson cost) is not used.
 */
#ifndef SPVS_FIXED_FIT_Q_H
#define SPVS_FIXED_FIT_Q_H

#include <stdint.h>

#include "points_q.h"

/* The 3 x 3 solve of a linear-fit pass (homography.c, solve_fit): the
 * system of SPVS_T_FIT_Y or SPVS_T_FIT_X sums (terms 0-5 the upper
 * triangle, 6-8 the right side) into x (Q27).  SPVS_OK, or
 * SPVS_E_DEGENERATE (|det| <= 1e-7 as float's solve3x3, a pivot of the
 * equilibrated matrix below 2^-20, or an entry outside (-16, 16)); x is
 * then unchanged. */
SPVS_NODISCARD int spvs_q_fit_solve(const spvs_q_sums_t *s, int32_t x[3]);

/* spvs_hf_fit_linear on the Q store: row 3 from the SPVS_T_FIT_Y sums at
 * the weights of Hq, then row 1 from the SPVS_T_FIT_X sums under
 * (0, 0, 0, 0, 0, 0, h3).  SPVS_OK; SPVS_E_TOO_FEW (fewer than 3 points
 * used); SPVS_E_DEGENERATE (a used point with w <= SPVS_W_EPS at Hq or at
 * the new row 3, or a system spvs_q_fit_solve refuses).  Row 2 is not
 * touched; on error Hq is unchanged.  Bound: 2 passes over n points. */
SPVS_NODISCARD int spvs_q_fit_linear(const spvs_q_store_t *st, const uint8_t *use, uint16_t n,
                                     int32_t Hq[9]);

/* spvs_hf_lin_solve on SPVS_T_LIN sums made at Hw: the 6 x 6 normal
 * matrix of terms 0-17 (homography.c, unpack_normal) and the right side
 * of terms 18-23 solved for the step d, and Hq = Hw with rows 1 and 3
 * moved by d (h11 h12 h13 += d0 d1 d2, h31 h32 h33 += d3 d4 d5).
 * SPVS_OK, or SPVS_E_DEGENERATE (a pivot of the equilibrated matrix below
 * 2^-20, or an entry of Hq outside (-16, 16)); Hq is then unchanged.  Hq
 * may be Hw. */
SPVS_NODISCARD int spvs_q_lin_solve(const spvs_q_sums_t *s, const int32_t Hw[9], int32_t Hq[9]);

#endif /* SPVS_FIXED_FIT_Q_H */
