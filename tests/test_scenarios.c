/*
 * test_scenarios.c - section 5 of the paper as closed-loop scenarios, through
 * the in-process link (issue 5, "Must be shown").  Target (0, 0, 0); the
 * default plane n = (0.3, -0.6, -0.75) normalised at d = 45 m unless a case
 * says otherwise; control period 0.1 s.
 *
 * test_closed_loop.c already runs (-3, -10, -30) and (5, 2, -50) without
 * noise and (-3, -10, -30) with 1 px noise; the cases here cover the rest of
 * Figure 5, Table 1, 1 px noise from all six Figure 5 poses, odometry drift
 * and calibration errors.  tools/experiments.py runs the same experiments at
 * full size and writes docs/RESULTS.md.  Every failing run is printed with its
 * status and final error before the assertion.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "sim/link_fixed.h"
#include "sim/link_inproc.h"
#include "sim/sim.h"

/* The core under test: the float core in-process, or the fixed-point core
 * (docs/FIXED.md) where the test is built with SPVS_TEST_FIXED=1 (the
 * _fixed tests): the same scenarios and the same limits for both. */
#if defined(SPVS_TEST_FIXED) && SPVS_TEST_FIXED
#define sim_run_core sim_run_fixed
#else
#define sim_run_core sim_run_inproc
#endif

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

/* The six start poses of the paper's Figure 5 (x m, z m, phi deg). */
static const double fig5_poses[6][3] = {
    {-3.0, -10.0, -30.0}, {0.0, -8.0, -40.0}, {6.0, -6.0, 0.0},
    {-6.0, 4.0, 20.0},    {6.0, 8.0, 10.0},   {5.0, 2.0, -50.0},
};

/* Heading at the end of step 1, recorded by the frame callback. */
typedef struct {
    double phi_end_step1_rad;
    int seen_step2;
} step1_watch_t;

static int watch_step1(const sim_frame_t *f, void *user)
{
    step1_watch_t *w = user;
    if (!w->seen_step2 && f->out->step == SPVS_STEP_ROTATE) {
        w->phi_end_step1_rad = f->pose.phi_rad;
    }
    if (f->out->step == SPVS_STEP_TRANSLATE) {
        w->seen_step2 = 1;
    }
    return 0;
}

/* Run c through a fresh in-process controller; fails the test if the
 * set-up is refused (a refused set-up is a bug in the test, not a result). */
static void run_cfg(const sim_config_t *c, sim_result_t *res, sim_frame_cb cb,
                    void *user)
{
    char err[160];
    int rc = sim_run_core(c, res, cb, user, err, sizeof(err));
    if (rc != 0) {
        print_message("the run did not take place: %s\n", err);
    }
    assert_int_equal(rc, 0);
}

static void config(sim_config_t *c, int method, const double pose[3])
{
    sim_config_default(c);
    c->method = method;
    c->start.x_m = pose[0];
    c->start.z_m = pose[1];
    c->start.phi_rad = pose[2] * DEG;
}

/* Converged, and |x|, |z| < tol_m and |phi| < tol_deg. */
static int within(const sim_result_t *r, double tol_m, double tol_deg)
{
    return r->status == SIM_CONVERGED && fabs(r->err_x_m) < tol_m &&
           fabs(r->err_z_m) < tol_m && fabs(r->err_phi_deg) < tol_deg;
}

static void report(const char *what, const sim_config_t *c,
                   const sim_result_t *r)
{
    print_message("%s%smethod %d from (%g, %g, %g) seed %u: %s%s%s after "
                  "%.1f s, final error x %+.4f m, z %+.4f m, phi %+.4f deg\n",
                  what, what[0] ? ": " : "", c->method, c->start.x_m, c->start.z_m,
                  c->start.phi_rad / DEG, (unsigned)c->seed,
                  sim_status_str(r->status), r->reason[0] ? " " : "",
                  r->reason, r->time_s, r->err_x_m, r->err_z_m,
                  r->err_phi_deg);
}

