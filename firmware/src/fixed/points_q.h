/*
 * points_q.h - the estimator's per-point kernels in fixed point (private:
 * not installed, not part of the API; the formats and their ranges are in
 * docs/FIXED.md).
 *
 * The same contracts as the float kernels of points.h, on a Q point store:
 * loading a frame's matches, the Sampson-error inlier count with its early
 * stop and bail-out, RANSAC's tie-break cost, the sums of the linear
 * fits (SPVS_T_FIT_Y, SPVS_T_FIT_X, SPVS_T_LIN, with the re-selection's
 * move of one point) and the summed Sampson error (SPVS_T_SAMPSON).
 * Nothing here reads a float or double except through its bits
 * (fixed/q.h), so the object links no floating-point helper.
 *
 * Formats (value = integer 2^-f):
 *   coordinates  scaled units (pixels / SPVS_COORD_SCALE, as the float
 *                store), int32 Q26 (SPVS_QC): |c| <= SPVS_MAX_COORD_PX /
 *                SPVS_COORD_SCALE <= 16 (checked at compile time), the
 *                loader rejects larger; resolution 2^-26 scaled units
 *                (7.6e-6 px at the default scale 512);
 *   H            scaled units, planar form, int32 Q27 (SPVS_QH): every
 *                entry in (-16, 16); resolution 7.5e-9;
 *   w, h1 . p    exact in int64 Q53 (|.| < 528, no rounding);
 *   residuals, Sampson terms, weights, per-point fit terms: spvs_qf_t
 *                (a 31-bit mantissa with its own exponent), since their
 *                range is unbounded as w -> 0 and grows with |H|;
 *   t2           the squared threshold in scaled units, spvs_qf_t;
 *   cost         uint64 Q52 (SPVS_QCOST), saturating (flagged) at 4096;
 *   sums         block floating point: int64 mantissas with one exponent
 *                per block of terms (spvs_q_sums_t): the normal matrix,
 *                the right side and the Sampson cost each their own.
 * The store is in rows (point i at v[4 i .. 4 i + 3]) on every target:
 * the kernels read one point at a time.
 */
#ifndef SPVS_FIXED_POINTS_Q_H
#define SPVS_FIXED_POINTS_Q_H

#include <stddef.h>
#include <stdint.h>

#include "../points.h"
#include "q.h"

#define SPVS_QC 26
#define SPVS_QH 27
#define SPVS_QCOST 52

SPVS_STATIC_ASSERT((SPVS_COORD_SCALE & (SPVS_COORD_SCALE - 1)) == 0,
               "the Q store scales pixels by a power of two");
SPVS_STATIC_ASSERT(SPVS_MAX_COORD_PX <= 16 * SPVS_COORD_SCALE,
               "scaled coordinates must stay within 16 (Q26 with 2^30 as the bound)");

/* A frame's points in scaled units, Q26, rows; cur_max: the largest |x_cur|
 * and |y_cur| (Q26), which bound the Sampson error's Jacobian; tgt_max:
 * the largest |x_tgt| and |y_tgt|, which with cur_max bound every
 * per-point quantity of a model (the inlier test's per-model scaling). */
typedef struct {
    int32_t v[4u * SPVS_MAX_MATCHES];
    int32_t cur_max[2];
    int32_t tgt_max[2];
} spvs_q_store_t;

/* A sum of per-point terms in block floating point: term k is
 * m[k] 2^e[b], its block b = (k >= split) + (k >= split2), so that each
 * block has its own exponent and a small block keeps its precision beside
 * a large one:
 *   SPVS_T_FIT_Y, SPVS_T_FIT_X  nt = 9: q q^T (0-5), q r (6-8);
 *                 split = 6, split2 = 9 (no block 2);
 *   SPVS_T_LIN    nt = 25: the normal matrix (0-17), the right side
 *                 (18-23), the passed H's summed squared Sampson error
 *                 eps^T W eps (term 24, SPVS_H_LIN_COST, which the final
 *                 refit compares with a candidate's SPVS_T_SAMPSON sum);
 *                 split = 18, split2 = 24;
 *   SPVS_T_SAMPSON  nt = 1: the summed squared Sampson error (term 0);
 *                 split = split2 = 1 (block 0 alone).
 * Every |m[k]| < 2^62; adding a term raises its block's exponent before a
 * mantissa could reach 2^62 (so none overflows however many are added).
 * Read a term with spvs_q_sums_term, which needs no knowledge of the
 * layout. */
