/*
 * test_frontend.c - the image front end (sim/frontend.h): matches from
 * rendered images against the scene's ground truth, the core's homography
 * against OpenCV's and the true one on the same matches, reproducibility
 * and bad input.  Default scene: plane n = (0.3, -0.6, -0.75) normalised,
 * d = 45 m, 10 off-plane quads at 12..35 m, seed 0; the image runs' camera
 * (SIM_FRONTEND_FOCAL_MM, 400 px).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sim/frontend.h"
#include "sim/sim.h"
#include "spvs/spvs.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

/* Mean transfer error over the matched target points, pixels: where two
 * homographies send the target points of a frame's plane matches.  The
 * core's planar H (six unknowns) against the true H of eq. (2); the core's
 * H against OpenCV's general H (eight unknowns, which also bends towards
 * off-plane matches of small parallax, so its own distance to the truth is
 * larger).  The four image corners are printed too; from a pose turned
 * 40 deg away the matches cover a third of the target image and the
 * corners are an extrapolation, so the bounds are on the matched points. */
#define H_CORE_TRUE_BOUND_PX 1.0
#define H_CORE_CV_BOUND_PX 2.0

static sim_world_t world;
static sim_obs_t obs[SPVS_MAX_MATCHES];

static sim_frontend_t *make(uint64_t seed)
{
    sim_config_t c;
    sim_config_default(&c);
    c.focal_true_mm = SIM_FRONTEND_FOCAL_MM;
    c.focal_assumed_mm = SIM_FRONTEND_FOCAL_MM;
    char err[200];
    assert_int_equal(sim_config_world(&c, &world, err, sizeof(err)), 0);
    sim_frontend_params_t p;
    sim_frontend_params_default(&p);
    p.seed = seed;
    sim_frontend_t *f = sim_frontend_create(&p, &world.cam, &world.plane, err,
                                            sizeof(err));
    if (f == NULL) {
        print_message("front end: %s\n", err);
    }
    assert_non_null(f);
    return f;
}

static double corner_error(const double A[9], const double B[9])
{
    static const double cx[4] = { -320, 320, 320, -320 };
    static const double cy[4] = { -240, -240, 240, 240 };
    double sum = 0.0;
    for (int i = 0; i < 4; ++i) {
        double ax, ay, bx, by;
        sim_h_apply(A, cx[i], cy[i], &ax, &ay);
        sim_h_apply(B, cx[i], cy[i], &bx, &by);
        sum += hypot(ax - bx, ay - by);
    }
    return sum / 4.0;
}

/* Mean transfer error over the target points of the plane matches (true
 * plane features that are not mismatched). */
static double support_error(const double A[9], const double B[9],
                            const sim_obs_t *o, uint16_t n)
{
    double sum = 0.0;
    int k = 0;
    for (uint16_t i = 0; i < n; ++i) {
        if (!o[i].on_plane || o[i].mismatched) {
            continue;
        }
        double ax, ay, bx, by;
        sim_h_apply(A, o[i].x_tgt, o[i].y_tgt, &ax, &ay);
        sim_h_apply(B, o[i].x_tgt, o[i].y_tgt, &bx, &by);
        sum += hypot(ax - bx, ay - by);
        ++k;
    }
    return k ? sum / k : INFINITY;
}

/* Poses on and near the paths of the closed-loop runs. */
static const double test_poses[][3] = {
    { 0.0, -2.0, 0.0 },     /* straight behind the target                */
    { -1.0, -3.0, -10.0 },  /* late in step 2 from (-3, -10, -30)        */
    { -2.0, -7.0, -16.7 },  /* on the line of step 2 from that pose      */
    { -3.0, -10.0, -30.0 }, /* Figure 5 start poses                      */
    { 0.0, -8.0, -40.0 },
    { 6.0, -6.0, 0.0 },
    { 3.0, -3.0, 45.0 },    /* on the line of step 2 from (6, -6, 0)     */
};

/* Matches agree with the ground truth: enough of them, few mismatches,
 * the right index range, and sub-2-px accuracy for the median match. */
