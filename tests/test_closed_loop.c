/*
 * test_closed_loop.c - the whole controller in the simulated loop, through
 * the in-process link: the paper's set-up (section 5), default plane
 * n = (0.3, -0.6, -0.75) normalised, d = 45 m, control period 0.1 s.
 * Each failure prints the run's final error and status.
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

/* What the frame callback gathers about step 2. */
typedef struct {
    uint32_t frames_step2;
    double max_v_step2;      /* m/s */
    double signed_path_m;    /* sum of v dt over step 2, metres */
    double dt_s;
} step2_stats_t;

static int watch_step2(const sim_frame_t *f, void *user)
{
    step2_stats_t *s = user;
    if (f->out->step == SPVS_STEP_TRANSLATE) {
        double v = (double)f->out->v;
        s->frames_step2++;
        s->max_v_step2 = s->frames_step2 == 1 ? v : fmax(s->max_v_step2, v);
        s->signed_path_m += v * s->dt_s;
    }
    return 0;
}

/* One run of `method` from (x, z, phi_deg) with noise sigma and seed. */
static void run(int method, double x, double z, double phi_deg, double noise,
                uint32_t seed, sim_result_t *res, step2_stats_t *st)
{
    sim_config_t c;
    sim_config_default(&c);
    c.method = method;
    c.start.x_m = x;
    c.start.z_m = z;
    c.start.phi_rad = phi_deg * DEG;
    c.noise_px = noise;
    c.seed = seed;

    char err[160];
    memset(st, 0, sizeof(*st));
    st->dt_s = c.dt_s;
    int rc = sim_run_core(&c, res, watch_step2, st, err, sizeof(err));
    if (rc != 0) {
        print_message("the run did not take place: %s\n", err);
    }
    assert_int_equal(rc, 0);
}

static void report(const char *what, int method, uint32_t seed,
                   const sim_result_t *r)
{
    print_message("%s: method %d seed %u: %s%s%s after %.1f s, final error "
                  "x %+.4f m, z %+.4f m, phi %+.4f deg\n",
                  what, method, (unsigned)seed, sim_status_str(r->status),
                  r->reason[0] ? " " : "", r->reason, r->time_s, r->err_x_m,
                  r->err_z_m, r->err_phi_deg);
}

/* Perfect data from (-3 m, -10 m, -30 deg): every method converges to
 * within 2 cm and 0.1 deg. */
static void test_noise_free_converges(void **state)
{
    (void)state;
    int bad = 0;
    for (int method = 1; method <= 3; ++method) {
        sim_result_t r;
        step2_stats_t st;
        run(method, -3.0, -10.0, -30.0, 0.0, 0, &r, &st);
        int ok = r.status == SIM_CONVERGED && fabs(r.err_x_m) < 0.02 &&
                 fabs(r.err_z_m) < 0.02 && fabs(r.err_phi_deg) < 0.1;
        if (!ok) {
            report("noise-free, limits 0.02 m / 0.1 deg", method, 0, &r);
            ++bad;
        }
    }
    assert_int_equal(bad, 0);
}

/* 1 px image noise (the paper's Figure 6), seeds 0..4: every method ends
 * within 0.25 m and 0.5 deg, with status converged, or not_at_target where
 * the verified arrival (docs/CONTROL.md) could not confirm it: it never
 * claims converged outside those limits. */
static void test_one_pixel_noise(void **state)
{
    (void)state;
    int bad = 0;
    for (int method = 1; method <= 3; ++method) {
        for (uint32_t seed = 0; seed < 5; ++seed) {
            sim_result_t r;
            step2_stats_t st;
            run(method, -3.0, -10.0, -30.0, 1.0, seed, &r, &st);
            int ok = (r.status == SIM_CONVERGED || r.core_status == SPVS_E_NOT_AT_TARGET) &&
                     fabs(r.err_x_m) < 0.25 && fabs(r.err_z_m) < 0.25 &&
                     fabs(r.err_phi_deg) < 0.5;
            if (!ok) {
                report("1 px noise, limits 0.25 m / 0.5 deg", method, seed, &r);
                ++bad;
            }
        }
    }
    assert_int_equal(bad, 0);
}

/* Target behind the robot, (5 m, 2 m, -50 deg): each method converges and
 * drives the straight line of step 2 backwards (v <= 0 on every frame, and
 * at least 90 % of the 5.39 m start distance covered in reverse). */
static void test_target_behind_drives_backwards(void **state)
{
    (void)state;
    int bad = 0;
    const double dist0 = hypot(5.0, 2.0);
    for (int method = 1; method <= 3; ++method) {
        sim_result_t r;
        step2_stats_t st;
        run(method, 5.0, 2.0, -50.0, 0.0, 0, &r, &st);
        int ok = r.status == SIM_CONVERGED && fabs(r.err_x_m) < 0.02 &&
                 fabs(r.err_z_m) < 0.02 && fabs(r.err_phi_deg) < 0.1;
        int back = st.frames_step2 > 0 && st.max_v_step2 <= 1e-6 &&
                   st.signed_path_m < -0.9 * dist0;
        if (!ok || !back) {
            report("target behind", method, 0, &r);
            print_message("  step 2: %u frames, largest v %+.4f m/s, "
                          "signed path %+.3f m (start distance %.3f m)\n",
                          (unsigned)st.frames_step2, st.max_v_step2,
                          st.signed_path_m, dist0);
            ++bad;
        }
    }
    assert_int_equal(bad, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_noise_free_converges),
        cmocka_unit_test(test_one_pixel_noise),
        cmocka_unit_test(test_target_behind_drives_backwards),
    };
    return cmocka_run_group_tests_name("closed_loop", tests, NULL, NULL);
}
