/* test_fixed_plane_h.c - the robust planar-motion homography in fixed
 * point (firmware/src/fixed/plane_h_q.c) against the float estimator
 * (plane_h.c) on the same frames with the same seed: random planar-motion
 * scenes with noise in both images and mismatches, the golden vectors,
 * and the input checks.  Figures: the statuses, the inlier counts and the
 * mean transfer of the image corners in pixels, against each other and
 * against the true H (docs/FIXED.md). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "unity.h"
#include "unit_support.h"

#include "core_util.h"
#include "fixed/plane_h_q.h"
#include "fixed/spvs_q.h"
#include "fixed_scene.h"
#include "golden/golden_vectors.h"
#include "spvs/plane_h.h"
#include "spvs/spvs.h"

/* ---- tolerances ------------------------------------------------------------ */

/* The Q estimator's mean corner error against the true H may exceed the
 * float estimator's by this much, pixels, on a scene's median: both fit
 * the same inliers by the same steps, and the Q sums and solves are more
 * accurate than float's (docs/FIXED.md), so only a different RANSAC path
 * (a point at the threshold, the stopping rule's count) can part them,
 * and then both are estimates of the same consensus. */
#define TOL_MEDIAN_EXCESS_PX 0.02
/* Scenes whose status differs between the builds, out of all: a status
 * decided at a threshold (SPVS_MIN_INLIERS reached by one build only). */
#define TOL_STATUS_DIFFER 2
/* The share of scenes on which the two estimates may be more than
 * TOL_AGREE_PX apart (corner transfer): those where RANSAC took another
 * path.  The rest agree to the rounding of the sums and solves. */
#define TOL_AGREE_PX 0.05
#define TOL_AGREE_SHARE 0.1

/* ---- helpers --------------------------------------------------------------- */

static double ld_h(int32_t q)
{
    return ldexp((double)q, -SPVS_QH);
}

/* The mean distance between the transfers of the image corners
 * (+-320, +-240 px) by two H in scaled units, pixels. */
