/* test_control.c - the Shortest Path Control laws, gain signs, step logic
 * and latched failures (control.h), fed with exact geometry. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "unity.h"
#include "unit_support.h"

#include "spvs/control.h"
#include "spvs/homography.h"
#include "synth.h"

#define DEG (SYNTH_PI / 180.0)

static synth_plane_t default_plane(void)
{
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    return pl;
}

/* The controller's input for a pose: H of eq. (2), the signed epipole
 * e = K(-R c) and a parallax that shrinks with the distance (pixels). */
static void make_input(const synth_pose_t *p, const synth_plane_t *pl, double t,
                       spvs_control_input_t *in)
{
    double H[9];
    synth_H(p, pl, 800, H);
    for (int k = 0; k < 9; k++) {
        in->H[k] = (spvs_real)H[k];
    }
    double c = cos(p->phi), s = sin(p->phi);
    double e1 = -(c * p->x + s * p->z), e3 = -(-s * p->x + c * p->z);
    double r = sqrt(p->x * p->x + p->z * p->z);
    in->e_valid = r > 0.05;
    double ex = 800 * e1 / e3;
    if (fabs(ex) > 20000) {
        ex = ex > 0 ? 20000 : -20000;
    }
    in->e_x_px = (spvs_real)ex;
    in->e_dir_x = (spvs_real)(800 * e1);
    in->e_dir_z = (spvs_real)e3;
    in->parallax_px = (spvs_real)(20.0 * r);
    /* The remembered points' parallax has no direction here. */
    in->parallax_x_px = 0;
    in->parallax_r_px = 0;
    in->t_s = (spvs_real)t;
    in->n_inliers = 100;
}

typedef struct {
    spvs_step_t step;
    int status;
    double t_end[4];
    double phi_end[4];
    synth_pose_t pose;
    double min_v, max_v;
} loop_result_t;

/* The control law alone on the unicycle of eq. (7), dt = 0.1 s. */
static void run_loop(spvs_method_t m, synth_pose_t pose, const synth_plane_t *pl,
                     loop_result_t *res)
{
    spvs_control_params_t p;
    spvs_control_params_default(&p, m);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_control_params_check(&p));
    spvs_control_t c;
    spvs_control_reset(&c);
    res->min_v = 1e9;
    res->max_v = -1e9;
    for (int k = 1; k < 4; k++) {
        res->t_end[k] = -1;
    }
    double dt = 0.1;
    for (int k = 0; k < 3000; k++) {
        spvs_control_input_t in;
        make_input(&pose, pl, k * dt, &in);
        spvs_real v, w;
        spvs_step_t before = c.step;
        int rc = spvs_control_step(&c, &p, &in, &v, &w);
        res->status = rc;
        if (rc != SPVS_OK) {
            TEST_ASSERT_TRUE(v == 0 && w == 0);
        }
        TEST_ASSERT_TRUE(fabs((double)v) <= (double)p.v_max && fabs((double)w) <= (double)p.w_max);
        if (c.step != before && before >= SPVS_STEP_ROTATE && before <= SPVS_STEP_ALIGN) {
            res->t_end[before] = k * dt;
            res->phi_end[before] = pose.phi;
        }
        if (c.step == SPVS_STEP_TRANSLATE || before == SPVS_STEP_TRANSLATE) {
            if (v < res->min_v) {
                res->min_v = v;
            }
            if (v > res->max_v) {
                res->max_v = v;
            }
        }
        if (c.step == SPVS_STEP_DONE || c.step == SPVS_STEP_FAILED) {
            break;
        }
        /* Exact integration of eq. (7). */
        double vv = v, ww = w;
        if (fabs(ww) > 1e-12) {
            pose.x += vv / ww * (cos(pose.phi + ww * dt) - cos(pose.phi));
            pose.z += vv / ww * (sin(pose.phi + ww * dt) - sin(pose.phi));
        } else {
            pose.x += -vv * dt * sin(pose.phi);
            pose.z += vv * dt * cos(pose.phi);
        }
        pose.phi += ww * dt;
    }
    res->step = c.step;
    res->pose = pose;
}

