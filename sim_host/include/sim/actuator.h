/*
 * actuator.h - what a robot adds between a command and its motion: a
 * latency (each command acts latency_s after its frame was taken) and
 * acceleration limits (the robot's v and w follow the command within
 * accel_mps2 and alpha_radps2).  With neither, a command acts at once for
 * the whole period and the motion is sim_kin_step's, bit for bit.
 */
#ifndef SIM_ACTUATOR_H
#define SIM_ACTUATOR_H

#include "sim/geometry.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Commands in flight at most: a latency of up to SIM_ACT_QUEUE - 1
 * control periods (sim_config_check refuses more). */
#define SIM_ACT_QUEUE 64
/* The longest step of the integration while a speed ramps, seconds. */
#define SIM_ACT_SUBSTEP_S 0.005

typedef struct {
    double latency_s;    /* >= 0: a command acts this long after its frame */
    double accel_mps2;   /* > 0: |dv/dt| limit; 0: none                    */
    double alpha_radps2; /* > 0: |dw/dt| limit; 0: none                    */
} sim_actuator_spec_t;

typedef struct {
    sim_actuator_spec_t spec;
    double v, w;         /* the robot's speeds now, m/s and rad/s         */
    double cmd_v, cmd_w; /* the command acting now (0, 0 before the first) */
    /* Commands not acting yet, oldest first: act_t[i] is when each acts. */
    double act_t[SIM_ACT_QUEUE], act_v[SIM_ACT_QUEUE], act_w[SIM_ACT_QUEUE];
    unsigned head, count;
} sim_actuator_t;

/* A robot at rest with no command in flight. */
void sim_actuator_init(sim_actuator_t *a, const sim_actuator_spec_t *spec);

/* The command (v_mps, w_radps) of the frame taken at t_s, then the motion
 * of pose from t_s to t_s + dt_s (kinematics.h's eq. (7) with drift):
 * each command in flight takes over at its time, and the speeds follow
 * the acting command within the limits (piecewise constant over substeps
 * of at most SIM_ACT_SUBSTEP_S, at their mean over each).  Bound: the
 * commands due in the period plus dt_s / SIM_ACT_SUBSTEP_S + 1 substeps
 * each. */
void sim_actuator_step(sim_actuator_t *a, sim_pose_t *pose, double t_s, double v_mps,
                       double w_radps, double dt_s, double drift_rad_per_m);

#ifdef __cplusplus
}
#endif

#endif /* SIM_ACTUATOR_H */
