/*
 * homography.c - planar-motion homography: 3-point minimal solver, the
 * linear fit and the joint linear fit at Sampson weights (paper, section
 * 2), on rows the caller gives (homography.h) or on the estimator's point
 * store (h_fit.h).
 */
#include <math.h>

#include "core_util.h"
#include "h_fit.h"
#include "spvs/homography.h"

/* A 3x3 determinant this small (scaled units, so entries are O(1)) means the
 * sample is degenerate: collinear target points or a y-row with no content. */
#define DET_EPS SPVS_R(1.0e-7)

/* Solve the 3x3 system A x = b by the adjugate; returns 0 when |det| is
 * below det_eps (relative to nothing: callers keep entries O(1)). */
static int solve3x3(const spvs_real A[3][3], const spvs_real b[3], spvs_real x[3])
{
    spvs_real c00 = A[1][1] * A[2][2] - A[1][2] * A[2][1];
    spvs_real c01 = A[1][2] * A[2][0] - A[1][0] * A[2][2];
    spvs_real c02 = A[1][0] * A[2][1] - A[1][1] * A[2][0];
    spvs_real det = A[0][0] * c00 + A[0][1] * c01 + A[0][2] * c02;
    if (!(SPVS_FABS(det) > DET_EPS)) {
        return 0;
    }
    spvs_real inv = SPVS_R(1.0) / det;
    spvs_real c10 = A[0][2] * A[2][1] - A[0][1] * A[2][2];
    spvs_real c11 = A[0][0] * A[2][2] - A[0][2] * A[2][0];
    spvs_real c12 = A[0][1] * A[2][0] - A[0][0] * A[2][1];
    spvs_real c20 = A[0][1] * A[1][2] - A[0][2] * A[1][1];
    spvs_real c21 = A[0][2] * A[1][0] - A[0][0] * A[1][2];
    spvs_real c22 = A[0][0] * A[1][1] - A[0][1] * A[1][0];
    x[0] = (c00 * b[0] + c10 * b[1] + c20 * b[2]) * inv;
    x[1] = (c01 * b[0] + c11 * b[1] + c21 * b[2]) * inv;
    x[2] = (c02 * b[0] + c12 * b[1] + c22 * b[2]) * inv;
    return 1;
}

int spvs_h_solve3_strided(const spvs_real *const pc[4], const uint16_t idx[3], uint32_t is,
                          spvs_real H_out[9])
{
#define P3(i, k) (pc[k][(uint32_t)idx[i] * is])
    /* Both 3x3 systems rest on P, the rows (x_tgt, y_tgt, 1) of the three
     * points: the y-equations are D P h3 = y_tgt with D = diag(y_cur), the
     * x-equations P h1 = x_cur w.  So one adjugate of P serves both, with
     * adj(D P) = adj(P) adj(D) and det(D P) = det(D) det(P).  c[i][j] is the
     * cofactor of P at (i, j); the third column of P is ones. */
    const spvs_real x0 = P3(0, 0), y0 = P3(0, 1);
    const spvs_real x1 = P3(1, 0), y1 = P3(1, 1);
    const spvs_real x2 = P3(2, 0), y2 = P3(2, 1);
    const spvs_real c[3][3] = {{y1 - y2, x2 - x1, x1 * y2 - x2 * y1},
                               {y2 - y0, x0 - x2, x2 * y0 - x0 * y2},
                               {y0 - y1, x1 - x0, x0 * y1 - x1 * y0}};
    const spvs_real det_p = (c[0][2] + c[1][2]) + c[2][2];
    const spvs_real v0 = P3(0, 3), v1 = P3(1, 3), v2 = P3(2, 3);
    const spvs_real det_y = (v0 * v1) * v2 * det_p;
    /* Collinear target points, or a y-row with no content (y_cur = 0). */
    if (!(SPVS_FABS(det_p) > DET_EPS) || !(SPVS_FABS(det_y) > DET_EPS)) {
        return SPVS_E_DEGENERATE;
    }
    /* Row 3: h3 = adj(P) adj(D) y_tgt / det(D P). */
    const spvs_real by[3] = {(v1 * v2) * y0, (v0 * v2) * y1, (v0 * v1) * y2};
    const spvs_real iy = SPVS_R(1.0) / det_y;
    spvs_real h3[3];
    for (int j = 0; j < 3; j++) {
        h3[j] = (c[0][j] * by[0] + c[1][j] * by[1] + c[2][j] * by[2]) * iy;
    }
    /* Row 1: h1 = adj(P) (x_cur w) / det(P), w = h3 . p_tgt. */
    spvs_real bx[3];
    for (int i = 0; i < 3; i++) {
        const spvs_real w = h3[0] * P3(i, 0) + h3[1] * P3(i, 1) + h3[2];
        /* A plane point seen by both cameras has a positive depth ratio. */
        if (!(w > SPVS_W_EPS)) {
            return SPVS_E_DEGENERATE;
        }
        bx[i] = P3(i, 2) * w;
    }
    const spvs_real ip = SPVS_R(1.0) / det_p;
    spvs_real h1[3];
    for (int j = 0; j < 3; j++) {
        h1[j] = (c[0][j] * bx[0] + c[1][j] * bx[1] + c[2][j] * bx[2]) * ip;
    }
    if (!spvs_finite3x2(h1, h3)) {
        return SPVS_E_DEGENERATE;
    }
    H_out[0] = h1[0];
    H_out[1] = h1[1];
    H_out[2] = h1[2];
    H_out[3] = SPVS_R(0.0);
    H_out[4] = SPVS_R(1.0);
    H_out[5] = SPVS_R(0.0);
    H_out[6] = h3[0];
    H_out[7] = h3[1];
    H_out[8] = h3[2];
    return SPVS_OK;
#undef P3
}