/* All three methods, from the paper's first pose and from behind the target:
 * step 1 ends facing the target line (phi_t = -atan(x / z)), step 2 drives
 * forwards or backwards as needed, and the robot ends at the target. */
static void test_closed_loop_law(void)
{
    synth_plane_t pl = default_plane();
    const double poses[][3] = {{-3, -10, -30}, {5, 2, -50}, {6, -6, 0}, {-6, 4, 20}};
    for (int m = 1; m <= 3; m++) {
        for (int i = 0; i < 4; i++) {
            synth_pose_t p = {poses[i][0], poses[i][1], poses[i][2] * DEG};
            double phit = -atan(p.x / p.z);
            loop_result_t r;
            run_loop((spvs_method_t)m, p, &pl, &r);
            UNIT_NOTE("method %d from (%g,%g,%g): step ends %.1f %.1f %.1f s, final (%.4f, %.4f, %.3f deg)\n", m, poses[i][0], poses[i][1], poses[i][2], r.t_end[1], r.t_end[2], r.t_end[3], r.pose.x, r.pose.z, r.pose.phi / DEG);
            TEST_ASSERT_EQUAL_INT64(SPVS_STEP_DONE, r.step);
            TEST_ASSERT_EQUAL_INT64(SPVS_OK, r.status);
            /* Facing the target line within 0.1 deg when step 1 ends. */
            UNIT_NOTE("  step-1 end heading error %.3f deg\n", (r.phi_end[1] - phit) / DEG);
            TEST_ASSERT_TRUE(fabs(r.phi_end[1] - phit) < 0.1 * DEG);
            TEST_ASSERT_TRUE(r.t_end[1] > 0 && r.t_end[2] > r.t_end[1] && r.t_end[3] > r.t_end[2]);
            TEST_ASSERT_TRUE(fabs(r.pose.x) < 0.02 && fabs(r.pose.z) < 0.02);
            TEST_ASSERT_TRUE(fabs(r.pose.phi) < 0.1 * DEG);
            if (p.z < 0) {
                TEST_ASSERT_TRUE(r.min_v >= 0 && r.max_v > 0.1); /* forwards */
            } else {
                TEST_ASSERT_TRUE(r.max_v <= 0 && r.min_v < -0.1); /* backwards */
            }
        }
    }
}

/* The start: hold_frames frames standing still while the plane check and the
 * signs are decided from their sums, then the first command.  From (-3, -10,
 * -30 deg): v = 0 and the robot turns towards phi_t = -16.7 deg (w > 0) with
 * every method; from (5, 2, -50 deg) towards phi_t = -68.2 deg (w < 0). */
static void start_frames(spvs_control_t *c, const spvs_control_params_t *p,
                         const synth_pose_t *pose, const synth_plane_t *pl, int expect_last,
                         spvs_real *v, spvs_real *w)
{
    spvs_control_input_t in;
    for (uint16_t k = 0; k < p->hold_frames; k++) {
        make_input(pose, pl, 0.1 * k, &in);
        int rc = spvs_control_step(c, p, &in, v, w);
        if (k + 1u < p->hold_frames) {
            TEST_ASSERT_EQUAL_INT64(SPVS_OK, rc);
            TEST_ASSERT_TRUE(*v == 0 && *w == 0);
            TEST_ASSERT_EQUAL_INT64(SPVS_STEP_ROTATE, c->step);
        } else {
            TEST_ASSERT_EQUAL_INT64(expect_last, rc);
        }
    }
}

static void test_first_command_signs(void)
{
    synth_plane_t pl = default_plane();
    for (int m = 1; m <= 3; m++) {
        spvs_control_params_t p;
        spvs_control_params_default(&p, (spvs_method_t)m);
        spvs_control_t c;
        spvs_real v, w;
        synth_pose_t a = {-3, -10, -30 * DEG};
        spvs_control_reset(&c);
        start_frames(&c, &p, &a, &pl, SPVS_OK, &v, &w);
        TEST_ASSERT_TRUE(v == 0 && w > 0);
        TEST_ASSERT_EQUAL_INT64(1, c.ahead);
        synth_pose_t b = {5, 2, -50 * DEG};
        spvs_control_reset(&c);
        start_frames(&c, &p, &b, &pl, SPVS_OK, &v, &w);
        TEST_ASSERT_TRUE(v == 0 && w < 0);
        TEST_ASSERT_EQUAL_INT64(-1, c.ahead);
    }
}

