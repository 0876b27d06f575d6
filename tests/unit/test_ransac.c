/* test_ransac.c - RANSAC's loop bound, adaptive count, tie-break, PRNG and
 * the planar estimator recovering the inlier set (ransac.h, spvs.h). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "unity.h"
#include "unit_support.h"

#include "spvs/ransac.h"
#include "spvs/instance.h"
#include "synth.h"

#define SENTINEL 0x5EA1C0DEu

/* A mock estimator: every fit succeeds (or none does), every model scores
 * `count` inliers with cost = model[0], which is the running number of the
 * fit call, so the tie-break is observable.  Model k's inliers are the
 * `count` points from k on (mod 100), so the mask tells which model it is
 * from (mock_mask_of). */
typedef struct {
    uint32_t fits;
    uint32_t scores;
    uint16_t count;
    int degenerate;
    int cost_down; /* 1: later models cost less */
    uint32_t costs;
    uint32_t refines;
} mock_t;

static int mock_fit(void *ctx, const uint16_t *sample, spvs_real *model)
{
    mock_t *m = (mock_t *)ctx;
    (void)sample;
    m->fits++;
    if (m->degenerate) {
        return SPVS_E_DEGENERATE;
    }
    model[0] = (spvs_real)m->fits;
    return SPVS_OK;
}

static uint16_t mock_score(void *ctx, const spvs_real *model, spvs_real t2, uint16_t need,
                           uint8_t *mask)
{
    mock_t *m = (mock_t *)ctx;
    (void)t2;
    (void)need;
    m->scores++;
    if (mask) {
        const uint16_t k = (uint16_t)model[0];
        for (uint16_t i = 0; i < 100; i++) {
            mask[i] = (uint8_t)((uint16_t)(i + 100u - k % 100u) % 100u < m->count);
        }
    }
    return m->count;
}

/* The model whose mask (mock_score) `mask` is, or -1 for none. */
static int mock_mask_of(const mock_t *m, const uint8_t *mask)
{
    for (uint16_t k = 0; k < 100; k++) {
        int same = 1;
        for (uint16_t i = 0; i < 100; i++) {
            same &= mask[i] == (uint8_t)((uint16_t)(i + 100u - k) % 100u < m->count);
        }
        if (same) {
            return k;
        }
    }
    return -1;
}

/* The cost of a model, given the mask score() wrote for it: the mask must
 * be that model's own (ransac.h). */
static spvs_real mock_cost(void *ctx, const spvs_real *model, const uint8_t *mask)
{
    mock_t *m = (mock_t *)ctx;
    m->costs++;
    TEST_ASSERT_EQUAL_INT64((int)((uint32_t)model[0] % 100u), mock_mask_of(m, mask));
    return m->cost_down ? SPVS_R(1000.0) - model[0] : model[0];
}

static int mock_refine(void *ctx, spvs_real *model, const uint8_t *mask)
{
    mock_t *m = (mock_t *)ctx;
    (void)model;
    (void)mask;
    m->refines++;
    return SPVS_OK;
}

/* The buffers of one spvs_ransac call on 100 points. */
typedef struct {
    spvs_rng_t rng;
    uint16_t idx[100];
    uint8_t scratch[100];
    spvs_real model[SPVS_MODEL_MAX];
    uint8_t mask[100];
    spvs_ransac_stats_t st;
} run_t;

/* Appends k mismatches to the n matches m[]: mismatch i keeps match i's
 * target point and takes a current point uniform in the 640 x 480 frame,
 * as feature n + i.  Returns the new count. */
static uint16_t add_mismatches(spvs_match_t *m, uint16_t n, int k, uint64_t *rng)
{
    const uint16_t n0 = n;
    for (int i = 0; i < k; i++) {
        m[n] = m[i];
        m[n].x_cur = (spvs_real)((synth_uniform(rng) - 0.5) * 640);
        m[n].y_cur = (spvs_real)((synth_uniform(rng) - 0.5) * 480);
        m[n].feature = (uint16_t)(n0 + i);
        n++;
    }
    return n;
}

static int run(const spvs_estimator_t *est, const spvs_ransac_opts_t *o, run_t *r)
{
    return spvs_ransac(est, o, &r->rng, r->idx, r->model, r->mask, r->scratch, &r->st);
}

/* The LO step polishes a new best only when at least a fifth of the points
 * are its inliers: a model with fewer is almost surely a contaminated
 * sample's, and polishing it is wasted. */
