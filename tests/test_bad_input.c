/*
 * test_bad_input.c - every class of bad input to spvs_update() gets its own
 * status and a stop command, (v, w) = (0, 0) exactly (docs/ROBUSTNESS.md has
 * the table; this file is its evidence).
 *
 * Each test starts from a good frame of the default scene (DESIGN.md section
 * 5, imaged by the simulator library), damages it in one way, and asserts
 * the exact status, v == 0, w == 0, and for transient classes that the next
 * good frame is accepted again (the error is not latched).  NaN and
 * infinities are made at run time (0.0 / zero), not with library macros, so
 * the compiler cannot fold them away.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sim/scene.h"
#include "sim/sim.h"
#include "spvs/common.h"
#include "spvs/spvs.h"

#define DEG (3.14159265358979323846 / 180.0)

/* A non-constant zero: NaN and Inf made from it survive optimisation. */
static volatile double g_zero = 0.0;

static spvs_t g_s;
static sim_world_t g_world;
static sim_obs_t g_obs[SIM_MAX_POINTS];
static spvs_match_t g_m[SPVS_MAX_MATCHES + 4];

/* Image the default scene (or a variant) from the default start pose. */
static uint16_t scene_frame(const double normal[3], double d_m, uint16_t n_off,
                            const sim_pose_t *pose)
{
    sim_config_t c;
    sim_config_default(&c);
    if (normal) {
        memcpy(c.normal, normal, sizeof(c.normal));
    }
    if (d_m > 0.0) {
        c.distance_m = d_m;
    }
    c.scene.n_off = n_off;
    char err[160];
    assert_int_equal(sim_config_world(&c, &g_world, err, sizeof(err)), 0);
    const sim_pose_t start = pose ? *pose : c.start;
    uint16_t cap = SIM_MAX_POINTS < SPVS_MAX_MATCHES ? SIM_MAX_POINTS : SPVS_MAX_MATCHES;
    uint16_t n = sim_world_observe(&g_world, &start, g_obs, cap);
    sim_obs_to_matches(g_obs, n, g_m);
    return n;
}

static uint16_t default_frame(void)
{
    return scene_frame(NULL, 0.0, 25, NULL);
}

static void init(spvs_method_t method)
{
    spvs_params_t p;
    spvs_params_default(&p, method);
    assert_int_equal(spvs_init(&g_s, &p), SPVS_OK);
}

/* One update that must fail with `want` and command a stop. */
static void expect_stop(const spvs_match_t *m, uint16_t n, double t_s, int want)
{
    spvs_output_t out;
    memset(&out, 0x5A, sizeof(out)); /* stale bytes must not leak out */
    int rc = spvs_update(&g_s, m, n, (spvs_real)t_s, &out);
    assert_int_equal(rc, want);
    assert_int_equal(out.status, want);
    assert_true(out.v == SPVS_R(0.0));
    assert_true(out.w == SPVS_R(0.0));
    /* Input and estimation errors leave the arrival check's figures at
     * their "no check" zeros, not the caller's stale bytes. */
    if (want >= SPVS_E_STALE) {
        assert_true(out.arrival_corner_px == SPVS_R(0.0));
        assert_true(out.arrival_stat == SPVS_R(0.0));
        assert_true(out.arrival_threshold == SPVS_R(0.0));
        assert_true(out.arrival_lateral_sd_px == SPVS_R(0.0));
        assert_true(out.arrival_depth_sd_px == SPVS_R(0.0));
        assert_true(out.arrival_h13_sd_px == SPVS_R(0.0));
        assert_true(out.arrival_parallax_px == SPVS_R(0.0));
        assert_int_equal(out.arrival_frames, 0);
    }
    /* Input and estimation errors leave no estimate; control errors (no
     * parallax, plane, step timeout) come after a valid H. */
    if (want >= SPVS_E_STALE) {
        assert_int_equal(out.h_valid, 0);
    }
}

