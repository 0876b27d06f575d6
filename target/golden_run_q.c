/*
 * golden_run_q.c - the golden-vector checks of tests/golden/golden_check_q.h
 * on the target, in the fixed-point build: integers only, the same
 * tolerances and the same integers as the host test (test_golden_fixed).
 *
 * Built with SPVS_GOLDEN_TAMPER=1, h11 of case 0's true H is perturbed by
 * 1e-3 (relative), and the run must then fail: that proves the checks and
 * the exit status can fail at all.
 */
#include "checks.h"

#include "fmt.h"
#include "spvs/spvs.h"

#define SPVS_GOLDEN_T spvs_real
#include "golden/golden_vectors.h"
#include "golden/golden_check_q.h"

#ifndef SPVS_GOLDEN_TAMPER
#define SPVS_GOLDEN_TAMPER 0
#endif

/* v (Q18 pixels) as "I.FFFF" in pixels, integers only (v >= 0). */
static void out_q18_px(int64_t v)
{
    if (v < 0 || v > ((int64_t)1 << 48)) {
        out_str("inf");
        return;
    }
    out_u32((uint32_t)(v >> 18));
    out_str(".");
    uint32_t frac = (uint32_t)(((v & ((1 << 18) - 1)) * 10000 + (1 << 17)) >> 18);
    if (frac > 9999u) {
        frac = 9999u;
    }
    for (uint32_t d = 1000u; d > frac && d > 1u; d /= 10u) {
        out_str("0");
    }
    out_u32(frac);
}

int golden_run(void)
{
    int fails = 0;
    int64_t worst_corner = 0, worst_opt = 0, worst_e = 0;
    for (int c = 0; c < SPVS_GOLDEN_N_H; ++c) {
        int32_t tamper = 0;
#if SPVS_GOLDEN_TAMPER
        if (c == 0) {
            int bad = 0;
            tamper = golden_q_in(spvs_golden_h[0].H[0], SPVS_QH, &bad) / 1000;
        }
#endif
        golden_q_h_result_t r;
        golden_q_run_h(&spvs_golden_h[c], tamper, &r);
        const int ok = golden_q_h_ok(&r);
        out_fail_case("fixed-point H", c, ok);
        fails += !ok;
        worst_corner = r.corner_q18 > worst_corner ? r.corner_q18 : worst_corner;
        worst_opt = r.optimum_q18 > worst_opt ? r.optimum_q18 : worst_opt;
    }
    for (int c = 0; c < SPVS_GOLDEN_N_E; ++c) {
        golden_q_e_result_t r;
        golden_q_run_e(&spvs_golden_e[c], &r);
        const int ok = golden_q_e_ok(&r);
        out_fail_case("fixed-point epipole", c, ok);
        fails += !ok;
        worst_e = r.err_q16 > worst_e ? r.err_q16 : worst_e;
    }
    out_str("golden (fixed point): ");
    out_int(SPVS_GOLDEN_N_H);
    out_str(" H cases, worst corner error ");
    out_q18_px(worst_corner);
    out_str(" px (true H), ");
    out_q18_px(worst_opt);
    out_str(" px (optimum); ");
    out_int(SPVS_GOLDEN_N_E);
    out_str(" epipole cases, worst e_x error ");
    out_q18_px(worst_e * 4);
    out_str(" px; ");
    out_int(fails);
    out_str(" failed\n");
    return fails;
}
