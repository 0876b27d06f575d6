/* sim.c - configuration and the closed loop (sim.h). */
#define _POSIX_C_SOURCE 200809L
#include "sim/sim.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sim/clock.h"
#include "sim/actuator.h"
#include "sim/kinematics.h"

#define SIM_PI 3.14159265358979323846
#define DEG (SIM_PI / 180.0)

const char *sim_status_str(sim_status_t s)
{
    switch (s) {
    case SIM_CONVERGED: return "converged";
    case SIM_FAILED: return "failed";
    case SIM_TIMEOUT: return "timeout";
    case SIM_LINK_ERROR: return "link_error";
    case SIM_ABORTED: return "aborted";
    }
    return "unknown";
}

void sim_config_default(sim_config_t *c)
{
    memset(c, 0, sizeof(*c));
    c->method = 3;
    c->start.x_m = -3.0;
    c->start.z_m = -10.0;
    c->start.phi_rad = -30.0 * DEG;
    c->normal[0] = 0.3;
    c->normal[1] = -0.6;
    c->normal[2] = -0.75;
    c->distance_m = 45.0;
    c->scene.n_plane = 100;
    c->scene.n_off = 25;
    c->scene.off_zmin_m = 15.0;
    c->scene.off_zmax_m = 40.0;
    c->focal_true_mm = 6.0;
    c->focal_assumed_mm = 6.0;
    c->pixel_mm = 0.0075;
    c->dt_s = 0.1;
    c->max_time_s = 300.0;
}

int sim_config_check(const sim_config_t *c, char *err, unsigned err_len)
{
    /* hypot keeps huge or tiny components from overflowing the length. */
    double nn = hypot(hypot(c->normal[0], c->normal[1]), c->normal[2]);
    if (c->method < 1 || c->method > 3) {
        snprintf(err, err_len, "method must be 1, 2 or 3, got %d", c->method);
    } else if (!isfinite(c->start.x_m) || !isfinite(c->start.z_m) ||
               !isfinite(c->start.phi_rad)) {
        snprintf(err, err_len, "start pose must be finite");
    } else if (!isfinite(nn) || !(nn > 1e-12)) {
        snprintf(err, err_len, "plane normal must be finite and non-zero");
    } else if (!isfinite(c->distance_m) || !(c->distance_m > 0.0)) {
        snprintf(err, err_len, "plane distance must be > 0 m, got %g",
                 c->distance_m);
    } else if (!isfinite(c->noise_px) || !(c->noise_px >= 0.0)) {
        snprintf(err, err_len, "noise must be >= 0 px, got %g", c->noise_px);
    } else if (!(c->outliers >= 0.0 && c->outliers < 1.0)) {
        snprintf(err, err_len, "outlier fraction must be in [0, 1), got %g",
                 c->outliers);
    } else if (!isfinite(c->drift_deg_per_m)) {
        snprintf(err, err_len, "drift must be finite");
    } else if (!isfinite(c->focal_true_mm) || !(c->focal_true_mm > 0.0) ||
               !isfinite(c->focal_assumed_mm) ||
               !(c->focal_assumed_mm > 0.0)) {
        snprintf(err, err_len, "focal length must be > 0 mm");
    } else if (!isfinite(c->pixel_mm) || !(c->pixel_mm > 0.0)) {
        snprintf(err, err_len, "pixel pitch must be > 0 mm");
    } else if (!isfinite(c->pp_offset_px) || fabs(c->pp_offset_px) > 1e4) {
        snprintf(err, err_len, "principal point offset must be finite, "
                 "within 10000 px");
    } else if (!isfinite(c->dt_s) || !(c->dt_s > 0.0) || c->dt_s > 10.0) {
        snprintf(err, err_len, "control period must be in (0, 10] s, got %g",
                 c->dt_s);
    } else if (!isfinite(c->max_time_s) || !(c->max_time_s > 0.0) ||
               c->max_time_s / c->dt_s > 1e7) {
        snprintf(err, err_len,
                 "max time must be > 0 s and at most 1e7 control periods");
    } else if (!isfinite(c->robot.latency_s) || c->robot.latency_s < 0.0 ||
               c->robot.latency_s >= (SIM_ACT_QUEUE - 1) * c->dt_s) {
        snprintf(err, err_len, "latency must be in [0, %d control periods), got %g s",
                 SIM_ACT_QUEUE - 1, c->robot.latency_s);
    } else if (!isfinite(c->robot.accel_mps2) || c->robot.accel_mps2 < 0.0 ||
               !isfinite(c->robot.alpha_radps2) || c->robot.alpha_radps2 < 0.0) {
        snprintf(err, err_len, "acceleration limits must be finite and > 0 (0: none)");
    } else {
        return 0;
    }
    return -1;
}