/* The next good frame is accepted: the error was not latched. */
static void expect_recovery(uint16_t n, double t_s)
{
    spvs_output_t out;
    int rc = spvs_update(&g_s, g_m, n, (spvs_real)t_s, &out);
    assert_int_equal(rc, SPVS_OK);
    assert_int_equal(out.h_valid, 1);
    assert_true(out.n_inliers >= 90u);
}

/* ---- counts ------------------------------------------------------------ */

static void test_no_matches(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    expect_stop(g_m, 0, 0.0, SPVS_E_TOO_FEW);
    expect_recovery(n, 0.1);
}

static void test_two_matches(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    expect_stop(g_m, 2, 0.0, SPVS_E_TOO_FEW);
    expect_recovery(n, 0.1);
}

/* A minimal sample fits exactly, but seven points are no consensus. */
static void test_seven_matches(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    expect_stop(g_m, 7, 0.0, SPVS_E_TOO_FEW);
    expect_recovery(n, 0.1);
}

static void test_over_capacity(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    expect_stop(g_m, SPVS_MAX_MATCHES + 1, 0.0, SPVS_E_CAPACITY);
    expect_stop(g_m, UINT16_MAX, 0.1, SPVS_E_CAPACITY);
    expect_recovery(n, 0.2);
}

static void test_null_matches(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    expect_stop(NULL, 10, 0.0, SPVS_E_ARG);
    expect_recovery(n, 0.1);
}

/* ---- values ------------------------------------------------------------ */

/* NaN, +Inf and -Inf in each of the four coordinates of one match. */
static void test_non_finite_coordinates(void **state)
{
    (void)state;
    const double bad[3] = {0.0 / g_zero, 1.0 / g_zero, -1.0 / g_zero};
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    double t_s = 0.0;
    for (int field = 0; field < 4; field++) {
        for (int b = 0; b < 3; b++) {
            uint16_t n_good = default_frame();
            assert_int_equal(n_good, n);
            spvs_match_t *q = &g_m[n / 2];
            spvs_real *f[4] = {&q->x_tgt, &q->y_tgt, &q->x_cur, &q->y_cur};
            *f[field] = (spvs_real)bad[b];
            expect_stop(g_m, n, t_s, SPVS_E_NONFINITE);
            t_s += 0.1;
        }
    }
    default_frame();
    expect_recovery(n, t_s);
}

static void test_non_finite_time(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    expect_stop(g_m, n, 0.0 / g_zero, SPVS_E_NONFINITE);
    expect_stop(g_m, n, 1.0 / g_zero, SPVS_E_NONFINITE);
    expect_stop(g_m, n, -1.0 / g_zero, SPVS_E_NONFINITE);
    expect_recovery(n, 0.0);
}

/* Huge and just-out-of-range coordinates, and a feature index past the
 * off-plane memory. */
static void test_out_of_range(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    g_m[3].x_cur = (spvs_real)(SPVS_MAX_COORD_PX + 1);
    expect_stop(g_m, n, 0.0, SPVS_E_RANGE);
    default_frame();
    g_m[4].y_tgt = -SPVS_REAL_MAX;
    expect_stop(g_m, n, 0.1, SPVS_E_RANGE);
    default_frame();
    g_m[5].feature = SPVS_MAX_FEATURES;
    expect_stop(g_m, n, 0.2, SPVS_E_RANGE);
    default_frame();
    expect_recovery(n, 0.3);
}

/* ---- geometry ---------------------------------------------------------- */

/* Every match the same point: no sample fixes a homography. */
static void test_coincident_points(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    for (uint16_t i = 1; i < n; i++) {
        g_m[i] = g_m[0];
        g_m[i].feature = i;
    }
    expect_stop(g_m, n, 0.0, SPVS_E_DEGENERATE);
    default_frame();
    expect_recovery(n, 0.1);
}

