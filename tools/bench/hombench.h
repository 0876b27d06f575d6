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
    uint32_t case_id;   /* which (N, mismatch, noise) cell                */
    uint32_t instance;  /* random draw within the cell                    */
    uint32_t pose;      /* index of the pose along the homing run         */
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

/* Mean transfer error of the four image corners (+-w/2, +-h/2) under H_est
 * against H_true, pixels.  Returns INFINITY when a corner cannot be mapped or
 * H_est is not finite. */
double hb_corner_err(const hb_scene_t *sc, const double H_true[9],
                     const double H_est[9]);

/* Pose at fraction s in [0, 1] of the shortest-path homing run from
 * (x0, z0, phi0) to (0, 0, 0): rotate to face the target (first 20 % of s),
 * drive the straight line (next 60 %), rotate to phi = 0 (last 20 %). */
void hb_homing_pose(double x0_m, double z0_m, double phi0_rad, double s,
                    double *x_m, double *z_m, double *phi_rad);

/* Generate one record in place: n plane matches whose target points are
 * uniform in the target image, round(mismatch * n) of them (chosen at random)
 * with the current point replaced by a uniform point in the frame, and
 * Gaussian noise of sigma_px on both images.  rec->pts and rec->inlier must
 * hold n entries; the id fields are left to the caller.
 * Returns 0, or -1 on bad arguments (n = 0, mismatch outside [0, 1], sigma < 0). */
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
