/*
 * test_fixed_accel.c - the fixed-point core's accelerators
 * (firmware/src/fixed/accel/) against its reference path, on the same
 * random scenes: the reference translation units are compiled into this
 * test under other names (ref_*), the accelerated ones come from the
 * library.
 *
 *   loader  the same store bit for bit (coordinates, bounds, flags), on
 *           good frames and on frames with NaN, infinite, huge, tiny and
 *           subnormal coordinates and out-of-range feature indices;
 *   count   the same inlier masks and counts, under the true H and under
 *           3-point models, for several `need` values (the early stop and
 *           the bail-out test at the same points);
 *   cost    within TOL_COST_PER_POINT a point of the reference's exact
 *           terms;
 *   sums    every term of SPVS_T_LIN, SPVS_T_FIT_Y, SPVS_T_FIT_X and
 *           SPVS_T_SAMPSON within TOL_SUM of the largest term of its block
 *           (the fast paths' weights keep 2^-20 to 2^-25 of their bound
 *           over the frame, docs/FIXED.md), and the same return values;
 *   off-plane test  the same answer for every row, both ways round, at
 *           thresholds from 0.01 px to 1,000 px and at each row's own
 *           transfer error (one unit of Q16 px either side);
 *   cone    the epipole's support test: the same answer for every pair (a
 *           third within 1e-8 rad of the cone's edge), every count exact
 *           from `need` on and below `need` under it, the same floor
 *           square roots.
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "unit_support.h"

#include "fixed/epipole_cone_q.h"
#include "fixed/epipole_q.h"
#include "fixed/offplane_test_q.h"
#include "fixed/points_q.h"
#include "fixed/sums_q.h"
#include "spvs/homography.h"
#include "synth.h"

/* The reference path's definitions under their own names. */
#define spvs_q_pts_load ref_q_pts_load
#include "fixed/load_q.c"
#undef spvs_q_pts_load
#define spvs_q_thr ref_q_thr
#define spvs_q_pts_score ref_q_pts_score
#include "fixed/score_q.c"
#undef spvs_q_thr
#undef spvs_q_pts_score
#define spvs_q_pts_cost ref_q_pts_cost
#define spvs_q_pts_sum ref_q_pts_sum
#define spvs_q_lin_move ref_q_lin_move
#define spvs_q_sum_fast ref_q_sum_fast
#include "fixed/sums_q.c"
#undef spvs_q_pts_cost
#undef spvs_q_pts_sum
#undef spvs_q_lin_move
#undef spvs_q_sum_fast
#define spvs_q_off_thr ref_q_off_thr
#define spvs_q_off_above ref_q_off_above
#include "fixed/offplane_test_q.c"
#undef spvs_q_off_thr
#undef spvs_q_off_above
#define spvs_q_cone_supports ref_q_cone_supports
#define spvs_q_cone_count ref_q_cone_count
#define spvs_q_sqrt_floor ref_q_sqrt_floor
#include "fixed/epipole_cone_q.c"
#undef spvs_q_cone_supports
#undef spvs_q_cone_count
#undef spvs_q_sqrt_floor

#include "fixed_scene.h"

/* The cost's fast terms are within 2^-32 (|ex| + |ey|) + 2^-66 of the
 * exact ones (scaled units^2), and its residuals are below 8 px (2^-6
 * scaled units; larger ones take the exact term): under 2^-36 a point,
 * 2^16 units of the cost's Q52 with the rounding of the blocks. */
#define TOL_COST_PER_POINT 65536.0
/* A sum's term against the reference's, relative to its block's largest
 * reference term: the fast paths' weights keep 2^-20 to 2^-25 of their
 * bound over the frame. */
#define TOL_SUM 0x1p-20

#define SCENES 60

/* The two loaders on the same matches: the same store, features and
 * flags. */
