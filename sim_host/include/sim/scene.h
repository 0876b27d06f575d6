/*
 * scene.h - the simulated world: a plane of random points plus points off
 * the plane, the target image taken from the origin, and the matches the
 * robot's camera sees from any pose (DESIGN.md section 5).
 *
 * Bounds: at most SIM_MAX_POINTS scene points; drawing each point tries at
 * most SIM_SCENE_MAX_TRIES random pixels before giving up with an error.
 */
#ifndef SIM_SCENE_H
#define SIM_SCENE_H

#include <stdint.h>

#include "sim/geometry.h"
#include "sim/rng.h"
#include "spvs/spvs.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SIM_MAX_POINTS 512
#define SIM_SCENE_MAX_TRIES 10000

/* Ground truth of the scene.  Point i is feature feature[i] of the target
 * image; the features are a random permutation of 0..n-1, so an index does
 * not tell whether its point is on the plane. */
typedef struct {
    uint16_t n;
    double X[SIM_MAX_POINTS][3];     /* world (target camera) frame, metres  */
    double p_tgt[SIM_MAX_POINTS][2]; /* noise-free target image, centred px  */
    uint16_t feature[SIM_MAX_POINTS];
    uint8_t on_plane[SIM_MAX_POINTS];
} sim_scene_t;

/* How to draw a scene. */
typedef struct {
    uint16_t n_plane;    /* points on the plane (100 by default)              */
    uint16_t n_off;      /* points between the camera and the plane (25)      */
    double off_zmin_m;   /* depth range of the off-plane points (15..40 m)    */
    double off_zmax_m;
} sim_scene_spec_t;

/* Draw a scene seen by the TARGET camera `cam` (placed at the origin).
 * Plane points: a random pixel of the target image, its ray cut with the
 * plane, kept when the cut is in front of the camera.  Off-plane points: a
 * random pixel and a random depth Z in [off_zmin_m, off_zmax_m), kept when
 * nearer than the plane (n^T X > -d).
 * Returns 0, or -1 with a one-line reason in err when a point could not be
 * placed in SIM_SCENE_MAX_TRIES draws (the plane is not in view) or the spec
 * is out of range. */
int sim_scene_make(sim_scene_t *s, const sim_camera_t *cam,
                   const sim_plane_t *pl, const sim_scene_spec_t *spec,
                   sim_rng_t *rng, char *err, unsigned err_len);

/* What the camera delivers for one frame, in double precision. */
typedef struct {
    uint16_t feature;
    double x_tgt, y_tgt;  /* target image as the controller has it (noisy)  */
    double x_cur, y_cur;  /* current image, centred px                      */
    uint8_t on_plane;     /* ground truth of the scene point                */
    uint8_t mismatched;   /* x_cur, y_cur replaced by a random point        */
} sim_obs_t;

/* The camera model of one run: true camera, scene, noisy target image. */
typedef struct {
    sim_camera_t cam;       /* the TRUE camera                               */
    sim_plane_t plane;
    sim_scene_t scene;
    double p_tgt_obs[SIM_MAX_POINTS][2]; /* target image with its noise      */
    double noise_px;        /* Gaussian sigma added to every coordinate      */
    double outliers;        /* fraction of matches replaced each frame       */
    int clip;               /* 1: only points inside the image are matched   */
    sim_rng_t rng_frame;    /* per-frame noise                               */
    sim_rng_t rng_mismatch; /* which matches are replaced, and by what       */
} sim_world_t;

/* Set up a world: draw the scene with `rng_scene`, then the target-image
 * noise once from a stream of `seed`; frame noise and mismatches use their
 * own streams of `seed`.  noise_px >= 0, outliers in [0, 1).
 * Returns 0 or -1 with a reason in err (see sim_scene_make). */
int sim_world_init(sim_world_t *w, const sim_camera_t *cam_true,
                   const sim_plane_t *pl, const sim_scene_spec_t *spec,
                   double noise_px, double outliers, int clip, uint64_t seed,
                   char *err, unsigned err_len);

/* Image the scene from `pose`: every point with depth > SIM_MIN_DEPTH_M
 * (inside the frame too when clip is set, and within SPVS_MAX_COORD_PX of
 * the centre so that the controller accepts the coordinates), plus Gaussian
 * noise; then round(outliers * count) of them, chosen at random, get a
 * uniform random current point in the image instead.
 * obs: room for `cap` entries.  Returns the number of observations. */
uint16_t sim_world_observe(sim_world_t *w, const sim_pose_t *pose,
                           sim_obs_t *obs, uint16_t cap);

/* Convert observations to the core's match records. */
void sim_obs_to_matches(const sim_obs_t *obs, uint16_t n, spvs_match_t *m);

#ifdef __cplusplus
}
#endif

#endif /* SIM_SCENE_H */