/* Table 1's failures, said by a status: Methods I and III need n_z, Method
 * II needs n_y.  The failure is latched and commands a stop. */
static void test_plane_check(void)
{
    synth_plane_t wall, floor_pl;
    synth_plane(&wall, 1.0, 0.0, 0.0, 45);       /* n_z = 0, n_y = 0 */
    synth_plane(&floor_pl, 0.8, -0.6, 0.0, 45);  /* n_z = 0          */
    synth_plane_t front;
    synth_plane(&front, 0.0, 0.0, -1.0, 45);     /* n_y = 0          */
    synth_pose_t p = {-3, -10, -30 * DEG};
    const struct {
        int method;
        const synth_plane_t *pl;
        int expect;
    } cases[] = {{1, &wall, SPVS_E_PLANE_NZ}, {3, &floor_pl, SPVS_E_PLANE_NZ},
                 {2, &front, SPVS_E_PLANE_NY}, {2, &wall, SPVS_E_PLANE_NY},
                 {2, &floor_pl, SPVS_OK},      {1, &front, SPVS_OK}};
    for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        spvs_control_params_t prm;
        spvs_control_params_default(&prm, (spvs_method_t)cases[i].method);
        spvs_control_t c;
        spvs_control_reset(&c);
        spvs_real v = 1, w = 1;
        start_frames(&c, &prm, &p, cases[i].pl, cases[i].expect, &v, &w);
        if (cases[i].expect != SPVS_OK) {
            TEST_ASSERT_TRUE(v == 0 && w == 0);
            TEST_ASSERT_EQUAL_INT64(SPVS_STEP_FAILED, c.step);
            spvs_control_input_t in;
            make_input(&p, cases[i].pl, 1.0, &in);
            TEST_ASSERT_EQUAL_INT64(cases[i].expect, spvs_control_step(&c, &prm, &in, &v, &w));
            TEST_ASSERT_TRUE(v == 0 && w == 0);
        }
    }
}

static void test_no_parallax_and_timeout(void)
{
    synth_plane_t pl = default_plane();
    spvs_control_params_t p;
    spvs_control_params_default(&p, SPVS_METHOD_III);
    spvs_control_t c;
    spvs_control_reset(&c);
    synth_pose_t a = {-3, -10, -30 * DEG};
    spvs_control_input_t in;
    make_input(&a, &pl, 0, &in);
    in.e_valid = 0;
    spvs_real v = 1, w = 1;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NO_PARALLAX, spvs_control_step(&c, &p, &in, &v, &w));
    TEST_ASSERT_TRUE(v == 0 && w == 0);
    /* A robot that never turns (stuck wheels): the step times out. */
    in.e_valid = 1;
    int rc = SPVS_OK;
    for (int k = 1; k < 2000 && rc == SPVS_OK; k++) {
        in.t_s = (spvs_real)(0.1 * k);
        rc = spvs_control_step(&c, &p, &in, &v, &w);
    }
    TEST_ASSERT_EQUAL_INT64(SPVS_E_STEP_TIMEOUT, rc);
    TEST_ASSERT_TRUE(v == 0 && w == 0);
    TEST_ASSERT_TRUE((double)in.t_s > (double)p.step_timeout_s);
    TEST_ASSERT_TRUE((double)in.t_s < (double)p.step_timeout_s + 0.25);
}

/* Method III: near the target the parallax falls under 5 px and the rotation
 * switches to eq. (11) with cos(phi_t) learnt on the line (eq. 8). */
