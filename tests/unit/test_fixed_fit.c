/* test_fixed_fit.c - the solves of the linear fits in fixed point
 * (firmware/src/fixed/fit_q.c): the equilibrated Q30 Cholesky against a
 * long-double solve of the same Q sums, the whole two-stage fit and the
 * joint fit against the float fits (h_fit.h) on random scenes and the
 * golden vectors, and the degenerate and edge cases' statuses
 * (docs/FIXED.md).
 *
 * Every tolerance is stated beside its macro with its reason; the figures
 * measured are printed in one line per test. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "unity.h"
#include "unit_support.h"

#include "core_util.h"
#include "fixed/fit_q.h"
#include "fixed_scene.h"
#include "golden/golden_vectors.h"
#include "h_fit.h"

typedef long double ld;

/* ---- tolerances ------------------------------------------------------------ */

/* The Q solve against the long-double solve of the same sums, per entry:
 * the Q27 rounding of the result (2^-28) with a unit of margin, plus
 * TOL_SOLVE_C cond_1(N') 2^-28 max|y| / sqrt(N_ii), y = D^-1 x the
 * equilibrated solution.  The power-of-two equilibrated N'' (diagonal in
 * [1/2, 2)) carries a backward error of about 3 2^-31 per entry of the
 * exactly equilibrated N' (its Q30 rounding, scaled by up to 2, and for
 * the 6 x 6 the factor's entries from the 2^-28.6 reciprocal roots), 18
 * 2^-31 = 2^-26.8 in a row's 1-norm for n = 6, which the system
 * amplifies by its condition: 2.3 2^-28; the right side and the 6 x 6
 * substitutions keep 2^-29 of their largest entry (one block exponent
 * each), at most cond 2^-29 more; rounded up to 3.  Measured: 0.27 of
 * cond 2^-28 (the largest on well-conditioned 3 x 3 systems, the right
 * side's block), at conditions up to 5e4 (the small discs). */
#define TOL_SOLVE_ABS 0x1p-27
#define TOL_SOLVE_C 3.0
/* The Q fits against the float fits, mean transfer of the image corners
 * (pixels): float's own error against the long-double reference
 * dominates (measured 2.4e-3 px on the random scenes' two-stage fits:
 * 2^-24 per operation on sums of up to 256 terms, amplified by the
 * systems' conditions), the Q fits' is 100x smaller (2.4e-5 px), and the
 * two stores' inputs differ by 3.8e-6 px.  0.01 px is 4x float's worst. */
#define TOL_CORNER_PX 0.01
/* The same for the H entries (scaled units): measured 1e-5 (float's
 * error, as above); 10x. */
#define TOL_H_ENTRY 1e-4
/* The Q fits against the long-double fits of the same Q store (exact
 * inputs): the sums' error (up to ~2e-6 of their magnitudes on the fast
 * paths, docs/FIXED.md) and the solve's, amplified by the conditions:
 * measured 2.4e-5 px; 8x. */
#define TOL_CORNER_Q_REF_PX 2e-4

#define CORNER_X 320.0
#define CORNER_Y 240.0

/* ---- the long-double reference --------------------------------------------- */

/* The equilibrated Cholesky solve of the n x n (n <= 6) system N x = b in
 * long double, exact D = diag(N)^-1/2.  Returns 0 when a pivot of N' is
 * not positive.  *cond: cond_1(N') (from its inverse); y[]: D^-1 x;
 * *minpiv: the smallest pivot of N'. */
static int ld_solve(int n, const ld N[6][6], const ld b[6], ld x[6], ld y[6], ld *cond,
                    ld *minpiv)
{
    ld d[6], A[6][6], L[6][6] = {{0}};
    for (int i = 0; i < n; i++) {
        if (!(N[i][i] > 0)) {
            return 0;
        }
        d[i] = 1 / sqrtl(N[i][i]);
    }
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            A[i][j] = d[i] * N[i][j] * d[j];
        }
    }
    *minpiv = 1e30L;
    for (int i = 0; i < n; i++) {
        for (int j = 0; j <= i; j++) {
            ld s = A[i][j];
            for (int k = 0; k < j; k++) {
                s -= L[i][k] * L[j][k];
            }
            if (i == j) {
                if (!(s > 0)) {
                    return 0;
                }
                *minpiv = fminl(*minpiv, s);
                L[i][i] = sqrtl(s);
            } else {
                L[i][j] = s / L[j][j];
            }
        }
    }
    /* Columns 0..n-1: the inverse of N' (for the condition), column n: the
     * equilibrated right side D b. */
    ld inv[6][6], anorm = 0, inorm = 0;
    for (int c = 0; c <= n; c++) {
        ld z[6];
        for (int i = 0; i < n; i++) {
            ld s = c < n ? (ld)(i == c) : d[i] * b[i];
            for (int k = 0; k < i; k++) {
                s -= L[i][k] * z[k];
            }
            z[i] = s / L[i][i];
        }
        for (int i = n - 1; i >= 0; i--) {
            ld s = z[i];
            for (int k = i + 1; k < n; k++) {
                s -= L[k][i] * z[k];
            }
            z[i] = s / L[i][i];
        }
        for (int i = 0; i < n; i++) {
            if (c < n) {
                inv[i][c] = z[i];
            } else {
                y[i] = z[i];
                x[i] = d[i] * z[i];
            }
        }
    }
    for (int c = 0; c < n; c++) {
        ld sa = 0, si = 0;
        for (int i = 0; i < n; i++) {
            sa += fabsl(A[i][c]);
            si += fabsl(inv[i][c]);
        }
        anorm = fmaxl(anorm, sa);
        inorm = fmaxl(inorm, si);
    }
    *cond = anorm * inorm;
    return 1;
}