/* Figure 5 without noise: every method converges to within 0.02 m and
 * 0.1 deg from all six poses (18 of 18 runs), each through the arrival
 * check: converged means the check accepted the averaged H. */
static void test_fig5_noise_free(void **state)
{
    (void)state;
    int bad = 0;
    for (int i = 0; i < 6; ++i) {
        for (int method = 1; method <= 3; ++method) {
            sim_config_t c;
            sim_result_t r;
            config(&c, method, fig5_poses[i]);
            run_cfg(&c, &r, NULL, NULL);
            if (!within(&r, 0.02, 0.1)) {
                report("Figure 5, limits 0.02 m / 0.1 deg", &c, &r);
                ++bad;
            }
        }
    }
    assert_int_equal(bad, 0);
}

/* eq. (19)'s residual f at (x, z, phi) on the default plane, in the closed
 * form of DESIGN.md: f = 2A/d (n_x cos phi + n_z sin phi)
 * + A^2 (n_x^2 + n_z^2) / d^2, with A = x cos phi + z sin phi. */
static double eq19_residual(double x, double z, double phi)
{
    const double n0[3] = {0.3, -0.6, -0.75};
    const double nn = sqrt(n0[0] * n0[0] + n0[1] * n0[1] + n0[2] * n0[2]);
    const double nx = n0[0] / nn, nz = n0[2] / nn, d = 45.0;
    double a = x * cos(phi) + z * sin(phi);
    return 2.0 * a / d * (nx * cos(phi) + nz * sin(phi)) +
           a * a * (nx * nx + nz * nz) / (d * d);
}

/* Method I's false zero (docs/CONTROL_ANALYSIS.md): from (6, -6, 0) and
 * (-6, 4, 20), f vanishes at a heading phi_f other than the line through the
 * target phi_t, within 25 deg of the start and on the way to phi_t.  Step 1
 * must end facing the target (within 2 deg of phi_t, at least 5 deg past
 * phi_f), not at phi_f. */
static void test_method1_passes_false_zero(void **state)
{
    (void)state;
    const double starts[2][3] = {{6.0, -6.0, 0.0}, {-6.0, 4.0, 20.0}};
    for (int i = 0; i < 2; ++i) {
        const double x = starts[i][0], z = starts[i][1];
        const double phi0 = starts[i][2] * DEG;
        const double phit = atan(-x / z);
        /* The false zero: the sign change of f between phi0 - 5 deg and
         * phi_t that is not phi_t itself, found on a 0.01 deg grid. */
        double phif = NAN;
        const double lo = fmin(phi0, phit) - 5.0 * DEG;
        const double hi = fmax(phi0, phit);
        for (double p = lo; p < hi; p += 0.01 * DEG) {
            double f0 = eq19_residual(x, z, p);
            double f1 = eq19_residual(x, z, p + 0.01 * DEG);
            if ((f0 > 0.0) != (f1 > 0.0) && fabs(p - phit) > 1.0 * DEG) {
                phif = p;
                break;
            }
        }
        print_message("start (%g, %g, %g): phi_t %.2f deg, false zero of "
                      "eq. (19) at %.2f deg\n", x, z, starts[i][2],
                      phit / DEG, phif / DEG);
        assert_true(isfinite(phif));
        assert_true(fabs(phif - phi0) < 25.0 * DEG);

        sim_config_t c;
        sim_result_t r;
        step1_watch_t w = {NAN, 0};
        config(&c, 1, starts[i]);
        run_cfg(&c, &r, watch_step1, &w);
        print_message("  Method I: step 1 ended at %.2f deg; %s, final error "
                      "x %+.4f m, z %+.4f m, phi %+.4f deg\n",
                      w.phi_end_step1_rad / DEG, sim_status_str(r.status),
                      r.err_x_m, r.err_z_m, r.err_phi_deg);
        assert_true(w.seen_step2);
        assert_true(fabs(w.phi_end_step1_rad - phit) < 2.0 * DEG);
        assert_true(fabs(w.phi_end_step1_rad - phif) > 5.0 * DEG);
        assert_true(within(&r, 0.02, 0.1));
    }
}