static void test_method3_eq11(void)
{
    synth_plane_t pl = default_plane();
    spvs_control_params_t p;
    spvs_control_params_default(&p, SPVS_METHOD_III);
    spvs_control_t c;
    spvs_control_reset(&c);
    double phit = -atan(-3.0 / -10.0);
    int switched_at = -1;
    for (int k = 0; k < 400; k++) {
        double z = -10 + 0.03 * k;
        synth_pose_t pose = {-z * tan(phit), z, phit};
        spvs_control_input_t in;
        make_input(&pose, &pl, 0.1 * k, &in);
        spvs_real v, w;
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_control_step(&c, &p, &in, &v, &w));
        if (c.use_eq11 && switched_at < 0) {
            switched_at = k;
            /* The parallax model here is 20 px per metre: 5 px at 0.25 m;
             * the switch comes once it has stayed under 5 px for
             * hold_frames frames (the robot moves 0.031 m per frame here). */
            double r = sqrt(pose.x * pose.x + pose.z * pose.z);
            double r_expect = 0.25 - (p.hold_frames - 1) * 0.0313;
            TEST_ASSERT_TRUE(r < 0.25 && fabs(r - r_expect) < 0.032);
        }
        if (c.step == SPVS_STEP_ALIGN) {
            break;
        }
    }
    TEST_ASSERT_TRUE(switched_at > 0);
    TEST_ASSERT_TRUE(fabs((double)c.cos_phit - cos(phit)) < 1e-4);
    TEST_ASSERT_EQUAL_INT64(-1, c.sign_sin_phit);
}

/* The arrival check: a controller that has just ended step 3 at pose, fed
 * arrival_frames frames from there (the robot stands still), each with the
 * remembered off-plane points' parallax par_px, and h33 moved by
 * h33_bias + (-1)^k h33_noise (a goal image's fixed share and a current
 * image's noise, frame to frame). */
static int arrival_noisy(spvs_control_t *c, const spvs_control_params_t *p,
                         const synth_pose_t *pose, double t0, double par_px, double h33_bias,
                         double h33_noise)
{
    const synth_plane_t pl = default_plane();
    c->checked_plane = 1;
    c->step = SPVS_STEP_ALIGN;
    c->step_t0 = (spvs_real)t0;
    c->sign_w = 1;
    c->sign_v = 1;
    c->arriving = 1;
    c->arrive_n = 0;
    c->arrive_par_n = 0;
    c->arrive_par_sum = 0;
    for (int k = 0; k < 6; k++) {
        c->arrive_sum[k] = 0;
    }
    for (int k = 0; k < SPVS_CTL_ARRIVAL_RESIDUALS; k++) {
        c->arrive_res[k] = 0;
        c->arrive_sq[k] = 0;
    }
    int rc = SPVS_OK;
    for (int k = 0; k < p->arrival_frames && rc == SPVS_OK; k++) {
        spvs_control_input_t in;
        make_input(pose, &pl, t0 + 0.1 * k, &in);
        in.parallax_px = (spvs_real)par_px;
        in.parallax_x_px = 0;
        in.parallax_r_px = 0;
        in.H[SPVS_H33] += (spvs_real)(h33_bias + ((k & 1) ? -h33_noise : h33_noise));
        spvs_real v = 1, w = 1;
        rc = spvs_control_step(c, p, &in, &v, &w);
        TEST_ASSERT_TRUE(v == 0 && w == 0);
    }
    return rc;
}

static int arrival_at_par(spvs_control_t *c, const spvs_control_params_t *p,
                          const synth_pose_t *pose, double t0, double par_px)
{
    return arrival_noisy(c, p, pose, t0, par_px, 0.0, 0.0);
}

/* ... with no off-plane point in view (the H figures alone decide). */
static int arrival_at(spvs_control_t *c, const spvs_control_params_t *p,
                      const synth_pose_t *pose, double t0)
{
    return arrival_at_par(c, p, pose, t0, -1.0);
}

/* Mean corner transfer of the exact H at pose, pixels (the check's figure). */
static double corner_px(const synth_pose_t *pose)
{
    const synth_plane_t pl = default_plane();
    double H[9], sum = 0;
    synth_H(pose, &pl, 800, H);
    for (int k = 0; k < 4; k++) {
        double u = (k & 1) ? 320 : -320, v = (k & 2) ? 240 : -240;
        double x = H[0] * u + H[1] * v + H[2], y = H[3] * u + H[4] * v + H[5];
        double w = H[6] * u + H[7] * v + H[8];
        sum += hypot(x / w - u, y / w - v) / 4;
    }
    return sum;
}

