/*
 * test_fixed_control.c - the control law in fixed point (fixed/control_q.h)
 * against the float controller (control.h) on the same inputs.
 *
 * The strongest test first: the float closed loop (spvs_update on the
 * synthetic scene of the simulator's defaults, the unicycle of eq. (7)
 * driven by the float commands) is recorded frame by frame; each frame's
 * controller input is rebuilt from the output and the instance, run
 * through a second float controller (which must reproduce the loop's
 * command exactly: the rebuild is checked) and, converted to Q, through
 * the Q controller.  Every frame must give the same step and status and
 * commands within the tolerances below; from the six Figure 5 start
 * poses, every method, noise-free and with 1 px noise.  Then Table 1's
 * zero rows (the plane check's statuses) and the arrival check's paths
 * (accepted, re-entered, spent: SPVS_E_NOT_AT_TARGET).
 */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "unity.h"
#include "unit_support.h"

#include "fixed/control_q.h"
#include "spvs/instance.h"
#include "synth.h"
#include "synth_scene.h"

#define DEG (SYNTH_PI / 180.0)
#define DT_S 0.1
#define MAX_FRAMES 4000
#define CMD_ONE ((double)(1 << SPVS_QCTL_CMD))

/* |v_q - v_f| in m/s and |w_q - w_f| in rad/s.  The Q input rounds H to
 * 2^-28 (scaled) and e_x to 2^-17 px, the output to 2^-25; float32 itself
 * carries 2^-24 of the terms of f (near 1) and of step 2's least-squares
 * line (two terms of up to 0.2 cancelling), times gains up to 40: a few
 * 1e-6.  The test prints the largest gaps of every run. */
#define TOL_CMD 1e-5

/* Where the float controller's step-end test is decided by its own
 * rounding, the Q controller (exact sums, 31-bit mantissas) may decide the
 * other way.  Step 2's fitted signal a + b s cancels two terms of the size
 * of the start value D0 <= 0.2 to a few 1e-4: float32 leaves 2^-24 D0 per
 * operation, about 5e-8 after eight, 1.5e-6 m/s times k_v = 30.  A
 * divergence of the step-end counters is accepted as such a
 * tie only where a command is within TIE_CMD of the command at the
 * tolerance (k tol); from there on the two runs may part and the
 * comparison of that run stops. */
#define TIE_CMD 3e-6

/* The controller's input of the frame spvs_update just ran (spvs.c's
 * after_h): the output's H, epipole, parallax and inliers, and the side of
 * the epipole from the instance's history (the majority, or on a tie this
 * frame's side). */
static void rebuild_input(const spvs_t *inst, const spvs_output_t *out, double t,
                          spvs_control_input_t *in)
{
    const spvs_state_t *s = spvs_state_c(inst);
    memset(in, 0, sizeof *in);
    for (int k = 0; k < 9; k++) {
        in->H[k] = out->H[k];
    }
    in->e_valid = out->e_valid;
    in->e_x_px = out->e_x_px;
    if (out->e_valid) {
        int votes = 0;
        for (uint8_t i = 0; i < s->n_ehist; i++) {
            votes += s->ehist_z[i];
        }
        const uint8_t last = (uint8_t)((s->i_ehist + SPVS_EPIPOLE_MEDIAN - 1u) % SPVS_EPIPOLE_MEDIAN);
        const int side = votes > 0 ? 1 : (votes < 0 ? -1 : s->ehist_z[last]);
        in->e_dir_z = (spvs_real)side;
    }
    in->parallax_px = out->parallax_px;
    in->parallax_x_px = s->lateral_px;
    in->parallax_r_px = s->radial_px;
    in->t_s = (spvs_real)t;
    in->n_inliers = out->n_inliers;
}

typedef struct {
    int frames;
    int frames_ctl;          /* frames the controller ran        */
    int step_diff, status_diff, replay_diff;
    int tie_frame;           /* frame of an accepted tie, -1: none */
    int diverged;            /* counters parted without a tie      */
    double max_dv, max_dw;   /* m/s, rad/s                       */
    int switch_f[6];         /* first frame of each step (float) */
    int switch_q[6];
    int final_step, final_status;
    double err_x, err_z, err_phi_deg;
} twin_result_t;

