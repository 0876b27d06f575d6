/*
 * points.h - the frame's points in the build's layout, and every loop that
 * reads many of them (private to the core: not installed, not in the API).
 *
 * The estimator keeps a frame's points in a spvs_point_store_t
 * (plane_h.h).  How they lie in it is the build's choice of one
 * translation unit (firmware/CMakeLists.txt):
 *   points.c                 rows, point i is v[4 i .. 4 i + 3] =
 *                            (x_tgt, y_tgt, x_cur, y_cur), read one point
 *                            at a time (the reference: the Cortex-M
 *                            images, and every build with SPVS_ACCEL=OFF);
 *   accel/points_columns.c   columns, coordinate k of point i is
 *                            v[k SPVS_MAX_MATCHES + i], read SPVS_VLANES
 *                            points at a time on SIMD lanes (hosts with
 *                            SSE2 or NEON).
 * Nothing else knows which.  Every loop here adds its terms in the same
 * order either way (points.inc), so both give the same bits.
 *
 * Points are in the core's scaled units (pixels / SPVS_COORD_SCALE).
 */
#ifndef SPVS_POINTS_H
#define SPVS_POINTS_H

#include <stddef.h>

#include "spvs/plane_h.h"

/* Where a sum reads its points: n rows given by the caller (the public
 * homography API), or a point store (the estimator).  Exactly one is set. */
typedef struct {
    const spvs_real (*rows)[4];
    const spvs_point_store_t *store;
} spvs_pts_in_t;

/* The terms one point adds to a sum (the point arithmetic of
 * h_point.inc, which only points.c includes):
 *   SPVS_T_FIT_Y  linear fit, row 3 at the weights of H (9 terms);
 *   SPVS_T_FIT_X  linear fit, row 1 given row 3 (9 terms);
 *   SPVS_T_LIN    joint linear fit at the Sampson weights of H
 *                 (SPVS_H_LIN_SUMS);
 *   SPVS_T_SAMPSON  the squared Sampson error (1). */
typedef enum {
    SPVS_T_FIT_Y,
    SPVS_T_FIT_X,
    SPVS_T_LIN,
    SPVS_T_SAMPSON
} spvs_terms_t;

#define SPVS_NT_FIT 9
#define SPVS_NT_SAMPSON 1

/* A point's third coordinate H p_tgt must exceed this to be in front. */
#define SPVS_W_EPS SPVS_R(1.0e-6)

/* Sums the `kind` terms of the first n points flagged in use[] under H into
 * out[].  Returns the number of flagged points for SPVS_T_FIT_Y and
 * SPVS_T_LIN (0 for the other kinds), or -1 when a flagged point has
 * w <= SPVS_W_EPS.  Bound: n points. */
int32_t spvs_pts_sum(spvs_terms_t kind, const spvs_real H[9], const spvs_pts_in_t *in,
                     const uint8_t *use, uint16_t n, spvs_real *out);

/* Adds the SPVS_T_LIN terms of one point pt (a row) to acc (add != 0) or
 * removes them.  Returns 0 when the point has w <= SPVS_W_EPS (acc
 * unchanged), 1 otherwise. */
int spvs_pts_lin_move(const spvs_real H[9], const spvs_real pt[4], int add,
                      spvs_real acc[SPVS_H_LIN_SUMS]);

/* A stride for storing n matches in a spread order: near 0.618 n and
 * coprime with n (spvs_pts_load's stride; the Q loader takes the same),
 * so that r -> (r * stride) mod n is a permutation that puts
 * neighbouring matches far apart.  Bound: SPVS_SPREAD_TRIES candidates, each
 * tested by at most SPVS_GCD_STEPS steps of Euclid's algorithm (enough for any
 * 16-bit pair); 1 (the input order) if none passes. */
#define SPVS_SPREAD_TRIES 16
#define SPVS_GCD_STEPS 32
static inline uint16_t spvs_pts_spread_stride(uint16_t n)
{
    uint32_t p = ((uint32_t)n * 40503u) >> 16;
    for (int t = 0; t < SPVS_SPREAD_TRIES && p > 1u; t++, p--) {
        uint32_t a = n;
        uint32_t b = p;
        for (int k = 0; k < SPVS_GCD_STEPS && b != 0u; k++) {
            const uint32_t r = a % b;
            a = b;
            b = r;
        }
        if (a == 1u && b == 0u) {
            return (uint16_t)p;
        }
    }
    return 1u;
}

/* Copies n matches into the store in scaled units: slot k takes match
 * src(k), where src(k) for k < n_plane is the k-th of the sequence
 * p_0 = 0, p_{k+1} = (p_k + stride) mod n_plane mapped through order[] (or
 * itself when order is NULL), and for k >= n_plane it is order[k].  The
 * features go to feat[k], the largest |x_cur|, |y_cur| to st->cur_max.
 * Returns nonzero when a coordinate is not finite
 * or above SPVS_MAX_COORD_PX in magnitude, or a feature index is
 * SPVS_MAX_FEATURES or more (the store is then meaningless).  The checks
 * are made without branches.  Bound: n slots. */
int32_t spvs_pts_load(spvs_point_store_t *st, uint16_t *feat, const spvs_match_t *m, uint16_t n,
                      uint16_t n_plane, const uint16_t *order, uint16_t stride);

/* Point i as a row (x_tgt, y_tgt, x_cur, y_cur). */
void spvs_pts_row(const spvs_point_store_t *st, uint16_t i, spvs_real row[4]);

/* The 3-point solver (homography.h, spvs_h_solve3) on points idx[0..2] of
 * the store, read in place: the same bits as on a copy of them. */
SPVS_NODISCARD int spvs_pts_solve3(const spvs_point_store_t *st, const uint16_t idx[3],
                                   spvs_real H_out[9]);

/* Counts the inliers of H among the first n points, marking them in
 * mask[] when it is not NULL: w > 0 and the squared Sampson error at most
 * t2 (h_point.inc, hp_inlier).  Stops early with a
 * count below `need` once `need` cannot be reached, or at the bail-out
 * test: after every SPVS_SCORE_BLOCK points, a count more than
 * SPVS_BAIL_SIGMAS binomial standard deviations below the share need / n
 * of the points seen so far.  Counts, masks and where the tests are made
 * are the same in both layouts.  Bound: n points. */
uint16_t spvs_pts_score(const spvs_point_store_t *st, size_t n, const spvs_real H[9],
                        spvs_real t2, uint16_t need, uint8_t *mask);

/* The summed squared algebraic residual |p_cur w - H p_tgt|^2 of the
 * points flagged in mask[0..n) (H's inliers, as spvs_pts_score marked
 * them): RANSAC's tie-break.  Bound: n. */
spvs_real spvs_pts_cost(const spvs_point_store_t *st, uint16_t n, const spvs_real H[9],
                        const uint8_t *mask);

#endif /* SPVS_POINTS_H */
