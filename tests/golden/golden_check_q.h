/*
 * golden_check_q.h - the golden vectors (golden_vectors.h) on the
 * fixed-point core, checked in integers only: shared by the host test
 * (tests/test_golden_fixed.c) and the Cortex-M3 image of the fixed-point
 * build (target/golden_run_q.c), which links no floating-point helper.
 * The vectors are read as spvs_real (include golden_vectors.h with
 * SPVS_GOLDEN_T spvs_real first) through their bits (q.h), so host and
 * target compute the same integers.
 *
 *   solve3   the Q 3-point solver (spvs_q_solve3) on each case's exact
 *            triple: every entry of H within max|H| 2^-GOLDEN_Q_SOLVE3_SHIFT
 *            of the true H (scaled units, Q27);
 *   estimate the Q pipeline's estimate (spvs_q_estimate_h) on the 40 noisy
 *            matches (0.5 px in both images): all 40 inliers, the mean
 *            transfer of the image corners within GOLDEN_Q_CORNER_Q18 of
 *            the true H's and within GOLDEN_Q_OPTIMUM_Q18 of the
 *            least-squares optimum's;
 *   epipole  the Q epipole (spvs_q_epipole_estimate) from the true H and
 *            the 12 off-plane points: e_x within max(0.5 px, 1e-3 |e_x|)
 *            of e = K(-R c), the side (dir_z) right.
 * docs/FIXED.md, "Golden vectors and the replay on the Cortex-M3", gives
 * the measured errors behind the tolerances.
 */
#ifndef SPVS_GOLDEN_CHECK_Q_H
#define SPVS_GOLDEN_CHECK_Q_H

#include <stdint.h>

#include "spvs_q.h"

/* Tolerances.  Pixels in Q18 (a Q27 scaled unit is 512 px), e_x in Q16. */
#define GOLDEN_Q_SOLVE3_SHIFT 18                  /* 3.8e-6 of max|H|      */
#define GOLDEN_Q_CORNER_Q18 ((int64_t)1 << 17)    /* 0.5 px, as float's    */
/* The estimate minimises the Sampson error over both images (docs/
 * ESTIMATION.md); the optimum is the forward transfer error's least
 * squares, so the two part by some hundredths of a pixel. */
#define GOLDEN_Q_OPTIMUM_Q18 ((int64_t)1 << 15)   /* 0.125 px              */
#define GOLDEN_Q_EX_MIN_Q16 ((int64_t)1 << 15)    /* 0.5 px                */
#define GOLDEN_Q_EX_REL_DIV 1000                  /* 1e-3 |e_x|            */
#define GOLDEN_Q_SIN_TOL2_Q30 10737418            /* 0.01 (golden_check.h) */
#define GOLDEN_Q_MIN_SUPPORT 8u
/* log2 SPVS_COORD_SCALE: pixels to scaled units by the format alone. */
#define GOLDEN_Q_LOG2_SCALE 9

/* x in Qf through its bits (*bad set on NaN, infinity or saturation). */
static inline int32_t golden_q_in(spvs_real x, int f, int *bad)
{
    uint32_t sat = 0;
    const int32_t q = spvs_q_from_ieee(spvs_q_real_parts(x), f, &sat, 0);
    if (sat != 0u) {
        *bad = 1;
    }
    return q;
}

/* H in centred pixels (h22 = 1) to Q27 scaled units: h13 / 512, h31 and
 * h32 x 512, the rest as they are. */
static inline void golden_q_h_in(const spvs_real Hpx[9], int32_t Hq[9], int *bad)
{
    for (int k = 0; k < 9; k++) {
        const int f = k == 2 ? SPVS_QH - GOLDEN_Q_LOG2_SCALE
                             : (k == 6 || k == 7 ? SPVS_QH + GOLDEN_Q_LOG2_SCALE : SPVS_QH);
        Hq[k] = golden_q_in(Hpx[k], f, bad);
    }
}

/* The largest |A_k - B_k| against max |B_k| 2^-shift: 1 when within. */
static inline int golden_q_h_close(const int32_t A[9], const int32_t B[9], int shift,
                                   int64_t *worst_diff, int64_t *max_b)
{
    int64_t d = 0, m = 0;
    for (int k = 0; k < 9; k++) {
        const int64_t a = (int64_t)A[k] - B[k];
        const int64_t ad = a < 0 ? -a : a;
        const int64_t b = B[k] < 0 ? -(int64_t)B[k] : B[k];
        d = ad > d ? ad : d;
        m = b > m ? b : m;
    }
    *worst_diff = d;
    *max_b = m;
    return d <= (m >> shift);
}