static void twin_check_frame(twin_result_t *r, int k, int step_f, int rc_f, spvs_real v_f,
                             spvs_real w_f, int step_q, int rc_q, int32_t v_q, int32_t w_q)
{
    if (step_f != step_q) {
        r->step_diff++;
    }
    if (rc_f != rc_q) {
        r->status_diff++;
    }
    const double dv = fabs((double)v_q / CMD_ONE - (double)v_f);
    const double dw = fabs((double)w_q / CMD_ONE - (double)w_f);
    r->max_dv = fmax(r->max_dv, dv);
    r->max_dw = fmax(r->max_dw, dw);
    if (step_f >= 1 && step_f <= 5 && r->switch_f[step_f] < 0) {
        r->switch_f[step_f] = k;
    }
    if (step_q >= 1 && step_q <= 5 && r->switch_q[step_q] < 0) {
        r->switch_q[step_q] = k;
    }
}

/* The step-end counters of the two controllers agree. */
static int counters_equal(const spvs_control_t *cf, const spvs_q_ctl_t *cq)
{
    return cf->hold == cq->hold && cf->run_sign == cq->run_sign &&
           cf->run_len == cq->run_len && cf->held_sign == cq->held_sign &&
           (int)cf->step == (int)cq->step;
}

/* Is the frame's command, in step `step`, within TIE_CMD of the command at
 * that step's tolerance (float or Q)? */
static int near_tolerance(const spvs_control_params_t *p, int step, spvs_real v_f,
                          spvs_real w_f, int32_t v_q, int32_t w_q)
{
    double thr, a, b;
    if (step == SPVS_STEP_TRANSLATE) {
        thr = (double)p->k_v * (double)p->tol_translate;
        a = fabs((double)v_f);
        b = fabs(v_q / CMD_ONE);
    } else {
        thr = step == SPVS_STEP_ROTATE ? (double)p->k_w * (double)p->tol_align
                                       : (double)p->k_w3 * (double)p->tol_h13_px;
        a = fabs((double)w_f);
        b = fabs(w_q / CMD_ONE);
    }
    return fmin(fabs(a - thr), fabs(b - thr)) <= TIE_CMD;
}

/* One recorded float closed loop with its two twins. */
static void twin_run(spvs_method_t method, synth_pose_t pose, double sigma, uint64_t seed,
                     twin_result_t *r)
{
    static spvs_t s;
    static spvs_match_t m[SPVS_MAX_MATCHES];
    static synth_scene_t sc;
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    uint64_t rng = 0x9e3779b97f4a7c15ull ^ seed;
    synth_scene_make(&sc, &pl, &rng, 0.0);
    /* Noise in the target image too, drawn once (the simulator's model). */
    for (int i = 0; i < sc.n; i++) {
        sc.p_tgt[i][0] += sigma * synth_gauss(&rng);
        sc.p_tgt[i][1] += sigma * synth_gauss(&rng);
    }

    spvs_params_t prm;
    spvs_params_default(&prm, method);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_init(&s, &prm));
    spvs_control_t cf;
    spvs_control_reset(&cf);
    spvs_q_ctl_params_t qp;
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_ctl_params_from_real(&qp, &prm.ctl));
    spvs_q_ctl_t cq;
    spvs_q_ctl_reset(&cq);

    memset(r, 0, sizeof *r);
    r->tie_frame = -1;
    for (int i = 0; i < 6; i++) {
        r->switch_f[i] = r->switch_q[i] = -1;
    }
    double last_good = -1;
    for (int k = 0; k < MAX_FRAMES; k++) {
        const double t = k * DT_S;
        const uint16_t n = synth_scene_frame(&sc, &pose, sigma, 0.0, SPVS_MAX_COORD_PX, &rng, m);
        spvs_output_t out;
        const int rc = spvs_update(&s, m, n, (spvs_real)t, &out);
        r->frames = k + 1;
        if (!out.h_valid) {
            /* The controller did not run: the robot was told to stop. */
            cf.last_v = 0;
            cq.last_v = 0;
            continue;
        }
        if (last_good >= 0 && t - last_good > (double)prm.max_frame_gap_s) {
            cf.hold = 0, cf.run_sign = 0, cf.run_len = 0;
            cq.hold = 0, cq.run_sign = 0, cq.run_len = 0;
        }
        last_good = t;
        spvs_control_input_t in;
        rebuild_input(&s, &out, t, &in);
        spvs_real v_f = 0, w_f = 0;
        const int rc_f = spvs_control_step(&cf, &prm.ctl, &in, &v_f, &w_f);
        if (rc_f != rc || cf.step != out.step || v_f != out.v || w_f != out.w) {
            r->replay_diff++;
        }
        spvs_q_ctl_input_t qi;
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_ctl_input_from_real(&qi, &in));
        int32_t v_q = 0, w_q = 0;
        const int step_before = (int)cf.step;
        const int rc_q = spvs_q_ctl_step(&cq, &qp, &qi, &v_q, &w_q);
        if (r->tie_frame < 0 && !counters_equal(&cf, &cq)) {
            if (near_tolerance(&prm.ctl, step_before, v_f, w_f, v_q, w_q)) {
                r->tie_frame = k;
            } else {
                r->diverged++;
            }
        }
        if (r->tie_frame < 0) {
            r->frames_ctl++;
            twin_check_frame(r, k, (int)cf.step, rc_f, v_f, w_f, (int)cq.step, rc_q, v_q,
                             w_q);
        }
        /* Eq. (7), the float command held over the frame. */
        pose.x += -(double)out.v * sin(pose.phi) * DT_S;
        pose.z += (double)out.v * cos(pose.phi) * DT_S;
        pose.phi += (double)out.w * DT_S;
        if (cf.step == SPVS_STEP_DONE || cf.step == SPVS_STEP_FAILED) {
            break;
        }
    }
    r->final_step = (int)cf.step;
    r->final_status = cf.status;
    r->err_x = pose.x;
    r->err_z = pose.z;
    r->err_phi_deg = pose.phi / DEG;
}