static void check_load(const spvs_match_t *m, uint16_t n, uint16_t stride)
{
    static spvs_q_store_t a, b;
    uint16_t fa[NMAX], fb[NMAX];
    memset(&a, 0x55, sizeof a);
    memset(&b, 0x55, sizeof b);
    const uint32_t ra = spvs_q_pts_load(&a, fa, m, n, n, NULL, stride);
    const uint32_t rb = ref_q_pts_load(&b, fb, m, n, n, NULL, stride);
    TEST_ASSERT_EQUAL_INT64(ra, rb);
    TEST_ASSERT_EQUAL_MEMORY(a.v, b.v, 4u * n * sizeof a.v[0]);
    TEST_ASSERT_EQUAL_MEMORY(a.cur_max, b.cur_max, sizeof a.cur_max);
    TEST_ASSERT_EQUAL_MEMORY(a.tgt_max, b.tgt_max, sizeof a.tgt_max);
    TEST_ASSERT_EQUAL_MEMORY(fa, fb, n * sizeof fa[0]);
}

static void test_accel_load(void)
{
    uint64_t rng = 0x10adu;
    static scene_t sc;
    long frames = 0;
    for (int s = 0; s < SCENES; s++) {
        make_scene(&sc, &rng, 40 + (int)(synth_uniform(&rng) * 200), 1.0, 0.2);
        check_load(sc.m, sc.n, 1);
        frames++;
        /* Coordinates at every binade the fast path takes or leaves, and
         * values it must refuse: one match changed at a time. */
        const spvs_real zero = (spvs_real)(synth_uniform(&rng) * 0.0);
        const spvs_real odd[] = {zero / zero,
                                 (spvs_real)1.0 / zero,
                                 -(spvs_real)1.0 / zero,
                                 (spvs_real)SPVS_MAX_COORD_PX,
                                 (spvs_real)SPVS_MAX_COORD_PX * (spvs_real)1.0000001,
                                 (spvs_real)-5000.5,
                                 (spvs_real)1e-3,
                                 (spvs_real)-1e-20,
                                 (spvs_real)1e-40,
                                 (spvs_real)0.0,
                                 (spvs_real)0.03125,
                                 (spvs_real)4095.99};
        for (size_t k = 0; k < sizeof odd / sizeof odd[0]; k++) {
            const uint16_t i = (uint16_t)(synth_uniform(&rng) * sc.n);
            const spvs_match_t keep = sc.m[i];
            spvs_real *c = &sc.m[i].x_tgt;
            c[k % 4] = odd[k];
            check_load(sc.m, sc.n, 1);
            sc.m[i] = keep;
            frames++;
        }
        const uint16_t i = (uint16_t)(synth_uniform(&rng) * sc.n);
        sc.m[i].feature = SPVS_MAX_FEATURES;
        check_load(sc.m, sc.n, 1);
        frames++;
    }
    UNIT_NOTE("loader: %ld frames, accelerated = reference bit for bit\n", frames);
    TEST_ASSERT_EQUAL_INT64(frames, SCENES * 14);
}

/* A 3-point model of the scene from random points (Q27), or the true H
 * when none of a few tries solves. */
static void some_model(const scene_t *sc, uint64_t *rng, int32_t Hq[9])
{
    for (int t = 0; t < 20; t++) {
        uint16_t idx[3];
        for (int k = 0; k < 3; k++) {
            idx[k] = (uint16_t)(synth_uniform(rng) * sc->n);
        }
        if (spvs_q_solve3(&sc->qst, idx, Hq) == SPVS_OK) {
            return;
        }
    }
    TEST_ASSERT_EQUAL_INT64(spvs_q_h_from_real(sc->Hs, Hq), 0);
}