/* The normals of the paper's Table 1 as printed (rounded to two decimals;
 * normalised before use).  Rows 1/18 and 12/13 repeat a normal there and
 * are run once here. */
static const double table1_normals[16][3] = {
    {0.0, 0.0, -1.0},     {-0.20, 0.57, -0.80}, {-0.40, 0.69, -0.60},
    {-0.60, 0.69, -0.40}, {-0.80, 0.57, -0.20}, {-1.0, 0.0, 0.0},
    {1.0, 0.0, 0.0},      {0.98, -0.20, 0.0},   {0.92, -0.40, 0.0},
    {0.80, -0.60, 0.0},   {0.60, -0.80, 0.0},   {0.0, -1.0, 0.0},
    {0.57, -0.80, -0.20}, {0.69, -0.60, -0.40}, {0.69, -0.40, -0.60},
    {0.57, -0.20, -0.80},
};

/* Table 1 from (-3, -10, -30), every row judged against the status
 * docs/RESULTS.md gives it: where the component a method relies on (n_z
 * for I and III, n_y for II) is zero, the run fails with the plane status
 * and the robot never leaves its start pose; everywhere else, the rows
 * where that component is about 0.2 included, the method converges within
 * 0.05 m and 0.2 deg. */
static void test_table1_plane_normals(void **state)
{
    (void)state;
    int bad = 0;
    for (int row = 0; row < 16; ++row) {
        const double *n0 = table1_normals[row];
        double nn = sqrt(n0[0] * n0[0] + n0[1] * n0[1] + n0[2] * n0[2]);
        for (int method = 1; method <= 3; ++method) {
            sim_config_t c;
            sim_result_t r;
            config(&c, method, fig5_poses[0]);
            for (int k = 0; k < 3; ++k) {
                c.normal[k] = n0[k] / nn;
            }
            double comp = fabs(c.normal[method == 2 ? 1 : 2]);
            const char *why = method == 2 ? "plane_normal_ny_zero"
                                          : "plane_normal_nz_zero";
            run_cfg(&c, &r, NULL, NULL);
            int ok;
            if (comp < 1e-12) {
                ok = r.status == SIM_FAILED && strcmp(r.reason, why) == 0 &&
                     r.final_pose.x_m == c.start.x_m &&
                     r.final_pose.z_m == c.start.z_m &&
                     r.final_pose.phi_rad == c.start.phi_rad &&
                     r.path_m == 0.0;
            } else {
                ok = within(&r, 0.05, 0.2);
            }
            if (!ok) {
                print_message("Table 1 row %d, n = (%.2f, %.2f, %.2f), "
                              "component %.2f, expected %s: ", row + 1, n0[0],
                              n0[1], n0[2], comp,
                              comp < 1e-12 ? why : "0.05 m / 0.2 deg");
                report("", &c, &r);
                ++bad;
            }
        }
    }
    assert_int_equal(bad, 0);
}

/* 1 px image noise from the six Figure 5 poses, in three cases: alone
 * (seeds 0..19, 120 runs per method), with 20 % mismatches (seeds 0..4, 30
 * runs per method), and with a robot whose commands act 0.2 s after their
 * frame and whose speeds follow them within 0.5 m/s^2 and 1 rad/s^2 (seeds
 * 0..4): no run reports "converged" outside 0.25 m / 0.5 deg (the arrival
 * check, docs/CONTROL.md), and the share of runs that end within them
 * (whatever their status) and the share that end there converged each
 * reach a floor: the rate measured on 600 runs per method and case on
 * seeds the tests do not use (1000-1099, the table of docs/CONTROL.md, in
 * noise_rates below) minus three binomial standard deviations of a share
 * of this test's run count n, 3 sqrt(p (1 - p) / n), with p kept at most
 * 1 - 1/n so that a rate measured at or near 100 % still leaves a
 * margin. */
