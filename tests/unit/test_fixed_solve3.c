/* test_fixed_solve3.c - the 3-point minimal solver in fixed point
 * (firmware/src/fixed/solve3_q.c, spvs_q_solve3) against the same formula
 * in long double on the Q store's exact values and against the float
 * solver, on random planar-motion scenes (docs/FIXED.md). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "unity.h"
#include "unit_support.h"

#include "core_util.h"
#include "fixed_scene.h"

/* The 3-point solver: on random triples of random scenes (inlier and
 * mismatch samples alike), the Q solver against the same formula in long
 * double on the Q store's exact values, and against the float solver.
 * Two tolerances, both asserted on every entry of rows 1 and 3:
 *   - TOL_ABS + TOL_COND |adj P| / |det P| max|H| (the conditioning times
 *     the largest entry), the solver's contract since its first version;
 *   - the bound proved in solve3_q.c from its roundings (q_bound below),
 *     tighter on these scenes.
 * The degenerate decisions are those of the reference, but for at most
 * NEAR_MAX triples at a threshold.  The float solver's own error is
 * printed beside it. */
#define TOL_ABS 0x1p-26 /* two Q27 units: the final rounding and the rest */
#define TOL_COND 3e-8   /* relative, per unit of |adj P| / |det P| */
#define NEAR_MAX 3

/* What the reference returns beside H: cond = |adj P| / |det P| (the
 * largest cofactor), the largest w_i = y_tgt / y_cur, |x_cur| and
 * |x_cur w_i| of the triple (the scales of the right sides). */
typedef struct {
    long double cond, wmax, umax, bmax;
} ref_scale_t;

/* The error bound of spvs_q_solve3 (solve3_q.c) for entry k (0..2: row 1,
 * 6..8: row 3) of value h: the final rounding (2^-28), 1 / |det P| to
 * 2^-30, and the right sides and the cofactors c_i2 each to 2^-30 of their
 * largest, amplified by sum_i |c_ij| / |det P| <= 3 cond:
 *   w_i within 1.5 2^-30 wmax, b_i within 1.5 2^-30 |x_cur| wmax +
 *   2^-29 bmax, c_i2 within 2^-30 max|c_i2|.
 * Q_BOUND_SLACK covers the terms below 2^-50 of these (the 64 x 32-bit
 * products' truncation). */
#define Q_BOUND_SLACK 1.001
static double q_bound(int k, long double h, const ref_scale_t *rs)
{
    const long double u = 0x1p-30L;
    const long double c3 = 3 * rs->cond;
    long double rhs;
    if (k >= 6) {
        rhs = c3 * (1.5L * u * rs->wmax + (k == 8 ? u * rs->wmax : 0));
    } else {
        rhs = c3 * (1.5L * u * rs->umax * rs->wmax + 2 * u * rs->bmax +
                    (k == 2 ? u * rs->bmax : 0));
    }
    return (double)(Q_BOUND_SLACK * (0x1p-28L + u * fabsl(h) + rhs));
}

static int ref_solve3(const spvs_q_store_t *st, const uint16_t idx[3], long double H[9],
                      ref_scale_t *rs)
{
    long double x[3], y[3], u[3], v[3];
    for (int i = 0; i < 3; i++) {
        int32_t r[4];
        spvs_q_pts_row(st, idx[i], r);
        x[i] = ldexpl(r[0], -SPVS_QC);
        y[i] = ldexpl(r[1], -SPVS_QC);
        u[i] = ldexpl(r[2], -SPVS_QC);
        v[i] = ldexpl(r[3], -SPVS_QC);
    }
    long double c[3][3];
    for (int i = 0; i < 3; i++) {
        const int a = (i + 1) % 3, b = (i + 2) % 3;
        c[i][0] = y[a] - y[b];
        c[i][1] = x[b] - x[a];
        c[i][2] = x[a] * y[b] - x[b] * y[a];
    }
    const long double det = c[0][2] + c[1][2] + c[2][2];
    const long double dety = v[0] * v[1] * v[2] * det;
    long double cn = 0;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            cn = fmaxl(cn, fabsl(c[i][j]));
        }
    }
    rs->cond = cn / fabsl(det);
    rs->wmax = rs->umax = rs->bmax = 0;
    if (!(fabsl(det) > 1e-7L) || !(fabsl(dety) > 1e-7L)) {
        return -1;
    }
    long double w[3], h3[3], h1[3];
    for (int i = 0; i < 3; i++) {
        w[i] = y[i] / v[i];
        rs->wmax = fmaxl(rs->wmax, fabsl(w[i]));
        rs->umax = fmaxl(rs->umax, fabsl(u[i]));
        rs->bmax = fmaxl(rs->bmax, fabsl(u[i] * w[i]));
    }
    for (int j = 0; j < 3; j++) {
        h3[j] = (c[0][j] * w[0] + c[1][j] * w[1] + c[2][j] * w[2]) / det;
    }
    long double bx[3];
    for (int i = 0; i < 3; i++) {
        const long double wi = h3[0] * x[i] + h3[1] * y[i] + h3[2];
        if (!(wi > 1e-6L)) {
            return -2;
        }
        bx[i] = u[i] * wi;
    }
    for (int j = 0; j < 3; j++) {
        h1[j] = (c[0][j] * bx[0] + c[1][j] * bx[1] + c[2][j] * bx[2]) / det;
    }
    const long double Hl[9] = {h1[0], h1[1], h1[2], 0, 1, 0, h3[0], h3[1], h3[2]};
    for (int k = 0; k < 9; k++) {
        H[k] = Hl[k];
        if (!(fabsl(Hl[k]) < 16)) {
            return -3;
        }
    }
    return 0;
}