static double corner_px(const double A[9], const double B[9])
{
    static const double c[4][2] = {{-320, -240}, {320, -240}, {320, 240}, {-320, 240}};
    double sum = 0;
    for (int k = 0; k < 4; k++) {
        const double x = c[k][0] / S, y = c[k][1] / S;
        const double wa = A[6] * x + A[7] * y + A[8], wb = B[6] * x + B[7] * y + B[8];
        const double ua = (A[0] * x + A[1] * y + A[2]) / wa, ub = (B[0] * x + B[1] * y + B[2]) / wb;
        const double va = y / wa, vb = y / wb;
        sum += hypot(ua - ub, va - vb) * S;
    }
    return sum / 4;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Both estimators on sc's matches with the same seed. */
typedef struct {
    int rc_f, rc_q;
    uint16_t inl_f, inl_q;
    uint32_t it_f, it_q;
    double Hf[9], Hq[9];
} both_t;

static spvs_plane_h_t g_ef;
static spvs_q_plane_h_t g_eq;

static void run_both(const spvs_match_t *m, uint16_t n, uint32_t seed, both_t *r)
{
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    const spvs_real inlier_px = spvs_inlier_px(&p);
    spvs_rng_t rf, rq;
    spvs_rng_seed(&rf, seed);
    spvs_rng_seed(&rq, seed);
    memset(r, 0, sizeof *r);
    r->rc_f = spvs_plane_h_load(&g_ef, m, n, NULL, 0);
    r->rc_q = spvs_q_plane_h_load(&g_eq, m, n, NULL, 0);
    TEST_ASSERT_EQUAL_INT64(r->rc_q, r->rc_f);
    if (r->rc_f != SPVS_OK) {
        return;
    }
    r->rc_f = spvs_plane_h_estimate(&g_ef, inlier_px, p.confidence, p.max_iters, &rf, &r->it_f);
    uint32_t sat = 0;
    const spvs_real t = inlier_px * (SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
    const spvs_qf_t t2 = spvs_q_t2_from_real(t * t, &sat);
    TEST_ASSERT_EQUAL_INT64(0, sat);
    /* The confidence 2^-32, as the fixed build reads it. */
    const uint32_t conf_q32 = (uint32_t)((double)p.confidence * 4294967296.0);
    r->rc_q = spvs_q_plane_h_estimate(&g_eq, t2, conf_q32, p.max_iters, &rq, &r->it_q);
    r->inl_f = g_ef.n_inliers;
    r->inl_q = g_eq.n_inliers;
    for (int k = 0; k < 9; k++) {
        r->Hf[k] = (double)g_ef.H_sc[k];
        r->Hq[k] = ld_h(g_eq.H[k]);
    }
}

/* ---- random scenes ---------------------------------------------------------- */

#define N_SCENES 300

static void test_plane_h_random(void)
{
    static scene_t sc;
    static double ef[N_SCENES], eq[N_SCENES];
    uint64_t rng = 2718;
    int compared = 0, status_differ = 0, apart = 0, inl_differ = 0;
    double worst_agree = 0;
    long it_f = 0, it_q = 0;
    for (int c = 0; c < N_SCENES; c++) {
        make_scene(&sc, &rng, 30 + (int)(synth_uniform(&rng) * 226), 1.0,
                   0.4 * synth_uniform(&rng));
        if (sc.n < 3) {
            continue;
        }
        both_t r;
        run_both(sc.m, sc.n, (uint32_t)(1000 + c), &r);
        if (r.rc_f != r.rc_q) {
            status_differ++;
            continue;
        }
        if (r.rc_f != SPVS_OK) {
            continue;
        }
        double Ht[9];
        for (int k = 0; k < 9; k++) {
            Ht[k] = (double)sc.Hs[k];
        }
        ef[compared] = corner_px(r.Hf, Ht);
        eq[compared] = corner_px(r.Hq, Ht);
        const double d = corner_px(r.Hf, r.Hq);
        if (d > TOL_AGREE_PX) {
            apart++;
        } else if (d > worst_agree) {
            worst_agree = d;
        }
        inl_differ += r.inl_f != r.inl_q;
        it_f += (long)r.it_f;
        it_q += (long)r.it_q;
        compared++;
    }
    qsort(ef, (size_t)compared, sizeof ef[0], cmp_double);
    qsort(eq, (size_t)compared, sizeof eq[0], cmp_double);
    const double med_f = ef[compared / 2], med_q = eq[compared / 2];
    UNIT_NOTE("plane_h random: %d estimates, statuses differ in %d; corner error against the "
                  "true H, median float %.4f px, Q %.4f px, 90th %.4f / %.4f px; the two apart by "
                  "more than %.2f px in %d (largest below it %.2g px); inlier counts differ in %d; "
                  "hypotheses float %ld, Q %ld\n", compared, status_differ, med_f, med_q, ef[compared * 9 / 10], eq[compared * 9 / 10], TOL_AGREE_PX, apart, worst_agree, inl_differ, it_f, it_q);
    TEST_ASSERT_TRUE(compared > N_SCENES / 2);
    TEST_ASSERT_TRUE(status_differ <= TOL_STATUS_DIFFER);
    TEST_ASSERT_TRUE(med_q <= med_f + TOL_MEDIAN_EXCESS_PX);
    TEST_ASSERT_TRUE((double)apart <= TOL_AGREE_SHARE * compared);
}

/* ---- the golden vectors ---------------------------------------------------- */

/* The golden case's 40 noisy matches. */
static void golden_matches(const spvs_golden_h_t *g, spvs_match_t *m)
{
    for (uint16_t i = 0; i < SPVS_GOLDEN_N_NOISY; i++) {
        m[i].x_tgt = (spvs_real)g->noisy[i][0];
        m[i].y_tgt = (spvs_real)g->noisy[i][1];
        m[i].x_cur = (spvs_real)g->noisy[i][2];
        m[i].y_cur = (spvs_real)g->noisy[i][3];
        m[i].feature = i;
    }
}

/* Every golden case (40 plane matches, 0.5 px noise in both images): both
 * estimators find every point an inlier, and the Q estimate is as near the
 * least-squares optimum as the float one. */
static void test_plane_h_golden(void)
{
    static spvs_match_t m[SPVS_GOLDEN_N_NOISY];
    double worst_f = 0, worst_q = 0, worst_fq = 0;
    for (int c = 0; c < SPVS_GOLDEN_N_H; c++) {
        const spvs_golden_h_t *g = &spvs_golden_h[c];
        golden_matches(g, m);
        both_t r;
        run_both(m, SPVS_GOLDEN_N_NOISY, 7u + (uint32_t)c, &r);
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, r.rc_f);
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, r.rc_q);
        TEST_ASSERT_EQUAL_INT64(SPVS_GOLDEN_N_NOISY, r.inl_q);
        TEST_ASSERT_EQUAL_INT64(SPVS_GOLDEN_N_NOISY, r.inl_f);
        spvs_real Hs[9];
        double Hfit[9];
        rescale_scaled(g->H_fit, Hs);
        for (int k = 0; k < 9; k++) {
            Hfit[k] = (double)Hs[k];
        }
        worst_f = fmax(worst_f, corner_px(r.Hf, Hfit));
        worst_q = fmax(worst_q, corner_px(r.Hq, Hfit));
        worst_fq = fmax(worst_fq, corner_px(r.Hf, r.Hq));
    }
    UNIT_NOTE("plane_h golden: largest corner distance to the least-squares optimum float "
                  "%.4f px, Q %.4f px; float to Q %.4f px\n", worst_f, worst_q, worst_fq);
    TEST_ASSERT_TRUE(worst_q <= worst_f + TOL_MEDIAN_EXCESS_PX);
    TEST_ASSERT_TRUE(worst_fq <= TOL_AGREE_PX);
}

