/*
 * hombench.h - the homography benchmark's case file (HOMBENCH v1, see
 * BENCH_CASES.md in the shared notes and docs/BENCHMARKS.md) and the synthetic
 * case generator that writes it.
 *
 * Conventions are DESIGN.md's: world = target camera frame, robot state
 * (x, z, phi) in metres and radians, points in pixels centred on the
 * principal point, H_cur_tgt = K R (I + c n^T / d) K^-1 normalised so that
 * h22 (row-major index 4) = 1.
 *
 * Everything here is plain C and double precision; it is the bench's own
 * ground truth, independent of the core.
 */
#ifndef HOMBENCH_H
#define HOMBENCH_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Largest N one record may carry, and largest record count of a file: bounds
 * that keep a corrupt header from asking for absurd allocations. */
#define HB_MAX_N 100000u
#define HB_MAX_RECORDS 1000000u

/* The file header's scene: camera and plane, shared by every record. */
typedef struct {
    double alpha_x;   /* focal length in x, pixels                        */
    double alpha_y;   /* focal length in y, pixels                        */
    double width_px;  /* image width, pixels (640)                        */
    double height_px; /* image height, pixels (480)                       */
    double normal[3]; /* unit plane normal n, target camera frame         */
    double d_m;       /* plane distance d > 0, metres (n^T X = -d)        */
} hb_scene_t;

/* One estimation problem. */
typedef struct {
    uint32_t case_id;   /* which (family, N, mismatch, noise) cell        */
    uint32_t instance;  /* random draw within the cell                    */
    uint32_t pose;      /* the pose within its family (hb_family_pose)    */
    uint32_t n;         /* number of matches                              */
    uint32_t n_inliers; /* true inliers among them                        */
    uint64_t seed;      /* seed the record was generated with             */
    double mismatch;    /* mismatch fraction, 0..1                        */
    double sigma_px;    /* noise sigma, pixels                            */
    double x_m, z_m;    /* robot position, metres                         */
    double phi_rad;     /* robot heading, radians                         */
    double H[9];        /* true H_cur_tgt, row-major, H[4] = 1            */
    double (*pts)[4];   /* n x (x_tgt, y_tgt, x_cur, y_cur), centred px   */
    uint8_t *inlier;    /* n flags: 1 true inlier, 0 mismatch             */
} hb_record_t;

typedef struct {
    hb_scene_t scene;
    uint32_t count;
    hb_record_t *rec; /* count records (heap, released by hb_set_free)    */
} hb_set_t;

/* The paper's default scene: 640x480, alpha = 800 px, n = (0.3, -0.6, -0.75)
 * normalised, d = 45 m. */
void hb_scene_default(hb_scene_t *sc);

/* True H_cur_tgt for robot pose (x_m, z_m, phi_rad), eq. (2), h22 = 1. */
void hb_true_h(const hb_scene_t *sc, double x_m, double z_m, double phi_rad,
               double H[9]);

/* Map a centred pixel point through H.  Returns 0, or -1 when the point maps
 * to or behind the line at infinity (third coordinate <= tiny). */
int hb_apply_h(const double H[9], double x, double y, double *xo, double *yo);

/* Mean transfer error of the four corners of the seen rectangle
 * (hb_view_region: the whole image, +-w/2, +-h/2, wherever the current
 * camera sees all of it) under H_est against H_true, pixels.  Returns
 * INFINITY when a corner cannot be mapped, H_est is not finite, or nothing
 * of the image is seen. */
double hb_corner_err(const hb_scene_t *sc, const double H_true[9],
                     const double H_est[9]);

/* The same corners' error expressed in target-image pixels: each corner c
 * mapped by H_est, then back by H_true^-1, against c.  Where H_true
 * magnifies (grazing views) this is the current-image error divided by the
 * local magnification; where it does not, it is close to hb_corner_err.
 * INFINITY as hb_corner_err. */
double hb_corner_err_tgt(const hb_scene_t *sc, const double H_true[9],
                         const double H_est[9]);

/* Pose at fraction s in [0, 1] of the shortest-path homing run from
 * (x0, z0, phi0) to (0, 0, 0): rotate onto the line through the target
 * (first 20 % of s), drive it (next 60 %), rotate to phi = 0 (last 20 %).
 * The robot drives forwards when the target is ahead of it and backwards
 * when it is behind (the heading on the line is the one of the two nearer
 * phi0), and every rotation takes the short way, as the controller does. */
void hb_homing_pose(double x0_m, double z0_m, double phi0_rad, double s,
                    double *x_m, double *z_m, double *phi_rad);

/* ---- pose families ------------------------------------------------------
 * The benchmark's matrix has a pose-family dimension (docs/BENCHMARKS.md):
 *   HB_FAMILY_HOMING   P poses along the homing run from (-3, -10, -30 deg)
 *                      (pose id k = 0..P-1, s = k / (P - 1));
 *   HB_FAMILY_FIG5     P poses along the homing run of each of the six
 *                      Figure 5 starts (pose id = start * HB_POSE_STRIDE + k);
 *   HB_FAMILY_GRAZING  at each Figure 5 start position, the robot turned so
 *                      that the goal image's centre is seen off its optical
 *                      axis by an angle of HB_GRAZING_MIN_DEG..MAX_DEG in P
 *                      even steps, right of the axis for even k and left
 *                      of it for odd k (pose id = start * HB_POSE_STRIDE + k).
 * The goal image's centre is the plane point on the goal camera's optical
 * axis; its off-axis angle is hb_off_axis(). */
