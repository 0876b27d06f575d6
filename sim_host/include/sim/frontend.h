/*
 * frontend.h - a vision front end for the simulator: render the camera image
 * of a textured scene at any pose, detect SIFT (or ORB) features, match them
 * against the target image with a ratio test, and hand the matches to the
 * loop as sim_obs_t records (C-callable; the implementation is C++ with
 * OpenCV).
 *
 * The scene: the dominant plane n^T X = -d of the run (a procedural texture
 * with corners at several scales, deterministic per seed) and a few
 * fronto-parallel textured quads between the target camera and the plane,
 * for parallax.  Images are 640x480, 8-bit grey, rendered by casting one
 * ray per pixel into the surfaces (the nearest hit wins) and sampling their
 * textures bilinearly; pixel (u, v) is the centred point (u - 320, v - 240)
 * of DESIGN.md section 1.
 *
 * Matches: the target image (pose (0, 0, 0)) is rendered and described once,
 * keeping at most target_features <= SPVS_MAX_FEATURES keypoints; feature
 * i of a match is target keypoint i.  Each current image is matched to it
 * (Hamming distance, Lowe's ratio test, optionally a mutual best check) and
 * the best max_matches <= SPVS_MAX_MATCHES matches by distance are kept.
 *
 * Ground truth: each target keypoint's 3D point is found by casting its
 * ray into the scene.  A match is a mismatch when its current point is more
 * than mismatch_px from the true projection of that point.
 *
 * Bounds: rendering is O(pixels x surfaces); matching is O(n_target x
 * n_current) Hamming distances.  No call loops on its input.
 */
#ifndef SIM_FRONTEND_H
#define SIM_FRONTEND_H

#include <stdint.h>

#include "sim/geometry.h"
#include "sim/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SIM_FRONTEND_WIDTH 640
#define SIM_FRONTEND_HEIGHT 480
/* Focal length of the camera the image runs use (sim_config_t's
 * focal_true_mm and focal_assumed_mm), with its 0.0075 mm pixels 400 px:
 * a field of view of 77 x 62 deg.  The paper's 6 mm (800 px, 44 deg) loses
 * the target's view of the scene when the robot turns 40..50 deg to face
 * the target line from the Figure 5 poses. */
#define SIM_FRONTEND_FOCAL_MM 3.0
/* The image noise the controller's arrival check is told for these matches
 * (docs/CONTROL.md): it sets the gate on the remembered off-plane points'
 * unsigned parallax, and SIFT on rendered images at the target leaves more
 * of it than the point scene's 1 px noise, with a bias of its own, so the
 * check assumes 1.5 px there. */
#define SIM_FRONTEND_ARRIVAL_SIGMA_PX 1.5
/* Most off-plane quads a scene can hold. */
#define SIM_FRONTEND_MAX_OBJECTS 16

/* Feature detectors and descriptors (all in OpenCV's main modules). */
#define SIM_FRONTEND_ORB 0
#define SIM_FRONTEND_SIFT 1
#define SIM_FRONTEND_AKAZE 2

typedef struct {
    uint64_t seed;          /* textures and object placement              */
    int n_objects;          /* off-plane quads, 0..SIM_FRONTEND_MAX_OBJECTS (10) */
    double obj_zmin_m;      /* their depth range in the target camera (12) */
    double obj_zmax_m;      /* (35)                                        */
    int target_features;    /* keypoints kept on the target image, 16..
                               SPVS_MAX_FEATURES (500)                      */
    int current_features;   /* keypoints on each current image (1500)      */
    double ratio;           /* Lowe's ratio test, (0, 1] (0.7)             */
    int cross_check;        /* 1: keep only mutual best matches (1)        */
    int max_matches;        /* 1..SPVS_MAX_MATCHES (256)                   */
    double mismatch_px;     /* ground-truth mismatch distance, px (3)      */
    double image_noise;     /* sensor noise sigma, grey levels (1.5)       */
    int subpixel;           /* 1: refine matched corners to sub-pixel (1)  */
    int detector;           /* SIM_FRONTEND_SIFT (default), _ORB, _AKAZE   */
    int levels;             /* SIFT: layers per octave; ORB: pyramid levels
                               of 1.2; 1..16 (3)                           */
    int detect_half;        /* 1: detect and describe on the image halved,
                               keypoints mapped back and refined on the
                               full image (1)                              */
    const char *texture;    /* an image file (a photograph) for the plane's
                               texture, scaled to cover it, or NULL for the
                               procedural one (NULL)                       */
} sim_frontend_params_t;

