/* actuator.c - latency and acceleration limits between the controller's
 * command and the robot's motion (actuator.h). */
#include "sim/actuator.h"

#include <math.h>
#include <string.h>

#include "sim/kinematics.h"

void sim_actuator_init(sim_actuator_t *a, const sim_actuator_spec_t *spec)
{
    memset(a, 0, sizeof(*a));
    a->spec = *spec;
}

/* x moved towards target by at most limit * h (no limit where limit is 0). */
static double follow(double x, double target, double limit, double h)
{
    if (limit <= 0.0) {
        return target;
    }
    const double d = target - x;
    const double most = limit * h;
    return d > most ? x + most : (d < -most ? x - most : target);
}

/* The motion over h seconds under the acting command: at once where no
 * speed ramps, else in substeps, each at its mean speeds. */
static void move(sim_actuator_t *a, sim_pose_t *pose, double h, double drift)
{
    const int ramps = a->v != a->cmd_v || a->w != a->cmd_w;
    if (!ramps || (a->spec.accel_mps2 <= 0.0 && a->spec.alpha_radps2 <= 0.0)) {
        a->v = a->cmd_v;
        a->w = a->cmd_w;
        sim_kin_step(pose, a->v, a->w, h, drift);
        return;
    }
    const int n = (int)ceil(h / SIM_ACT_SUBSTEP_S);
    const double hs = h / n;
    for (int i = 0; i < n; ++i) {
        const double v1 = follow(a->v, a->cmd_v, a->spec.accel_mps2, hs);
        const double w1 = follow(a->w, a->cmd_w, a->spec.alpha_radps2, hs);
        sim_kin_step(pose, 0.5 * (a->v + v1), 0.5 * (a->w + w1), hs, drift);
        a->v = v1;
        a->w = w1;
    }
}

void sim_actuator_step(sim_actuator_t *a, sim_pose_t *pose, double t_s, double v_mps,
                       double w_radps, double dt_s, double drift_rad_per_m)
{
    /* A full queue (sim_config_check keeps the latency below it) drops the
     * oldest command rather than memory beyond the arrays. */
    if (a->count == SIM_ACT_QUEUE) {
        a->head = (a->head + 1u) % SIM_ACT_QUEUE;
        a->count--;
    }
    const unsigned tail = (a->head + a->count) % SIM_ACT_QUEUE;
    a->act_t[tail] = t_s + a->spec.latency_s;
    a->act_v[tail] = v_mps;
    a->act_w[tail] = w_radps;
    a->count++;

    /* Times within the period as offsets from t_s, so that a command
     * acting at t_s moves the robot for dt_s itself. */
    double done = 0.0;
    /* Bound: the commands in the queue, at most SIM_ACT_QUEUE. */
    while (a->count > 0 && a->act_t[a->head] - t_s < dt_s) {
        const double at = a->act_t[a->head] - t_s;
        if (at > done) {
            move(a, pose, at - done, drift_rad_per_m);
            done = at;
        }
        a->cmd_v = a->act_v[a->head];
        a->cmd_w = a->act_w[a->head];
        a->head = (a->head + 1u) % SIM_ACT_QUEUE;
        a->count--;
    }
    if (dt_s > done) {
        move(a, pose, dt_s - done, drift_rad_per_m);
    }
}