static void test_accel_score(void)
{
    uint64_t rng = 0x5c0eu;
    static scene_t sc;
    long counts = 0, models = 0;
    const double t = INLIER_PX / S;
    uint32_t sat = 0;
    const spvs_qf_t t2 = spvs_q_t2_from_real((spvs_real)(t * t), &sat);
    TEST_ASSERT_EQUAL_INT64(sat, 0);
    const spvs_q_thr_t thr_a = spvs_q_thr(t2);
    const spvs_q_thr_t thr_r = ref_q_thr(t2);
    for (int s = 0; s < SCENES; s++) {
        make_scene(&sc, &rng, 40 + (int)(synth_uniform(&rng) * 200), 1.0, 0.3);
        load_both(&sc);
        for (int m = 0; m < 12; m++) {
            int32_t Hq[9];
            if (m == 0) {
                TEST_ASSERT_EQUAL_INT64(spvs_q_h_from_real(sc.Hs, Hq), 0);
            } else {
                some_model(&sc, &rng, Hq);
            }
            models++;
            const uint16_t needs[] = {0, 3, (uint16_t)(sc.n / 2), (uint16_t)(sc.n * 3 / 4),
                                      sc.n, (uint16_t)(sc.n + 5)};
            for (size_t k = 0; k < sizeof needs / sizeof needs[0]; k++) {
                uint8_t ma[NMAX], mr[NMAX];
                memset(ma, 7, sizeof ma);
                memset(mr, 7, sizeof mr);
                const uint16_t ca = spvs_q_pts_score(&sc.qst, sc.n, Hq, &thr_a, needs[k], ma);
                const uint16_t cr = ref_q_pts_score(&sc.qst, sc.n, Hq, &thr_r, needs[k], mr);
                TEST_ASSERT_EQUAL_INT64(ca, cr);
                /* The masks agree wherever both counts wrote them: the
                 * reference writes every point up to its stop, as the
                 * filters do. */
                TEST_ASSERT_EQUAL_MEMORY(ma, mr, sc.n);
                const uint16_t na = spvs_q_pts_score(&sc.qst, sc.n, Hq, &thr_a, needs[k], NULL);
                TEST_ASSERT_EQUAL_INT64(na, cr);
                counts += 2;
            }
        }
    }
    UNIT_NOTE("inlier counts: %ld counts of %ld models, accelerated = reference\n", counts,
                  models);
    TEST_ASSERT_EQUAL_INT64(models, SCENES * 12);
}

static void test_accel_cost_sums(void)
{
    uint64_t rng = 0xc057u;
    static scene_t sc;
    double worst_cost = 0, worst_sum = 0;
    long sums = 0;
    const spvs_terms_t kinds[] = {SPVS_T_LIN, SPVS_T_FIT_Y, SPVS_T_FIT_X, SPVS_T_SAMPSON};
    for (int s = 0; s < SCENES; s++) {
        make_scene(&sc, &rng, 40 + (int)(synth_uniform(&rng) * 200), 1.0, 0.2);
        load_both(&sc);
        int32_t Hq[9];
        TEST_ASSERT_EQUAL_INT64(spvs_q_h_from_real(sc.Hs, Hq), 0);
        uint8_t use[NMAX];
        for (uint16_t i = 0; i < sc.n; i++) {
            use[i] = (uint8_t)(synth_uniform(&rng) < 0.8);
        }
        uint32_t sa = 0, sr = 0;
        const uint64_t ca = spvs_q_pts_cost(&sc.qst, sc.n, Hq, use, &sa);
        const uint64_t cr = ref_q_pts_cost(&sc.qst, sc.n, Hq, use, &sr);
        TEST_ASSERT_EQUAL_INT64(sa, sr);
        const double dc = fabs((double)ca - (double)cr);
        worst_cost = dc > worst_cost ? dc : worst_cost;
        TEST_ASSERT_TRUE(dc <= TOL_COST_PER_POINT * sc.n);
        for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
            spvs_q_sums_t a, r;
            const int32_t na = spvs_q_pts_sum(kinds[k], Hq, &sc.qst, use, sc.n, &a);
            const int32_t nr = ref_q_pts_sum(kinds[k], Hq, &sc.qst, use, sc.n, &r);
            TEST_ASSERT_EQUAL_INT64(na, nr);
            TEST_ASSERT_EQUAL_INT64(a.nt, r.nt);
            /* Each term against its block's largest reference term. */
            double big[3] = {0, 0, 0};
            for (int j = 0; j < r.nt; j++) {
                const spvs_qf_t v = spvs_q_sums_term(&r, j);
                const double x = fabs(ldexp((double)v.m, v.e));
                big[blk_of(&r, j)] = x > big[blk_of(&r, j)] ? x : big[blk_of(&r, j)];
            }
            for (int j = 0; j < r.nt; j++) {
                const spvs_qf_t va = spvs_q_sums_term(&a, j), vr = spvs_q_sums_term(&r, j);
                const double d = fabs(ldexp((double)va.m, va.e) - ldexp((double)vr.m, vr.e)) /
                                 big[blk_of(&r, j)];
                worst_sum = d > worst_sum ? d : worst_sum;
                TEST_ASSERT_TRUE(d <= TOL_SUM);
            }
            sums++;
        }
    }
    UNIT_NOTE("cost: worst difference %.0f units of Q52 (tolerance %.0f a point); sums: %ld, "
                  "worst %.3g of the block's largest term (tolerance %.3g)\n",
                  worst_cost, TOL_COST_PER_POINT, sums, worst_sum, TOL_SUM);
    TEST_ASSERT_EQUAL_INT64(sums, SCENES * 4);
}