/* What the front end saw in one frame. */
typedef struct {
    uint32_t seq;
    uint16_t n_keypoints;   /* keypoints in the current image              */
    uint16_t n_matches;     /* matches handed on                           */
    uint16_t n_mismatches;  /* of those, farther than mismatch_px from the
                               truth                                       */
    uint16_t n_offplane;    /* of those, target features off the plane    */
    double render_ms;       /* wall-clock time of rendering                */
    double match_ms;        /* of detection, description and matching     */
} sim_frontend_frame_stats_t;

/* Totals over every frame observed since creation (or the last reset). */
typedef struct {
    uint32_t frames;
    uint64_t matches;
    uint64_t mismatches;
    uint16_t min_matches;   /* fewest matches in one frame                 */
    uint16_t max_matches;
    double max_mismatch_rate; /* worst frame, mismatches / matches         */
    double render_ms;       /* summed                                      */
    double match_ms;
} sim_frontend_totals_t;

typedef struct sim_frontend sim_frontend_t;

/* The defaults listed in sim_frontend_params_t. */
void sim_frontend_params_default(sim_frontend_params_t *p);

/* Build the scene for the TRUE camera `cam` and plane `pl`, render the target
 * image at (0, 0, 0), detect and describe its features.
 * Returns a new front end, or NULL with a one-line reason in err when the
 * parameters are out of range, the plane is not in view, or the target image
 * yields fewer than 16 features. */
sim_frontend_t *sim_frontend_create(const sim_frontend_params_t *p,
                                    const sim_camera_t *cam,
                                    const sim_plane_t *pl, char *err,
                                    unsigned err_len);

void sim_frontend_destroy(sim_frontend_t *f);

/* Render the image at the TRUE pose, match it to the target and write up to
 * `cap` observations (centred px; x_tgt, y_tgt are the target keypoint,
 * on_plane and mismatched are ground truth).  `seq` seeds the sensor noise.
 * st may be NULL.  Returns the number of observations (0 when nothing
 * matched or the pose is not finite). */
uint16_t sim_frontend_observe(sim_frontend_t *f, uint32_t seq,
                              const sim_pose_t *pose, sim_obs_t *obs,
                              uint16_t cap, sim_frontend_frame_stats_t *st);

/* The same, shaped as sim_config_t.observe (user = the front end). */
uint16_t sim_frontend_observe_cb(void *user, uint32_t seq,
                                 const sim_world_t *w, const sim_pose_t *pose,
                                 sim_obs_t *obs, uint16_t cap);

/* Stats of the last observed frame, and totals since creation. */
void sim_frontend_last(const sim_frontend_t *f, sim_frontend_frame_stats_t *st);
void sim_frontend_totals(const sim_frontend_t *f, sim_frontend_totals_t *t);
void sim_frontend_reset_totals(sim_frontend_t *f);

/* Number of target features (keypoints kept on the target image). */
uint16_t sim_frontend_target_count(const sim_frontend_t *f);

/* Ground truth of target feature i: its keypoint (centred px) and its 3D
 * point (world, metres); on_plane 1 when the ray met the plane first.
 * Returns 0, or -1 when i is out of range or its ray met nothing. */
int sim_frontend_target_point(const sim_frontend_t *f, uint16_t i,
                              double p_tgt[2], double X[3], int *on_plane);

/* Write the target image, the last current image, or a side-by-side picture
 * of the last frame's matches (target left, current right; green lines for
 * correct matches, red for mismatches) as PNG.  Returns 0, or -1 with a
 * reason in err when nothing was rendered yet or the file cannot be
 * written. */
int sim_frontend_save_target(const sim_frontend_t *f, const char *path,
                             char *err, unsigned err_len);
int sim_frontend_save_frame(const sim_frontend_t *f, const char *path,
                            char *err, unsigned err_len);
int sim_frontend_save_matches(const sim_frontend_t *f, const char *path,
                              char *err, unsigned err_len);

/* OpenCV's cv::findHomography (RANSAC, threshold thresh_px) on observations,
 * target -> current, centred px, h22 = 1: the reference the core's planar
 * estimate is checked against.  Returns 0, or -1 when fewer than 4
 * observations are given or OpenCV finds no homography. */
int sim_frontend_opencv_h(const sim_obs_t *obs, uint16_t n, double thresh_px,
                          double H[9]);

#ifdef __cplusplus
}
#endif

#endif /* SIM_FRONTEND_H */
