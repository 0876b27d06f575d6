/* kinematics.c - exact integration of eq. (7) (kinematics.h). */
#include "sim/kinematics.h"

#include <math.h>

void sim_kin_step(sim_pose_t *pose, double v_mps, double w_radps, double dt_s,
                  double drift_rad_per_m)
{
    double w = w_radps + drift_rad_per_m * fabs(v_mps);
    double phi = pose->phi_rad;
    if (fabs(w) > 1e-9) {
        double phi1 = phi + w * dt_s;
        pose->x_m += (v_mps / w) * (cos(phi1) - cos(phi));
        pose->z_m += (v_mps / w) * (sin(phi1) - sin(phi));
        pose->phi_rad = sim_wrap_pi(phi1);
    } else {
        pose->x_m += -v_mps * sin(phi) * dt_s;
        pose->z_m += v_mps * cos(phi) * dt_s;
        pose->phi_rad = sim_wrap_pi(phi + w * dt_s);
    }
}