static const double fig5[6][3] = {{-3, -10, -30}, {0, -8, -40}, {6, -6, 0},
                                  {-6, 4, 20},    {6, 8, 10},   {5, 2, -50}};

static void twin_all(double sigma, int *n_done)
{
    int bad = 0, ties = 0;
    double worst_v = 0, worst_w = 0;
    for (int method = 1; method <= 3; method++) {
        for (int i = 0; i < 6; i++) {
            const synth_pose_t start = {fig5[i][0], fig5[i][1], fig5[i][2] * DEG};
            twin_result_t r;
            twin_run((spvs_method_t)method, start, sigma, (uint64_t)(i + 1), &r);
            worst_v = fmax(worst_v, r.max_dv);
            worst_w = fmax(worst_w, r.max_dw);
            *n_done += r.final_step == SPVS_STEP_DONE;
            ties += r.tie_frame >= 0;
            const int same_switch = r.tie_frame >= 0 ||
                                    memcmp(r.switch_f, r.switch_q, sizeof r.switch_f) == 0;
            const int ok = r.step_diff == 0 && r.status_diff == 0 && r.replay_diff == 0 &&
                           r.diverged == 0 && r.max_dv <= TOL_CMD && r.max_dw <= TOL_CMD &&
                           same_switch;
            UNIT_NOTE("  M%d (%+.0f, %+.0f, %+.0f) %.0f px: %4d frames (%4d ctl), steps "
                          "from %d/%d/%d/%d (Q %d/%d/%d/%d), end step %d status %d at "
                          "(%+.3f, %+.3f, %+.2f deg), |dv| %.1e |dw| %.1e%s\n", method, fig5[i][0], fig5[i][1], fig5[i][2], sigma, r.frames, r.frames_ctl, r.switch_f[1], r.switch_f[2], r.switch_f[3], r.switch_f[4], r.switch_q[1], r.switch_q[2], r.switch_q[3], r.switch_q[4], r.final_step, r.final_status, r.err_x, r.err_z, r.err_phi_deg, r.max_dv, r.max_dw, ok ? "" : "  MISMATCH");
            if (r.tie_frame >= 0) {
                UNIT_NOTE("    a tie at the tolerance at frame %d: compared up to there\n", r.tie_frame);
            }
            if (!ok) {
                UNIT_NOTE("    step diffs %d, status diffs %d, replay diffs %d\n", r.step_diff, r.status_diff, r.replay_diff);
                bad++;
            }
        }
    }
    UNIT_NOTE("  largest |v_q - v_f| %.2e m/s, |w_q - w_f| %.2e rad/s (tolerance %.0e), "
                  "%d of 18 runs with a tie\n", worst_v, worst_w, TOL_CMD, ties);
    TEST_ASSERT_EQUAL_INT64(0, bad);
    /* A tie needs a frame within TIE_CMD of a tolerance: rare. */
    TEST_ASSERT_TRUE(ties <= 2);
}