#define HB_FAMILY_HOMING 0u
#define HB_FAMILY_FIG5 1u
#define HB_FAMILY_GRAZING 2u
#define HB_FAMILIES 3u
#define HB_FIG5_STARTS 6u
#define HB_POSE_STRIDE 1000u
#define HB_GRAZING_MIN_DEG 60.0
#define HB_GRAZING_MAX_DEG 100.0

/* Largest |coordinate| (centred pixels) at which a plane point counts as
 * seen by the current camera: the image plane is not clipped to 640x480 (as
 * in the simulator), but the core accepts coordinates under 8192 px only. */
#define HB_VIEW_PX 8000.0

/* "homing", "fig5", "grazing", or NULL for an unknown family. */
const char *hb_family_name(uint32_t family);

/* Figure 5 start i (0..5): (-3, -10, -30), (0, -8, -40), (6, -6, 0),
 * (-6, 4, 20), (6, 8, 10), (5, 2, -50) in m, m, deg (tools/experiments.py's
 * FIG5_POSES).  Returns 0, or -1 for i out of range. */
int hb_fig5_start(uint32_t i, double *x_m, double *z_m, double *phi_rad);

/* Records per instance of a family with P poses: P (homing) or 6 P. */
uint32_t hb_family_poses(uint32_t family, uint32_t poses);

/* Pose number k (0 .. hb_family_poses() - 1) of a family with P poses per
 * start: robot pose and the pose id the record carries.  Returns 0, or -1
 * for a bad family, k or P, or a scene whose plane the goal camera's axis
 * does not meet. */
int hb_family_pose(const hb_scene_t *sc, uint32_t family, uint32_t k,
                   uint32_t poses, double *x_m, double *z_m, double *phi_rad,
                   uint32_t *pose_id);

/* Signed angle (radians) between the current camera's optical axis and the
 * ray from its centre to the goal image's centre point on the plane,
 * positive when that point lies right of the axis (current image x > 0);
 * NAN when the goal camera's axis does not meet the plane. */
double hb_off_axis(const hb_scene_t *sc, double x_m, double z_m, double phi_rad);

/* The rectangle of the target image that the current camera sees: every
 * point of it maps under H_true in front of the current camera and within
 * HB_VIEW_PX of its centre.  The whole image (+-w/2, +-h/2) when it all
 * maps so; else, of the centred heights h, 15/16 h, ..., h/16, the rectangle
 * of largest area with the widest x-range that does.  r = {x_lo, x_hi,
 * y_lo, y_hi}.  Returns 0, or -1 when no such rectangle is at least 1 px
 * wide.  The generator draws target points in it and hb_corner_err scores
 * its corners. */
int hb_view_region(const hb_scene_t *sc, const double H_true[9], double r[4]);

/* Share of the record's true inliers whose forward transfer error under the
 * true H, |H p_tgt - p_cur| on the noisy points, exceeds px: the inliers a
 * fixed threshold of px in the current image cuts even at the true H. */
double hb_inliers_over(const hb_record_t *rec, double px);

/* Share of the record's true inliers whose first-order geometric error at
 * the true H exceeds chi2: e^T (sigma^2 (I + A A^T))^-1 e > chi2, with e =
 * p_cur - H(p_tgt) and A the 2x2 Jacobian of H's map at p_tgt (Sampson's
 * approximation with noise of sigma on both images; Hartley and Zisserman,
 * section 4.2.6).  With Gaussian noise it is about the chi-square tail
 * (0.01 for chi2 = 9.21, two degrees of freedom) wherever the first-order
 * model holds.  0 when sigma <= 0. */
double hb_inliers_over_sampson(const hb_record_t *rec, double sigma, double chi2);

/* Generate one record in place: n plane matches whose target points are
 * uniform in the seen rectangle of the target image (hb_view_region; the
 * whole image unless the view is grazing), round(mismatch * n) of them (chosen at random)
 * with the current point replaced by a uniform point in the frame, and
 * Gaussian noise of sigma_px on both images.  rec->pts and rec->inlier must
 * hold n entries; the id fields are left to the caller.
 * Returns 0, or -1 on bad arguments (n = 0, mismatch outside [0, 1], sigma < 0)
 * or when the current camera sees no part of the target image. */
int hb_generate(const hb_scene_t *sc, uint32_t n, double mismatch,
                double sigma_px, double x_m, double z_m, double phi_rad,
                uint64_t seed, hb_record_t *rec);

/* Allocate rec->pts and rec->inlier for n matches.  Returns 0 or -1. */
int hb_record_alloc(hb_record_t *rec, uint32_t n);

/* Release every record and reset the set to empty. */
void hb_set_free(hb_set_t *set);

/* Write a set to a HOMBENCH v1 file.  Returns 0, or -1 with a one-line reason
 * in err (err_len bytes). */
int hb_write(const char *path, const hb_set_t *set, char *err, size_t err_len);

/* Read and validate a HOMBENCH v1 file (magic, version, sizes against the
 * file length, finite values, flags 0/1, padding).  On success *set owns its
 * records (free with hb_set_free).  Returns 0, or -1 with a one-line reason in
 * err and *set empty. */
int hb_read(const char *path, hb_set_t *set, char *err, size_t err_len);

/* Small deterministic generator (SplitMix64) used by the case generator and
 * the homing scene, so that cases are the same on every machine. */
typedef struct {
    uint64_t state;
} hb_rng_t;

void hb_rng_seed(hb_rng_t *r, uint64_t seed);
uint64_t hb_rng_next(hb_rng_t *r);
/* Uniform in [lo, hi). */
double hb_rng_uniform(hb_rng_t *r, double lo, double hi);
/* Standard normal (Box-Muller, one value per call). */
double hb_rng_normal(hb_rng_t *r);

#ifdef __cplusplus
}
#endif

#endif /* HOMBENCH_H */