enum { CASE_NOISE, CASE_MISMATCH, CASE_ROBOT, CASE_COUNT };
static const int case_seeds[CASE_COUNT] = {20, 5, 5};
static const char *const case_name[CASE_COUNT] = {"1 px", "1 px, 20 % mismatches",
                                                  "1 px, 0.2 s latency, 0.5 m/s^2, 1 rad/s^2"};

/* Measured rates (docs/CONTROL.md, seeds 1000-1099): [case][method - 1] =
 * {home, converged}. */
static const double noise_rates[CASE_COUNT][3][2] = {
    {{600 / 600.0, 600 / 600.0}, {589 / 600.0, 589 / 600.0}, {600 / 600.0, 600 / 600.0}},
    {{598 / 600.0, 593 / 600.0}, {593 / 600.0, 592 / 600.0}, {600 / 600.0, 600 / 600.0}},
    {{600 / 600.0, 600 / 600.0}, {580 / 600.0, 580 / 600.0}, {599 / 600.0, 599 / 600.0}},
};

/* The fewest of `runs` runs that may meet a rate measured at p. */
static int binomial_floor(double p, int runs)
{
    const double pc = p < 1.0 - 1.0 / runs ? p : 1.0 - 1.0 / runs;
    const double floor_share = p - 3.0 * sqrt(pc * (1.0 - pc) / runs);
    return (int)ceil(floor_share * runs - 1e-9);
}

typedef struct {
    int home;         /* ended within 0.25 m / 0.5 deg, any status */
    int converged;    /* ... and converged                         */
    int false_claims; /* converged outside                         */
} noise_count_t;

static void noise_runs(int method, int kase, int seeds, noise_count_t *n)
{
    for (int i = 0; i < 6; ++i) {
        for (uint64_t seed = 0; seed < (uint64_t)seeds; ++seed) {
            sim_config_t c;
            sim_result_t r;
            config(&c, method, fig5_poses[i]);
            c.noise_px = 1.0;
            c.outliers = kase == CASE_MISMATCH ? 0.2 : 0.0;
            if (kase == CASE_ROBOT) {
                c.robot.latency_s = 0.2;
                c.robot.accel_mps2 = 0.5;
                c.robot.alpha_radps2 = 1.0;
            }
            c.seed = seed;
            run_cfg(&c, &r, NULL, NULL);
            const int home = fabs(r.err_x_m) < 0.25 && fabs(r.err_z_m) < 0.25 &&
                             fabs(r.err_phi_deg) < 0.5;
            n->home += home;
            n->converged += home && r.status == SIM_CONVERGED;
            if (!home && r.status == SIM_CONVERGED) {
                report("  claims converged outside 0.25 m / 0.5 deg", &c, &r);
                ++n->false_claims;
            }
        }
    }
}

static void test_one_pixel_noise_six_poses(void **state)
{
    (void)state;
    int short_counts = 0, false_claims = 0;
    for (int method = 1; method <= 3; ++method) {
        for (int kase = 0; kase < CASE_COUNT; ++kase) {
            const int seeds = case_seeds[kase];
            const int runs = 6 * seeds;
            noise_count_t n = {0, 0, 0};
            noise_runs(method, kase, seeds, &n);
            const int min_home = binomial_floor(noise_rates[kase][method - 1][0], runs);
            const int min_conv = binomial_floor(noise_rates[kase][method - 1][1], runs);
            print_message("method %d, %s: %d of %d runs end within 0.25 m / 0.5 deg (at least "
                          "%d needed), %d of them converged (at least %d needed)\n", method,
                          case_name[kase], n.home, runs, min_home, n.converged, min_conv);
            short_counts += (n.home < min_home) + (n.converged < min_conv);
            false_claims += n.false_claims;
        }
    }
    assert_int_equal(false_claims, 0);
    assert_int_equal(short_counts, 0);
}