static void test_lo_only_plausible(void)
{
    mock_t mk = {0, 0, 19, 0, 0, 0, 0};
    spvs_estimator_t est = {3, 100, &mk, mock_fit, mock_score, mock_cost, mock_refine};
    spvs_ransac_opts_t o = {SPVS_R(1.0), SPVS_R(0.99), 50, 8};
    run_t r;
    spvs_rng_seed(&r.rng, 1);
    /* 19 of 100: never polished, still a consensus. */
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, run(&est, &o, &r));
    TEST_ASSERT_EQUAL_INT64(0, mk.refines);
    TEST_ASSERT_EQUAL_INT64(19, r.st.n_inliers);
    /* 20 of 100: the first model (the only new best; the others tie) is. */
    mk = (mock_t){0, 0, 20, 0, 0, 0, 0};
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, run(&est, &o, &r));
    TEST_ASSERT_EQUAL_INT64(1, mk.refines);
}

static void test_needed(void)
{
    /* log(0.01) / log(1 - 0.5^3) = 34.5 -> 35. */
    TEST_ASSERT_EQUAL_INT64(35, spvs_ransac_needed(SPVS_R(0.5), 3, SPVS_R(0.99), 1000));
    /* log(0.001) / log(1 - 0.8^3) = 9.63 -> 10. */
    TEST_ASSERT_EQUAL_INT64(10, spvs_ransac_needed(SPVS_R(0.8), 3, SPVS_R(0.999), 1000));
    TEST_ASSERT_EQUAL_INT64(1, spvs_ransac_needed(SPVS_R(1.0), 3, SPVS_R(0.99), 1000));
    TEST_ASSERT_EQUAL_INT64(77, spvs_ransac_needed(SPVS_R(0.0), 3, SPVS_R(0.99), 77));
    TEST_ASSERT_EQUAL_INT64(200, spvs_ransac_needed(SPVS_R(0.05), 3, SPVS_R(0.99), 200));
}

/* With half the data inliers the loop stops at exactly the adaptive count. */
static void test_exact_iterations(void)
{
    mock_t mk = {0, 0, 50, 0, 0, 0, 0};
    spvs_estimator_t est = {3, 100, &mk, mock_fit, mock_score, mock_cost, NULL};
    spvs_ransac_opts_t o = {SPVS_R(1.0), SPVS_R(0.99), 200, 8};
    spvs_rng_t rng;
    spvs_rng_seed(&rng, 1);
    uint16_t idx[100];
    uint8_t scratch[100];
    struct {
        spvs_real model[SPVS_MODEL_MAX];
        uint32_t guard;
    } out;
    struct {
        uint8_t mask[100];
        uint32_t guard;
    } mk_out;
    out.guard = SENTINEL;
    mk_out.guard = SENTINEL;
    spvs_ransac_stats_t st;
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_ransac(&est, &o, &rng, idx, out.model, mk_out.mask, scratch, &st));
    TEST_ASSERT_EQUAL_INT64(35, st.iters);
    TEST_ASSERT_EQUAL_INT64(35, mk.fits);
    /* One pass per hypothesis: the best's mask is kept, not scored again. */
    TEST_ASSERT_EQUAL_INT64(35, mk.scores);
    TEST_ASSERT_EQUAL_INT64(50, st.n_inliers);
    TEST_ASSERT_EQUAL_INT64(SENTINEL, out.guard);
    TEST_ASSERT_EQUAL_INT64(SENTINEL, mk_out.guard);
    /* Ties (always 50 inliers): the first, cheapest model is kept, and
     * the mask is its own, not the last hypothesis'. */
    TEST_ASSERT_TRUE(out.model[0] == SPVS_R(1.0));
    TEST_ASSERT_EQUAL_INT64(1, mock_mask_of(&mk, mk_out.mask));

    /* The cap bounds the loop. */
    mk = (mock_t){0, 0, 10, 0, 0, 0, 0};
    o.max_iters = 20;
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_ransac(&est, &o, &rng, idx, out.model, mk_out.mask, scratch, &st));
    TEST_ASSERT_EQUAL_INT64(20, st.iters);
    TEST_ASSERT_EQUAL_INT64(20, mk.fits);

    /* Ties broken by the lower cost: here later models are cheaper.  The
     * cost is asked for only at ties: the first tie costs both models, each
     * later one only the newcomer (the best's cost is kept). */
    mk = (mock_t){0, 0, 10, 0, 1, 0, 0};
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_ransac(&est, &o, &rng, idx, out.model, mk_out.mask, scratch, &st));
    TEST_ASSERT_TRUE(out.model[0] == SPVS_R(20.0));
    TEST_ASSERT_EQUAL_INT64(20, mock_mask_of(&mk, mk_out.mask));
    TEST_ASSERT_EQUAL_INT64(20, mk.costs);
    /* Later models costlier: the first stays. */
    mk = (mock_t){0, 0, 10, 0, 0, 0, 0};
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_ransac(&est, &o, &rng, idx, out.model, mk_out.mask, scratch, &st));
    TEST_ASSERT_TRUE(out.model[0] == SPVS_R(1.0));
    TEST_ASSERT_EQUAL_INT64(20, mk.costs);
    /* Without a cost callback a tie keeps the earlier model. */
    mk = (mock_t){0, 0, 10, 0, 1, 0, 0};
    est.cost = NULL;
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_ransac(&est, &o, &rng, idx, out.model, mk_out.mask, scratch, &st));
    TEST_ASSERT_TRUE(out.model[0] == SPVS_R(1.0));
    TEST_ASSERT_EQUAL_INT64(0, mk.costs);
    est.cost = mock_cost;
}