/* Every target point on one image line: every 3-point sample is collinear. */
static void test_collinear_points(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    for (uint16_t i = 0; i < n; i++) {
        g_m[i].y_tgt = SPVS_R(0.25) * g_m[i].x_tgt + SPVS_R(10.0);
    }
    expect_stop(g_m, n, 0.0, SPVS_E_DEGENERATE);
    default_frame();
    expect_recovery(n, 0.1);
}

/* Three distinct plane matches, each repeated 20 times.  Samples holding a
 * repeated point are degenerate; the one distinct triple fits all 60 copies
 * exactly, so the consensus counts copies as support (docs/ROBUSTNESS.md
 * notes this).  With no off-plane point there is no epipole, and the robot
 * is told to stop. */
static void test_duplicates_only(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    for (uint16_t i = 3; i < 60; i++) {
        g_m[i] = g_m[i % 3];
    }
    spvs_output_t out;
    int rc = spvs_update(&g_s, g_m, 60, SPVS_R(0.0), &out);
    assert_int_equal(rc, SPVS_E_NO_PARALLAX);
    assert_int_equal(out.n_inliers, 60);
    assert_true(out.v == SPVS_R(0.0) && out.w == SPVS_R(0.0));
    default_frame();
    expect_recovery(n, 0.1);
}

/* Every current point replaced by an unrelated one. */
static void test_all_mismatches(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    uint32_t h = 12345u;
    for (uint16_t i = 0; i < n; i++) {
        h = h * 1664525u + 1013904223u;
        g_m[i].x_cur = (spvs_real)((double)(h >> 8 & 1023u) * 0.6 - 300.0);
        h = h * 1664525u + 1013904223u;
        g_m[i].y_cur = (spvs_real)((double)(h >> 8 & 1023u) * 0.45 - 230.0);
    }
    expect_stop(g_m, n, 0.0, SPVS_E_NO_CONSENSUS);
    default_frame();
    expect_recovery(n, 0.1);
}

/* ---- time -------------------------------------------------------------- */

static void test_time_repeated_or_backwards(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = default_frame();
    expect_recovery(n, 1.0);
    expect_stop(g_m, n, 1.0, SPVS_E_STALE);  /* same frame time */
    expect_stop(g_m, n, 0.9, SPVS_E_STALE);  /* backwards */
    expect_stop(g_m, n, -5.0, SPVS_E_STALE);
    expect_recovery(n, 1.1);
}

/* ---- plane and step failures (latched until reset) --------------------- */

/* Method III without any off-plane point: no epipole, no parallax. */
static void test_no_parallax(void **state)
{
    (void)state;
    init(SPVS_METHOD_III);
    uint16_t n = scene_frame(NULL, 0.0, 0, NULL);
    expect_stop(g_m, n, 0.0, SPVS_E_NO_PARALLAX);
    expect_stop(g_m, n, 0.1, SPVS_E_NO_PARALLAX);
}

/* A floor (n = (0, -1, 0), camera 1 m above it) gives Methods I and III no
 * n_z signal; a wall facing the camera (n = (0, 0, -1)) gives Method II no
 * n_y signal.  The failure is latched: later frames stop too. */
static void plane_case(spvs_method_t method, const double normal[3], double d_m,
                       int want)
{
    init(method);
    uint16_t n = scene_frame(normal, d_m, 25, NULL);
    int rc = SPVS_OK;
    double t_s = 0.0;
    /* The plane check runs once the gain signs can be chosen, within the
     * first frames. */
    for (int k = 0; k < 10 && rc == SPVS_OK; k++, t_s += 0.1) {
        spvs_output_t out;
        rc = spvs_update(&g_s, g_m, n, (spvs_real)t_s, &out);
        if (rc != SPVS_OK) {
            assert_true(out.v == SPVS_R(0.0) && out.w == SPVS_R(0.0));
        }
    }
    assert_int_equal(rc, want);
    expect_stop(g_m, n, t_s, want);
    assert_int_equal(spvs_step(&g_s), SPVS_STEP_FAILED);
}