/* Noise-free, the six Figure 5 poses, every method: the same steps,
 * statuses and switch frames, commands within TOL_CMD; every run ends
 * converged (as docs/RESULTS.md's table). */
static void test_twin_noise_free(void)
{
    int done = 0;
    twin_all(0.0, &done);
    TEST_ASSERT_EQUAL_INT64(18, done);
}

/* The same with 1 px image noise (the runs may end in any status: what is
 * asserted is that the two controllers agree on every frame). */
static void test_twin_one_pixel(void)
{
    int done = 0;
    twin_all(1.0, &done);
    UNIT_NOTE("  %d of 18 runs converged\n", done);
}

/* ---- exact-geometry inputs ---------------------------------------------- */

/* The controller's input at a pose: H of eq. (2), the signed epipole
 * K (-R c) and a parallax of 20 px per metre of distance. */
static void exact_input(const synth_pose_t *p, const synth_plane_t *pl, double t,
                        double parallax, spvs_control_input_t *in)
{
    double H[9];
    synth_H(p, pl, 800, H);
    for (int k = 0; k < 9; k++) {
        in->H[k] = (spvs_real)H[k];
    }
    const double c = cos(p->phi), s = sin(p->phi);
    const double e1 = -(c * p->x + s * p->z), e3 = -(-s * p->x + c * p->z);
    const double r = hypot(p->x, p->z);
    in->e_valid = r > 0.05;
    double ex = fabs(e3) > 1e-9 ? 800 * e1 / e3 : 20000;
    ex = fmax(-20000, fmin(20000, ex));
    in->e_x_px = (spvs_real)ex;
    in->e_dir_x = (spvs_real)e1;
    in->e_dir_z = (spvs_real)e3;
    in->parallax_px = (spvs_real)(parallax >= 0 ? parallax : 20.0 * r);
    in->parallax_x_px = 0; /* no direction in the remembered points' parallax */
    in->parallax_r_px = 0;
    in->t_s = (spvs_real)t;
    in->n_inliers = 100;
}

typedef struct {
    spvs_control_t f;
    spvs_q_ctl_t q;
    spvs_control_params_t pf;
    spvs_q_ctl_params_t pq;
} pair_t;

static void pair_init(pair_t *pr, spvs_method_t m)
{
    spvs_control_params_default(&pr->pf, m);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_ctl_params_from_real(&pr->pq, &pr->pf));
    spvs_control_reset(&pr->f);
    spvs_q_ctl_reset(&pr->q);
}

/* One frame through both: the same status and step, commands within
 * TOL_CMD; returns the status. */
static int pair_step(pair_t *pr, const spvs_control_input_t *in)
{
    spvs_real vf = 1, wf = 1;
    int32_t vq = 1, wq = 1;
    spvs_q_ctl_input_t qi;
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_ctl_input_from_real(&qi, in));
    const int rf = spvs_control_step(&pr->f, &pr->pf, in, &vf, &wf);
    const int rq = spvs_q_ctl_step(&pr->q, &pr->pq, &qi, &vq, &wq);
    TEST_ASSERT_EQUAL_INT64(rf, rq);
    TEST_ASSERT_EQUAL_INT64(pr->f.step, pr->q.step);
    TEST_ASSERT_TRUE(fabs((double)vq / CMD_ONE - (double)vf) <= TOL_CMD);
    TEST_ASSERT_TRUE(fabs((double)wq / CMD_ONE - (double)wf) <= TOL_CMD);
    return rf;
}

/* Table 1's zero rows: Methods I and III need n_z, Method II n_y; the
 * plane check latches the same status in both, with a stop. */