static void test_statuses(void)
{
    mock_t mk = {0, 0, 50, 1, 0, 0, 0};
    spvs_estimator_t est = {3, 100, &mk, mock_fit, mock_score, mock_cost, NULL};
    spvs_ransac_opts_t o = {SPVS_R(1.0), SPVS_R(0.99), 30, 8};
    run_t r;
    spvs_rng_seed(&r.rng, 1);
    /* Every sample degenerate: the cap, then a status. */
    TEST_ASSERT_EQUAL_INT64(SPVS_E_DEGENERATE, run(&est, &o, &r));
    TEST_ASSERT_EQUAL_INT64(30, r.st.iters);
    TEST_ASSERT_EQUAL_INT64(30, r.st.degenerate);
    /* Too few inliers for a consensus. */
    mk = (mock_t){0, 0, 5, 0, 0, 0, 0};
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NO_CONSENSUS, run(&est, &o, &r));
    /* Every model ties at 5 < min_inliers: no cost pass is spent on ties
     * that cannot make a consensus. */
    TEST_ASSERT_EQUAL_INT64(0, mk.costs);
    /* Too few data. */
    est.n = 2;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_TOO_FEW, run(&est, &o, &r));
    est.n = 100;
    /* Bad options. */
    o.confidence = SPVS_R(1.0);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, run(&est, &o, &r));
    o.confidence = SPVS_R(0.99);
    o.max_iters = SPVS_RANSAC_MAX_ITERS + 1;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, run(&est, &o, &r));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, run(NULL, &o, &r));
    /* With valid options again: the scratch mask missing, or the output
     * mask itself. */
    o.max_iters = 30;
    mk = (mock_t){0, 0, 50, 0, 0, 0, 0};
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, run(&est, &o, &r));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_ransac(&est, &o, &r.rng, r.idx, r.model, r.mask, NULL, &r.st));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_ransac(&est, &o, &r.rng, r.idx, r.model, r.mask, r.mask, &r.st));
}

static void test_rng(void)
{
    spvs_rng_t a, b;
    spvs_rng_seed(&a, 42);
    spvs_rng_seed(&b, 42);
    uint32_t hist[10] = {0};
    for (int i = 0; i < 100000; i++) {
        uint32_t x = spvs_rng_below(&a, 10);
        TEST_ASSERT_EQUAL_INT64(spvs_rng_below(&b, 10), x);
        TEST_ASSERT_TRUE(x < 10);
        hist[x]++;
    }
    /* Uniform within 5 standard deviations (sd ~ 95). */
    for (int k = 0; k < 10; k++) {
        TEST_ASSERT_TRUE(hist[k] > 10000 - 475 && hist[k] < 10000 + 475);
    }
}

/* The planar estimator with 50% mismatches returns exactly the plane points,
 * and the same seed gives the same result. */