/* Exact frames have no spread: every residual's sd is the least,
 * SPVS_CTL_ARRIVAL_SD_MIN_MPX (0.01 px).  Accepted at the target; rejected 0.3 m
 * along the axis (first the one depth correction, then a failed check:
 * step 2 again), 0.3 m sideways facing the target heading's h13 = 0 (step
 * 1's verdict: the robot backs off, in step 2, for a new start) and 0.5
 * deg off the heading (step 3 again), each with the mean corner transfer
 * of that pose's exact H. */
static void test_arrival_check(void)
{
    for (int m = 1; m <= 3; m++) {
        spvs_control_params_t p;
        spvs_control_params_default(&p, (spvs_method_t)m);
        spvs_control_t c;
        spvs_control_reset(&c);
        synth_pose_t home = {0, 0, 0};
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, arrival_at(&c, &p, &home, 0));
        TEST_ASSERT_EQUAL_INT64(SPVS_STEP_DONE, c.step);
        TEST_ASSERT_TRUE(c.arrival_stat < 1e-2);
        TEST_ASSERT_TRUE(fabs((double)c.arrival_h13_sd_px - 0.01) < 1e-6);
        TEST_ASSERT_TRUE(fabs((double)c.arrival_depth_sd_px - 0.01) < 1e-6);
        TEST_ASSERT_TRUE(c.arrival_corner_px < 1e-3);
        TEST_ASSERT_EQUAL_INT64(0, c.reentries);

        const double nz = -0.75 / sqrt(0.3 * 0.3 + 0.6 * 0.6 + 0.75 * 0.75);
        const struct {
            synth_pose_t pose;
            spvs_step_t verdict, step;
        } cases[] = {{{0, 0.3, 0}, SPVS_STEP_TRANSLATE, SPVS_STEP_TRANSLATE},
                     {{0.3, 0, -atan(0.3 * nz / 45)}, SPVS_STEP_ROTATE, SPVS_STEP_TRANSLATE},
                     {{0, 0, 0.5 * DEG}, SPVS_STEP_ALIGN, SPVS_STEP_ALIGN}};
        for (int i = 0; i < 3; i++) {
            spvs_control_reset(&c);
            TEST_ASSERT_EQUAL_INT64(SPVS_OK, arrival_at(&c, &p, &cases[i].pose, 0));
            if (i == 0) {
                /* The depth correction: not a failed check. */
                TEST_ASSERT_EQUAL_INT64(SPVS_STEP_TRANSLATE, c.step);
                TEST_ASSERT_EQUAL_INT64(0, c.reentries);
                TEST_ASSERT_EQUAL_INT64(1, c.depth_fixed);
                TEST_ASSERT_EQUAL_INT64(SPVS_OK, arrival_at(&c, &p, &cases[i].pose, 10.0));
            }
            UNIT_NOTE("method %d case %d: statistic %.1f, lateral %.3f, depth %.3f, h13 %.3f px\n", m, i, (double)c.arrival_stat, (double)c.arrival_lateral_px, (double)c.arrival_depth_px, (double)c.arrival_h13_px);
            TEST_ASSERT_EQUAL_INT64(cases[i].step, c.step);
            TEST_ASSERT_EQUAL_INT64(cases[i].verdict, c.arrival_next);
            TEST_ASSERT_EQUAL_INT64(cases[i].verdict == SPVS_STEP_ROTATE, c.backing);
            TEST_ASSERT_EQUAL_INT64(1, c.reentries);
            TEST_ASSERT_TRUE(c.arrival_stat > p.arrival_k);
            TEST_ASSERT_TRUE(fabs((double)c.arrival_corner_px - corner_px(&cases[i].pose)) <
                        1e-3 * corner_px(&cases[i].pose));
        }
    }
}

