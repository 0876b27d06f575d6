/*
 * homography.c - planar-motion homography: 3-point minimal solver and the
 * Gauss-Newton transfer-error refit (paper, section 2).
 */
#include <math.h>

#include "spvs/homography.h"
#include "core_util.h"

/* A 3x3 determinant this small (scaled units, so entries are O(1)) means the
 * sample is degenerate: collinear target points or a y-row with no content. */
#define DET_EPS SPVS_R(1.0e-7)
/* H p_tgt must have a third coordinate above this to be in front. */
#define W_EPS SPVS_R(1.0e-6)

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

int spvs_h_solve3(const spvs_real pts[3][4], spvs_real H_out[9])
{
    spvs_real A[3][3];
    spvs_real b[3];
    spvs_real h3[3];
    spvs_real h1[3];
    spvs_real w[3];

    /* Row 3 from the y-equations: y_cur (h3 . p_tgt) = y_tgt. */
    for (int i = 0; i < 3; i++) {
        A[i][0] = pts[i][3] * pts[i][0];
        A[i][1] = pts[i][3] * pts[i][1];
        A[i][2] = pts[i][3];
        b[i] = pts[i][1];
    }
    if (!solve3x3(A, b, h3)) {
        return SPVS_E_DEGENERATE;
    }
    /* Row 1 from the x-equations: [x_tgt y_tgt 1] h1 = x_cur (h3 . p_tgt). */
    for (int i = 0; i < 3; i++) {
        w[i] = h3[0] * pts[i][0] + h3[1] * pts[i][1] + h3[2];
        /* A plane point seen by both cameras has a positive depth ratio. */
        if (!(w[i] > W_EPS)) {
            return SPVS_E_DEGENERATE;
        }
        A[i][0] = pts[i][0];
        A[i][1] = pts[i][1];
        A[i][2] = SPVS_R(1.0);
        b[i] = pts[i][2] * w[i];
    }
    if (!solve3x3(A, b, h1)) {
        return SPVS_E_DEGENERATE;
    }
    for (int i = 0; i < 3; i++) {
        if (!spvs_is_finite(h1[i]) || !spvs_is_finite(h3[i])) {
            return SPVS_E_DEGENERATE;
        }
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
}

spvs_real spvs_h_transfer_err2(const spvs_real H[9], const spvs_real pt[4])
{
    spvs_real w = H[6] * pt[0] + H[7] * pt[1] + H[8];
    if (!(w > W_EPS)) {
        return SPVS_R(-1.0);
    }
    spvs_real iw = SPVS_R(1.0) / w;
    spvs_real du = (H[0] * pt[0] + H[1] * pt[1] + H[2]) * iw - pt[2];
    spvs_real dv = pt[1] * iw - pt[3];
    return du * du + dv * dv;
}

int spvs_h_fit_linear(const spvs_real (*pts)[4], const uint8_t *use, uint16_t n,
                      spvs_real H[9])
{
    /* Row 3: sum over the used points of (y_cur (h3 . p) - y_tgt)^2 / w0^2,
     * w0 the current H's third coordinate, is the y transfer error at w0. */
    /* Unique entries of the symmetric normal matrices, kept in scalars so
     * that the per-point work stays in registers. */
    spvs_real a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;
    spvs_real b0 = 0, b1 = 0, b2 = 0;
    uint16_t used = 0;
    for (uint16_t i = 0; i < n; i++) {
        if (!use[i]) {
            continue;
        }
        const spvs_real *q = pts[i];
        spvs_real w0 = H[6] * q[0] + H[7] * q[1] + H[8];
        if (!(w0 > W_EPS)) {
            return SPVS_E_DEGENERATE;
        }
        spvs_real iw = SPVS_R(1.0) / w0;
        /* Row r = y_cur (x_tgt, y_tgt, 1) / w0, right side y_tgt / w0. */
        spvs_real r2 = q[3] * iw;
        spvs_real r0 = r2 * q[0];
        spvs_real r1 = r2 * q[1];
        spvs_real rhs = q[1] * iw;
        a00 += r0 * r0;
        a01 += r0 * r1;
        a02 += r0 * r2;
        a11 += r1 * r1;
        a12 += r1 * r2;
        a22 += r2 * r2;
        b0 += r0 * rhs;
        b1 += r1 * rhs;
        b2 += r2 * rhs;
        used++;
    }
    if (used < 3) {
        return SPVS_E_TOO_FEW;
    }
    const spvs_real A[3][3] = {{a00, a01, a02}, {a01, a11, a12}, {a02, a12, a22}};
    const spvs_real b[3] = {b0, b1, b2};
    spvs_real h3[3];
    if (!solve3x3(A, b, h3)) {
        return SPVS_E_DEGENERATE;
    }
    /* Row 1 given row 3: sum of (h1 . p - x_cur w)^2 / w^2 is exactly the x
     * transfer error. */
    spvs_real c00 = 0, c01 = 0, c02 = 0, c11 = 0, c12 = 0, c22 = 0;
    spvs_real d0 = 0, d1 = 0, d2 = 0;
    for (uint16_t i = 0; i < n; i++) {
        if (!use[i]) {
            continue;
        }
        const spvs_real *q = pts[i];
        spvs_real w = h3[0] * q[0] + h3[1] * q[1] + h3[2];
        if (!(w > W_EPS)) {
            return SPVS_E_DEGENERATE;
        }
        spvs_real iw = SPVS_R(1.0) / w;
        spvs_real p0 = q[0] * iw;
        spvs_real p1 = q[1] * iw;
        spvs_real p2 = iw;
        spvs_real rhs = q[2];
        c00 += p0 * p0;
        c01 += p0 * p1;
        c02 += p0 * p2;
        c11 += p1 * p1;
        c12 += p1 * p2;
        c22 += p2 * p2;
        d0 += p0 * rhs;
        d1 += p1 * rhs;
        d2 += p2 * rhs;
    }
    const spvs_real B[3][3] = {{c00, c01, c02}, {c01, c11, c12}, {c02, c12, c22}};
    const spvs_real c[3] = {d0, d1, d2};
    spvs_real h1[3];
    if (!solve3x3(B, c, h1)) {
        return SPVS_E_DEGENERATE;
    }
    for (int k = 0; k < 3; k++) {
        if (!spvs_is_finite(h1[k]) || !spvs_is_finite(h3[k])) {
            return SPVS_E_DEGENERATE;
        }
    }
    H[0] = h1[0];
    H[1] = h1[1];
    H[2] = h1[2];
    H[6] = h3[0];
    H[7] = h3[1];
    H[8] = h3[2];
    return SPVS_OK;
}

/* Solve the 6x6 symmetric positive definite system N x = g by Cholesky.
 * Returns 0 when N is not (numerically) positive definite. */
static int cholesky6(spvs_real N[6][6], const spvs_real g[6], spvs_real x[6])
{
    spvs_real L[6][6] = {{0}};
    for (int i = 0; i < 6; i++) {
        for (int j = 0; j <= i; j++) {
            spvs_real s = N[i][j];
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
    for (int i = 0; i < 6; i++) {
        spvs_real s = g[i];
        for (int k = 0; k < i; k++) {
            s -= L[i][k] * y[k];
        }
        y[i] = s / L[i][i];
    }
    for (int i = 5; i >= 0; i--) {
        spvs_real s = y[i];
        for (int k = i + 1; k < 6; k++) {
            s -= L[k][i] * x[k];
        }
        x[i] = s / L[i][i];
    }
    return 1;
}

/* One pass over the used points at H: the summed squared transfer error
 * (returned; SPVS_REAL_MAX when a point is behind the camera) and the
 * Gauss-Newton normal equations N d = g for theta = (h11 h12 h13 h31 h32 h33)
 * with residuals r_x = (h1 . p) / w - x_cur, r_y = y_tgt / w - y_cur,
 * w = h3 . p.  With u = (h1 . p) / w and v = y_tgt / w the Jacobian rows are
 * d r_x = [p / w, -u p / w] and d r_y = [0, -v p / w], so every block of N
 * is a weighted sum of p p^T:
 *   N11 = sum p p^T / w^2, N13 = -sum u p p^T / w^2,
 *   N33 = sum (u^2 + v^2) p p^T / w^2,
 * and only the six distinct entries of p p^T are accumulated, per weight. */
static spvs_real refit_pass(const spvs_real (*pts)[4], const uint8_t *use, uint16_t n,
                            const spvs_real H[9], spvs_real N[6][6], spvs_real g[6])
{
    /* q = (x^2, x y, x, y^2, y, 1) */
    spvs_real S1[6] = {0}, S2[6] = {0}, S3[6] = {0};
    spvs_real G1[3] = {0}, G3[3] = {0};
    spvs_real cost = SPVS_R(0.0);
    for (uint16_t i = 0; i < n; i++) {
        if (!use[i]) {
            continue;
        }
        const spvs_real *q = pts[i];
        const spvs_real x = q[0], y = q[1];
        spvs_real w = H[6] * x + H[7] * y + H[8];
        if (!(w > W_EPS)) {
            return SPVS_REAL_MAX;
        }
        spvs_real iw = SPVS_R(1.0) / w;
        spvs_real u = (H[0] * x + H[1] * y + H[2]) * iw;
        spvs_real v = y * iw;
        spvs_real rx = u - q[2];
        spvs_real ry = v - q[3];
        cost += rx * rx + ry * ry;
        spvs_real iw2 = iw * iw;
        spvs_real a1 = iw2;
        spvs_real a2 = -u * iw2;
        spvs_real a3 = (u * u + v * v) * iw2;
        spvs_real b1 = -rx * iw;
        spvs_real b3 = (u * rx + v * ry) * iw;
        const spvs_real xx = x * x, xy = x * y, yy = y * y;
        S1[0] += a1 * xx;
        S1[1] += a1 * xy;
        S1[2] += a1 * x;
        S1[3] += a1 * yy;
        S1[4] += a1 * y;
        S1[5] += a1;
        S2[0] += a2 * xx;
        S2[1] += a2 * xy;
        S2[2] += a2 * x;
        S2[3] += a2 * yy;
        S2[4] += a2 * y;
        S2[5] += a2;
        S3[0] += a3 * xx;
        S3[1] += a3 * xy;
        S3[2] += a3 * x;
        S3[3] += a3 * yy;
        S3[4] += a3 * y;
        S3[5] += a3;
        G1[0] += b1 * x;
        G1[1] += b1 * y;
        G1[2] += b1;
        G3[0] += b3 * x;
        G3[1] += b3 * y;
        G3[2] += b3;
    }
    /* Unpack the symmetric 3x3 blocks: index of (r, c) in q. */
    static const uint8_t qi[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) {
            N[r][c] = S1[qi[r][c]];
            N[r][3 + c] = S2[qi[r][c]];
            N[3 + r][c] = S2[qi[r][c]];
            N[3 + r][3 + c] = S3[qi[r][c]];
        }
        g[r] = G1[r];
        g[3 + r] = G3[r];
    }
    return cost;
}

/* The summed squared transfer error of the used points at H, alone (the
 * check of a last Gauss-Newton step needs no normal equations);
 * SPVS_REAL_MAX when a point is behind the camera. */
static spvs_real refit_cost(const spvs_real (*pts)[4], const uint8_t *use, uint16_t n,
                            const spvs_real H[9])
{
    spvs_real cost = SPVS_R(0.0);
    for (uint16_t i = 0; i < n; i++) {
        if (!use[i]) {
            continue;
        }
        spvs_real e2 = spvs_h_transfer_err2(H, pts[i]);
        if (e2 < SPVS_R(0.0)) {
            return SPVS_REAL_MAX;
        }
        cost += e2;
    }
    return cost;
}

int spvs_h_refit(const spvs_real (*pts)[4], const uint8_t *use, uint16_t n,
                 uint16_t max_iters, spvs_real H[9])
{
    if (max_iters < 1u) {
        max_iters = 1u;
    }
    if (max_iters > SPVS_REFIT_MAX_ITERS) {
        max_iters = SPVS_REFIT_MAX_ITERS;
    }
    uint16_t used = 0;
    for (uint16_t i = 0; i < n; i++) {
        used = (uint16_t)(used + (use[i] ? 1u : 0u));
    }
    if (used < 3) {
        return SPVS_E_TOO_FEW;
    }

    spvs_real Hc[9];
    spvs_real Hprev[9];
    for (int k = 0; k < 9; k++) {
        Hc[k] = H[k];
        Hprev[k] = H[k];
    }
    spvs_real N[6][6];
    spvs_real g[6];
    spvs_real prev = SPVS_REAL_MAX;
    int have = 0;
    /* Each pass evaluates the cost of the last step and linearises there.
     * A step that raises the cost is undone and ends the refit; so does a
     * relative improvement under 1e-4 (a Gauss-Newton from a RANSAC start
     * gets there in one or two steps).  The pass after the last step only
     * evaluates the cost.  Bound: max_iters + 1 <= SPVS_REFIT_MAX_ITERS + 1
     * passes. */
    for (uint16_t it = 0; it <= max_iters; it++) {
        spvs_real cost = it < max_iters ? refit_pass(pts, use, n, Hc, N, g)
                                        : refit_cost(pts, use, n, Hc);
        if (!(cost <= prev)) {
            for (int k = 0; k < 9; k++) {
                Hc[k] = Hprev[k];
            }
            break;
        }
        have = 1;
        int small = (prev - cost) <= SPVS_R(1.0e-4) * cost;
        prev = cost;
        if (small || it == max_iters) {
            break;
        }
        spvs_real d[6];
        if (!cholesky6(N, g, d)) {
            if (it == 0) {
                return SPVS_E_DEGENERATE;
            }
            break;
        }
        for (int k = 0; k < 9; k++) {
            Hprev[k] = Hc[k];
        }
        Hc[0] += d[0];
        Hc[1] += d[1];
        Hc[2] += d[2];
        Hc[6] += d[3];
        Hc[7] += d[4];
        Hc[8] += d[5];
    }
    if (!have) {
        return SPVS_E_DEGENERATE;
    }
    for (int k = 0; k < 9; k++) {
        if (!spvs_is_finite(Hc[k])) {
            return SPVS_E_DEGENERATE;
        }
    }
    for (int k = 0; k < 9; k++) {
        H[k] = Hc[k];
    }
    return SPVS_OK;
}

void spvs_h_rescale(spvs_real H[9], spvs_real scale)
{
    H[2] *= scale;
    H[6] /= scale;
    H[7] /= scale;
}
