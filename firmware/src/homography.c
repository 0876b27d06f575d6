/*
 * homography.c - planar-motion homography: 3-point minimal solver and the
 * Gauss-Newton transfer-error refit (paper, section 2).
 */
#include <math.h>

#include "spvs/homography.h"

/* A 3x3 determinant this small (scaled units, so entries are O(1)) means the
 * sample is degenerate: collinear target points or a y-row with no content. */
#define DET_EPS SPVS_R(1.0e-7)
/* H p_tgt must have a third coordinate above this to be in front. */
#define W_EPS SPVS_R(1.0e-6)

static int is_finite(spvs_real x)
{
    /* Written without isfinite() so no libm call is needed on any target:
     * NaN fails the first test, +-Inf the second. */
    return (x == x) && (x - x == SPVS_R(0.0));
}

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
        if (!is_finite(h1[i]) || !is_finite(h3[i])) {
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

/* Sum of squared transfer errors over the used points; a point behind the
 * camera makes the whole cost "infinite" so a step that causes it is refused. */
static spvs_real refit_cost(const spvs_real (*pts)[4], const uint8_t *use,
                            uint16_t n, const spvs_real H[9])
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

int spvs_h_refit(const spvs_real (*pts)[4], const uint8_t *use, uint16_t n,
                 spvs_real H[9])
{
    uint16_t used = 0;
    for (uint16_t i = 0; i < n; i++) {
        used = (uint16_t)(used + (use[i] ? 1u : 0u));
    }
    if (used < 3) {
        return SPVS_E_TOO_FEW;
    }

    spvs_real Hc[9];
    for (int k = 0; k < 9; k++) {
        Hc[k] = H[k];
    }
    spvs_real cost = refit_cost(pts, use, n, Hc);
    if (!(cost < SPVS_REAL_MAX)) {
        return SPVS_E_DEGENERATE;
    }

    /* Gauss-Newton on theta = (h11 h12 h13 h31 h32 h33) with residuals
     *   r_x = (h1 . p) / w - x_cur,  r_y = y_tgt / w - y_cur,  w = h3 . p.
     * Jacobian per point (p = (x_tgt, y_tgt, 1), u = (h1 . p) / w,
     * v = y_tgt / w):  d r_x = [p / w, -u p / w],  d r_y = [0, -v p / w]. */
    int improved = 0;
    for (int it = 0; it < SPVS_REFIT_MAX_ITERS; it++) {
        spvs_real N[6][6] = {{0}};
        spvs_real g[6] = {0};
        for (uint16_t i = 0; i < n; i++) {
            if (!use[i]) {
                continue;
            }
            const spvs_real *q = pts[i];
            spvs_real w = Hc[6] * q[0] + Hc[7] * q[1] + Hc[8];
            spvs_real iw = SPVS_R(1.0) / w; /* w > 0: refit_cost checked it */
            spvs_real u = (Hc[0] * q[0] + Hc[1] * q[1] + Hc[2]) * iw;
            spvs_real v = q[1] * iw;
            spvs_real rx = u - q[2];
            spvs_real ry = v - q[3];
            spvs_real p[3] = {q[0] * iw, q[1] * iw, iw};
            spvs_real jx[6] = {p[0], p[1], p[2], -u * p[0], -u * p[1], -u * p[2]};
            spvs_real jy3[3] = {-v * p[0], -v * p[1], -v * p[2]};
            for (int a = 0; a < 6; a++) {
                g[a] -= jx[a] * rx;
                for (int b = 0; b <= a; b++) {
                    N[a][b] += jx[a] * jx[b];
                }
            }
            for (int a = 0; a < 3; a++) {
                g[3 + a] -= jy3[a] * ry;
                for (int b = 0; b <= a; b++) {
                    N[3 + a][3 + b] += jy3[a] * jy3[b];
                }
            }
        }
        for (int a = 0; a < 6; a++) {
            for (int b = a + 1; b < 6; b++) {
                N[a][b] = N[b][a];
            }
        }
        spvs_real d[6];
        if (!cholesky6(N, g, d)) {
            if (!improved && it == 0) {
                return SPVS_E_DEGENERATE;
            }
            break;
        }
        spvs_real Hn[9];
        for (int k = 0; k < 9; k++) {
            Hn[k] = Hc[k];
        }
        Hn[0] += d[0];
        Hn[1] += d[1];
        Hn[2] += d[2];
        Hn[6] += d[3];
        Hn[7] += d[4];
        Hn[8] += d[5];
        spvs_real cn = refit_cost(pts, use, n, Hn);
        /* Keep a step only if it lowers the cost; Gauss-Newton from a RANSAC
         * start converges in one or two steps, so stop at the first refusal. */
        if (!(cn <= cost)) {
            break;
        }
        spvs_real rel = cost - cn;
        for (int k = 0; k < 9; k++) {
            Hc[k] = Hn[k];
        }
        cost = cn;
        improved = 1;
        if (rel <= SPVS_R(1.0e-6) * cost) {
            break;
        }
    }
    for (int k = 0; k < 9; k++) {
        if (!is_finite(Hc[k])) {
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