static const uint8_t FIT_IX[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};

/* The system of 9 fit sums or 24 joint-fit sums (homography.c solve_fit,
 * unpack_normal), sums t[] in long double. */
static int ld_system(int lin, const ld *t, ld N[6][6], ld b[6])
{
    if (!lin) {
        for (int r = 0; r < 3; r++) {
            for (int c = 0; c < 3; c++) {
                N[r][c] = t[FIT_IX[r][c]];
            }
            b[r] = t[6 + r];
        }
        return 3;
    }
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) {
            N[r][c] = t[FIT_IX[r][c]];
            N[r][3 + c] = N[3 + r][c] = t[6 + FIT_IX[r][c]];
            N[3 + r][3 + c] = t[12 + FIT_IX[r][c]];
        }
    }
    for (int k = 0; k < 6; k++) {
        b[k] = t[18 + k];
    }
    return 6;
}

/* The Q sums' values, exactly (an int64 mantissa fits long double's 64
 * bits); terms below split2 are in blocks 0 and 1. */
static void ld_from_sums(const spvs_q_sums_t *s, int nt, ld *t)
{
    for (int k = 0; k < nt; k++) {
        t[k] = ldexpl((ld)s->m[k], s->e[k >= (int)s->split ? 1 : 0]);
    }
}

static ld qv(int32_t v, int f)
{
    return ldexpl((ld)v, -f);
}

/* Point i of the Q store, exactly. */
static void ld_pt(const spvs_q_store_t *st, uint16_t i, ld p[4])
{
    int32_t r[4];
    spvs_q_pts_row(st, i, r);
    for (int k = 0; k < 4; k++) {
        p[k] = qv(r[k], SPVS_QC);
    }
}

/* SPVS_T_FIT_Y (y = 1) or SPVS_T_FIT_X terms (h_point.inc) in long
 * double.  Returns the number used, -1 for a point behind the camera. */
static int ld_fit_sums(int fy, const ld H[9], const spvs_q_store_t *st, const uint8_t *use,
                       uint16_t n, ld t[9])
{
    int used = 0;
    memset(t, 0, 9 * sizeof t[0]);
    for (uint16_t i = 0; i < n; i++) {
        if (!use[i]) {
            continue;
        }
        ld p[4];
        ld_pt(st, i, p);
        const ld w = H[6] * p[0] + H[7] * p[1] + H[8];
        if (!(w > 1e-6L)) {
            return -1;
        }
        used++;
        const ld sc = fy ? p[3] / w : 1 / w, r = fy ? p[1] / w : p[2];
        const ld q[3] = {sc * p[0], sc * p[1], sc};
        t[0] += q[0] * q[0];
        t[1] += q[0] * q[1];
        t[2] += q[0] * q[2];
        t[3] += q[1] * q[1];
        t[4] += q[1] * q[2];
        t[5] += q[2] * q[2];
        for (int k = 0; k < 3; k++) {
            t[6 + k] += q[k] * r;
        }
    }
    return used;
}

