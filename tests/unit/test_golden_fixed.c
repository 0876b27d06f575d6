/*
 * test_golden_fixed.c - the fixed-point core against the golden vectors,
 * with the integer checks the Cortex-M3 image of the fixed-point build runs
 * (tests/golden/golden_check_q.h): the Q 3-point solver on the exact
 * triples, the Q pipeline's estimate on the 40 noisy matches (corner
 * transfer against the true H and against the least-squares optimum), and
 * the Q epipole against e = K(-R c).  A perturbed true H must fail the
 * checks.  The figures are printed in pixels and relative errors.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "unity.h"
#include "unit_support.h"

#include "spvs/spvs.h"

#define SPVS_GOLDEN_T spvs_real
#include "golden/golden_vectors.h"
#include "golden/golden_check_q.h"

/* The harness's own test (SPVS_UNIT_SELF_FAIL=1, the fixed-point build's
 * unity_self_fail*): test_golden_q_h runs every case with the true H
 * perturbed as test_golden_q_tamper does, so it must fail, and the run must
 * count exactly one failed test. */
#if defined(SPVS_UNIT_SELF_FAIL) && SPVS_UNIT_SELF_FAIL
#define UNIT_SELF_FAIL_TAMPER 1
#else
#define UNIT_SELF_FAIL_TAMPER 0
#endif

static double q18_px(int64_t v)
{
    return (double)v / (double)(1 << 18);
}

static void test_golden_q_h(void)
{
    double worst_rel = 0, worst_corner = 0, worst_opt = 0;
    int fails = 0;
    for (int c = 0; c < SPVS_GOLDEN_N_H; c++) {
        golden_q_h_result_t r;
        int bad = 0;
        const int32_t tamper = UNIT_SELF_FAIL_TAMPER
            ? golden_q_in(spvs_golden_h[c].H[0], SPVS_QH, &bad) / 1000 : 0;
        golden_q_run_h(&spvs_golden_h[c], tamper, &r);
        const double rel = r.solve3_max > 0 ? (double)r.solve3_diff / (double)r.solve3_max : 1.0;
        worst_rel = rel > worst_rel ? rel : worst_rel;
        worst_corner = q18_px(r.corner_q18) > worst_corner ? q18_px(r.corner_q18) : worst_corner;
        worst_opt = q18_px(r.optimum_q18) > worst_opt ? q18_px(r.optimum_q18) : worst_opt;
        if (!golden_q_h_ok(&r)) {
            UNIT_NOTE("case %d: solve3 %d (rel %.3g), estimate %d, %u inliers, corner %.4f px, "
                          "optimum %.4f px, inputs %d\n", c, r.st_solve3, rel, r.st_estimate, r.n_inliers, q18_px(r.corner_q18), q18_px(r.optimum_q18), r.inputs_ok);
            fails++;
        }
    }
    UNIT_NOTE("golden Q: %d cases; solve3 worst entry error %.3g of max|H| (tolerance %.3g); "
                  "estimate's corner error worst %.4f px against the true H (tolerance %.2f), "
                  "%.4f px against the optimum (tolerance %.4f)\n", SPVS_GOLDEN_N_H, worst_rel, 1.0 / (double)(1 << GOLDEN_Q_SOLVE3_SHIFT), worst_corner, q18_px(GOLDEN_Q_CORNER_Q18), worst_opt, q18_px(GOLDEN_Q_OPTIMUM_Q18));
    TEST_ASSERT_EQUAL_INT64(0, fails);
}

static void test_golden_q_e(void)
{
    double worst = 0;
    int fails = 0;
    for (int c = 0; c < SPVS_GOLDEN_N_E; c++) {
        golden_q_e_result_t r;
        golden_q_run_e(&spvs_golden_e[c], &r);
        const double err = (double)r.err_q16 / 65536.0;
        worst = err > worst ? err : worst;
        if (!golden_q_e_ok(&r)) {
            UNIT_NOTE("epipole case %d: status %d, e_x %.3f px, error %.4f px (tolerance "
                          "%.3f), side %d, support %u\n", c, r.st, (double)r.e_x_q16 / 65536.0, err, (double)r.tol_q16 / 65536.0, r.side_ok, r.n_support);
            fails++;
        }
    }
    UNIT_NOTE("golden Q epipole: %d cases, e_x worst error %.4f px\n", SPVS_GOLDEN_N_E, worst);
    TEST_ASSERT_EQUAL_INT64(0, fails);
}

/* The checks can fail: h11 of the true H off by 1e-3 (relative) breaks the
 * 3-point solver's check in every case. */
static void test_golden_q_tamper(void)
{
    int caught = 0;
    for (int c = 0; c < SPVS_GOLDEN_N_H; c++) {
        golden_q_h_result_t r;
        int bad = 0;
        const int32_t h11 = golden_q_in(spvs_golden_h[c].H[0], SPVS_QH, &bad);
        golden_q_run_h(&spvs_golden_h[c], h11 / 1000, &r);
        caught += !golden_q_h_ok(&r);
    }
    TEST_ASSERT_EQUAL_INT64(SPVS_GOLDEN_N_H, caught);
}

void suite_golden_fixed(void)
{
    UNIT_SUITE_FILE();
    RUN_TEST(test_golden_q_h);
    RUN_TEST(test_golden_q_e);
    RUN_TEST(test_golden_q_tamper);
}

UNIT_MAIN(suite_golden_fixed)
