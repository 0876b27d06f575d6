/*
 * golden_run.c - the golden-vector checks of tests/golden/golden_check.h on
 * the target, in float32, with the same tolerances as the host test.
 *
 * Built with SPVS_GOLDEN_TAMPER=1, one expected value (h11 of case 0, by
 * 1e-3 relative) is perturbed, and the run must then fail: that proves the
 * checks and the exit status can fail at all.
 */
#include "checks.h"

#include "fmt.h"
#include "spvs/spvs.h"

#define SPVS_GOLDEN_T spvs_real
#include "golden/golden_vectors.h"
#include "golden/golden_check.h"

#ifndef SPVS_GOLDEN_TAMPER
#define SPVS_GOLDEN_TAMPER 0
#endif

int golden_run(void)
{
    int fails = 0;
    spvs_real worst_rel = SPVS_R(0.0), worst_corner = SPVS_R(0.0), worst_opt = SPVS_R(0.0);
    for (int c = 0; c < SPVS_GOLDEN_N_H; ++c) {
        const spvs_golden_h_t *g = &spvs_golden_h[c];
#if SPVS_GOLDEN_TAMPER
        static spvs_golden_h_t tampered;
        if (c == 0) {
            tampered = *g;
            tampered.H[0] *= SPVS_R(1.001);
            g = &tampered;
        }
#endif
        golden_h_result_t r;
        golden_run_h(g, &r);
        int ok3 = r.st_solve3 == SPVS_OK && r.solve3_rel <= GOLDEN_TOL_SOLVE3_REL;
        int okr = r.st_start == SPVS_OK && r.st_refit == SPVS_OK &&
                  r.refit_corner_px < GOLDEN_TOL_CORNER_PX &&
                  r.optimum_corner_px < GOLDEN_TOL_OPTIMUM_PX;
        out_fail_case("solve3", c, ok3);
        out_fail_case("refit", c, okr);
        out_fail_case("sentinel", c, r.sentinel_ok);
        fails += !ok3 + !okr + !r.sentinel_ok;
        /* Written so that a NaN becomes the worst value. */
        if (!(r.solve3_rel <= worst_rel)) {
            worst_rel = r.solve3_rel;
        }
        if (!(r.refit_corner_px <= worst_corner)) {
            worst_corner = r.refit_corner_px;
        }
        if (!(r.optimum_corner_px <= worst_opt)) {
            worst_opt = r.optimum_corner_px;
        }
    }
    out_str("golden solve3: worst relative entry error ");
    out_sci(worst_rel);
    out_str(" (tolerance ");
    out_sci(GOLDEN_TOL_SOLVE3_REL);
    out_str(")\ngolden refit: worst corner error ");
    out_float(worst_corner, 3);
    out_str(" px vs truth (< 0.5), ");
    out_float(worst_opt, 4);
    out_str(" px vs optimum (< 0.02)\n");

    spvs_real worst_ex = SPVS_R(0.0);
    for (int c = 0; c < SPVS_GOLDEN_N_E; ++c) {
        golden_e_result_t r;
        golden_run_e(&spvs_golden_e[c], &r);
        int ok = r.st == SPVS_OK && r.e_x_err_px <= r.e_x_tol_px && r.dir_sign_ok &&
                 r.sentinel_ok;
        out_fail_case("epipole", c, ok);
        fails += !ok;
        if (!(r.e_x_err_px <= worst_ex)) {
            worst_ex = r.e_x_err_px;
        }
    }
    out_str("golden epipole: worst e_x error ");
    out_float(worst_ex, 4);
    out_str(" px (tolerance max(0.5 px, 1e-3 |e_x|))\n");
    return fails;
}