/* SPVS_T_LIN's terms 0-23 (h_point.inc, hp_terms_lin) in long double. */
static void ld_lin_sums(const ld H[9], const spvs_q_store_t *st, const uint8_t *use, uint16_t n,
                        ld t[24])
{
    memset(t, 0, 24 * sizeof t[0]);
    for (uint16_t i = 0; i < n; i++) {
        if (!use[i]) {
            continue;
        }
        ld pt[4];
        ld_pt(st, i, pt);
        const ld x = pt[0], y = pt[1], u = pt[2], v = pt[3];
        const ld w = H[6] * x + H[7] * y + H[8];
        const ld ex = u * w - (H[0] * x + H[1] * y + H[2]), ey = v * w - y;
        const ld p = u * H[6] - H[0], q = u * H[7] - H[1], r = v * H[6], s = v * H[7] - 1;
        const ld ja = p * p + q * q + w * w, jb = r * r + s * s + w * w, jc = p * r + q * s;
        const ld id = 1 / (ja * jb - jc * jc);
        const ld w11 = jb * id, w12 = -jc * id, w22 = ja * id;
        const ld uw = u * w11 + v * w12;
        const ld a[3] = {w11, -uw, u * uw + v * (u * w12 + v * w22)};
        const ld qq[6] = {x * x, x * y, x, y * y, y, 1};
        for (int m = 0; m < 3; m++) {
            for (int k = 0; k < 6; k++) {
                t[6 * m + k] += a[m] * qq[k];
            }
        }
        const ld b1 = w11 * ex + w12 * ey, b2 = w12 * ex + w22 * ey, b3 = -(u * b1 + v * b2);
        const ld g[6] = {b1 * x, b1 * y, b1, b3 * x, b3 * y, b3};
        for (int k = 0; k < 6; k++) {
            t[18 + k] += g[k];
        }
    }
}

/* The two-stage linear fit in long double from the weights of H (row 3,
 * then row 1 given it), into H.  0 when a system is singular or a point
 * is behind the camera. */
static int ld_fit_linear(const spvs_q_store_t *st, const uint8_t *use, uint16_t n, ld H[9])
{
    ld t[9], N[6][6], b[6], x3[6], x1[6], y[6], cond, mp;
    if (ld_fit_sums(1, H, st, use, n, t) < 3) {
        return 0;
    }
    ld_system(0, t, N, b);
    if (!ld_solve(3, N, b, x3, y, &cond, &mp)) {
        return 0;
    }
    const ld Hw[9] = {0, 0, 0, 0, 0, 0, x3[0], x3[1], x3[2]};
    if (ld_fit_sums(0, Hw, st, use, n, t) < 0) {
        return 0;
    }
    ld_system(0, t, N, b);
    if (!ld_solve(3, N, b, x1, y, &cond, &mp)) {
        return 0;
    }
    for (int j = 0; j < 3; j++) {
        H[j] = x1[j];
        H[6 + j] = x3[j];
    }
    return 1;
}

/* The joint fit in long double: the step from Hw solved, into H. */
static int ld_lin_fit(const spvs_q_store_t *st, const uint8_t *use, uint16_t n, const ld Hw[9],
                      ld H[9])
{
    ld t[24], N[6][6], b[6], d[6], y[6], cond, mp;
    ld_lin_sums(Hw, st, use, n, t);
    ld_system(1, t, N, b);
    if (!ld_solve(6, N, b, d, y, &cond, &mp)) {
        return 0;
    }
    static const int at[6] = {0, 1, 2, 6, 7, 8};
    for (int k = 0; k < 9; k++) {
        H[k] = Hw[k];
    }
    for (int k = 0; k < 6; k++) {
        H[at[k]] += d[k];
    }
    return 1;
}

/* ---- comparisons ------------------------------------------------------------ */

static void ld_from_q(const int32_t Hq[9], ld H[9])
{
    for (int k = 0; k < 9; k++) {
        H[k] = qv(Hq[k], SPVS_QH);
    }
}

static void ld_from_real(const spvs_real Hf[9], ld H[9])
{
    for (int k = 0; k < 9; k++) {
        H[k] = (ld)Hf[k];
    }
}

/* The mean distance (pixels) between the transfers of the four image
 * corners (+-320, +-240) px by two H in scaled units. */
static double corner_px(const ld A[9], const ld B[9])
{
    double sum = 0;
    for (int c = 0; c < 4; c++) {
        const ld x = ((c & 1) ? CORNER_X : -CORNER_X) / S, y = ((c & 2) ? CORNER_Y : -CORNER_Y) / S;
        const ld wa = A[6] * x + A[7] * y + A[8], wb = B[6] * x + B[7] * y + B[8];
        const ld du = (A[0] * x + A[1] * y + A[2]) / wa - (B[0] * x + B[1] * y + B[2]) / wb;
        const ld dv = y / wa - y / wb;
        sum += (double)sqrtl(du * du + dv * dv) * S;
    }
    return sum / 4;
}

static double entry_diff(const ld A[9], const ld B[9])
{
    double m = 0;
    for (int k = 0; k < 9; k++) {
        m = fmax(m, (double)fabsl(A[k] - B[k]));
    }
    return m;
}

/* ---- the Q solves against long double on the same sums --------------------- */

