/*
 * golden_check.h - the checks of the core against golden_vectors.h, written
 * once and shared by the host test (tests/unit/test_golden.c, Unity) and the
 * Cortex-M4F image (target/golden_run.c), so both run the same arithmetic.
 *
 * Everything here computes in spvs_real: on the float MCU build no double
 * operation is emitted (the image's nm check enforces it).  Include
 * golden_vectors.h first (with SPVS_GOLDEN_T defined as the caller wants).
 *
 * Tolerances (stated once, used by both runners):
 *   solve3 on 3 exact matches: max |H - H_true| over the entries, in the
 *     core's scaled units (pixels / SPVS_COORD_SCALE), divided by the
 *     Frobenius norm of H_true in the same units: <= 1e-4 (float), 1e-9
 *     (double);
 *   refit on 40 matches with 0.5 px noise: mean transfer error of the four
 *     image corners (+-320, +-240) against the true H: < 0.5 px, and
 *     against the least-squares optimum the generator found (in double, to
 *     convergence): < 0.02 px, so the refit minimises the stated cost;
 *   epipole from 12 noise-free off-plane matches: |e_x - e_x_true| <=
 *     max(0.5 px, 1e-3 |e_x_true|), and sign(dir_z) = sign(e_cam_z).
 */
#ifndef SPVS_GOLDEN_CHECK_H
#define SPVS_GOLDEN_CHECK_H

#include <math.h>
#include <stdint.h>

#include "spvs/common.h"
#include "spvs/epipole.h"
#include "spvs/homography.h"
#include "spvs/spvs.h"
#include "support/h_refit.h"

#if SPVS_USE_DOUBLE
#define GOLDEN_TOL_SOLVE3_REL SPVS_R(1e-9)
#else
#define GOLDEN_TOL_SOLVE3_REL SPVS_R(1e-4)
#endif
#define GOLDEN_TOL_CORNER_PX SPVS_R(0.5)
#define GOLDEN_TOL_OPTIMUM_PX SPVS_R(0.02)
#define GOLDEN_TOL_EX_PX SPVS_R(0.5)
#define GOLDEN_TOL_EX_REL SPVS_R(1e-3)
/* Epipole options: a candidate supports a hypothesis within ~5.7 deg, and
 * at least 8 of the 12 candidates must agree. */
#define GOLDEN_EPI_SIN_TOL2 SPVS_R(0.01)
#define GOLDEN_EPI_MIN_SUPPORT 8u
/* Written after every output buffer; a changed value means an overrun. */
#define GOLDEN_SENTINEL SPVS_R(-12345.0)

/* Pixels to the core's scaled units, n points. */
static inline void golden_to_scaled(const SPVS_GOLDEN_T (*px)[4], uint16_t n,
                                    spvs_real (*out)[4])
{
    const spvs_real inv = SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE;
    for (uint16_t i = 0; i < n; ++i) {
        for (int k = 0; k < 4; ++k) {
            out[i][k] = (spvs_real)px[i][k] * inv;
        }
    }
}

/* A golden H (pixels) as spvs_real. */
static inline void golden_h_copy(const SPVS_GOLDEN_T src[9], spvs_real dst[9])
{
    for (int k = 0; k < 9; ++k) {
        dst[k] = (spvs_real)src[k];
    }
}

/* Largest entry error of H_scaled against H_true_px (converted to scaled
 * units), relative to the Frobenius norm of the truth in scaled units. */