static void test_matches_against_truth(void **state)
{
    (void)state;
    sim_frontend_t *f = make(0);
    uint16_t n_tgt = sim_frontend_target_count(f);
    assert_true(n_tgt >= 400 && n_tgt <= 500);
    for (size_t k = 0; k < sizeof(test_poses) / sizeof(test_poses[0]); ++k) {
        sim_pose_t pose = { test_poses[k][0], test_poses[k][1],
                            test_poses[k][2] * DEG };
        sim_frontend_frame_stats_t st;
        uint16_t n = sim_frontend_observe(f, (uint32_t)k, &pose, obs,
                                          SPVS_MAX_MATCHES, &st);
        double err[SPVS_MAX_MATCHES];
        uint16_t bad = 0;
        for (uint16_t i = 0; i < n; ++i) {
            assert_true(obs[i].feature < n_tgt);
            double pt[2], X[3], p[2];
            int on = -1;
            assert_int_equal(sim_frontend_target_point(f, obs[i].feature, pt,
                                                       X, &on), 0);
            assert_true(pt[0] == obs[i].x_tgt && pt[1] == obs[i].y_tgt);
            assert_int_equal(on, obs[i].on_plane);
            assert_int_equal(sim_project(&world.cam, &pose, X, p, NULL), 0);
            err[i] = hypot(p[0] - obs[i].x_cur, p[1] - obs[i].y_cur);
            bad = (uint16_t)(bad + (err[i] > 3.0));
            assert_int_equal(obs[i].mismatched, err[i] > 3.0);
        }
        /* Median by partial selection sort: n <= 256. */
        for (uint16_t i = 0; i <= n / 2; ++i) {
            for (uint16_t j = (uint16_t)(i + 1); j < n; ++j) {
                if (err[j] < err[i]) {
                    double t = err[i];
                    err[i] = err[j];
                    err[j] = t;
                }
            }
        }
        double rate = n ? (double)bad / n : 1.0;
        print_message("pose (%g, %g, %g deg): %u matches, %u mismatched "
                      "(%.1f %%), median error %.2f px\n", test_poses[k][0],
                      test_poses[k][1], test_poses[k][2], (unsigned)n,
                      (unsigned)bad, 100.0 * rate, n ? err[n / 2] : -1.0);
        assert_int_equal(st.n_matches, n);
        assert_int_equal(st.n_mismatches, bad);
        assert_true(n >= 40);
        assert_true(rate <= 0.15);
        assert_true(err[n / 2] <= 2.0);
    }
    sim_frontend_destroy(f);
}

/* Ground truth of the target features: plane features lie on the plane,
 * the others are nearer than it, between 12 and 35 m deep. */
static void test_target_points_on_surfaces(void **state)
{
    (void)state;
    sim_frontend_t *f = make(0);
    int n_off = 0;
    for (uint16_t i = 0; i < sim_frontend_target_count(f); ++i) {
        double pt[2], X[3];
        int on = -1;
        if (sim_frontend_target_point(f, i, pt, X, &on) != 0) {
            continue;
        }
        double s = world.plane.n[0] * X[0] + world.plane.n[1] * X[1] +
                   world.plane.n[2] * X[2] + world.plane.d_m;
        if (on) {
            assert_true(fabs(s) < 1e-6);
        } else {
            ++n_off;
            assert_true(s > 0.0);
            assert_true(X[2] >= 12.0 - 1e-9 && X[2] < 35.0 + 1e-9);
        }
        /* The point lies on the ray of its keypoint. */
        assert_true(fabs(world.cam.alpha_x_px * X[0] / X[2] - pt[0]) < 1e-6);
        assert_true(fabs(world.cam.alpha_y_px * X[1] / X[2] - pt[1]) < 1e-6);
    }
    print_message("%d of %u target features off the plane\n", n_off,
                  (unsigned)sim_frontend_target_count(f));
    /* Parallax for the epipole needs off-plane features; the plane must
     * still dominate for the homography. */
    assert_true(n_off >= 20);
    assert_true(n_off < sim_frontend_target_count(f) / 2);
    sim_frontend_destroy(f);
}

/* On the same matches, the core's planar H, OpenCV's general H (RANSAC,
 * 3 px) and the true H of eq. (2) send the matched target points to within
 * the bounds above of each other on average. */
static void test_h_cross_check(void **state)
{
    (void)state;
    sim_frontend_t *f = make(0);
    static spvs_t core;
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    p.ctl.alpha_x = (spvs_real)world.cam.alpha_x_px;
    p.ctl.alpha_y = (spvs_real)world.cam.alpha_y_px;
    assert_int_equal(spvs_init(&core, &p), SPVS_OK);
    for (size_t k = 0; k < sizeof(test_poses) / sizeof(test_poses[0]); ++k) {
        sim_pose_t pose = { test_poses[k][0], test_poses[k][1],
                            test_poses[k][2] * DEG };
        uint16_t n = sim_frontend_observe(f, (uint32_t)k, &pose, obs,
                                          SPVS_MAX_MATCHES, NULL);
        static spvs_match_t m[SPVS_MAX_MATCHES];
        sim_obs_to_matches(obs, n, m);
        spvs_reset(&core);
        spvs_output_t out;
        int rc = spvs_estimate_h(&core, m, n, &out);
        assert_int_equal(rc, SPVS_OK);
        double H_core[9], H_cv[9], H_true[9];
        for (int i = 0; i < 9; ++i) {
            H_core[i] = (double)out.H[i];
        }
        assert_int_equal(sim_frontend_opencv_h(obs, n, 3.0, H_cv), 0);
        sim_h_eq2(&world.cam, &world.plane, &pose, H_true);
        double e_true = support_error(H_core, H_true, obs, n);
        double e_cv = support_error(H_core, H_cv, obs, n);
        double e_cv_true = support_error(H_cv, H_true, obs, n);
        print_message("pose (%g, %g, %g deg): %u matches, %u core inliers; "
                      "transfer at the matched points: core-true %.2f px, "
                      "core-OpenCV %.2f px, OpenCV-true %.2f px; at the "
                      "corners %.2f, %.2f, %.2f px\n", test_poses[k][0],
                      test_poses[k][1], test_poses[k][2], (unsigned)n,
                      (unsigned)out.n_inliers, e_true, e_cv, e_cv_true,
                      corner_error(H_core, H_true), corner_error(H_core, H_cv),
                      corner_error(H_cv, H_true));
        assert_true(e_true < H_CORE_TRUE_BOUND_PX);
        assert_true(e_cv < H_CORE_CV_BOUND_PX);
    }
    sim_frontend_destroy(f);
}