typedef struct {
    long systems;
    double worst;     /* largest error / tolerance */
    double worst_abs; /* largest |error| of an entry (scaled units) */
    double max_cond;
    double min_piv;
    double worst_rel; /* largest (error - 2^-28) / (cond 2^-28 max|y| / sqrt(N_ii)) */
    long refused, refused_det;
} solve_stats_t;

/* Checks one system: Q solution xq (Q27; for the joint fit, the moved
 * entries minus Hw's) against the long-double solve of the same sums. */
static void check_solve(const ld *t, int lin, const int32_t *xq, const int32_t *base,
                        solve_stats_t *ss)
{
    ld N[6][6], b[6], x[6], y[6], cond, mp;
    const int n = ld_system(lin, t, N, b);
    TEST_ASSERT_TRUE(ld_solve(n, N, b, x, y, &cond, &mp));
    ld ymax = 0;
    for (int i = 0; i < n; i++) {
        ymax = fmaxl(ymax, fabsl(y[i]));
    }
    for (int i = 0; i < n; i++) {
        const ld got = qv(xq[i], SPVS_QH) - (base ? qv(base[i], SPVS_QH) : 0);
        const double err = (double)fabsl(got - x[i]);
        const double tol =
            TOL_SOLVE_ABS + TOL_SOLVE_C * (double)(cond * ymax / sqrtl(N[i][i])) * 0x1p-28;
        ss->worst = fmax(ss->worst, err / tol);
        ss->worst_abs = fmax(ss->worst_abs, err);
        ss->worst_rel = fmax(ss->worst_rel, (err - 0x1p-28) / (tol - TOL_SOLVE_ABS) * TOL_SOLVE_C);
        TEST_ASSERT_TRUE(err <= tol);
    }
    ss->systems++;
    ss->max_cond = fmax(ss->max_cond, (double)cond);
    ss->min_piv = fmin(ss->min_piv, (double)mp);
}

/* A Q solve refused where the long-double one succeeds: only with a pivot
 * of N' below the floor, 2^-20, within the Q factor's backward error
 * (2^-26 of the unit diagonal), or for a 3 x 3 system float's own test,
 * |det| <= 1e-7, within 1e-6 of it (the Q determinant comes from the
 * exact cofactors of N'', whose entries are rounded to 2^-31, and its
 * 31-bit mantissa). */
static void check_refused(const ld *t, int lin, solve_stats_t *ss)
{
    ld N[6][6], b[6], x[6], y[6], cond, mp;
    const int n = ld_system(lin, t, N, b);
    if (ld_solve(n, N, b, x, y, &cond, &mp)) {
        const ld det = lin ? 1
                           : N[0][0] * (N[1][1] * N[2][2] - N[1][2] * N[2][1]) -
                                 N[0][1] * (N[1][0] * N[2][2] - N[1][2] * N[2][0]) +
                                 N[0][2] * (N[1][0] * N[2][1] - N[1][1] * N[2][0]);
        TEST_ASSERT_TRUE(mp < 0x1p-20 + 0x1p-26 || fabsl(det) <= 1e-7L * (1 + 1e-6L));
        if (!(mp < 0x1p-20 + 0x1p-26)) {
            ss->refused_det++;
        }
    }
    ss->refused++;
}

/* The three systems of one set: row 3's at Hq, row 1's at the Q row 3,
 * the joint fit's at Hq; each against long double, or refused. */
static void solve_set(scene_t *sc, const int32_t Hq[9], const uint8_t *use, solve_stats_t *ss)
{
    spvs_q_sums_t s;
    ld tt[24];
    TEST_ASSERT_TRUE(spvs_q_pts_sum(SPVS_T_FIT_Y, Hq, &sc->qst, use, sc->n, &s) >= 8);
    int32_t h3[3], h1[3];
    ld_from_sums(&s, 9, tt);
    if (spvs_q_fit_solve(&s, h3) != SPVS_OK) {
        check_refused(tt, 0, ss);
        return;
    }
    check_solve(tt, 0, h3, NULL, ss);
    const int32_t Hw[9] = {0, 0, 0, 0, 0, 0, h3[0], h3[1], h3[2]};
    TEST_ASSERT_TRUE(spvs_q_pts_sum(SPVS_T_FIT_X, Hw, &sc->qst, use, sc->n, &s) >= 0);
    ld_from_sums(&s, 9, tt);
    if (spvs_q_fit_solve(&s, h1) != SPVS_OK) {
        check_refused(tt, 0, ss);
    } else {
        check_solve(tt, 0, h1, NULL, ss);
    }
    TEST_ASSERT_TRUE(spvs_q_pts_sum(SPVS_T_LIN, Hq, &sc->qst, use, sc->n, &s) >= 8);
    ld_from_sums(&s, 24, tt);
    int32_t Hn[9];
    if (spvs_q_lin_solve(&s, Hq, Hn) != SPVS_OK) {
        check_refused(tt, 1, ss);
        return;
    }
    /* Row 2 is Hw's. */
    TEST_ASSERT_EQUAL_INT64(Hq[3], Hn[3]);
    TEST_ASSERT_EQUAL_INT64(Hq[4], Hn[4]);
    TEST_ASSERT_EQUAL_INT64(Hq[5], Hn[5]);
    const int32_t dq[6] = {Hn[0], Hn[1], Hn[2], Hn[6], Hn[7], Hn[8]};
    const int32_t bq[6] = {Hq[0], Hq[1], Hq[2], Hq[6], Hq[7], Hq[8]};
    check_solve(tt, 1, dq, bq, ss);
}