/* The spread comes from the hold's own frames, and the goal image's share
 * (a bias the same in every frame) is counted once, not averaged: with h33
 * moved by b + (-1)^k s over N = 20 frames, the depth residual is b |c|
 * (|c| = 400 px, the corner's radius) with sd = sqrt((400 s)^2 N/(N - 1)
 * (1 + 1/N) + 0.01^2) = sqrt((400 s)^2 (21/19) + 0.01^2), and the
 * statistic is (b |c| - 0.5 px, the dead zone) / sd.  A bias 0.8 sd beyond
 * the zone is accepted (a bound averaging both images' noise over the
 * frames would have been 3.2 times tighter); one 2.5 sd beyond is driven
 * off once (the correction, over 1 sd), then accepted (the threshold is
 * 3); one 5 sd beyond fails the check after its correction. */
static void test_arrival_goal_share(void)
{
    spvs_control_params_t p;
    spvs_control_params_default(&p, SPVS_METHOD_I);
    const synth_pose_t home = {0, 0, 0};
    const double s = 1e-3; /* 0.4 px at the corner */
    const double sd = sqrt(400.0 * 400.0 * s * s * 21.0 / 19.0 + 0.01 * 0.01);
    const struct {
        double z;
        int corrections, reentries;
        spvs_step_t step;
    } cases[] = {{0.8, 0, 0, SPVS_STEP_DONE}, {2.5, 1, 0, SPVS_STEP_DONE},
                 {5.0, 1, 1, SPVS_STEP_TRANSLATE}};
    for (int i = 0; i < 3; i++) {
        spvs_control_t c;
        spvs_control_reset(&c);
        const double b = (0.5 + cases[i].z * sd) / 400.0;
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, arrival_noisy(&c, &p, &home, 0, -1.0, b, s));
        TEST_ASSERT_TRUE(fabs((double)c.arrival_depth_px - 400.0 * b) < 1e-3);
        TEST_ASSERT_TRUE(fabs((double)c.arrival_depth_sd_px - sd) < 1e-3 * sd);
        TEST_ASSERT_TRUE(fabs((double)c.arrival_stat - cases[i].z) < 0.01);
        if (cases[i].corrections) {
            TEST_ASSERT_EQUAL_INT64(SPVS_STEP_TRANSLATE, c.step);
            TEST_ASSERT_EQUAL_INT64(0, c.reentries);
            TEST_ASSERT_EQUAL_INT64(SPVS_OK, arrival_noisy(&c, &p, &home, 10.0, -1.0, b, s));
        }
        TEST_ASSERT_EQUAL_INT64(cases[i].step, c.step);
        TEST_ASSERT_EQUAL_INT64(cases[i].reentries, c.reentries);
    }
}

/* The off-plane points' parallax decides where H cannot: standing at the
 * target (H = I), a mean parallax under 1.5 x 1.665 sigma = 2.497 px (its
 * median there under the noise of both images, with margin) is accepted,
 * one over it is a sideways offset: the robot backs off at -v_max, straight,
 * for SPVS_CTL_ARRIVAL_BACKOFF_DM decimetres by odometry, then starts over
 * (step 1, signs not chosen) with the re-entry counted. */