int sim_config_world(const sim_config_t *c, sim_world_t *w, char *err,
                     unsigned err_len)
{
    if (sim_config_check(c, err, err_len) != 0) {
        return -1;
    }
    sim_camera_t cam;
    sim_camera_make(&cam, c->focal_true_mm, c->pixel_mm, c->pp_offset_px);
    /* hypot keeps huge or tiny components from overflowing the length. */
    double nn = hypot(hypot(c->normal[0], c->normal[1]), c->normal[2]);
    sim_plane_t pl = { { c->normal[0] / nn, c->normal[1] / nn,
                         c->normal[2] / nn }, c->distance_m };
    return sim_world_init(w, &cam, &pl, &c->scene, c->noise_px, c->outliers,
                          c->clip, c->seed, err, err_len);
}

static void finish(sim_result_t *res, const sim_pose_t *pose)
{
    res->final_pose = *pose;
    res->err_x_m = pose->x_m;
    res->err_z_m = pose->z_m;
    /* Report (-180, 180] in degrees, as the wrap in radians gives. */
    res->err_phi_deg = sim_wrap_pi(pose->phi_rad) * (180.0 / SIM_PI);
}

/* Clears res, checks the link and builds the world.  0, or -1 with the
 * reason in err. */
static int run_begin(const sim_config_t *c, const sim_link_t *link,
                     sim_world_t *world, sim_result_t *res, char *err,
                     unsigned err_len)
{
    memset(res, 0, sizeof(*res));
    for (int i = 0; i < 4; ++i) {
        res->step_start_s[i] = -1.0;
        res->step_end_s[i] = -1.0;
    }
    if (link == NULL || link->exchange == NULL) {
        snprintf(err, err_len, "no link to a controller");
        return -1;
    }
    return sim_config_world(c, world, err, err_len);
}

/* Frame k's observations, from the configured source or the world, at
 * most cap of them. */
static uint16_t observe(const sim_config_t *c, uint32_t k,
                        sim_world_t *world, const sim_pose_t *pose,
                        sim_obs_t *obs, uint16_t cap)
{
    uint16_t n = c->observe != NULL
                     ? c->observe(c->observe_user, k, world, pose, obs, cap)
                     : sim_world_observe(world, pose, obs, cap);
    /* A source that claims more than it was given room for is a bug at
     * the edge; never hand the controller memory past the buffer. */
    return n > cap ? cap : n;
}

/* Frame k to the controller and its answer into out.  0, or -1 when the
 * link failed (res then says so). */
static int exchange_frame(const sim_link_t *link, uint32_t k, double t,
                          const spvs_match_t *m, uint16_t n,
                          spvs_output_t *out, sim_result_t *res)
{
    memset(out, 0, sizeof(*out));
    char lerr[128] = "";
    int rc = link->exchange(link->ctx, k, t, m, n, out, lerr,
                            (unsigned)sizeof(lerr));
    res->time_s = t;
    if (rc < 0) {
        res->status = SIM_LINK_ERROR;
        snprintf(res->reason, sizeof(res->reason), "%s",
                 lerr[0] ? lerr : "link failure");
        return -1;
    }
    res->frames = k + 1;
    res->core_status = out->status;
    return 0;
}

/* Step bookkeeping: a change of step ends the old step and starts the new
 * one at this frame's time t. */