/* Corner (cx, cy) in pixels transferred by Hq (Q27 scaled units): Q27
 * scaled, which is Q18 pixels.  0 when the corner is behind the camera. */
static inline int golden_q_transfer(const int32_t Hq[9], int32_t cx, int32_t cy, int64_t *u,
                                    int64_t *v)
{
    /* A corner in scaled units, Q27: px 2^27 / 512 = px 2^18. */
    const int64_t x = (int64_t)cx * ((int64_t)1 << 18), y = (int64_t)cy * ((int64_t)1 << 18);
    /* Q54 sums: |h| < 16 (2^31 in Q27), |x|, |y| < 1 (2^27): below 2^60. */
    const int64_t num = (int64_t)Hq[0] * x + (int64_t)Hq[1] * y + (int64_t)Hq[2] * ((int64_t)1 << 27);
    const int64_t den = (int64_t)Hq[6] * x + (int64_t)Hq[7] * y + (int64_t)Hq[8] * ((int64_t)1 << 27);
    const int64_t den27 = den / ((int64_t)1 << 27);
    if (den27 <= 0) {
        return 0;
    }
    *u = num / den27;
    *v = y * ((int64_t)1 << 27) / den27;
    return 1;
}

/* The mean distance between the transfers of the image corners (+-320,
 * +-240 px) by A and B, Q18 pixels (INT64_MAX when a corner is behind
 * either camera; each distance capped at 2^30, 4096 px). */
static inline int64_t golden_q_corner_q18(const int32_t A[9], const int32_t B[9])
{
    static const int32_t c[4][2] = {{-320, -240}, {320, -240}, {320, 240}, {-320, 240}};
    int64_t sum = 0;
    for (int k = 0; k < 4; k++) {
        int64_t ua, va, ub, vb;
        if (!golden_q_transfer(A, c[k][0], c[k][1], &ua, &va) ||
            !golden_q_transfer(B, c[k][0], c[k][1], &ub, &vb)) {
            return INT64_MAX;
        }
        int64_t du = ua - ub, dv = va - vb;
        const int64_t cap = (int64_t)1 << 30;
        du = du > cap ? cap : (du < -cap ? -cap : du);
        dv = dv > cap ? cap : (dv < -cap ? -cap : dv);
        sum += (int64_t)spvs_q_isqrt64((uint64_t)(du * du) + (uint64_t)(dv * dv));
    }
    return sum / 4;
}

/* ---- one homography case ---------------------------------------------------- */

typedef struct {
    int st_solve3;          /* spvs_q_solve3 on the exact triple           */
    int64_t solve3_diff;    /* its largest entry error, Q27                */
    int64_t solve3_max;     /* max |H| of the true H, Q27                  */
    int solve3_ok;
    int st_estimate;        /* spvs_q_estimate_h on the 40 noisy matches   */
    uint16_t n_inliers;
    int64_t corner_q18;     /* the estimate against the true H             */
    int64_t optimum_q18;    /* the estimate against the optimum H_fit      */
    int inputs_ok;          /* every golden value read without saturation  */
} golden_q_h_result_t;

/* The instances, static as on a robot (the pipeline's is several KiB). */
static spvs_q_plane_h_t golden_q_est;
static spvs_q_t golden_q_core;

/* tamper_q27: added to h11 of the true H before the checks (0: none), so
 * that a test can prove the checks fail. */