static inline spvs_real golden_h_rel_err(const spvs_real H_scaled[9],
                                         const SPVS_GOLDEN_T H_true_px[9])
{
    spvs_real T[9];
    golden_h_copy(H_true_px, T);
    spvs_h_rescale(T, SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
    spvs_real norm2 = SPVS_R(0.0);
    spvs_real worst = SPVS_R(0.0);
    for (int k = 0; k < 9; ++k) {
        norm2 += T[k] * T[k];
        spvs_real e = SPVS_FABS(H_scaled[k] - T[k]);
        /* A NaN entry must fail, so compare in the direction NaN loses. */
        if (!(e <= worst)) {
            worst = e;
        }
    }
    return worst / SPVS_SQRT(norm2);
}

/* Mean distance, pixels, between the images of the four corners (+-320,
 * +-240) under two homographies in pixels.  A corner mapped behind either
 * camera counts as an error of 1e6 px. */
static inline spvs_real golden_corner_err_px(const spvs_real A[9], const spvs_real B[9])
{
    static const spvs_real cx[4] = {SPVS_R(-320.0), SPVS_R(320.0), SPVS_R(320.0), SPVS_R(-320.0)};
    static const spvs_real cy[4] = {SPVS_R(-240.0), SPVS_R(-240.0), SPVS_R(240.0), SPVS_R(240.0)};
    spvs_real sum = SPVS_R(0.0);
    for (int k = 0; k < 4; ++k) {
        spvs_real wa = A[6] * cx[k] + A[7] * cy[k] + A[8];
        spvs_real wb = B[6] * cx[k] + B[7] * cy[k] + B[8];
        if (!(wa > SPVS_R(0.0)) || !(wb > SPVS_R(0.0))) {
            sum += SPVS_R(1e6);
            continue;
        }
        spvs_real ua = (A[0] * cx[k] + A[1] * cy[k] + A[2]) / wa;
        spvs_real va = (A[3] * cx[k] + A[4] * cy[k] + A[5]) / wa;
        spvs_real ub = (B[0] * cx[k] + B[1] * cy[k] + B[2]) / wb;
        spvs_real vb = (B[3] * cx[k] + B[4] * cy[k] + B[5]) / wb;
        sum += SPVS_SQRT((ua - ub) * (ua - ub) + (va - vb) * (va - vb));
    }
    return sum / SPVS_R(4.0);
}

/* Result of one homography case. */
typedef struct {
    int st_solve3;           /* status of spvs_h_solve3 on the exact triple   */
    spvs_real solve3_rel;    /* golden_h_rel_err of its H                     */
    int st_start;            /* status of spvs_h_solve3 on the start triple   */
    int st_refit;            /* status of h_refit on the 40 noisy points      */
    spvs_real refit_corner_px;   /* corner error of the refit vs true H       */
    spvs_real optimum_corner_px; /* corner error of the refit vs the optimum  */
    int sentinel_ok;         /* output buffers not overrun                     */
} golden_h_result_t;

/* Run one homography case through the core. */
static inline void golden_run_h(const spvs_golden_h_t *g, golden_h_result_t *r)
{
    spvs_real exact[3][4];
    spvs_real noisy[SPVS_GOLDEN_N_NOISY][4];
    spvs_real H[10];
    spvs_real Hpx_true[9], Hpx_fit[9];
    uint8_t use[SPVS_GOLDEN_N_NOISY + 1];

    golden_to_scaled(g->exact, 3, exact);
    H[9] = GOLDEN_SENTINEL;
    r->st_solve3 = spvs_h_solve3((const spvs_real(*)[4])exact, H);
    r->solve3_rel = golden_h_rel_err(H, g->H);

    /* The refit starts where RANSAC would: from the minimal solution of a
     * well-spread triple of the noisy points. */
    golden_to_scaled(g->noisy, SPVS_GOLDEN_N_NOISY, noisy);
    spvs_real start[3][4];
    for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 4; ++k) {
            start[i][k] = noisy[g->start[i]][k];
        }
    }
    r->st_start = spvs_h_solve3((const spvs_real(*)[4])start, H);
    for (int i = 0; i < SPVS_GOLDEN_N_NOISY; ++i) {
        use[i] = 1u;
    }
    use[SPVS_GOLDEN_N_NOISY] = 0xA5u;
    r->st_refit = h_refit((const spvs_real(*)[4])noisy, use, SPVS_GOLDEN_N_NOISY,
                          H_REFIT_MAX_ITERS, H);
    spvs_h_rescale(H, (spvs_real)SPVS_COORD_SCALE);
    golden_h_copy(g->H, Hpx_true);
    golden_h_copy(g->H_fit, Hpx_fit);
    r->refit_corner_px = golden_corner_err_px(H, Hpx_true);
    r->optimum_corner_px = golden_corner_err_px(H, Hpx_fit);
    r->sentinel_ok = (H[9] == GOLDEN_SENTINEL) && (use[SPVS_GOLDEN_N_NOISY] == 0xA5u);
}

/* Result of one epipole case. */
typedef struct {
    int st;                  /* status of spvs_epipole_estimate               */
    spvs_real e_x_px;        /* its e_x                                       */
    spvs_real e_x_err_px;    /* |e_x - truth|                                 */
    spvs_real e_x_tol_px;    /* max(0.5, 1e-3 |truth|)                        */
    int dir_sign_ok;         /* sign(dir_z) == sign(e_cam_z)                  */
    uint16_t n_support;
    int sentinel_ok;
} golden_e_result_t;

/* Run one epipole case through the core. */
static inline void golden_run_e(const spvs_golden_e_t *g, golden_e_result_t *r)
{
    spvs_real pts[SPVS_GOLDEN_N_OFF][4];
    spvs_real H[9];
    uint16_t cand[SPVS_GOLDEN_N_OFF];
    uint8_t support[SPVS_GOLDEN_N_OFF + 1];
    spvs_epipole_t e;
    /* Static, as the core's own instance keeps it: off the small MCU stack. */
    static spvs_epipole_work_t work;

    golden_to_scaled(g->pts, SPVS_GOLDEN_N_OFF, pts);
    golden_h_copy(g->H, H);
    spvs_h_rescale(H, SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
    for (uint16_t i = 0; i < SPVS_GOLDEN_N_OFF; ++i) {
        cand[i] = i;
    }
    support[SPVS_GOLDEN_N_OFF] = 0xA5u;
    e.e_x_px = SPVS_R(0.0);
    e.dir_z = SPVS_R(0.0);
    e.n_support = 0;
    r->st = spvs_epipole_estimate(H, (const spvs_real(*)[4])pts, cand,
                                  SPVS_GOLDEN_N_OFF, GOLDEN_EPI_SIN_TOL2,
                                  GOLDEN_EPI_MIN_SUPPORT, &e, support, &work);
    spvs_real truth = (spvs_real)g->e_x_px;
    r->e_x_px = e.e_x_px;
    r->e_x_err_px = SPVS_FABS(e.e_x_px - truth);
    if (r->e_x_err_px != r->e_x_err_px) {
        r->e_x_err_px = SPVS_REAL_MAX; /* NaN fails */
    }
    r->e_x_tol_px = GOLDEN_TOL_EX_REL * SPVS_FABS(truth);
    if (r->e_x_tol_px < GOLDEN_TOL_EX_PX) {
        r->e_x_tol_px = GOLDEN_TOL_EX_PX;
    }
    r->dir_sign_ok = ((spvs_real)g->e_cam[2] > SPVS_R(0.0)) ? (e.dir_z > SPVS_R(0.0))
                                                           : (e.dir_z < SPVS_R(0.0));
    r->n_support = e.n_support;
    r->sentinel_ok = support[SPVS_GOLDEN_N_OFF] == 0xA5u;
}

#endif /* SPVS_GOLDEN_CHECK_H */
