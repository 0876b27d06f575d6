/*
 * test_actuator.c - the simulated robot's latency and acceleration limits
 * (sim_host/src/actuator.c): when a command starts to act, how fast the
 * speeds follow it, the distances and headings that follow, and that a
 * robot without either moves as sim_kin_step moves it, bit for bit.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sim/actuator.h"
#include "sim/kinematics.h"
#include "sim/sim.h"

#define DT 0.1

/* Drives a robot at rest from the origin (heading +z) with the command
 * (v, w) every period for `periods` periods. */
static sim_pose_t drive(const sim_actuator_spec_t *spec, double v, double w, int periods,
                        sim_actuator_t *a)
{
    sim_pose_t pose = {0.0, 0.0, 0.0};
    sim_actuator_init(a, spec);
    for (int k = 0; k < periods; ++k) {
        sim_actuator_step(a, &pose, k * DT, v, w, DT, 0.0);
    }
    return pose;
}

/* No latency and no limits: sim_kin_step's motion, bit for bit, whatever
 * the commands. */
static void test_plain_is_kinematics(void **state)
{
    (void)state;
    const sim_actuator_spec_t none = {0.0, 0.0, 0.0};
    sim_actuator_t a;
    sim_actuator_init(&a, &none);
    sim_pose_t p = {1.0, -2.0, 0.3}, q = p;
    for (int k = 0; k < 50; ++k) {
        const double v = 0.3 * sin(0.7 * k), w = 0.2 * cos(0.3 * k);
        sim_actuator_step(&a, &p, k * DT, v, w, DT, 0.01);
        sim_kin_step(&q, v, w, DT, 0.01);
        assert_memory_equal(&p, &q, sizeof p);
    }
}

/* A latency of 0.25 s: the robot stands still until then, and drives
 * 0.5 m/s after: 0.5 (1 - 0.25) m in one second. */
static void test_latency(void **state)
{
    (void)state;
    const sim_actuator_spec_t late = {0.25, 0.0, 0.0};
    sim_actuator_t a;
    sim_pose_t p = drive(&late, 0.5, 0.0, 2, &a);
    assert_true(fabs(p.z_m) < 1e-15); /* at 0.2 s: nothing acts yet */
    p = drive(&late, 0.5, 0.0, 10, &a);
    assert_true(fabs(p.z_m - 0.375) < 1e-12);
    assert_true(fabs(p.x_m) < 1e-15);
    /* At 1 s the commands of the frames at 0.8 s and 0.9 s are still in
     * flight (they act at 1.05 s and 1.15 s). */
    assert_int_equal(a.count, 2);
}

/* An acceleration limit of 0.5 m/s^2 from rest to 1 m/s: 0.5 m/s and
 * 0.25 m after 1 s, 1 m/s after 2 s, then 1 m/s: 1 + 1 m at 3 s. */
static void test_accel_limit(void **state)
{
    (void)state;
    const sim_actuator_spec_t lim = {0.0, 0.5, 1.0};
    sim_actuator_t a;
    sim_pose_t p = drive(&lim, 1.0, 0.0, 10, &a);
    assert_true(fabs(a.v - 0.5) < 1e-12);
    assert_true(fabs(p.z_m - 0.25) < 1e-12);
    p = drive(&lim, 1.0, 0.0, 30, &a);
    assert_true(fabs(a.v - 1.0) < 1e-12);
    assert_true(fabs(p.z_m - 2.0) < 1e-12);
}

/* A turn of 1 rad/s under 1 rad/s^2 from rest, stopped after 2 s by the
 * command (0, 0): the rate ramps up for 1 s, holds for 1 s and ramps down
 * for 1 s, a heading of 0.5 + 1 + 0.5 = 2 rad (positive w turns the
 * heading (-sin phi, cos phi) from +z towards -x). */
static void test_turn_ramp(void **state)
{
    (void)state;
    const sim_actuator_spec_t lim = {0.0, 0.5, 1.0};
    sim_actuator_t a;
    sim_actuator_init(&a, &lim);
    sim_pose_t p = {0.0, 0.0, 0.0};
    for (int k = 0; k < 40; ++k) {
        const double w = k < 20 ? 1.0 : 0.0;
        sim_actuator_step(&a, &p, k * DT, 0.0, w, DT, 0.0);
    }
    assert_true(fabs(p.phi_rad - 2.0) < 1e-12);
    assert_true(fabs(a.w) < 1e-15);
    assert_true(fabs(p.x_m) < 1e-15 && fabs(p.z_m) < 1e-15);
}

/* sim_config_check refuses a latency beyond the queue and negative or
 * non-finite limits. */
static void test_config_checks(void **state)
{
    (void)state;
    sim_config_t c;
    char err[160];
    sim_config_default(&c);
    assert_int_equal(sim_config_check(&c, err, sizeof err), 0);
    c.robot.latency_s = (SIM_ACT_QUEUE - 1) * c.dt_s;
    assert_int_equal(sim_config_check(&c, err, sizeof err), -1);
    c.robot.latency_s = (SIM_ACT_QUEUE - 2) * c.dt_s;
    assert_int_equal(sim_config_check(&c, err, sizeof err), 0);
    c.robot.accel_mps2 = -1.0;
    assert_int_equal(sim_config_check(&c, err, sizeof err), -1);
    c.robot.accel_mps2 = 0.5;
    c.robot.alpha_radps2 = NAN;
    assert_int_equal(sim_config_check(&c, err, sizeof err), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plain_is_kinematics), cmocka_unit_test(test_latency),
        cmocka_unit_test(test_accel_limit),         cmocka_unit_test(test_turn_ramp),
        cmocka_unit_test(test_config_checks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