static inline void golden_q_run_h(const spvs_golden_h_t *g, int32_t tamper_q27,
                                  golden_q_h_result_t *r)
{
    int bad = 0;
    int32_t Ht[9], Hfit[9];
    golden_q_h_in(g->H, Ht, &bad);
    golden_q_h_in(g->H_fit, Hfit, &bad);
    Ht[0] += tamper_q27;

    static spvs_match_t m[SPVS_GOLDEN_N_NOISY];
    for (uint16_t i = 0; i < 3; i++) {
        m[i].x_tgt = g->exact[i][0];
        m[i].y_tgt = g->exact[i][1];
        m[i].x_cur = g->exact[i][2];
        m[i].y_cur = g->exact[i][3];
        m[i].feature = i;
    }
    /* Three points are too few for an estimate (SPVS_E_TOO_FEW), but the
     * store is loaded, in an order the solver does not care about. */
    const int st_load = spvs_q_plane_h_load(&golden_q_est, m, 3, 0, 0);
    static const uint16_t idx[3] = {0, 1, 2};
    int32_t Hq[9] = {0};
    r->st_solve3 = st_load == SPVS_E_TOO_FEW ? spvs_q_solve3(&golden_q_est.pts, idx, Hq) : st_load;
    r->solve3_ok = r->st_solve3 == SPVS_OK &&
                   golden_q_h_close(Hq, Ht, GOLDEN_Q_SOLVE3_SHIFT, &r->solve3_diff, &r->solve3_max);

    for (uint16_t i = 0; i < SPVS_GOLDEN_N_NOISY; i++) {
        m[i].x_tgt = g->noisy[i][0];
        m[i].y_tgt = g->noisy[i][1];
        m[i].x_cur = g->noisy[i][2];
        m[i].y_cur = g->noisy[i][3];
        m[i].feature = i;
    }
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    spvs_output_t out;
    r->st_estimate = spvs_q_init(&golden_q_core, &p);
    if (r->st_estimate == SPVS_OK) {
        r->st_estimate = spvs_q_estimate_h(&golden_q_core, m, SPVS_GOLDEN_N_NOISY, &out);
    }
    r->n_inliers = r->st_estimate == SPVS_OK ? out.n_inliers : 0u;
    r->corner_q18 = INT64_MAX;
    r->optimum_q18 = INT64_MAX;
    if (r->st_estimate == SPVS_OK) {
        int32_t He[9];
        golden_q_h_in(out.H, He, &bad);
        r->corner_q18 = golden_q_corner_q18(He, Ht);
        r->optimum_q18 = golden_q_corner_q18(He, Hfit);
    }
    r->inputs_ok = !bad;
}

/* 1 when every check of the case holds. */
static inline int golden_q_h_ok(const golden_q_h_result_t *r)
{
    return r->inputs_ok && r->solve3_ok && r->st_estimate == SPVS_OK &&
           r->n_inliers == SPVS_GOLDEN_N_NOISY && r->corner_q18 <= GOLDEN_Q_CORNER_Q18 &&
           r->optimum_q18 <= GOLDEN_Q_OPTIMUM_Q18;
}

/* ---- one epipole case ------------------------------------------------------- */

typedef struct {
    int st;                 /* spvs_q_epipole_estimate                      */
    int32_t e_x_q16;
    int64_t err_q16;        /* |e_x - truth|                                */
    int64_t tol_q16;        /* max(0.5 px, 1e-3 |truth|)                    */
    int side_ok;            /* sign(dir_z) == sign(e_cam_z)                 */
    uint16_t n_support;
    int inputs_ok;
} golden_q_e_result_t;

static inline void golden_q_run_e(const spvs_golden_e_t *g, golden_q_e_result_t *r)
{
    int bad = 0;
    int32_t H[9];
    golden_q_h_in(g->H, H, &bad);
    /* Rows in Q26 scaled units: pixels in Q17. */
    static int32_t pts[SPVS_GOLDEN_N_OFF][4];
    static uint16_t cand[SPVS_GOLDEN_N_OFF];
    static uint8_t support[SPVS_GOLDEN_N_OFF];
    static spvs_q_epipole_work_t work;
    for (uint16_t i = 0; i < SPVS_GOLDEN_N_OFF; i++) {
        for (int k = 0; k < 4; k++) {
            pts[i][k] = golden_q_in(g->pts[i][k], 26 - GOLDEN_Q_LOG2_SCALE, &bad);
        }
        cand[i] = i;
    }
    spvs_q_epipole_t e = {0, 0, 0, 0, 0};
    r->st = spvs_q_epipole_estimate(H, (const int32_t(*)[4])pts, cand, SPVS_GOLDEN_N_OFF,
                                    GOLDEN_Q_SIN_TOL2_Q30, GOLDEN_Q_MIN_SUPPORT, &e, support,
                                    &work);
    const int64_t truth = golden_q_in(g->e_x_px, 16, &bad);
    const int64_t d = (int64_t)e.e_x_q16 - truth;
    r->e_x_q16 = e.e_x_q16;
    r->err_q16 = d < 0 ? -d : d;
    const int64_t rel = (truth < 0 ? -truth : truth) / GOLDEN_Q_EX_REL_DIV;
    r->tol_q16 = rel > GOLDEN_Q_EX_MIN_Q16 ? rel : GOLDEN_Q_EX_MIN_Q16;
    const int ahead = !spvs_q_real_parts(g->e_cam[2]).neg;
    r->side_ok = ahead ? e.dir_z > 0 : e.dir_z < 0;
    r->n_support = e.n_support;
    r->inputs_ok = !bad;
}

static inline int golden_q_e_ok(const golden_q_e_result_t *r)
{
    return r->inputs_ok && r->st == SPVS_OK && r->err_q16 <= r->tol_q16 && r->side_ok &&
           r->n_support >= GOLDEN_Q_MIN_SUPPORT;
}

#endif /* SPVS_GOLDEN_CHECK_Q_H */