static void test_plane_nz_method1(void **state)
{
    (void)state;
    const double floor_n[3] = {0.0, -1.0, 0.0};
    plane_case(SPVS_METHOD_I, floor_n, 1.0, SPVS_E_PLANE_NZ);
}

static void test_plane_nz_method3(void **state)
{
    (void)state;
    const double floor_n[3] = {0.0, -1.0, 0.0};
    plane_case(SPVS_METHOD_III, floor_n, 1.0, SPVS_E_PLANE_NZ);
}

static void test_plane_ny_method2(void **state)
{
    (void)state;
    const double wall_n[3] = {0.0, 0.0, -1.0};
    plane_case(SPVS_METHOD_II, wall_n, 45.0, SPVS_E_PLANE_NY);
}

/* The robot never turns (its commands are not applied): step 1 runs past
 * its time bound, fails, and stays failed with a stop. */
static void test_step_timeout(void **state)
{
    (void)state;
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    p.ctl.step_timeout_s = SPVS_R(2.0);
    assert_int_equal(spvs_init(&g_s, &p), SPVS_OK);
    uint16_t n = default_frame();
    int rc = SPVS_OK;
    int k = 0;
    spvs_output_t out;
    for (; k < 40 && rc != SPVS_E_STEP_TIMEOUT; k++) {
        rc = spvs_update(&g_s, g_m, n, (spvs_real)(0.1 * k), &out);
        if (rc == SPVS_OK) {
            assert_int_equal(out.step, SPVS_STEP_ROTATE);
        }
    }
    assert_int_equal(rc, SPVS_E_STEP_TIMEOUT);
    /* It fails on the first frame past the bound, not later. */
    assert_true(0.1 * (k - 1) > 2.0 - 1e-6 && 0.1 * (k - 1) < 2.2 + 1e-6);
    assert_int_equal(out.step, SPVS_STEP_FAILED);
    assert_true(out.v == SPVS_R(0.0) && out.w == SPVS_R(0.0));
    expect_stop(g_m, n, 0.1 * k + 0.1, SPVS_E_STEP_TIMEOUT);
    /* Reset clears it. */
    spvs_reset(&g_s);
    expect_recovery(n, 10.0);
}

/* ---- configuration ----------------------------------------------------- */

static void test_bad_config(void **state)
{
    (void)state;
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_II);
    p.noise_px = SPVS_R(0.0) / (spvs_real)g_zero; /* NaN */
    assert_int_equal(spvs_init(&g_s, &p), SPVS_E_CONFIG);
    spvs_params_default(&p, SPVS_METHOD_II);
    p.max_iters = SPVS_RANSAC_MAX_ITERS + 1u;
    assert_int_equal(spvs_init(&g_s, &p), SPVS_E_CONFIG);
    spvs_params_default(&p, SPVS_METHOD_II);
    p.ctl.v_max = -SPVS_R(1.0);
    assert_int_equal(spvs_init(&g_s, &p), SPVS_E_CONFIG);
    assert_int_equal(spvs_init(NULL, &p), SPVS_E_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_no_matches),
        cmocka_unit_test(test_two_matches),
        cmocka_unit_test(test_seven_matches),
        cmocka_unit_test(test_over_capacity),
        cmocka_unit_test(test_null_matches),
        cmocka_unit_test(test_non_finite_coordinates),
        cmocka_unit_test(test_non_finite_time),
        cmocka_unit_test(test_out_of_range),
        cmocka_unit_test(test_coincident_points),
        cmocka_unit_test(test_collinear_points),
        cmocka_unit_test(test_duplicates_only),
        cmocka_unit_test(test_all_mismatches),
        cmocka_unit_test(test_time_repeated_or_backwards),
        cmocka_unit_test(test_no_parallax),
        cmocka_unit_test(test_plane_nz_method1),
        cmocka_unit_test(test_plane_nz_method3),
        cmocka_unit_test(test_plane_ny_method2),
        cmocka_unit_test(test_step_timeout),
        cmocka_unit_test(test_bad_config),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