typedef struct {
    int64_t m[SPVS_H_LIN_SUMS];
    int32_t e[3];
    uint8_t nt;
    uint8_t split;
    uint8_t split2;
} spvs_q_sums_t;

/* Term k (0 <= k < s->nt) of sums made by spvs_q_pts_sum or moved by
 * spvs_q_lin_move, as a spvs_qf_t (its mantissa rounded to 31 bits:
 * relative error <= 2^-31); 0 for k outside 0..nt-1.  Two terms compare
 * exactly on these values with spvs_qf_le. */
spvs_qf_t spvs_q_sums_term(const spvs_q_sums_t *s, int k);

/* H (scaled units, h22 = 1) from the float build's scalar to Q27, rnd
 * (|error| <= 2^-28).  Returns 0, or SPVS_Q_SAT (an entry outside
 * (-16, 16), clamped) and/or SPVS_Q_NONFINITE: such an H is outside the
 * kernels' range and must not be passed to them. */
SPVS_NODISCARD uint32_t spvs_q_h_from_real(const spvs_real H[9], int32_t Hq[9]);

/* The squared inlier threshold t2 (scaled units^2, spvs_plane_h_t.t2) as a
 * spvs_qf_t.  *sat gets SPVS_Q_NONFINITE for a NaN or infinite t2. */
spvs_qf_t spvs_q_t2_from_real(spvs_real t2, uint32_t *sat);

/* A frame's inlier threshold: t2 (scaled units^2) and, for the count's
 * fast test, T = floor(t 2^26) with t = sqrt(t2) (fast = 0 where t >= 2
 * scaled units, 1,024 px: every point then goes to the exact test).  Made
 * once per frame (one integer square root), read by every model. */
typedef struct {
    spvs_qf_t t2;
    int32_t T;
    int fast;
} spvs_q_thr_t;

spvs_q_thr_t spvs_q_thr(spvs_qf_t t2);

/* spvs_pts_load (points.h) into the Q store: slot k takes match src(k) in
 * the same spread order, coordinates rounded to Q26 scaled units (|error|
 * <= 2^-27 scaled = 3.8e-6 px).  Returns 0, or a nonzero mask of
 * SPVS_Q_NONFINITE (a NaN or infinite coordinate) and SPVS_Q_SAT (a
 * coordinate above SPVS_MAX_COORD_PX in magnitude, or a feature index
 * SPVS_MAX_FEATURES or more); the store is then meaningless.  Bound: n
 * slots. */
uint32_t spvs_q_pts_load(spvs_q_store_t *st, uint16_t *feat, const spvs_match_t *m, uint16_t n,
                         uint16_t n_plane, const uint16_t *order, uint16_t stride);

/* Point i as a row (x_tgt, y_tgt, x_cur, y_cur), Q26. */
void spvs_q_pts_row(const spvs_q_store_t *st, uint16_t i, int32_t row[4]);

/* The 3-point minimal solver (homography.c, spvs_h_solve3_strided) on the
 * Q store's points idx[0..2] (solve3_q.c): H (Q27, h22 = 1) from the two
 * 3 x 3 systems on the target points' cofactors, in integers: det P and the
 * 2 x 2 minors exact in int64, w = y_tgt / y_cur and x_cur w in 31 and 30
 * bits at a scale per row, one reciprocal of det P (error bound in
 * solve3_q.c).  SPVS_OK, or SPVS_E_DEGENERATE for collinear target points
 * (|det P| <= 1e-7), a current y of 0, a point with w <= SPVS_W_EPS,
 * |det(D P)| <= 1e-7, or an entry outside (-16, 16) (the kernels' range; no
 * consensus keeps such a model, docs/FIXED.md); Hq is then unchanged. */
int spvs_q_solve3(const spvs_q_store_t *st, const uint16_t idx[3], int32_t Hq[9]);

/* spvs_pts_score on the Q store: the inliers of Hq (Q27) among the first
 * n points, marked in mask[] when it is not NULL: w > 0 and the squared
 * Sampson error at most thr->t2.  The same early stop (a count below `need`
 * once `need` cannot be reached, tested at every point as in the rows
 * layout) and the same bail-out test after every SPVS_SCORE_BLOCK points,
 * made in integers (exact).  The test's relative error on the squared
 * Sampson error is below 1e-7 (docs/FIXED.md), so only points that close
 * to the threshold can be decided otherwise than by exact arithmetic.
 * Bound: n points. */