static void test_q_solves_ref(void)
{
    static scene_t sc;
    static uint8_t mask[NMAX], disc[NMAX];
    solve_stats_t ss = {0, 0, 0, 0, 1e30, 0, 0, 0};
    uint64_t rng = 77;
    const spvs_real t = (spvs_real)(INLIER_PX / S);
    uint32_t sat = 0;
    const spvs_q_thr_t thr = spvs_q_thr(spvs_q_t2_from_real(t * t, &sat));
    for (int c = 0; c < 120; c++) {
        make_scene(&sc, &rng, 16 + (int)(synth_uniform(&rng) * 240), 1.0,
                   0.4 * synth_uniform(&rng));
        load_both(&sc);
        int32_t Hq[9];
        if (spvs_q_h_from_real(sc.Hs, Hq) != 0) {
            continue;
        }
        if (spvs_q_pts_score(&sc.qst, sc.n, Hq, &thr, 0, mask) < 8) {
            continue;
        }
        solve_set(&sc, Hq, mask, &ss);
        /* The inliers within a disc of 15-100 px around one of them: the
         * smaller the disc, the worse the systems' conditions. */
        uint16_t c0 = 0;
        while (!mask[c0]) {
            c0++;
        }
        int32_t r0[4], ri[4];
        spvs_q_pts_row(&sc.qst, c0, r0);
        const double rad = (15 + 85 * synth_uniform(&rng)) / S;
        uint16_t k = 0;
        for (uint16_t i = 0; i < sc.n; i++) {
            spvs_q_pts_row(&sc.qst, i, ri);
            const double dx = ldexp(ri[0] - r0[0], -SPVS_QC), dy = ldexp(ri[1] - r0[1], -SPVS_QC);
            disc[i] = (uint8_t)(mask[i] && dx * dx + dy * dy <= rad * rad);
            k = (uint16_t)(k + disc[i]);
        }
        if (k >= 8) {
            solve_set(&sc, Hq, disc, &ss);
        }
    }
    UNIT_NOTE("solves vs long double: %ld systems (%ld refused, %ld of them by float's |det| test), largest error / tolerance "
                  "%.3g, beyond the Q27 rounding %.3g of cond 2^-28 max|y| / sqrt(N_ii); largest "
                  "entry error %.3g scaled units, cond(N') up to %.3g, smallest pivot of N' %.3g "
                  "(floor 2^-20 = 9.5e-7)\n", ss.systems, ss.refused, ss.refused_det, ss.worst, ss.worst_rel, ss.worst_abs, ss.max_cond, ss.min_piv);
    TEST_ASSERT_TRUE(ss.systems > 200);
}

/* ---- the whole fits against float ------------------------------------------ */

typedef struct {
    long fits;
    double qf_corner, qf_entry; /* Q against float */
    double q_ref, f_ref;        /* corners, Q and float against long double */
} fit_stats_t;

static void fit_compare(const ld Hq[9], const ld Hf[9], const ld Hr[9], fit_stats_t *fs)
{
    const double cq = corner_px(Hq, Hf), eq = entry_diff(Hq, Hf);
    const double qr = corner_px(Hq, Hr), fr = corner_px(Hf, Hr);
    fs->qf_corner = fmax(fs->qf_corner, cq);
    fs->qf_entry = fmax(fs->qf_entry, eq);
    fs->q_ref = fmax(fs->q_ref, qr);
    fs->f_ref = fmax(fs->f_ref, fr);
    fs->fits++;
    TEST_ASSERT_TRUE(cq <= TOL_CORNER_PX);
    TEST_ASSERT_TRUE(eq <= TOL_H_ENTRY);
    TEST_ASSERT_TRUE(qr <= TOL_CORNER_Q_REF_PX);
}

/* Both fits of one set at the model Hs: the two-stage fit from Hs's
 * weights and the joint fit at Hs, float (float store) and Q (Q store)
 * against each other and the long-double fits of the Q store. */