static void note_step(sim_result_t *res, int *prev_step, int step, double t)
{
    if (step == *prev_step) {
        return;
    }
    if (*prev_step >= 1 && *prev_step <= 3) {
        res->step_end_s[*prev_step] = t;
    }
    if (step >= 1 && step <= 3 && !res->started[step]) {
        res->started[step] = 1;
        res->step_start_s[step] = t;
    }
    *prev_step = step;
}

/* Whether frame k's answer ends the run: the controller arrived or failed,
 * or answered with a command that cannot be executed (res says which). */
static int run_ends(const spvs_output_t *out, uint32_t k, sim_result_t *res)
{
    if (out->step == SPVS_STEP_DONE) {
        res->status = SIM_CONVERGED;
        return 1;
    }
    if (out->step == SPVS_STEP_FAILED) {
        res->status = SIM_FAILED;
        snprintf(res->reason, sizeof(res->reason), "%s",
                 spvs_status_str(out->status));
        return 1;
    }
    /* A controller answering with non-finite numbers is a broken link,
     * not a command to execute. */
    if (!isfinite((double)out->v) || !isfinite((double)out->w)) {
        res->status = SIM_LINK_ERROR;
        snprintf(res->reason, sizeof(res->reason),
                 "non-finite command at frame %u", (unsigned)k);
        return 1;
    }
    return 0;
}

int sim_run(const sim_config_t *c, const sim_link_t *link, sim_result_t *res,
            sim_frame_cb cb, void *user, char *err, unsigned err_len)
{
    /* The world is ~30 kB: static keeps it off small thread stacks.  The
     * simulator runs one loop at a time. */
    static sim_world_t world;
    static sim_obs_t obs[SIM_MAX_POINTS];
    static spvs_match_t m[SIM_MAX_POINTS];

    if (run_begin(c, link, &world, res, err, err_len) != 0) {
        return -1;
    }
    sim_pose_t pose = c->start;
    pose.phi_rad = sim_wrap_pi(pose.phi_rad);
    sim_actuator_t robot;
    sim_actuator_init(&robot, &c->robot);
    const double drift = c->drift_deg_per_m * DEG;
    const uint32_t max_frames = (uint32_t)floor(c->max_time_s / c->dt_s) + 1u;
    const uint16_t cap = SIM_MAX_POINTS < SPVS_MAX_MATCHES
                             ? (uint16_t)SIM_MAX_POINTS
                             : (uint16_t)SPVS_MAX_MATCHES;
    /* --realtime: frame k leaves k control periods after the start. */
    const double t0_s = sim_clock_now_s();
    int prev_step = 0;
    res->status = SIM_TIMEOUT;

    for (uint32_t k = 0; k < max_frames; ++k) {
        double t = (double)k * c->dt_s;
        if (c->realtime) {
            sim_clock_sleep_until(t0_s + (double)k * c->dt_s);
        }
        uint16_t n = observe(c, k, &world, &pose, obs, cap);
        sim_obs_to_matches(obs, n, m);
        spvs_output_t out;
        if (exchange_frame(link, k, t, m, n, &out, res) != 0) {
            break;
        }
        note_step(res, &prev_step, out.step, t);
        if (cb != NULL) {
            sim_frame_t f = { k, t, pose, obs, m, n, &out };
            if (cb(&f, user) != 0) {
                res->status = SIM_ABORTED;
                snprintf(res->reason, sizeof(res->reason),
                         "stopped by the frame callback");
                break;
            }
        }
        if (run_ends(&out, k, res)) {
            break;
        }
        double x0 = pose.x_m, z0 = pose.z_m;
        sim_actuator_step(&robot, &pose, t, (double)out.v, (double)out.w, c->dt_s, drift);
        res->path_m += hypot(pose.x_m - x0, pose.z_m - z0);
    }
    /* A run that timed out on an error says which: the last frame's
     * status, e.g. too_few_matches where the camera sees too little of
     * the plane (the robot stood still on it, as it must). */
    if (res->status == SIM_TIMEOUT && res->frames > 0 && res->core_status < 0) {
        snprintf(res->reason, sizeof(res->reason), "%s",
                 spvs_status_str(res->core_status));
    }
    finish(res, &pose);
    return 0;
}