/* Same seed, same matches; another seed, another texture. */
static void test_reproducible(void **state)
{
    (void)state;
    static sim_obs_t a[SPVS_MAX_MATCHES], b[SPVS_MAX_MATCHES];
    sim_pose_t pose = { -1.0, -3.0, -10.0 * DEG };
    sim_frontend_t *f = make(7);
    uint16_t na = sim_frontend_observe(f, 3, &pose, a, SPVS_MAX_MATCHES, NULL);
    sim_frontend_destroy(f);
    f = make(7);
    uint16_t nb = sim_frontend_observe(f, 3, &pose, b, SPVS_MAX_MATCHES, NULL);
    sim_frontend_destroy(f);
    assert_true(na > 0);
    assert_int_equal(na, nb);
    assert_memory_equal(a, b, sizeof(a[0]) * na);
    f = make(8);
    uint16_t nc = sim_frontend_observe(f, 3, &pose, b, SPVS_MAX_MATCHES, NULL);
    sim_frontend_destroy(f);
    assert_true(nc != na || memcmp(a, b, sizeof(a[0]) * na) != 0);
}

/* Bad parameters give NULL and a one-line reason; a non-finite pose gives
 * no matches; a too-small buffer is never overrun. */
static void test_bad_input(void **state)
{
    (void)state;
    sim_config_t c;
    sim_config_default(&c);
    char err[200];
    assert_int_equal(sim_config_world(&c, &world, err, sizeof(err)), 0);
    sim_frontend_params_t p;
    sim_frontend_params_default(&p);
    p.target_features = SPVS_MAX_FEATURES + 1;
    err[0] = '\0';
    assert_null(sim_frontend_create(&p, &world.cam, &world.plane, err,
                                    sizeof(err)));
    assert_true(strlen(err) > 0 && strchr(err, '\n') == NULL);
    sim_frontend_params_default(&p);
    p.ratio = 0.0 / (p.ratio - p.ratio); /* NaN at run time */
    assert_null(sim_frontend_create(&p, &world.cam, &world.plane, err,
                                    sizeof(err)));
    sim_frontend_params_default(&p);
    p.detector = 7;
    assert_null(sim_frontend_create(&p, &world.cam, &world.plane, err,
                                    sizeof(err)));
    sim_frontend_params_default(&p);
    p.levels = 0;
    assert_null(sim_frontend_create(&p, &world.cam, &world.plane, err,
                                    sizeof(err)));
    sim_frontend_params_default(&p);
    sim_plane_t behind = world.plane;
    behind.n[0] = 0.0;
    behind.n[1] = 0.0;
    behind.n[2] = 1.0;
    assert_null(sim_frontend_create(&p, &world.cam, &behind, err,
                                    sizeof(err)));

    /* The most objects a scene holds: their textures fit in the atlas. */
    sim_frontend_params_default(&p);
    p.n_objects = SIM_FRONTEND_MAX_OBJECTS;
    sim_frontend_t *f = sim_frontend_create(&p, &world.cam, &world.plane, err,
                                            sizeof(err));
    assert_non_null(f);
    sim_pose_t near = { 0.0, -2.0, 0.0 };
    assert_true(sim_frontend_observe(f, 0, &near, obs, SPVS_MAX_MATCHES,
                                     NULL) >= 40);
    sim_frontend_destroy(f);

    f = make(0);
    double zero = 0.0;
    sim_pose_t nan_pose = { zero / zero, 0.0, 0.0 };
    assert_int_equal(sim_frontend_observe(f, 0, &nan_pose, obs,
                                          SPVS_MAX_MATCHES, NULL), 0);
    sim_pose_t pose = { 0.0, -2.0, 0.0 };
    static sim_obs_t small[6];
    memset(small, 0xA5, sizeof(small));
    assert_int_equal(sim_frontend_observe(f, 1, &pose, small, 5, NULL), 5);
    const unsigned char *sentinel = (const unsigned char *)&small[5];
    for (size_t i = 0; i < sizeof(small[5]); ++i) {
        assert_int_equal(sentinel[i], 0xA5);
    }
    sim_frontend_destroy(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_against_truth),
        cmocka_unit_test(test_target_points_on_surfaces),
        cmocka_unit_test(test_h_cross_check),
        cmocka_unit_test(test_reproducible),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