static void fits_of_set(scene_t *sc, const spvs_real Hs[9], const uint8_t *use, fit_stats_t *two,
                        fit_stats_t *joint)
{
    const spvs_pts_in_t in = {NULL, &sc->fst};
    int32_t Hq0[9];
    TEST_ASSERT_EQUAL_INT64(0, spvs_q_h_from_real(Hs, Hq0));
    ld Hr[9], Hq[9], Hf[9], H0[9];
    ld_from_q(Hq0, H0);
    /* The two-stage fit. */
    spvs_real Hfr[9];
    int32_t Hqr[9];
    memcpy(Hfr, Hs, sizeof Hfr);
    memcpy(Hqr, Hq0, sizeof Hqr);
    const int rf = spvs_hf_fit_linear(&in, use, sc->n, Hfr);
    const int rq = spvs_q_fit_linear(&sc->qst, use, sc->n, Hqr);
    TEST_ASSERT_EQUAL_INT64(rf, rq);
    memcpy(Hr, H0, sizeof Hr);
    if (rf == SPVS_OK) {
        TEST_ASSERT_TRUE(ld_fit_linear(&sc->qst, use, sc->n, Hr));
        ld_from_q(Hqr, Hq);
        ld_from_real(Hfr, Hf);
        fit_compare(Hq, Hf, Hr, two);
    }
    /* The joint fit at Hs. */
    spvs_real sums[SPVS_H_LIN_SUMS];
    const int sf = spvs_hf_lin_sums(&in, use, sc->n, Hs, sums);
    spvs_q_sums_t qs;
    const int32_t used = spvs_q_pts_sum(SPVS_T_LIN, Hq0, &sc->qst, use, sc->n, &qs);
    TEST_ASSERT_EQUAL_INT64(used >= 3, sf == SPVS_OK);
    if (sf != SPVS_OK) {
        return;
    }
    const int lf = spvs_hf_lin_solve(sums, Hs, Hfr);
    const int lq = spvs_q_lin_solve(&qs, Hq0, Hqr);
    TEST_ASSERT_EQUAL_INT64(lf, lq);
    if (lf == SPVS_OK) {
        TEST_ASSERT_TRUE(ld_lin_fit(&sc->qst, use, sc->n, H0, Hr));
        ld_from_q(Hqr, Hq);
        ld_from_real(Hfr, Hf);
        fit_compare(Hq, Hf, Hr, joint);
    }
}

static void test_q_fits_random(void)
{
    static scene_t sc;
    static uint8_t mask[NMAX];
    fit_stats_t two = {0}, joint = {0};
    uint64_t rng = 5;
    const spvs_real t = (spvs_real)(INLIER_PX / S);
    for (int c = 0; c < 120; c++) {
        make_scene(&sc, &rng, 16 + (int)(synth_uniform(&rng) * 240), 1.0,
                   0.4 * synth_uniform(&rng));
        load_both(&sc);
        int32_t Hq[9];
        if (spvs_q_h_from_real(sc.Hs, Hq) != 0) {
            continue;
        }
        /* The float inlier set of the true H, as the estimator's. */
        (void)spvs_pts_score(&sc.fst, sc.n, sc.Hs, t * t, 0, mask);
        fits_of_set(&sc, sc.Hs, mask, &two, &joint);
    }
    UNIT_NOTE("fits, random scenes: two-stage %ld: Q vs float corners %.3g px, entries %.3g; "
                  "against long double Q %.3g px, float %.3g px; joint %ld: Q vs float %.3g px, "
                  "entries %.3g; against long double Q %.3g px, float %.3g px\n", two.fits, two.qf_corner, two.qf_entry, two.q_ref, two.f_ref, joint.fits, joint.qf_corner, joint.qf_entry, joint.q_ref, joint.f_ref);
    TEST_ASSERT_TRUE(two.fits > 100 && joint.fits > 100);
}