static void test_planar_half_outliers(void)
{
    static spvs_plane_h_t e;
    uint64_t rng = 3;
    for (int t = 0; t < 10; t++) {
        synth_pose_t p = {-3 + synth_uniform(&rng), -10 + 4 * synth_uniform(&rng), -0.5 + synth_uniform(&rng)};
        synth_plane_t pl;
        synth_plane(&pl, 0.3, -0.6, -0.75, 45);
        spvs_match_t m[200];
        uint16_t n = synth_frame(&p, &pl, 800, 100, 0, 0.0, &rng, m, NULL);
        TEST_ASSERT_EQUAL_INT64(100, n);
        n = add_mismatches(m, n, 100, &rng);
        spvs_params_t prm;
        spvs_params_default(&prm, SPVS_METHOD_III);
        spvs_rng_t r1, r2;
        spvs_rng_seed(&r1, (uint32_t)t);
        spvs_rng_seed(&r2, (uint32_t)t);
        uint32_t it1 = 0, it2 = 0;
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_plane_h_load(&e, m, n, NULL, n));
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_plane_h_estimate(&e, spvs_inlier_px(&prm), prm.confidence, prm.max_iters,
                                               &r1, &it1));
        TEST_ASSERT_EQUAL_INT64(100, e.n_inliers);
        for (int i = 0; i < n; i++) {
            TEST_ASSERT_EQUAL_INT64(e.feat[i] < 100 ? 1 : 0, e.mask[i]);
        }
        double Ht[9], He[9];
        synth_H(&p, &pl, 800, Ht);
        spvs_real H1[9];
        for (int k = 0; k < 9; k++) {
            H1[k] = e.H_sc[k];
        }
        spvs_h_rescale(H1, (spvs_real)SPVS_COORD_SCALE);
        for (int k = 0; k < 9; k++) {
            He[k] = (double)H1[k];
        }
        TEST_ASSERT_TRUE(synth_corner_err(He, Ht) < 0.05);
        /* Determinism: same seed, same hypotheses, same H. */
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_plane_h_load(&e, m, n, NULL, n));
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_plane_h_estimate(&e, spvs_inlier_px(&prm), prm.confidence, prm.max_iters,
                                               &r2, &it2));
        TEST_ASSERT_EQUAL_INT64(it2, it1);
        spvs_real H2[9];
        for (int k = 0; k < 9; k++) {
            H2[k] = e.H_sc[k];
        }
        spvs_h_rescale(H2, (spvs_real)SPVS_COORD_SCALE);
        TEST_ASSERT_EQUAL_MEMORY(H2, H1, sizeof H1);
        TEST_ASSERT_TRUE(it1 <= SPVS_RANSAC_MAX_ITERS);
    }
}

/* The LO step's two passes lift the best model's inlier count close to the
 * plane's, so that the adaptive count stops early: N = 200 with 20 %
 * mismatches and 1 px noise on both images, confidence 0.999, 3 px (the
 * benchmark's case, docs/BENCHMARKS.md).  There the plane points within
 * 3 px are about 0.71 of all, which asks for about 16 hypotheses; with one
 * pass of the LO step the mean was about 25. */
static void test_lo_lifts_share(void)
{
    static spvs_t s;
    uint64_t rng = 17;
    double sum_iters = 0, sum_share = 0;
    const int frames = 60;
    for (int t = 0; t < frames; t++) {
        synth_pose_t p = {-3 + 3 * synth_uniform(&rng), -10 + 8 * synth_uniform(&rng),
                          -0.5 + synth_uniform(&rng)};
        synth_plane_t pl;
        synth_plane(&pl, 0.3, -0.6, -0.75, 45);
        spvs_match_t m[200];
        uint16_t n = synth_frame(&p, &pl, 800, 160, 0, 1.0, &rng, m, NULL);
        TEST_ASSERT_EQUAL_INT64(160, n);
        for (int i = 0; i < n; i++) {
            m[i].x_tgt = (spvs_real)(m[i].x_tgt + synth_gauss(&rng));
            m[i].y_tgt = (spvs_real)(m[i].y_tgt + synth_gauss(&rng));
        }
        n = add_mismatches(m, n, 40, &rng);
        spvs_params_t prm;
        spvs_params_default(&prm, SPVS_METHOD_III);
        prm.noise_px = 1;
        prm.confidence = SPVS_R(0.999);
        prm.seed = (uint32_t)(100 + t);
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_init(&s, &prm));
        spvs_output_t o;
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_estimate_h(&s, m, n, &o));
        sum_iters += o.ransac_iters;
        sum_share += (double)o.n_inliers / n;
    }
    UNIT_NOTE("LO: mean %.1f hypotheses, final inlier share %.3f\n", sum_iters / frames, sum_share / frames);
    TEST_ASSERT_TRUE(sum_iters / frames < 23.0);
    TEST_ASSERT_TRUE(sum_share / frames > 0.68);
}

void suite_ransac(void)
{
    UNIT_SUITE_FILE();
    RUN_TEST(test_needed);
    RUN_TEST(test_lo_only_plausible);
    RUN_TEST(test_exact_iterations);
    RUN_TEST(test_statuses);
    RUN_TEST(test_rng);
    RUN_TEST(test_planar_half_outliers);
    RUN_TEST(test_lo_lifts_share);
}

UNIT_MAIN(suite_ransac)