static void test_plane_zero_rows(void)
{
    synth_plane_t wall, floor_pl, front;
    synth_plane(&wall, 1.0, 0.0, 0.0, 45);      /* n_z = 0, n_y = 0 */
    synth_plane(&floor_pl, 0.8, -0.6, 0.0, 45); /* n_z = 0          */
    synth_plane(&front, 0.0, 0.0, -1.0, 45);    /* n_y = 0          */
    const synth_pose_t p = {-3, -10, -30 * DEG};
    const struct {
        int method;
        const synth_plane_t *pl;
        int expect;
    } cases[] = {{1, &wall, SPVS_E_PLANE_NZ}, {3, &floor_pl, SPVS_E_PLANE_NZ},
                 {2, &front, SPVS_E_PLANE_NY}, {2, &wall, SPVS_E_PLANE_NY},
                 {2, &floor_pl, SPVS_OK},      {1, &front, SPVS_OK}};
    for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        pair_t pr;
        pair_init(&pr, (spvs_method_t)cases[i].method);
        int rc = SPVS_OK;
        for (int k = 0; k < 6; k++) {
            spvs_control_input_t in;
            exact_input(&p, cases[i].pl, 0.1 * k, -1, &in);
            rc = pair_step(&pr, &in);
        }
        TEST_ASSERT_EQUAL_INT64(cases[i].expect, rc);
        TEST_ASSERT_EQUAL_INT64(cases[i].expect == SPVS_OK ? SPVS_STEP_ROTATE
                                                              : SPVS_STEP_FAILED, pr.q.step);
    }
}

/* Both controllers set at the start of the arrival check (step 3 ended). */
static void pair_arriving(pair_t *pr, double t0)
{
    pr->f.checked_plane = pr->q.checked_plane = 1;
    pr->f.step = pr->q.step = SPVS_STEP_ALIGN;
    pr->f.step_t0 = (spvs_real)t0;
    pr->q.step_t0 = (int32_t)lround(t0 * 65536.0);
    pr->f.sign_w = pr->q.sign_w = 1;
    pr->f.sign_v = pr->q.sign_v = 1;
    pr->f.arriving = pr->q.arriving = 1;
    /* The first line's slope of the step-2 signal per metre (the default
     * plane's n_z / d): a re-entered step 2 drives by odometry on it. */
    const spvs_real slope = (spvs_real)0.0166;
    pr->f.slope_sig = slope;
    pr->q.slope_sig = spvs_qf_from_i64((int64_t)llround((double)slope * 1099511627776.0), -40);
}

/* Frame times both formats hold exactly (1/8 s): a step's duration meets
 * the timeout on the same number in both.  At 0.1 s the 1200th frame of a
 * step is 120 s up to float32's rounding of 0.1 k, and which side of the
 * timeout it falls is that rounding's choice. */
#define STUCK_DT_S 0.125

/* A robot that stands at pose whatever it is told (a stuck plant): frames
 * until both end in DONE or FAILED, all equal; returns the last status. */
static int stuck_at(pair_t *pr, const synth_pose_t *pose, double sigma, int *frames)
{
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    uint64_t rng = 12345;
    int rc = SPVS_OK;
    int k = 0;
    for (; k < 20000 && pr->f.step != SPVS_STEP_DONE && pr->f.step != SPVS_STEP_FAILED; k++) {
        spvs_control_input_t in;
        exact_input(pose, &pl, STUCK_DT_S * k, -1, &in);
        /* No off-plane point in view: the H figures alone decide. */
        in.parallax_px = -1;
        for (int j = 0; j < 9 && sigma > 0; j++) {
            if (j != 4 && j != 3 && j != 5) {
                const double scale = (j == 6 || j == 7) ? 1e-6 : (j == 2 ? 0.5 : 1e-4);
                in.H[j] += (spvs_real)(sigma * scale * synth_gauss(&rng));
            }
        }
        rc = pair_step(pr, &in);
    }
    *frames = k;
    return rc;
}

/* The arrival check's three paths, in both: at the target it accepts
 * (DONE, the statistic within 1e-3 of its size and the figures within
 * 1e-4 px); 0.3 m short along the axis it corrects once and re-enters step
 * 2 SPVS_CTL_ARRIVAL_MAX_REENTRIES times (the robot never moves) and then
 * latches SPVS_E_NOT_AT_TARGET; 0.3 m sideways it backs off.  Each for
 * every method, exact H and H with noise. */