int spvs_h_solve3(const spvs_real pts[3][4], spvs_real H_out[9])
{
    static const uint16_t idx[3] = {0, 1, 2};
    const spvs_real *const c[4] = {&pts[0][0], &pts[0][1], &pts[0][2], &pts[0][3]};
    return spvs_h_solve3_strided(c, idx, 4u, H_out);
}

spvs_real spvs_h_transfer_err2(const spvs_real H[9], const spvs_real pt[4])
{
    spvs_real w = H[6] * pt[0] + H[7] * pt[1] + H[8];
    if (!(w > SPVS_W_EPS)) {
        return SPVS_R(-1.0);
    }
    spvs_real iw = SPVS_R(1.0) / w;
    spvs_real du = (H[0] * pt[0] + H[1] * pt[1] + H[2]) * iw - pt[2];
    spvs_real dv = pt[1] * iw - pt[3];
    return du * du + dv * dv;
}

/* ---- the fits ------------------------------------------------------------
 *
 * Each fit is a few sums over the flagged points (points.h, spvs_pts_sum),
 * then a small solve. */

/* Solves the 3x3 normal equations of a linear-fit pass: s[0..5] the upper
 * triangle of the symmetric matrix, s[6..8] the right side. */
static int solve_fit(const spvs_real s[SPVS_NT_FIT], spvs_real x[3])
{
    const spvs_real A[3][3] = {{s[0], s[1], s[2]}, {s[1], s[3], s[4]}, {s[2], s[4], s[5]}};
    const spvs_real b[3] = {s[6], s[7], s[8]};
    return solve3x3(A, b, x);
}

int spvs_hf_fit_linear(const spvs_pts_in_t *in, const uint8_t *use, uint16_t n, spvs_real H[9])
{
    /* Row 3: sum over the used points of (y_cur (h3 . p) - y_tgt)^2 / w0^2,
     * w0 the current H's third coordinate, is the y transfer error at w0. */
    spvs_real sy[SPVS_NT_FIT];
    const int32_t used = spvs_pts_sum(SPVS_T_FIT_Y, H, in, use, n, sy);
    if (used < 0) {
        return SPVS_E_DEGENERATE;
    }
    if (used < 3) {
        return SPVS_E_TOO_FEW;
    }
    spvs_real h3[3];
    if (!solve_fit(sy, h3)) {
        return SPVS_E_DEGENERATE;
    }
    /* Row 1 given row 3: sum of (h1 . p - x_cur w)^2 / w^2 is exactly the x
     * transfer error. */
    const spvs_real Hw[9] = {0, 0, 0, 0, 0, 0, h3[0], h3[1], h3[2]};
    spvs_real sx[SPVS_NT_FIT];
    if (spvs_pts_sum(SPVS_T_FIT_X, Hw, in, use, n, sx) < 0) {
        return SPVS_E_DEGENERATE;
    }
    spvs_real h1[3];
    if (!solve_fit(sx, h1)) {
        return SPVS_E_DEGENERATE;
    }
    if (!spvs_finite3x2(h1, h3)) {
        return SPVS_E_DEGENERATE;
    }
    H[0] = h1[0];
    H[1] = h1[1];
    H[2] = h1[2];
    H[6] = h3[0];
    H[7] = h3[1];
    H[8] = h3[2];
    return SPVS_OK;
}

int spvs_h_fit_linear(const spvs_real (*pts)[4], const uint8_t *use, uint16_t n,
                      spvs_real H[9])
{
    const spvs_pts_in_t in = {pts, 0};
    return spvs_hf_fit_linear(&in, use, n, H);
}

/* Solve the 6x6 symmetric positive definite system N x = g by Cholesky.
 * Returns 0 when N is not (numerically) positive definite. */