/* Odometry drift of 1 deg/m (the paper's Figure 7, first row): every method
 * still converges from (-3, -10, -30) within 0.05 m and 0.5 deg. */
static void test_drift_one_degree_per_metre(void **state)
{
    (void)state;
    int bad = 0;
    for (int method = 1; method <= 3; ++method) {
        sim_config_t c;
        sim_result_t r;
        config(&c, method, fig5_poses[0]);
        c.drift_deg_per_m = 1.0;
        run_cfg(&c, &r, NULL, NULL);
        if (!within(&r, 0.05, 0.5)) {
            report("drift 1 deg/m, limits 0.05 m / 0.5 deg", &c, &r);
            ++bad;
        }
    }
    assert_int_equal(bad, 0);
}

/* Focal length (Figure 8, first row): Methods II and III do not use alpha,
 * so with the true focal length at 4, 5, 7 or 8 mm while the controller
 * assumes 6 mm they still converge within 0.05 m and 0.2 deg. */
static void test_focal_length_methods_2_3(void **state)
{
    (void)state;
    const double focals_mm[4] = {4.0, 5.0, 7.0, 8.0};
    int bad = 0;
    for (int method = 2; method <= 3; ++method) {
        for (int i = 0; i < 4; ++i) {
            sim_config_t c;
            sim_result_t r;
            config(&c, method, fig5_poses[0]);
            c.focal_true_mm = focals_mm[i];
            run_cfg(&c, &r, NULL, NULL);
            if (!within(&r, 0.05, 0.2)) {
                print_message("true focal %.0f mm: ", focals_mm[i]);
                report("limits 0.05 m / 0.2 deg", &c, &r);
                ++bad;
            }
        }
    }
    assert_int_equal(bad, 0);
}

/* Principal point (Figure 8, second row): the paper finds Method III
 * sensitive to x0 and Method II robust.  Over offsets of -40, -20, 20 and
 * 40 px both now end converged within 0.15 m of the target: Method III's
 * first arrival is off as in the paper, and the arrival check's parallax
 * test sends it back until it is home (docs/CONTROL.md; docs/RESULTS.md,
 * Figure 8). */
static void test_principal_point_sensitivity(void **state)
{
    (void)state;
    const double offsets_px[4] = {-40.0, -20.0, 20.0, 40.0};
    double worst[4] = {0.0, 0.0, 0.0, 0.0};
    for (int method = 2; method <= 3; ++method) {
        for (int i = 0; i < 4; ++i) {
            sim_config_t c;
            sim_result_t r;
            config(&c, method, fig5_poses[0]);
            c.pp_offset_px = offsets_px[i];
            run_cfg(&c, &r, NULL, NULL);
            double dist = hypot(r.err_x_m, r.err_z_m);
            print_message("principal point offset %+.0f px: ", offsets_px[i]);
            report("", &c, &r);
            if (r.status != SIM_CONVERGED) {
                dist = INFINITY;
            }
            worst[method] = fmax(worst[method], dist);
        }
    }
    print_message("worst final distance: Method II %.3f m, Method III %.3f m\n",
                  worst[2], worst[3]);
    assert_true(worst[2] < 0.15);
    assert_true(worst[3] < 0.15);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fig5_noise_free),
        cmocka_unit_test(test_method1_passes_false_zero),
        cmocka_unit_test(test_table1_plane_normals),
        cmocka_unit_test(test_one_pixel_noise_six_poses),
        cmocka_unit_test(test_drift_one_degree_per_metre),
        cmocka_unit_test(test_focal_length_methods_2_3),
        cmocka_unit_test(test_principal_point_sensitivity),
    };
    return cmocka_run_group_tests_name("scenarios", tests, NULL, NULL);
}