static void test_arrival_paths(void)
{
    const synth_pose_t home = {0, 0, 0}, shortp = {0, 0.3, 0}, side = {0.3, 0, 0};
    for (int m = 1; m <= 3; m++) {
        for (int noisy = 0; noisy < 2; noisy++) {
            pair_t pr;
            int frames = 0;
            pair_init(&pr, (spvs_method_t)m);
            pair_arriving(&pr, 0);
            TEST_ASSERT_EQUAL_INT64(SPVS_OK, stuck_at(&pr, &home, noisy, &frames));
            TEST_ASSERT_EQUAL_INT64(SPVS_STEP_DONE, pr.f.step);
            TEST_ASSERT_TRUE(fabs(pr.q.arrival_stat / 65536.0 - (double)pr.f.arrival_stat) <
                             1e-3 * (1.0 + (double)pr.f.arrival_stat));
            TEST_ASSERT_TRUE(fabs(pr.q.arrival_depth_sd_px / 65536.0 - (double)pr.f.arrival_depth_sd_px) < 1e-4);
            TEST_ASSERT_TRUE(fabs(pr.q.arrival_corner_px / 65536.0 - (double)pr.f.arrival_corner_px) < 1e-4);

            pair_init(&pr, (spvs_method_t)m);
            pair_arriving(&pr, 0);
            TEST_ASSERT_EQUAL_INT64(SPVS_E_NOT_AT_TARGET, stuck_at(&pr, &shortp, noisy, &frames));
            TEST_ASSERT_EQUAL_INT64(pr.f.reentries, pr.q.reentries);
            TEST_ASSERT_EQUAL_INT64(SPVS_CTL_ARRIVAL_MAX_REENTRIES, pr.f.reentries);
            UNIT_NOTE("  M%d short, noise %d: NOT_AT_TARGET after %d frames, %d re-entries, "
                          "corner %.4f / %.4f px, depth %.4f / %.4f px (float / Q)\n", m, noisy, frames, pr.f.reentries, (double)pr.f.arrival_corner_px, pr.q.arrival_corner_px / 65536.0, (double)pr.f.arrival_depth_px, pr.q.arrival_depth_px / 65536.0);
            TEST_ASSERT_TRUE(fabs(pr.q.arrival_depth_px / 65536.0 - (double)pr.f.arrival_depth_px) < 1e-4);

            pair_init(&pr, (spvs_method_t)m);
            pair_arriving(&pr, 0);
            (void)stuck_at(&pr, &side, noisy, &frames);
            TEST_ASSERT_EQUAL_INT64(pr.f.arrival_next, pr.q.arrival_next);
            TEST_ASSERT_EQUAL_INT64(pr.f.reentries, pr.q.reentries);
        }
    }
}

/* Out-of-range input and parameters are statuses. */
static void test_conversions(void)
{
    spvs_control_params_t p;
    spvs_control_params_default(&p, SPVS_METHOD_I);
    spvs_q_ctl_params_t q;
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_ctl_params_from_real(&q, &p));
    p.v_max = 200; /* beyond Q24's 128 m/s */
    TEST_ASSERT_EQUAL_INT64(SPVS_E_CONFIG, spvs_q_ctl_params_from_real(&q, &p));
    spvs_control_params_default(&p, SPVS_METHOD_I);
    p.tol_align = 1e-12f; /* rounds to 0 in Q27 */
    TEST_ASSERT_EQUAL_INT64(SPVS_E_CONFIG, spvs_q_ctl_params_from_real(&q, &p));
    spvs_control_input_t in;
    const synth_plane_t pl = {{0, 0, -1}, 45};
    const synth_pose_t pose = {-3, -10, -0.5};
    exact_input(&pose, &pl, 1.0, -1, &in);
    spvs_q_ctl_input_t qi;
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_ctl_input_from_real(&qi, &in));
    TEST_ASSERT_TRUE(qi.e_side == (in.e_dir_z > 0 ? 1 : -1));
    TEST_ASSERT_TRUE(qi.parallax > 0);
    in.parallax_px = -1e-30f;
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_ctl_input_from_real(&qi, &in));
    TEST_ASSERT_TRUE(qi.parallax < 0);
    in.H[SPVS_H13] = 1e-12f; /* keeps its sign as one ulp */
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_ctl_input_from_real(&qi, &in));
    TEST_ASSERT_EQUAL_INT64(1, qi.H[SPVS_H13]);
    in.H[SPVS_H31] = 0.1f; /* 51 in scaled units */
    TEST_ASSERT_EQUAL_INT64(SPVS_E_RANGE, spvs_q_ctl_input_from_real(&qi, &in));
    volatile spvs_real zero = 0;
    in.H[SPVS_H31] = zero / zero;
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NONFINITE, spvs_q_ctl_input_from_real(&qi, &in));
}

