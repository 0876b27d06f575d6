/*
 * h_refit.c - the tests' Gauss-Newton refit of H on the forward transfer
 * error (h_refit.h), written for reading: one pass over the points builds
 * the cost, the normal matrix and the gradient, then a Cholesky solve.
 */
#include <math.h>

#include "h_refit.h"
#include "spvs/common.h"

/* A point's third coordinate must exceed this to be in front. */
#define W_EPS SPVS_R(1.0e-6)

/* Cost, normal matrix N and right side g of the Gauss-Newton step at H.
 * With w = h3 . p, p = (x_tgt, y_tgt, 1), the residuals are
 * r_x = (h1 . p) / w - x_cur and r_y = y_tgt / w - y_cur; with u = (h1 . p) / w
 * and v = y_tgt / w their Jacobian rows in theta are [p / w, -u p / w] and
 * [0, -v p / w].  N = J^T J and g = -J^T r.  Returns 0 when a flagged point
 * has w <= W_EPS. */
static int gn_pass(const spvs_real (*pts)[4], const uint8_t *use, uint16_t n,
                   const spvs_real H[9], spvs_real *cost, spvs_real N[6][6], spvs_real g[6])
{
    *cost = SPVS_R(0.0);
    for (int r = 0; r < 6; r++) {
        g[r] = SPVS_R(0.0);
        for (int c = 0; c < 6; c++) {
            N[r][c] = SPVS_R(0.0);
        }
    }
    for (uint16_t i = 0; i < n; i++) {
        if (!use[i]) {
            continue;
        }
        const spvs_real p[3] = {pts[i][0], pts[i][1], SPVS_R(1.0)};
        const spvs_real w = H[6] * p[0] + H[7] * p[1] + H[8];
        if (!(w > W_EPS)) {
            return 0;
        }
        const spvs_real u = (H[0] * p[0] + H[1] * p[1] + H[2]) / w;
        const spvs_real v = p[1] / w;
        const spvs_real rx = u - pts[i][2];
        const spvs_real ry = v - pts[i][3];
        spvs_real jx[6], jy[6];
        for (int k = 0; k < 3; k++) {
            jx[k] = p[k] / w;
            jx[3 + k] = -u * p[k] / w;
            jy[k] = SPVS_R(0.0);
            jy[3 + k] = -v * p[k] / w;
        }
        for (int r = 0; r < 6; r++) {
            for (int c = 0; c < 6; c++) {
                N[r][c] += jx[r] * jx[c] + jy[r] * jy[c];
            }
            g[r] -= jx[r] * rx + jy[r] * ry;
        }
        *cost += rx * rx + ry * ry;
    }
    return 1;
}

/* Solves the symmetric positive definite N d = g by Cholesky; 0 when N is
 * not (numerically) positive definite. */
static int cholesky6(const spvs_real N[6][6], const spvs_real g[6], spvs_real d[6])
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
            s -= L[k][i] * d[k];
        }
        d[i] = s / L[i][i];
    }
    return 1;
}

int h_refit(const spvs_real (*pts)[4], const uint8_t *use, uint16_t n, uint16_t max_iters,
            spvs_real H[9])
{
    if (max_iters < 1u) {
        max_iters = 1u;
    }
    if (max_iters > H_REFIT_MAX_ITERS) {
        max_iters = H_REFIT_MAX_ITERS;
    }
    uint16_t used = 0;
    for (uint16_t i = 0; i < n; i++) {
        used = (uint16_t)(used + (use[i] != 0));
    }
    if (used < 3) {
        return SPVS_E_TOO_FEW;
    }
    spvs_real Hc[9];
    for (int k = 0; k < 9; k++) {
        Hc[k] = H[k];
    }
    spvs_real cost, N[6][6], g[6], d[6];
    if (!gn_pass(pts, use, n, Hc, &cost, N, g) || !cholesky6(N, g, d)) {
        return SPVS_E_DEGENERATE;
    }
    for (uint16_t it = 0; it < max_iters; it++) {
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
        spvs_real next;
        /* A step that puts a point behind the camera or raises the cost
         * is undone, and the refit ends. */
        if (!gn_pass(pts, use, n, Hn, &next, N, g) || !(next <= cost)) {
            break;
        }
        const int small = cost - next <= SPVS_R(1.0e-4) * next;
        for (int k = 0; k < 9; k++) {
            Hc[k] = Hn[k];
        }
        cost = next;
        if (small || !cholesky6(N, g, d)) {
            break;
        }
    }
    for (int k = 0; k < 9; k++) {
        if (!(SPVS_FABS(Hc[k]) <= SPVS_REAL_MAX)) {
            return SPVS_E_DEGENERATE;
        }
    }
    for (int k = 0; k < 9; k++) {
        H[k] = Hc[k];
    }
    return SPVS_OK;
}