uint16_t spvs_q_pts_score(const spvs_q_store_t *st, size_t n, const int32_t Hq[9],
                          const spvs_q_thr_t *thr, uint16_t need, uint8_t *mask);

/* spvs_pts_cost on the Q store: the summed squared algebraic residual
 * |p_cur w - H p_tgt|^2 (scaled units^2) of the points flagged in
 * mask[0..n) (Hq's inliers, as spvs_q_pts_score marked them), uint64 Q52.
 * A sum above 2^12 saturates and ORs SPVS_Q_SAT into *sat.  Bound: n. */
uint64_t spvs_q_pts_cost(const spvs_q_store_t *st, uint16_t n, const int32_t Hq[9],
                         const uint8_t *mask, uint32_t *sat);

/* spvs_pts_sum for kind SPVS_T_FIT_Y, SPVS_T_FIT_X, SPVS_T_LIN or
 * SPVS_T_SAMPSON on the Q store: the terms of the first n points flagged
 * in use[] under Hq into *out (layouts at spvs_q_sums_t).  Returns the
 * number of flagged points for SPVS_T_FIT_Y, SPVS_T_LIN and SPVS_T_SAMPSON
 * (0 for SPVS_T_FIT_X; the float kernel returns 0 for SPVS_T_SAMPSON too,
 * which its callers only test for < 0), -1 when a flagged point has
 * w <= SPVS_W_EPS, or -2 for another kind.  Each term's relative error is
 * at most about 2^-26 and each sum's error at most about 2^-26 of the sum
 * of its terms' magnitudes, except on SPVS_T_LIN's fast path, whose
 * weights keep 2^-20 to 2^-25 of their bound over the frame.
 * SPVS_T_SAMPSON takes that fast path's term 24 where SPVS_T_LIN would
 * (the same bits for the same H and point), and elsewhere num / den with
 * one spvs_qf_t reciprocal and product (relative 2^-26); a sum of
 * positive terms, its arithmetic error is at most that of the fast path's
 * weights, about 1e-6 of the sum (docs/FIXED.md).
 * Bound: n points. */
int32_t spvs_q_pts_sum(spvs_terms_t kind, const int32_t Hq[9], const spvs_q_store_t *st,
                       const uint8_t *use, uint16_t n, spvs_q_sums_t *out);

/* spvs_pts_lin_move on the Q store's sums: adds (add != 0) or removes
 * (add = 0) the 25 SPVS_T_LIN terms of one point p (a row, Q26) under the
 * weight model Hw (Q27) to sums s made by spvs_q_pts_sum(SPVS_T_LIN, Hw,
 * ...).  The terms are those of SPVS_T_LIN's fast path in formats from
 * the point alone where it is in that path's range (docs/FIXED.md), the
 * exact path's elsewhere; each is rounded once to its block's unit
 * (<= 1/2 unit) and added or subtracted as that same integer, so removing
 * a point after adding it gives the sums back bit for bit unless a
 * block's exponent rose in between (a sum reaching 2^62, or a term above
 * the block's unit by 2^30 or more); each such rise rounds that block's
 * sums once more (<= 1/2 unit of the new exponent).  No mantissa reaches
 * 2^62 however many points are added.  Returns 1, or 0 when p has
 * w <= SPVS_W_EPS under Hw (s unchanged). */
int spvs_q_lin_move(const int32_t Hw[9], const int32_t p[4], int add, spvs_q_sums_t *s);

/* 1 when spvs_q_pts_sum's terms of kind (SPVS_T_LIN, SPVS_T_SAMPSON,
 * SPVS_T_FIT_Y or SPVS_T_FIT_X) of the first n points of st under Hq take
 * the fast path on the frame's bounds (docs/FIXED.md; for SPVS_T_LIN and
 * SPVS_T_SAMPSON its points with a residual of 16 px or more still take
 * the exact path), 0 when they do not: a sum then takes its formats from
 * the bounds of its flagged points, or the exact path where those fail
 * too. */
int spvs_q_sum_fast(spvs_terms_t kind, const spvs_q_store_t *st, const int32_t Hq[9],
                    uint16_t n);

#endif /* SPVS_FIXED_POINTS_Q_H */