/* ---- the parameter check on the bits ------------------------------------ */

#if SPVS_USE_DOUBLE
#define R_NEXT(x, toward) nextafter((x), (toward))
#define R_TYPE_MAX DBL_MAX
#define R_NORM_MIN DBL_MIN
#else
#define R_NEXT(x, toward) nextafterf((x), (toward))
#define R_TYPE_MAX FLT_MAX
#define R_NORM_MIN FLT_MIN
#endif

#define RF(f) {offsetof(spvs_control_params_t, f), #f}
/* Every spvs_real field of the parameters. */
static const struct {
    size_t off;
    const char *name;
} real_fields[] = {
    RF(alpha_x), RF(alpha_y), RF(k_w), RF(k_v), RF(k_w3), RF(k_w11), RF(v_max),
    RF(w_max), RF(w_min_escape), RF(tol_align), RF(tol_translate), RF(tol_h13_px),
    RF(lock_ex_px), RF(switch_parallax_px), RF(hold_heading_ratio), RF(tol_det),
    RF(min_signal_ratio), RF(step_timeout_s), RF(fit_min_span_m), RF(arrival_sigma_px),
    RF(arrival_k), RF(arrival_corner_x_px), RF(arrival_corner_y_px),
    RF(arrival_resolution_px)};
/* ... and every integer one. */
static const struct {
    size_t off;
    const char *name;
} u16_fields[] = {RF(hold_frames), RF(fit_min_frames), RF(arrival_frames)};
#define N_REAL_FIELDS (sizeof real_fields / sizeof real_fields[0])
_Static_assert(sizeof real_fields / sizeof real_fields[0] == 24 &&
                   sizeof u16_fields / sizeof u16_fields[0] == 3,
               "control.h's parameters: 24 reals, 3 counts and the method");

/* Magnitudes the values are made around: control.c's bounds (0, 1,
 * SPVS_REAL_MAX; w_max for w_min_escape: the other field's default), the
 * type's extremes and every default of the three methods. */
#define MAX_MAGS (5 + 3 * N_REAL_FIELDS)
/* Each magnitude, the next float down and up, in both signs; infinity,
 * NaN and the NaN next to infinity's bits (a signalling NaN, payload 1),
 * in both signs. */
#define MAX_VALUES (6 * MAX_MAGS + 6)

static int real_values(spvs_real *v)
{
    spvs_real mags[MAX_MAGS];
    int nm = 0;
    mags[nm++] = 0;
    mags[nm++] = 1;
    mags[nm++] = SPVS_REAL_MAX;
    mags[nm++] = R_TYPE_MAX;
    mags[nm++] = R_NORM_MIN;
    for (int m = SPVS_METHOD_I; m <= SPVS_METHOD_III; m++) {
        spvs_control_params_t d;
        spvs_control_params_default(&d, (spvs_method_t)m);
        for (size_t f = 0; f < N_REAL_FIELDS; f++) {
            memcpy(&mags[nm++], (const char *)&d + real_fields[f].off, sizeof(spvs_real));
        }
    }
    volatile spvs_real zero = 0;
    const spvs_real inf = 1 / zero, nan = zero / zero;
    int n = 0;
    for (int i = 0; i < nm; i++) {
        const spvs_real around[3] = {R_NEXT(mags[i], -inf), mags[i], R_NEXT(mags[i], inf)};
        for (int k = 0; k < 3; k++) {
            v[n++] = around[k];
            v[n++] = -around[k];
        }
    }
    v[n++] = inf;
    v[n++] = -inf;
    v[n++] = nan;
    v[n++] = (spvs_real)copysign(nan, -1.0);
#if SPVS_USE_DOUBLE
    const uint64_t snan_bits[2] = {0x7ff0000000000001u, 0xfff0000000000001u};
#else
    const uint32_t snan_bits[2] = {0x7f800001u, 0xff800001u};
#endif
    memcpy(&v[n], snan_bits, sizeof snan_bits);
    n += 2;
    TEST_ASSERT_EQUAL_INT64(MAX_VALUES, n);
    return n;
}