/* The two off-plane tests on row p under H at offplane_q16: the same
 * answer.  Returns 1 when the row's error is within one unit of Q16 px of
 * the threshold. */
static int check_off(const int32_t H[9], const int32_t p[4], int32_t offplane_q16)
{
    const spvs_q_off_thr_t ta = spvs_q_off_thr(offplane_q16);
    const spvs_q_off_thr_t tr = ref_q_off_thr(offplane_q16);
    TEST_ASSERT_EQUAL_UINT64(ta.off2, tr.off2);
    TEST_ASSERT_EQUAL_INT64(ref_q_off_above(H, p, &tr), spvs_q_off_above(H, p, &ta));
    const int64_t e2 = spvs_q_transfer_err2(H, p);
    const uint32_t lo = offplane_q16 > 1 ? 2u * (uint32_t)(offplane_q16 - 1) : 0u;
    const uint32_t hi = 2u * (uint32_t)offplane_q16 + 2u;
    return e2 >= 0 && (uint64_t)e2 >= (uint64_t)lo * lo && (uint64_t)e2 <= (uint64_t)hi * hi;
}

static void test_accel_offplane(void)
{
    uint64_t rng = 0x0ff9u;
    static scene_t sc;
    long tests = 0, near = 0;
    /* 0.01, 0.5, 2, 5 and 1,000 px in Q16. */
    const int32_t fixed_q16[] = {655, 32768, 131072, 327680, 65536000};
    for (int s = 0; s < SCENES; s++) {
        make_scene(&sc, &rng, 40 + (int)(synth_uniform(&rng) * 200), 1.0, 0.3);
        load_both(&sc);
        for (int m = 0; m < 4; m++) {
            int32_t Hq[9];
            if (m == 0) {
                TEST_ASSERT_EQUAL_INT64(spvs_q_h_from_real(sc.Hs, Hq), 0);
            } else {
                some_model(&sc, &rng, Hq);
            }
            for (uint16_t i = 0; i < sc.n; i++) {
                int32_t row[4];
                spvs_q_pts_row(&sc.qst, i, row);
                const int32_t back[4] = {row[2], row[3], row[0], row[1]};
                for (size_t k = 0; k < sizeof fixed_q16 / sizeof fixed_q16[0]; k++) {
                    (void)check_off(Hq, row, fixed_q16[k]);
                    (void)check_off(Hq, back, fixed_q16[k]);
                    tests += 2;
                }
                /* At the row's own error: o = 2 offplane_q16 = sqrt(e2). */
                const int64_t e2 = spvs_q_transfer_err2(Hq, row);
                if (e2 > 0) {
                    const int32_t own = (int32_t)(spvs_q_isqrt64((uint64_t)e2) / 2u);
                    for (int32_t d = -1; d <= 1; d++) {
                        near += check_off(Hq, row, own + d);
                        tests++;
                    }
                }
            }
        }
    }
    UNIT_NOTE("off-plane test: %ld tests, %ld within a unit of the threshold, "
              "accelerated = reference\n", tests, near);
    TEST_ASSERT_TRUE(near >= 10000);
}

/* A Q30 unit direction at angle a (radians). */
static void unit_dir(double a, int32_t d[2])
{
    d[0] = (int32_t)lround(cos(a) * 1073741824.0);
    d[1] = (int32_t)lround(sin(a) * 1073741824.0);
}