static void test_arrival_parallax(void)
{
    spvs_control_params_t p;
    spvs_control_params_default(&p, SPVS_METHOD_I);
    spvs_control_t c;
    const synth_pose_t home = {0, 0, 0};
    spvs_control_reset(&c);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, arrival_at_par(&c, &p, &home, 0, 2.48));
    TEST_ASSERT_EQUAL_INT64(SPVS_STEP_DONE, c.step);
    TEST_ASSERT_TRUE(fabs((double)c.arrival_parallax_px - 2.48) < 1e-5);

    spvs_control_reset(&c);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, arrival_at_par(&c, &p, &home, 0, 2.51));
    TEST_ASSERT_EQUAL_INT64(SPVS_STEP_TRANSLATE, c.step);
    TEST_ASSERT_EQUAL_INT64(SPVS_STEP_ROTATE, c.arrival_next);
    TEST_ASSERT_EQUAL_INT64(1, c.backing);
    TEST_ASSERT_EQUAL_INT64(1, c.reentries);

    /* Backing off: v = -v_max, w = 0, until the odometry says 5 m. */
    const synth_plane_t pl = default_plane();
    const double dist = 0.1 * SPVS_CTL_ARRIVAL_BACKOFF_DM;
    double t = 10.0, driven = 0;
    int frames = 0;
    spvs_real v = 0, w = 0;
    for (; frames < 1000 && c.backing; frames++) {
        spvs_control_input_t in;
        synth_pose_t at = {0, -driven, 0};
        make_input(&at, &pl, t, &in);
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_control_step(&c, &p, &in, &v, &w));
        if (c.backing) {
            TEST_ASSERT_TRUE(v == -p.v_max && w == 0);
        }
        driven += -(double)v * 0.1;
        t += 0.1;
    }
    TEST_ASSERT_EQUAL_INT64(0, c.backing);
    TEST_ASSERT_TRUE(driven >= dist - 1e-6 && driven < dist + (double)p.v_max * 0.1 + 1e-6);
    /* The new start: as after a reset, with the count kept. */
    TEST_ASSERT_EQUAL_INT64(SPVS_STEP_ROTATE, c.step);
    TEST_ASSERT_EQUAL_INT64(0, c.checked_plane);
    TEST_ASSERT_EQUAL_INT64(0, c.sign_w);
    TEST_ASSERT_EQUAL_INT64(1, c.reentries);
    TEST_ASSERT_EQUAL_INT64(SPVS_STEP_ROTATE, c.arrival_next);
    TEST_ASSERT_TRUE(fabs((double)c.arrival_parallax_px - 2.51) < 1e-5);

    /* A step 2 of the new homing that drives on past twice the back-off is
     * going the wrong way: a latched SPVS_E_NOT_AT_TARGET with a stop. */
    c.checked_plane = 1;
    c.sign_w = 1;
    c.step = SPVS_STEP_TRANSLATE;
    c.odo_s = (spvs_real)(2 * dist + 0.01);
    spvs_control_input_t in;
    synth_pose_t away = {0, -2 * dist, 0};
    make_input(&away, &pl, t, &in);
    v = 1;
    w = 1;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NOT_AT_TARGET, spvs_control_step(&c, &p, &in, &v, &w));
    TEST_ASSERT_TRUE(v == 0 && w == 0);
    TEST_ASSERT_EQUAL_INT64(SPVS_STEP_FAILED, c.step);
}

/* The re-entries are bounded: a robot that stays 0.3 m short is sent back
 * once to correct it, then SPVS_CTL_ARRIVAL_MAX_REENTRIES times, then the
 * run ends with SPVS_E_NOT_AT_TARGET, latched with a stop, never
 * converged. */
static void test_arrival_bound_spent(void)
{
    spvs_control_params_t p;
    spvs_control_params_default(&p, SPVS_METHOD_II);
    spvs_control_t c;
    spvs_control_reset(&c);
    synth_pose_t shortp = {0, 0.3, 0};
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, arrival_at(&c, &p, &shortp, 0.0));
    TEST_ASSERT_EQUAL_INT64(SPVS_STEP_TRANSLATE, c.step);
    TEST_ASSERT_EQUAL_INT64(0, c.reentries);
    for (int k = 0; k < SPVS_CTL_ARRIVAL_MAX_REENTRIES; k++) {
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, arrival_at(&c, &p, &shortp, 10.0 * (k + 1)));
        TEST_ASSERT_EQUAL_INT64(SPVS_STEP_TRANSLATE, c.step);
        TEST_ASSERT_EQUAL_INT64(k + 1, c.reentries);
    }
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NOT_AT_TARGET, arrival_at(&c, &p, &shortp, 100.0));
    TEST_ASSERT_EQUAL_INT64(SPVS_STEP_FAILED, c.step);
    spvs_control_input_t in;
    synth_plane_t pl = default_plane();
    make_input(&shortp, &pl, 200.0, &in);
    spvs_real v = 1, w = 1;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NOT_AT_TARGET, spvs_control_step(&c, &p, &in, &v, &w));
    TEST_ASSERT_TRUE(v == 0 && w == 0);
}

/* Method II's depth re-entry reads the distance from h33 with the first
 * line's slope of h33 - h11 (reentry_signal).  From the grazing start the
 * line is driven about 72 deg off the target heading, where h33 alone
 * carries cos phi and a degree of heading moves it as much as a metre of
 * the line.  Here the line's heading is disturbed as by wheel slip, a turn
 * of +-2 deg per metre driven with a 4 m period, which the controller's
 * rotation law keeps correcting: the slope kept must be n_z / d all the
 * same.  The test also fits h33 alone along the same line, to show that
 * the disturbance is there to be rejected. */