/* The largest error of one row (entries k0, k0 + 1, k0 + 2) of Hq against
 * the reference, as a share of each tolerance, and in absolute terms. */
typedef struct {
    double abs, tol, bound;
} row_err_t;

static void check_row(const int32_t Hq[9], const long double Hr[9], int k0,
                      const ref_scale_t *rs, row_err_t *er)
{
    long double hmax = 0;
    for (int k = 0; k < 9; k++) {
        hmax = fmaxl(hmax, fabsl(Hr[k]));
    }
    for (int k = k0; k < k0 + 3; k++) {
        const double e = (double)fabsl(ldexpl(Hq[k], -SPVS_QH) - Hr[k]);
        const double tol = TOL_ABS + TOL_COND * (double)(rs->cond * hmax);
        const double bound = q_bound(k, Hr[k], rs);
        er->abs = fmax(er->abs, e);
        er->tol = fmax(er->tol, e / tol);
        er->bound = fmax(er->bound, e / bound);
        TEST_ASSERT_TRUE(e <= tol);
        TEST_ASSERT_TRUE(e <= bound);
    }
}

static void test_q_solve3(void)
{
    static scene_t sc;
    uint64_t rng = 314;
    long solved = 0, degenerate = 0, near = 0, float_cmp = 0;
    row_err_t r1 = {0, 0, 0}, r3 = {0, 0, 0};
    double worst_f = 0;
    for (int c = 0; c < 60; c++) {
        make_scene(&sc, &rng, 20 + (int)(synth_uniform(&rng) * 200), 1.0,
                   0.4 * synth_uniform(&rng));
        if (sc.n < 8) {
            continue;
        }
        load_both(&sc);
        for (int t = 0; t < 200; t++) {
            uint16_t idx[3];
            idx[0] = (uint16_t)(synth_uniform(&rng) * sc.n);
            do {
                idx[1] = (uint16_t)(synth_uniform(&rng) * sc.n);
            } while (idx[1] == idx[0]);
            do {
                idx[2] = (uint16_t)(synth_uniform(&rng) * sc.n);
            } while (idx[2] == idx[0] || idx[2] == idx[1]);
            long double Hr[9];
            ref_scale_t rs;
            const int rr = ref_solve3(&sc.qst, idx, Hr, &rs);
            int32_t Hq[9];
            const int rq = spvs_q_solve3(&sc.qst, idx, Hq);
            if ((rr == 0) != (rq == SPVS_OK)) {
                /* Only a triple at a threshold may be decided otherwise:
                 * its reference result sits within 1e-6 of the bound. */
                near++;
                TEST_ASSERT_TRUE(near <= NEAR_MAX);
                continue;
            }
            if (rq != SPVS_OK) {
                degenerate++;
                continue;
            }
            solved++;
            TEST_ASSERT_EQUAL_INT64(0, Hq[3]);
            TEST_ASSERT_EQUAL_INT64((int32_t)1 << SPVS_QH, Hq[4]);
            TEST_ASSERT_EQUAL_INT64(0, Hq[5]);
            check_row(Hq, Hr, 0, &rs, &r1);
            check_row(Hq, Hr, 6, &rs, &r3);
            /* The float solver on the float store's points (which differ
             * from the Q store's by up to 2^-27 scaled units). */
            spvs_real pf[3][4], Hf[9];
            for (int i = 0; i < 3; i++) {
                spvs_pts_row(&sc.fst, idx[i], pf[i]);
            }
            if (spvs_h_solve3(pf, Hf) == SPVS_OK && rs.cond < 1e3) {
                float_cmp++;
                for (int k = 0; k < 9; k++) {
                    worst_f = fmax(worst_f, fabs((double)Hf[k] - (double)Hr[k]) /
                                                (1 + fabs((double)Hr[k])));
                }
            }
        }
    }
    UNIT_NOTE("solve3: %ld solved, %ld degenerate, %ld decided otherwise at a threshold\n"
                  "  row 1: largest error %.3g scaled units, %.3g of the tolerance, "
                  "%.3g of the bound\n"
                  "  row 3: largest error %.3g scaled units, %.3g of the tolerance, "
                  "%.3g of the bound\n"
                  "  float against the reference (%ld triples with |adj P| / |det P| < 1e3): "
                  "%.3g relative\n", solved, degenerate, near, r1.abs, r1.tol, r1.bound, r3.abs, r3.tol, r3.bound, float_cmp, worst_f);
    TEST_ASSERT_TRUE(solved > 8000);
}

