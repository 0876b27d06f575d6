/*
 * sim.h - the closed loop: the simulated robot and camera on one side of a
 * sim_link_t, the controller on the other.
 *
 * Frame k is taken at t = k * dt: the scene is imaged at the true pose, the
 * matches go through the link, and the answered command (v, w) drives the
 * robot for dt (kinematics.h).  The run ends when the controller reports
 * SPVS_STEP_DONE ("converged"), SPVS_STEP_FAILED ("failed"), when t passes
 * max_time_s ("timeout"), when the link fails ("link_error"), or when the
 * frame callback asks to stop ("aborted").  At most
 * floor(max_time_s / dt_s) + 1 frames.
 */
#ifndef SIM_SIM_H
#define SIM_SIM_H

#include <stdint.h>

#include "sim/actuator.h"
#include "sim/geometry.h"
#include "sim/link.h"
#include "sim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* An optional source of observations that replaces the point scene, e.g.
 * features matched in rendered images (sim/frontend.h).  Called once per
 * frame with the frame number `seq`, the run's world (true camera, plane)
 * and the TRUE pose; writes at most `cap` observations to obs and returns
 * their count. */
typedef uint16_t (*sim_observe_fn)(void *user, uint32_t seq,
                                   const sim_world_t *w,
                                   const sim_pose_t *pose, sim_obs_t *obs,
                                   uint16_t cap);

/* Everything that defines a run.  sim_config_default() gives DESIGN.md
 * section 5's defaults. */
typedef struct {
    int method;               /* 1, 2 or 3 (spvs_method_t)                   */
    sim_pose_t start;         /* initial pose; default (-3 m, -10 m, -30 deg) */
    double normal[3];         /* plane normal, normalised by the simulator   */
    double distance_m;        /* plane distance d > 0                        */
    sim_scene_spec_t scene;   /* 100 plane + 25 off-plane points, 15..40 m   */
    double noise_px;          /* image noise sigma, pixels                   */
    double outliers;          /* mismatch fraction per frame, [0, 1)         */
    double drift_deg_per_m;   /* odometry drift in rotation                  */
    double focal_true_mm;     /* true focal length (6 mm)                    */
    double focal_assumed_mm;  /* what the controller is told (6 mm)          */
    double arrival_sigma_px;  /* image noise the in-process controller's
                                 arrival check assumes; 0: its default
                                 (1 px); the image front end's matches need
                                 more (SIM_FRONTEND_ARRIVAL_SIGMA_PX)        */
    double pixel_mm;          /* pixel pitch (0.0075 mm)                     */
    double pp_offset_px;      /* true principal point minus assumed, x, px   */
    uint64_t seed;            /* scene, noise and the controller's RANSAC    */
    double dt_s;              /* control period (0.1 s)                      */
    sim_actuator_spec_t robot; /* latency and acceleration limits (none)     */
    double max_time_s;        /* give up after this (300 s)                  */
    int clip;                 /* 1: match only points inside the 640x480 frame */
    int realtime;             /* 1: pace frames at dt in wall-clock time     */
    sim_observe_fn observe;   /* NULL (default): the point scene             */
    void *observe_user;       /* passed to observe                           */
} sim_config_t;

typedef enum {
    SIM_CONVERGED = 0,
    SIM_FAILED = 1,
    SIM_TIMEOUT = 2,
    SIM_LINK_ERROR = 3,
    SIM_ABORTED = 4
} sim_status_t;

/* "converged", "failed", "timeout", "link_error", "aborted". */
const char *sim_status_str(sim_status_t s);

/* One frame, as the callback sees it. */
typedef struct {
    uint32_t seq;
    double t_s;
    sim_pose_t pose;           /* true pose when the frame was taken         */
    const sim_obs_t *obs;      /* the observations, double precision         */
    const spvs_match_t *m;     /* what the controller was given              */
    uint16_t n;
    const spvs_output_t *out;  /* its answer                                 */
} sim_frame_t;

/* Called after every answered frame.  Return 0 to go on, anything else to
 * stop the run with status SIM_ABORTED. */
typedef int (*sim_frame_cb)(const sim_frame_t *f, void *user);

typedef struct {
    sim_status_t status;
    int core_status;           /* spvs_status_t of the last answered frame   */
    char reason[160];          /* core status name when failed, link or
                                  callback message otherwise; "" when none   */
    double time_s;             /* time of the last frame                     */
    uint32_t frames;           /* frames answered                            */
    sim_pose_t final_pose;     /* pose at the end                            */
    double err_x_m;            /* final error = final pose (target is 0,0,0) */
    double err_z_m;
    double err_phi_deg;        /* wrapped to (-180, 180]                     */
    /* Steps 1..3 (index 0 unused): started[i] is set once step i was seen;
     * end times stay negative while a step has not ended. */
    uint8_t started[4];
    double step_start_s[4];
    double step_end_s[4];
    double path_m;             /* distance driven, metres                    */
} sim_result_t;

void sim_config_default(sim_config_t *c);

/* Check a configuration.  Returns 0, or -1 with a one-line reason in err. */
int sim_config_check(const sim_config_t *c, char *err, unsigned err_len);

/* Build the world of a configuration (true camera, plane, scene, noise). */
int sim_config_world(const sim_config_t *c, sim_world_t *w, char *err,
                     unsigned err_len);

/* Run the closed loop through `link` (left open: the caller closes it).
 * cb may be NULL.  Returns 0 when the run took place, whatever its status
 * (see res->status), or -1 with a reason in err when the configuration or
 * the scene is unusable (nothing was sent). */
int sim_run(const sim_config_t *c, const sim_link_t *link, sim_result_t *res,
            sim_frame_cb cb, void *user, char *err, unsigned err_len);

#ifdef __cplusplus
}
#endif

#endif /* SIM_SIM_H */