static void test_q_fits_golden(void)
{
    static scene_t sc;
    fit_stats_t two = {0}, joint = {0};
    uint8_t all[NMAX];
    memset(all, 1, sizeof all);
    for (int c = 0; c < SPVS_GOLDEN_N_H; c++) {
        const spvs_golden_h_t *g = &spvs_golden_h[c];
        sc.n = SPVS_GOLDEN_N_NOISY;
        for (uint16_t i = 0; i < sc.n; i++) {
            sc.m[i].x_tgt = (spvs_real)g->noisy[i][0];
            sc.m[i].y_tgt = (spvs_real)g->noisy[i][1];
            sc.m[i].x_cur = (spvs_real)g->noisy[i][2];
            sc.m[i].y_cur = (spvs_real)g->noisy[i][3];
            sc.m[i].feature = i;
        }
        rescale_scaled(g->H, sc.Hs);
        load_both(&sc);
        /* Every golden point is a plane point: all are used, at the true H
         * and at the least-squares H. */
        fits_of_set(&sc, sc.Hs, all, &two, &joint);
        spvs_real Hfit[9];
        rescale_scaled(g->H_fit, Hfit);
        fits_of_set(&sc, Hfit, all, &two, &joint);
    }
    UNIT_NOTE("fits, golden: two-stage %ld: Q vs float corners %.3g px, entries %.3g; "
                  "against long double Q %.3g px, float %.3g px; joint %ld: Q vs float %.3g px, "
                  "entries %.3g; against long double Q %.3g px, float %.3g px\n", two.fits, two.qf_corner, two.qf_entry, two.q_ref, two.f_ref, joint.fits, joint.qf_corner, joint.qf_entry, joint.q_ref, joint.f_ref);
    TEST_ASSERT_EQUAL_INT64(2 * SPVS_GOLDEN_N_H, two.fits);
    TEST_ASSERT_EQUAL_INT64(2 * SPVS_GOLDEN_N_H, joint.fits);
}

/* ---- degenerate and edge cases ----------------------------------------------- */

/* n matches of the plane motion H (scaled units) with target points
 * (pixels) spread over the image (shape 0), on the line y = 0 (1), on the
 * line y = 0.37 x + 13 (2), all at one point (3), or point 0 at x = -295
 * px and the others at x > -250 px (4); exact, no noise. */
static void set_from_H(scene_t *sc, const double H[9], int n, int shape, uint64_t *rng)
{
    sc->n = (uint16_t)n;
    for (int i = 0; i < n; i++) {
        double x = (synth_uniform(rng) - 0.5) * 600, y = (synth_uniform(rng) - 0.5) * 440;
        if (shape == 1) {
            y = 0;
        } else if (shape == 2) {
            y = 0.37 * x + 13;
        } else if (shape == 3) {
            x = 101.5;
            y = -47.25;
        } else if (shape == 4) {
            x = i == 0 ? -295 : -250 + 550 * (x / 600 + 0.5);
        }
        const double xs = x / S, ys = y / S, w = H[6] * xs + H[7] * ys + H[8];
        sc->m[i].x_tgt = (spvs_real)x;
        sc->m[i].y_tgt = (spvs_real)y;
        sc->m[i].x_cur = (spvs_real)((H[0] * xs + H[1] * ys + H[2]) / w * S);
        sc->m[i].y_cur = (spvs_real)(ys / w * S);
        sc->m[i].feature = (uint16_t)i;
    }
    load_both(sc);
}

/* Both fits of the set from the weights of H0 (scaled units; Q27 H0q, in
 * range): the statuses of the two-stage fit (*two_f, *two_q) and of the
 * joint fit at H0 (*lin_f, *lin_q); a Q result that is an error leaves
 * its H unchanged (asserted). */
static void edge_fits(scene_t *sc, const spvs_real H0[9], const uint8_t *use, int *two_f,
                      int *two_q, int *lin_f, int *lin_q)
{
    const spvs_pts_in_t in = {NULL, &sc->fst};
    int32_t Hq0[9], Hq[9];
    TEST_ASSERT_EQUAL_INT64(0, spvs_q_h_from_real(H0, Hq0));
    spvs_real Hf[9];
    memcpy(Hf, H0, sizeof Hf);
    memcpy(Hq, Hq0, sizeof Hq);
    *two_f = spvs_hf_fit_linear(&in, use, sc->n, Hf);
    *two_q = spvs_q_fit_linear(&sc->qst, use, sc->n, Hq);
    if (*two_q != SPVS_OK) {
        TEST_ASSERT_EQUAL_MEMORY(Hq0, Hq, sizeof Hq);
    }
    spvs_real sums[SPVS_H_LIN_SUMS];
    spvs_q_sums_t qs;
    *lin_f = spvs_hf_lin_sums(&in, use, sc->n, H0, sums);
    const int32_t used = spvs_q_pts_sum(SPVS_T_LIN, Hq0, &sc->qst, use, sc->n, &qs);
    *lin_q = used < 0 ? SPVS_E_DEGENERATE : used < 3 ? SPVS_E_TOO_FEW : SPVS_OK;
    if (*lin_f == SPVS_OK) {
        *lin_f = spvs_hf_lin_solve(sums, H0, Hf);
    }
    if (*lin_q == SPVS_OK) {
        memcpy(Hq, Hq0, sizeof Hq);
        *lin_q = spvs_q_lin_solve(&qs, Hq0, Hq);
        if (*lin_q != SPVS_OK) {
            TEST_ASSERT_EQUAL_MEMORY(Hq0, Hq, sizeof Hq);
        }
    }
}

