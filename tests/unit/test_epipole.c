/* test_epipole.c - the epipole from plane plus parallax (epipole.h). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "unity.h"
#include "unit_support.h"

#include "spvs/epipole.h"
#include "spvs/homography.h"
#include "synth.h"

#define S ((double)SPVS_COORD_SCALE)
#define SENTINEL 0xE919013Eu

#if SPVS_USE_DOUBLE
#define TOL_EX_REL 1e-6
#else
#define TOL_EX_REL 2e-3
#endif

typedef struct {
    spvs_real H[9];
    spvs_real pts[64][4];
    uint16_t cand[64];
    uint16_t n;
} frame_t;

/* n_plane plane points then n_off off-plane points, with the plane's exact
 * H, scaled units; every point is a candidate. */
static void make_frame_mixed(frame_t *f, const synth_pose_t *p, const synth_plane_t *pl,
                             int n_plane, int n_off, double sigma, uint64_t *rng)
{
    double H[9];
    synth_H(p, pl, 800, H);
    for (int k = 0; k < 9; k++) {
        f->H[k] = (spvs_real)H[k];
    }
    spvs_h_rescale(f->H, (spvs_real)(1.0 / S));
    spvs_match_t m[64];
    f->n = synth_frame(p, pl, 800, n_plane, n_off, sigma, rng, m, NULL);
    for (int i = 0; i < f->n; i++) {
        f->pts[i][0] = (spvs_real)(m[i].x_tgt / S);
        f->pts[i][1] = (spvs_real)(m[i].y_tgt / S);
        f->pts[i][2] = (spvs_real)(m[i].x_cur / S);
        f->pts[i][3] = (spvs_real)(m[i].y_cur / S);
        f->cand[i] = (uint16_t)i;
    }
}

static void make_frame(frame_t *f, const synth_pose_t *p, const synth_plane_t *pl, int n_off,
                       double sigma, uint64_t *rng)
{
    make_frame_mixed(f, p, pl, 0, n_off, sigma, rng);
}

/* The estimator with the pipeline's settings: sine tolerance 0.1, three
 * supporters. */
static int estimate(const frame_t *f, uint16_t n, spvs_epipole_t *e, uint8_t *support)
{
    static spvs_epipole_work_t work;
    return spvs_epipole_estimate(f->H, (const spvs_real(*)[4])f->pts, f->cand, n, SPVS_R(0.01), 3,
                                 e, support, &work);
}

/* e = K(-R c): the x of the epipole in pixels and the sign of its depth. */
static double true_ex(const synth_pose_t *p, int *ahead)
{
    double c = cos(p->phi), s = sin(p->phi);
    double e1 = -(c * p->x + s * p->z), e3 = -(-s * p->x + c * p->z);
    *ahead = e3 > 0 ? 1 : -1;
    return 800 * e1 / e3;
}

/* On the line x = -z tan(phi_t) the epipole is alpha_x tan(phi - phi_t). */
static void test_exact_on_line(void)
{
    uint64_t rng = 5;
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    for (int t = 0; t < 50; t++) {
        double phit = (-40 + 80 * synth_uniform(&rng)) * SYNTH_PI / 180;
        double z = -12 + 10 * synth_uniform(&rng);
        double dphi = (-30 + 60 * synth_uniform(&rng)) * SYNTH_PI / 180;
        synth_pose_t p = {-z * tan(phit), z, phit + dphi};
        frame_t f;
        make_frame(&f, &p, &pl, 25, 0.0, &rng);
        struct {
            uint8_t support[64];
            uint32_t guard;
        } sup;
        sup.guard = SENTINEL;
        spvs_epipole_t e;
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, estimate(&f, f.n, &e, sup.support));
        TEST_ASSERT_EQUAL_INT64(SENTINEL, sup.guard);
        double expect = 800 * tan(dphi);
        TEST_ASSERT_TRUE(fabs((double)e.e_x_px - expect) <= TOL_EX_REL * (1 + fabs(expect)));
        /* The target is in front (z < 0, facing it within 30 deg). */
        TEST_ASSERT_TRUE(e.dir_z > 0);
        TEST_ASSERT_EQUAL_INT64(f.n, e.n_support);
        TEST_ASSERT_TRUE(e.parallax_px > 0);
    }
}

/* Anywhere (including behind the target): e_x = alpha_x e1 / e3 and the
 * sign of e_z says whether the target is in front. */