typedef struct {
    int cases, ok, config;
} check_count_t;

/* Both checks on p: the same status; a parameter the float check refuses
 * is refused by the conversion too. */
static void check_one(const spvs_control_params_t *p, check_count_t *c)
{
    const int rf = spvs_control_params_check(p);
    const int rq = spvs_q_ctl_params_check(p);
    if (rq != rf) {
        UNIT_FAIL_NOTE("check %d, float check %d", rq, rf);
    }
    if (rf != SPVS_OK) {
        spvs_q_ctl_params_t q;
        TEST_ASSERT_EQUAL_INT64(SPVS_E_CONFIG, spvs_q_ctl_params_from_real(&q, p));
    }
    c->cases++;
    c->ok += rf == SPVS_OK;
    c->config += rf == SPVS_E_CONFIG;
}

/* spvs_q_ctl_params_check against spvs_control_params_check: the three
 * methods' defaults, then each field of each method's defaults set in
 * turn to values at, just inside and just outside every bound (the next
 * float up and down), NaN and infinities; the counts at and around
 * theirs. */
static void test_params_check(void)
{
    static spvs_real vals[MAX_VALUES];
    const int nv = real_values(vals);
    const uint16_t counts[] = {0, 1, 2, 3, 9, 10, 11, 19, 20, 21, 79, 80, 81,
                               SPVS_CTL_ARRIVAL_MAX_FRAMES - 1, SPVS_CTL_ARRIVAL_MAX_FRAMES,
                               SPVS_CTL_ARRIVAL_MAX_FRAMES + 1, UINT16_MAX};
    const int methods[] = {-1, 0, 1, 2, 3, 4, 255};
    check_count_t c = {0, 0, 0};
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_q_ctl_params_check(NULL));
    for (int m = SPVS_METHOD_I; m <= SPVS_METHOD_III; m++) {
        spvs_control_params_t d;
        spvs_control_params_default(&d, (spvs_method_t)m);
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_ctl_params_check(&d));
        check_one(&d, &c);
        for (size_t f = 0; f < N_REAL_FIELDS; f++) {
            for (int i = 0; i < nv; i++) {
                spvs_control_params_t p = d;
                memcpy((char *)&p + real_fields[f].off, &vals[i], sizeof(spvs_real));
                check_one(&p, &c);
            }
        }
        for (size_t f = 0; f < sizeof u16_fields / sizeof u16_fields[0]; f++) {
            for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
                spvs_control_params_t p = d;
                memcpy((char *)&p + u16_fields[f].off, &counts[i], sizeof(uint16_t));
                check_one(&p, &c);
            }
        }
        for (size_t i = 0; i < sizeof methods / sizeof methods[0]; i++) {
            spvs_control_params_t p = d;
            p.method = (spvs_method_t)methods[i];
            check_one(&p, &c);
        }
    }
    const int expect = 3 * (1 + (int)N_REAL_FIELDS * nv +
                            (int)(sizeof u16_fields / sizeof u16_fields[0] *
                                  (sizeof counts / sizeof counts[0])) +
                            (int)(sizeof methods / sizeof methods[0]));
    TEST_ASSERT_EQUAL_INT64(expect, c.cases);
    TEST_ASSERT_EQUAL_INT64(c.cases, c.ok + c.config);
    /* Both answers are common: each field's bounds are straddled. */
    TEST_ASSERT_TRUE(c.ok > c.cases / 10 && c.config > c.cases / 10);
    UNIT_NOTE("  %d parameter sets compared with the float check: %d pass, %d refused\n", c.cases, c.ok, c.config);
}

void suite_fixed_control(void)
{
    UNIT_SUITE_FILE();
    RUN_TEST(test_twin_noise_free);
    RUN_TEST(test_twin_one_pixel);
    RUN_TEST(test_plane_zero_rows);
    RUN_TEST(test_arrival_paths);
    RUN_TEST(test_conversions);
    RUN_TEST(test_params_check);
}

UNIT_MAIN(suite_fixed_control)