static void test_reentry_slope_slip(void)
{
    synth_plane_t pl = default_plane();
    spvs_control_params_t p;
    spvs_control_params_default(&p, SPVS_METHOD_II);
    spvs_control_t c;
    spvs_control_reset(&c);
    synth_pose_t pose = {5.0, 2.0, -50.0 * DEG};
    const double dt = 0.1;
    const double slip_deg_per_m = 2.0, slip_period_m = 4.0;
    double n = 0, S = 0, SS = 0, Sh = 0, SSh = 0, phi_line = 0;
    for (int k = 0; k < 3000 && c.step != SPVS_STEP_ALIGN; k++) {
        spvs_control_input_t in;
        make_input(&pose, &pl, k * dt, &in);
        spvs_real v, w;
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_control_step(&c, &p, &in, &v, &w));
        if (c.step == SPVS_STEP_TRANSLATE) {
            const double s = (double)c.odo_s, h33 = (double)in.H[SPVS_H33];
            n += 1;
            S += s;
            SS += s * s;
            Sh += h33;
            SSh += s * h33;
            phi_line = pose.phi;
        }
        double vv = v, ww = w;
        pose.x += -vv * dt * sin(pose.phi);
        pose.z += vv * dt * cos(pose.phi);
        pose.phi += ww * dt;
        if (c.step == SPVS_STEP_TRANSLATE) {
            pose.phi += slip_deg_per_m * DEG * cos(2 * SYNTH_PI * (double)c.odo_s / slip_period_m) *
                        fabs(vv) * dt;
        }
    }
    TEST_ASSERT_EQUAL_INT64(SPVS_STEP_ALIGN, c.step);
    TEST_ASSERT_TRUE(fabs(phi_line) > 65 * DEG);
    const double nz_d = fabs(pl.n[2]) / pl.d;
    const double h33_slope = (n * SSh - S * Sh) / (n * SS - S * S);
    UNIT_NOTE("slope of h33 - h11 %.5f, of h33 %.5f, n_z / d %.5f per metre\n", fabs((double)c.slope_ax), fabs(h33_slope), nz_d);
    TEST_ASSERT_TRUE(fabs(fabs((double)c.slope_ax) / nz_d - 1.0) < 0.02);
    TEST_ASSERT_TRUE(fabs(fabs(h33_slope) / nz_d - 1.0) > 0.1);
    /* The same sign as the step-2 signal's: n_y and n_z are both negative. */
    TEST_ASSERT_TRUE((c.slope_ax > 0) == (c.slope_sig > 0));
}

static void test_params_check(void)
{
    spvs_control_params_t p;
    spvs_control_params_default(&p, SPVS_METHOD_II);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_control_params_check(&p));
    volatile spvs_real zero = 0;
    p.k_w = zero / zero; /* NaN, made at run time */
    TEST_ASSERT_EQUAL_INT64(SPVS_E_CONFIG, spvs_control_params_check(&p));
    spvs_control_params_default(&p, SPVS_METHOD_II);
    p.v_max = -1;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_CONFIG, spvs_control_params_check(&p));
    spvs_control_params_default(&p, SPVS_METHOD_II);
    p.method = (spvs_method_t)7;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_CONFIG, spvs_control_params_check(&p));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_control_params_check(NULL));
}

void suite_control(void)
{
    UNIT_SUITE_FILE();
    RUN_TEST(test_closed_loop_law);
    RUN_TEST(test_first_command_signs);
    RUN_TEST(test_plane_check);
    RUN_TEST(test_no_parallax_and_timeout);
    RUN_TEST(test_method3_eq11);
    RUN_TEST(test_arrival_check);
    RUN_TEST(test_arrival_goal_share);
    RUN_TEST(test_arrival_parallax);
    RUN_TEST(test_arrival_bound_spent);
    RUN_TEST(test_reentry_slope_slip);
    RUN_TEST(test_params_check);
}

UNIT_MAIN(suite_control)