static void test_q_fit_edges(void)
{
    static scene_t sc;
    uint64_t rng = 11;
    uint8_t use[NMAX];
    /* A plane motion in scaled units and a start H near it. */
    const double H[9] = {0.93, 0.02, 0.15, 0, 1, 0, 0.04, -0.03, 1.05};
    const spvs_real H0[9] = {0.9f, 0, 0.1f, 0, 1, 0, 0, 0, 1};
    int tf, tq, lf, lq;
    /* Fewer than 3 used points: 2, then none. */
    set_from_H(&sc, H, 40, 0, &rng);
    memset(use, 0, sizeof use);
    use[3] = use[17] = 1;
    edge_fits(&sc, H0, use, &tf, &tq, &lf, &lq);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_TOO_FEW, tf);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_TOO_FEW, tq);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_TOO_FEW, lf);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_TOO_FEW, lq);
    memset(use, 0, sizeof use);
    edge_fits(&sc, H0, use, &tf, &tq, &lf, &lq);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_TOO_FEW, tq);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_TOO_FEW, tf);
    /* Collinear and coincident target points: no system is positive
     * definite. */
    memset(use, 1, sizeof use);
    int st[3][4];
    for (int shape = 1; shape <= 3; shape++) {
        set_from_H(&sc, H, 40, shape, &rng);
        edge_fits(&sc, H0, use, &tf, &tq, &lf, &lq);
        st[shape - 1][0] = tf;
        st[shape - 1][1] = tq;
        st[shape - 1][2] = lf;
        st[shape - 1][3] = lq;
    }
    for (int k = 0; k < 3; k++) {
        for (int j = 0; j < 4; j++) {
            TEST_ASSERT_EQUAL_INT64(SPVS_E_DEGENERATE, st[k][j]);
        }
    }
    /* A used point behind the camera at the start H (w = 1.9 x + 1 < 0 at
     * x = -295 px only); unused, it is ignored. */
    set_from_H(&sc, H, 40, 4, &rng);
    const spvs_real Hb[9] = {1, 0, 0, 0, 1, 0, 1.9f, 0, 1};
    edge_fits(&sc, Hb, use, &tf, &tq, &lf, &lq);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_DEGENERATE, tf);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_DEGENERATE, tq);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_DEGENERATE, lf);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_DEGENERATE, lq);
    use[0] = 0;
    edge_fits(&sc, Hb, use, &tf, &tq, &lf, &lq);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, tf);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, tq);
    use[0] = 1;
    /* Solutions at the edge of the Q range: h11 = 15.9 is solved by both;
     * h11 = 17 only by float (an H outside the Q27 range is
     * SPVS_E_DEGENERATE in Q, as the 3-point solver's), from starts in
     * range (h11 = 15, 15.5).  (A large h33 would not do: float's
     * absolute |det| > 1e-7 refuses row 3's system, whose entries scale
     * as 1 / h33^2.) */
    double Hr[9] = {15.9, 0.02, 0.1, 0, 1, 0, 0.04, -0.03, 1.05};
    const spvs_real Hs0[9] = {15.0f, 0, 0, 0, 1, 0, 0, 0, 1};
    const spvs_real Hs1[9] = {15.5f, 0.02f, 0.1f, 0, 1, 0, 0.04f, -0.03f, 1.05f};
    set_from_H(&sc, Hr, 40, 0, &rng);
    edge_fits(&sc, Hs0, use, &tf, &tq, &lf, &lq);
    const int in_range[4] = {tf, tq, lf, lq};
    edge_fits(&sc, Hs1, use, &tf, &tq, &lf, &lq);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, lf);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, lq);
    Hr[0] = 17;
    set_from_H(&sc, Hr, 40, 0, &rng);
    edge_fits(&sc, Hs0, use, &tf, &tq, &lf, &lq);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, tf);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_DEGENERATE, tq);
    edge_fits(&sc, Hs1, use, &tf, &tq, &lf, &lq);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, lf);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_DEGENERATE, lq);
    for (int k = 0; k < 4; k++) {
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, in_range[k]);
    }
    UNIT_NOTE("edges: fewer than 3, collinear (2 lines), coincident, behind the camera: "
                  "float's statuses; h11 = 15.9 solved, 17 SPVS_E_DEGENERATE in Q only\n");
}

void suite_fixed_fit(void)
{
    UNIT_SUITE_FILE();
    RUN_TEST(test_q_solves_ref);
    RUN_TEST(test_q_fits_random);
    RUN_TEST(test_q_fits_golden);
    RUN_TEST(test_q_fit_edges);
}

UNIT_MAIN(suite_fixed_fit)