static int cholesky6(spvs_real N[6][6], const spvs_real g[6], spvs_real x[6])
{
    spvs_real L[6][6] = {{0}};
    SPVS_UNROLL
    for (int i = 0; i < 6; i++) {
        SPVS_UNROLL
        for (int j = 0; j <= i; j++) {
            spvs_real s = N[i][j];
            SPVS_UNROLL
            for (int k = 0; k < j; k++) {
                s -= L[i][k] * L[j][k];
            }
            if (i == j) {
                if (!(s > SPVS_R(1.0e-12) * (SPVS_R(1.0) + N[i][i]))) {
                    return 0;
                }
                L[i][i] = SPVS_SQRT(s);
            } else {
                L[i][j] = s / L[j][j];
            }
        }
    }
    spvs_real y[6];
    SPVS_UNROLL
    for (int i = 0; i < 6; i++) {
        spvs_real s = g[i];
        SPVS_UNROLL
        for (int k = 0; k < i; k++) {
            s -= L[i][k] * y[k];
        }
        y[i] = s / L[i][i];
    }
    SPVS_UNROLL
    for (int i = 5; i >= 0; i--) {
        spvs_real s = y[i];
        SPVS_UNROLL
        for (int k = i + 1; k < 6; k++) {
            s -= L[k][i] * x[k];
        }
        x[i] = s / L[i][i];
    }
    return 1;
}

/* The 6x6 normal matrix from the 18 sums laid out as SPVS_T_LIN's terms
 * 0-17: the symmetric 3x3 blocks N11, N13 and N33, each six entries of
 * q = (x^2, x y, x, y^2, y, 1). */
static void unpack_normal(const spvs_real *s, spvs_real N[6][6])
{
    /* Index of (r, c) in q. */
    static const uint8_t qi[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) {
            N[r][c] = s[qi[r][c]];
            N[r][3 + c] = s[6 + qi[r][c]];
            N[3 + r][c] = s[6 + qi[r][c]];
            N[3 + r][3 + c] = s[12 + qi[r][c]];
        }
    }
}

/* Moves rows 1 and 3 of H by the step d = (h11 h12 h13 h31 h32 h33). */
static void add_step(spvs_real H[9], const spvs_real d[6])
{
    H[0] += d[0];
    H[1] += d[1];
    H[2] += d[2];
    H[6] += d[3];
    H[7] += d[4];
    H[8] += d[5];
}

/* ---- the joint linear fit at fixed weights ------------------------------ */

int spvs_hf_lin_sums(const spvs_pts_in_t *in, const uint8_t *use, uint16_t n,
                     const spvs_real Hw[9], spvs_real sums[SPVS_H_LIN_SUMS])
{
    spvs_real t[SPVS_H_LIN_SUMS];
    const int32_t used = spvs_pts_sum(SPVS_T_LIN, Hw, in, use, n, t);
    if (used < 0) {
        return SPVS_E_DEGENERATE;
    }
    if (used < 3) {
        return SPVS_E_TOO_FEW;
    }
    for (int k = 0; k < SPVS_H_LIN_SUMS; k++) {
        sums[k] = t[k];
    }
    return SPVS_OK;
}

int spvs_hf_lin_solve(const spvs_real sums[SPVS_H_LIN_SUMS], const spvs_real Hw[9],
                      spvs_real H[9])
{
    spvs_real N[6][6];
    unpack_normal(sums, N);
    spvs_real d[6];
    if (!cholesky6(N, sums + 18, d) || !spvs_finite3x2(d, d + 3)) {
        return SPVS_E_DEGENERATE;
    }
    for (int k = 0; k < 9; k++) {
        H[k] = Hw[k];
    }
    add_step(H, d);
    return SPVS_OK;
}

int spvs_h_inverse(const spvs_real H[9], spvs_real Hi[9])
{
    /* Planar form: H = [[a b c] [0 1 0] [g h i]]. */
    const spvs_real a = H[0], b = H[1], c = H[2], g = H[6], h = H[7], i = H[8];
    spvs_real det = a * i - c * g;
    if (!(SPVS_FABS(det) > SPVS_R(1.0e-9))) {
        return SPVS_E_DEGENERATE;
    }
    spvs_real id = SPVS_R(1.0) / det;
    Hi[0] = i * id;
    Hi[1] = (c * h - b * i) * id;
    Hi[2] = -c * id;
    Hi[3] = SPVS_R(0.0);
    Hi[4] = SPVS_R(1.0);
    Hi[5] = SPVS_R(0.0);
    Hi[6] = -g * id;
    Hi[7] = (b * g - a * h) * id;
    Hi[8] = a * id;
    return SPVS_OK;
}

void spvs_h_rescale(spvs_real H[9], spvs_real scale)
{
    H[2] *= scale;
    H[6] /= scale;
    H[7] /= scale;
}