/* Triples built at the thresholds, on exact Q store values: the solver's
 * status must be the expected one (and the reference's), and a solved H
 * within both tolerances. */
typedef struct {
    int32_t pt[3][4]; /* x_tgt, y_tgt, x_cur, y_cur (Q26) */
    int ok;           /* 1: SPVS_OK expected */
} edge_t;

static void check_edge(const edge_t *ed)
{
    static spvs_q_store_t st;
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k < 4; k++) {
            st.v[4 * i + k] = ed->pt[i][k];
        }
    }
    const uint16_t idx[3] = {0, 1, 2};
    long double Hr[9];
    ref_scale_t rs;
    TEST_ASSERT_EQUAL_INT64(ed->ok, ref_solve3(&st, idx, Hr, &rs) == 0);
    int32_t Hq[9] = {0};
    TEST_ASSERT_EQUAL_INT64(ed->ok ? SPVS_OK : SPVS_E_DEGENERATE, spvs_q_solve3(&st, idx, Hq));
    if (ed->ok) {
        row_err_t er = {0, 0, 0};
        check_row(Hq, Hr, 0, &rs, &er);
        check_row(Hq, Hr, 6, &rs, &er);
    }
}

/* Y = 1.2 scaled units (Q26): det(D P) = y_cur0 y_cur1 y_cur2 det P stays
 * above its threshold while det P sits at its own. */
#define EDGE_Y 80530637

static void test_q_solve3_thresholds(void)
{
    const int32_t Y = EDGE_Y, U = 1 << 25;
    /* det P = 21222^2 - d e in Q52 units: 450359962 (1e-7 2^52 rounded
     * down, degenerate) with d e = 13322, 450359963 (solved) with
     * d e = 13321; w = 1 at every point, H = (0 0 U; 0 1 0; 0 0 1). */
    const edge_t det_lo = {{{0, Y, U, Y}, {21222, Y + 6661, U, Y + 6661},
                            {2, Y + 21222, U, Y + 21222}}, 0};
    const edge_t det_hi = {{{0, Y, U, Y}, {21222, Y + 173, U, Y + 173},
                            {77, Y + 21222, U, Y + 21222}}, 1};
    check_edge(&det_lo);
    check_edge(&det_hi);
    /* w = y_tgt / y_cur at SPVS_W_EPS = 1e-6 exactly at every point
     * (degenerate), then just above it (y_cur one unit smaller). */
    const int32_t X = 1 << 29;
    const edge_t w_at = {{{-X, 536, U, 536000000}, {0, 1072, U, 1072000000},
                          {X, 536, U, 536000000}}, 0};
    const edge_t w_above = {{{-X, 536, U, 535999999}, {0, 1072, U, 1071999998},
                             {X, 536, U, 535999999}}, 1};
    check_edge(&w_at);
    check_edge(&w_above);
    /* A y_cur of 0, and one of the wrong sign (w < 0). */
    const edge_t v_zero = {{{0, Y, U, Y}, {X, Y, U, 0}, {0, 2 * Y, U, 2 * Y}}, 0};
    const edge_t v_neg = {{{0, Y, U, Y}, {X, Y, U, -Y}, {0, 2 * Y, U, 2 * Y}}, 0};
    const edge_t v_ok = {{{0, Y, U, Y}, {X, Y, U, Y}, {0, 2 * Y, U, 2 * Y}}, 1};
    check_edge(&v_zero);
    check_edge(&v_neg);
    check_edge(&v_ok);
    /* h13 = x_cur w: x_cur = 16 scaled units (2^30) with w = 1.01 puts it
     * above 16 (degenerate); 15.5 below. */
    const int32_t V = 80000000, Yw = 80800000; /* w = 1.01 */
    const edge_t h_out = {{{0, Yw, 1 << 30, V}, {X, Yw, 1 << 30, V},
                           {0, 2 * Yw, 1 << 30, 2 * V}}, 0};
    const edge_t h_in = {{{0, Yw, 1040187392, V}, {X, Yw, 1040187392, V},
                          {0, 2 * Yw, 1040187392, 2 * V}}, 1};
    check_edge(&h_out);
    check_edge(&h_in);
}

void suite_fixed_solve3(void)
{
    UNIT_SUITE_FILE();
    RUN_TEST(test_q_solve3);
    RUN_TEST(test_q_solve3_thresholds);
}

UNIT_MAIN(suite_fixed_solve3)