static void test_accel_cone(void)
{
    uint64_t rng = 0xc0e5u;
    static int32_t u[SPVS_MAX_OFFPLANE + 1][2];
    long pairs = 0, edge = 0, counts = 0;
    /* sin^2 of the cone in Q30: 0, 1e-4, 0.01 (the default), 0.25, 0.5. */
    const uint32_t tol_q30[] = {0u, 107374u, 10737418u, 268435456u, 536870912u};
    for (size_t t = 0; t < sizeof tol_q30 / sizeof tol_q30[0]; t++) {
        const uint64_t tol = (uint64_t)tol_q30[t] << 32;
        const spvs_q_cone_t k = spvs_q_cone(tol);
        const double half = asin(sqrt((double)tol_q30[t] / 1073741824.0));
        for (int s = 0; s < 200; s++) {
            const double aj = synth_uniform(&rng) * 6.283185307179586;
            int32_t dj[2];
            unit_dir(aj, dj);
            const uint16_t n = (uint16_t)(1 + synth_uniform(&rng) * SPVS_MAX_OFFPLANE);
            for (uint16_t i = 0; i < n; i++) {
                /* A third at the cone's edge (within 1e-8 rad), a third
                 * inside or near it, the rest anywhere; a few zero. */
                const double r = synth_uniform(&rng);
                const double side = synth_uniform(&rng) < 0.5 ? -1.0 : 1.0;
                double a = aj + 6.283185307179586 * synth_uniform(&rng);
                if (r < 0.33) {
                    a = aj + side * (half + (synth_uniform(&rng) - 0.5) * 2e-8);
                } else if (r < 0.66) {
                    a = aj + side * half * 1.5 * synth_uniform(&rng);
                }
                unit_dir(a, u[i]);
                if (synth_uniform(&rng) < 0.02) {
                    u[i][0] = 0;
                    u[i][1] = 0;
                }
                const int sa = spvs_q_cone_supports(u[i], dj[0], dj[1], &k);
                TEST_ASSERT_EQUAL_INT64(ref_q_cone_supports(u[i], dj[0], dj[1], &k), sa);
                pairs++;
                edge += r < 0.33;
            }
            u[n][0] = 0;
            u[n][1] = 0;
            const uint16_t full = ref_q_cone_count(u, n, dj[0], dj[1], &k, 1u);
            for (uint32_t need = 1; need <= (uint32_t)n + 1u; need++) {
                const uint16_t c = spvs_q_cone_count(u, n, dj[0], dj[1], &k, need);
                /* Exact from need on; below need, below need. */
                TEST_ASSERT_TRUE(full >= need ? c == full : c < need);
                counts++;
            }
        }
    }
    /* The roots: the floor, on squares, their neighbours and random x. */
    long roots = 0;
    for (int s = 0; s < 20000; s++) {
        const uint64_t r = (uint64_t)(synth_uniform(&rng) * 4294967295.0);
        const uint64_t xs[] = {r * r, r * r - 1u, r * r + 1u,
                               (uint64_t)(synth_uniform(&rng) * 18446744073709551615.0)};
        for (size_t k = 0; k < sizeof xs / sizeof xs[0]; k++) {
            TEST_ASSERT_EQUAL_UINT64(ref_q_sqrt_floor(xs[k]), spvs_q_sqrt_floor(xs[k]));
            roots++;
        }
    }
    UNIT_NOTE("epipole cone: %ld pairs (%ld at the edge), %ld counts, %ld roots, "
              "accelerated = reference\n", pairs, edge, counts, roots);
    TEST_ASSERT_TRUE(edge >= 5000);
}

void suite_fixed_accel(void);
void suite_fixed_accel(void)
{
    UNIT_SUITE_FILE();
    RUN_TEST(test_accel_load);
    RUN_TEST(test_accel_score);
    RUN_TEST(test_accel_cost_sums);
    RUN_TEST(test_accel_offplane);
    RUN_TEST(test_accel_cone);
}

UNIT_MAIN(suite_fixed_accel)