static void test_exact_general_and_sign(void)
{
    uint64_t rng = 9;
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    int behind = 0;
    for (int t = 0; t < 60; t++) {
        synth_pose_t p = {-8 + 16 * synth_uniform(&rng), -12 + 20 * synth_uniform(&rng),
                          (-60 + 120 * synth_uniform(&rng)) * SYNTH_PI / 180};
        if (p.x * p.x + p.z * p.z < 1) {
            continue;
        }
        int ahead;
        double expect = true_ex(&p, &ahead);
        if (fabs(expect) > 5000) {
            continue; /* near infinity: checked by the clamp test */
        }
        frame_t f;
        make_frame(&f, &p, &pl, 25, 0.0, &rng);
        spvs_epipole_t e;
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, estimate(&f, f.n, &e, NULL));
        TEST_ASSERT_TRUE(fabs((double)e.e_x_px - expect) <= TOL_EX_REL * (1 + fabs(expect)));
        TEST_ASSERT_EQUAL_INT64(ahead, e.dir_z > 0 ? 1 : -1);
        behind += ahead < 0;
    }
    TEST_ASSERT_TRUE(behind >= 10);
}

/* 20% mismatches among the off-plane points move the estimate by under a
 * pixel; the mismatches get no support. */
static void test_mismatches(void)
{
    uint64_t rng = 21;
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    double worst = 0;
    for (int t = 0; t < 40; t++) {
        double phit = -0.3 + 0.6 * synth_uniform(&rng);
        double z = -10 + 6 * synth_uniform(&rng);
        double dphi = -0.3 + 0.6 * synth_uniform(&rng);
        synth_pose_t p = {-z * tan(phit), z, phit + dphi};
        frame_t f;
        make_frame(&f, &p, &pl, 25, 0.0, &rng);
        for (int i = 0; i < 5; i++) {
            f.pts[i][2] = (spvs_real)((synth_uniform(&rng) - 0.5) * 640 / S);
            f.pts[i][3] = (spvs_real)((synth_uniform(&rng) - 0.5) * 480 / S);
        }
        uint8_t sup[64];
        spvs_epipole_t e;
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, estimate(&f, f.n, &e, sup));
        double expect = 800 * tan(dphi);
        double err = fabs((double)e.e_x_px - expect);
        if (err > worst) {
            worst = err;
        }
        int sup_good = 0;
        for (int i = 5; i < f.n; i++) {
            sup_good += sup[i];
        }
        TEST_ASSERT_TRUE(sup_good >= 18);
        TEST_ASSERT_TRUE(e.dir_z > 0);
    }
    UNIT_NOTE("epipole with 20%% mismatches: worst error %.3f px\n", worst);
    TEST_ASSERT_TRUE(worst < 1.0);
}

static void test_no_parallax_and_args(void)
{
    uint64_t rng = 2;
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    spvs_epipole_work_t work;
    synth_pose_t p = {-3, -10, -0.5};
    frame_t f;
    make_frame(&f, &p, &pl, 25, 0.0, &rng);
    spvs_epipole_t e;
    /* Fewer candidates than the support needed. */
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NO_PARALLAX, estimate(&f, 2, &e, NULL));
    /* Points on the plane (zero parallax): no line at all. */
    frame_t g;
    make_frame_mixed(&g, &p, &pl, 20, 0, 0.0, &rng);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NO_PARALLAX, estimate(&g, g.n, &e, NULL));
    /* Argument errors. */
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_epipole_estimate(f.H, (const spvs_real(*)[4])f.pts, f.cand,
                                           SPVS_MAX_OFFPLANE + 1, SPVS_R(0.01), 3, &e, NULL, &work));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_epipole_estimate(f.H, (const spvs_real(*)[4])f.pts, f.cand, f.n,
                                           SPVS_R(0.01), 3, &e, NULL, NULL));
}

/* Side-on to the line the epipole is at infinity: clamped, right sign. */
static void test_clamp(void)
{
    uint64_t rng = 4;
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    /* Robot facing +z with the target 10 m to its side: phi - phi_t = 90 deg. */
    synth_pose_t p = {-10, 0, 1e-4};
    frame_t f;
    make_frame(&f, &p, &pl, 25, 0.0, &rng);
    spvs_epipole_t e;
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, estimate(&f, f.n, &e, NULL));
    TEST_ASSERT_TRUE(fabs((double)e.e_x_px) <= (double)SPVS_EPIPOLE_MAX_PX);
    TEST_ASSERT_TRUE(fabs((double)e.e_x_px) > 5000);
}

void suite_epipole(void)
{
    UNIT_SUITE_FILE();
    RUN_TEST(test_exact_on_line);
    RUN_TEST(test_exact_general_and_sign);
    RUN_TEST(test_mismatches);
    RUN_TEST(test_no_parallax_and_args);
    RUN_TEST(test_clamp);
}

UNIT_MAIN(suite_epipole)
