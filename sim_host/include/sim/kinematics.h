/*
 * kinematics.h - the differential-drive robot of eq. (7), integrated exactly
 * over one control period with constant (v, w).
 */
#ifndef SIM_KINEMATICS_H
#define SIM_KINEMATICS_H

#include "sim/geometry.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Move `pose` for dt_s seconds under the command (v_mps, w_radps).
 * The robot's actual rotation rate is w + drift_rad_per_m * |v|: odometry
 * drift turns the heading by drift_rad_per_m for every metre driven.
 * With rate w' the exact solution of eq. (7) is
 *   x += (v / w') (cos(phi + w' dt) - cos phi)
 *   z += (v / w') (sin(phi + w' dt) - sin phi),  phi += w' dt,
 * and a straight segment when |w'| <= 1e-9 rad/s.  phi is wrapped to
 * (-pi, pi]. */
void sim_kin_step(sim_pose_t *pose, double v_mps, double w_radps, double dt_s,
                  double drift_rad_per_m);

#ifdef __cplusplus
}
#endif

#endif /* SIM_KINEMATICS_H */