/* ---- the pipeline's estimation stage (spvs_q_estimate_h) ------------------- */

/* The mean distance between the transfers of the image corners by two H
 * in centred pixels (out->H), pixels. */
static double corner_px_px(const spvs_real A[9], const spvs_real B[9])
{
    static const double c[4][2] = {{-320, -240}, {320, -240}, {320, 240}, {-320, 240}};
    double sum = 0;
    for (int k = 0; k < 4; k++) {
        double t[2][2];
        const spvs_real *H[2] = {A, B};
        for (int j = 0; j < 2; j++) {
            const double w = (double)H[j][6] * c[k][0] + (double)H[j][7] * c[k][1] + (double)H[j][8];
            t[j][0] = ((double)H[j][0] * c[k][0] + (double)H[j][1] * c[k][1] + (double)H[j][2]) / w;
            t[j][1] = c[k][1] / w;
        }
        sum += hypot(t[0][0] - t[1][0], t[0][1] - t[1][1]);
    }
    return sum / 4;
}

static spvs_t g_sf;
static spvs_q_t g_sq;

/* spvs_estimate_h's twin on every golden case: the same status, every
 * match an inlier, the command (0, 0), and H in pixels within
 * TOL_AGREE_PX (corner transfer) of the float pipeline's; the input
 * statuses as the float pipeline's. */
static void test_estimate_h_pipeline(void)
{
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_init(&g_sf, &p));
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_init(&g_sq, &p));
    static spvs_match_t m[SPVS_GOLDEN_N_NOISY];
    double worst = 0;
    for (int c = 0; c < SPVS_GOLDEN_N_H; c++) {
        const spvs_golden_h_t *g = &spvs_golden_h[c];
        golden_matches(g, m);
        spvs_output_t of, oq;
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_estimate_h(&g_sf, m, SPVS_GOLDEN_N_NOISY, &of));
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_estimate_h(&g_sq, m, SPVS_GOLDEN_N_NOISY, &oq));
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, oq.status);
        TEST_ASSERT_EQUAL_INT64(1, oq.h_valid);
        TEST_ASSERT_EQUAL_INT64(SPVS_GOLDEN_N_NOISY, oq.n_matches);
        TEST_ASSERT_EQUAL_INT64(SPVS_GOLDEN_N_NOISY, oq.n_inliers);
        TEST_ASSERT_EQUAL_INT64(SPVS_GOLDEN_N_NOISY, of.n_inliers);
        TEST_ASSERT_TRUE(oq.ransac_iters >= 1);
        TEST_ASSERT_TRUE(oq.v == SPVS_R(0.0) && oq.w == SPVS_R(0.0));
        worst = fmax(worst, corner_px_px(of.H, oq.H));
    }
    UNIT_NOTE("estimate_h golden: float and Q pipelines' H at most %.4f px apart\n", worst);
    TEST_ASSERT_TRUE(worst <= TOL_AGREE_PX);
    spvs_output_t o;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_q_estimate_h(NULL, m, 10, &o));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_q_estimate_h(&g_sq, m, 10, NULL));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_TOO_FEW, spvs_q_estimate_h(&g_sq, m, 2, &o));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_TOO_FEW, spvs_estimate_h(&g_sf, m, 2, &o));
    TEST_ASSERT_EQUAL_INT64(0, o.h_valid);
    m[3].x_cur = (spvs_real)NAN;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NONFINITE, spvs_q_estimate_h(&g_sq, m, 20, &o));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NONFINITE, o.status);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NONFINITE, spvs_estimate_h(&g_sf, m, 20, &o));
}

/* ---- the input checks ------------------------------------------------------ */

static void test_plane_h_load_statuses(void)
{
    static spvs_match_t m[SPVS_MAX_MATCHES + 1];
    for (int i = 0; i <= SPVS_MAX_MATCHES; i++) {
        m[i].x_tgt = (spvs_real)(i % 17);
        m[i].y_tgt = (spvs_real)(i % 13) + SPVS_R(1.0);
        m[i].x_cur = (spvs_real)(i % 11);
        m[i].y_cur = SPVS_R(2.0);
        m[i].feature = (uint16_t)i;
    }
    TEST_ASSERT_EQUAL_INT64(SPVS_E_CAPACITY, spvs_q_plane_h_load(&g_eq, m, SPVS_MAX_MATCHES + 1, NULL, 0));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_q_plane_h_load(&g_eq, NULL, 5, NULL, 0));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_TOO_FEW, spvs_q_plane_h_load(&g_eq, m, 2, NULL, 0));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_TOO_FEW, spvs_q_plane_h_load(&g_eq, m, 7, NULL, 0));
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_plane_h_load(&g_eq, m, 20, NULL, 0));
    m[3].x_cur = (spvs_real)NAN;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NONFINITE, spvs_q_plane_h_load(&g_eq, m, 20, NULL, 0));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NONFINITE, spvs_plane_h_load(&g_ef, m, 20, NULL, 0));
    m[3].x_cur = (spvs_real)(SPVS_MAX_COORD_PX + 1);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_RANGE, spvs_q_plane_h_load(&g_eq, m, 20, NULL, 0));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_RANGE, spvs_plane_h_load(&g_ef, m, 20, NULL, 0));
    m[3].x_cur = SPVS_R(0.0);
    m[4].feature = SPVS_MAX_FEATURES;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_RANGE, spvs_q_plane_h_load(&g_eq, m, 20, NULL, 0));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_RANGE, spvs_plane_h_load(&g_ef, m, 20, NULL, 0));
    m[4].feature = 4;
    /* Several kinds of bad value: the first in match order decides, in
     * both cores. */
    static const struct {
        int range_at, nan_at, feature_at, want;
    } mixed[] = {
        {0, 1, -1, SPVS_E_RANGE},      /* x_cur out of range, then a NaN */
        {1, 0, -1, SPVS_E_NONFINITE},  /* the NaN first                  */
        {-1, 1, 0, SPVS_E_RANGE},      /* a feature out of range first   */
        {2, 2, -1, SPVS_E_NONFINITE},  /* one match: y_tgt NaN before x_cur */
    };
    for (unsigned k = 0; k < sizeof mixed / sizeof mixed[0]; k++) {
        static spvs_match_t b[20];
        memcpy(b, m, sizeof b);
        if (mixed[k].range_at >= 0) {
            b[mixed[k].range_at].x_cur = (spvs_real)(SPVS_MAX_COORD_PX + 1);
        }
        if (mixed[k].nan_at >= 0) {
            if (mixed[k].nan_at == mixed[k].range_at) {
                b[mixed[k].nan_at].y_tgt = (spvs_real)NAN;
            } else {
                b[mixed[k].nan_at].x_cur = (spvs_real)NAN;
            }
        }
        if (mixed[k].feature_at >= 0) {
            b[mixed[k].feature_at].feature = SPVS_MAX_FEATURES;
        }
        TEST_ASSERT_EQUAL_INT64(mixed[k].want, spvs_plane_h_load(&g_ef, b, 20, NULL, 0));
        TEST_ASSERT_EQUAL_INT64(mixed[k].want, spvs_q_plane_h_load(&g_eq, b, 20, NULL, 0));
    }
    /* Exactly at the limit is in range, one float above it is not. */
    {
        static spvs_match_t b[20];
        memcpy(b, m, sizeof b);
        b[5].x_tgt = (spvs_real)SPVS_MAX_COORD_PX;
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_plane_h_load(&g_eq, b, 20, NULL, 0));
        b[5].x_tgt = nextafterf((float)SPVS_MAX_COORD_PX, 1e9f);
        b[6].x_cur = (spvs_real)NAN;
        TEST_ASSERT_EQUAL_INT64(SPVS_E_RANGE, spvs_plane_h_load(&g_ef, b, 20, NULL, 0));
        TEST_ASSERT_EQUAL_INT64(SPVS_E_RANGE, spvs_q_plane_h_load(&g_eq, b, 20, NULL, 0));
    }
}

void suite_fixed_plane_h(void)
{
    UNIT_SUITE_FILE();
    RUN_TEST(test_plane_h_load_statuses);
    RUN_TEST(test_plane_h_golden);
    RUN_TEST(test_plane_h_random);
    RUN_TEST(test_estimate_h_pipeline);
}

UNIT_MAIN(suite_fixed_plane_h)
