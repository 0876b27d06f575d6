/*
 * geometry.h - the simulated camera, the robot pose and the homography they
 * induce (paper, eqs. (2), (3), (5); DESIGN.md section 1).
 *
 * World = target camera frame: X right, Y down, Z forward, metres.  The robot
 * pose (x, z, phi) puts the camera centre at c = (x, 0, z) and rotates world
 * points into the camera with R(phi) of eq. (3): X_cam = R (X - c).
 * Image points are pixels centred on the principal point the CONTROLLER
 * assumes (the image centre); the true camera's principal point sits x0_px to
 * the right of it.  H_cur_tgt maps target-image points to current-image
 * points, p_cur ~ H p_tgt, normalised so that h22 = 1.  Matrices are 3x3,
 * row-major, 9 doubles.
 */
#ifndef SIM_GEOMETRY_H
#define SIM_GEOMETRY_H

#ifdef __cplusplus
extern "C" {
#endif

/* Points at or nearer than this depth in a camera are not imaged (metres). */
#define SIM_MIN_DEPTH_M 0.1

/* Robot pose: camera centre (x_m, 0, z_m) in the world, heading phi_rad
 * (eq. 3; the robot drives along (-sin phi, cos phi)). */
typedef struct {
    double x_m;
    double z_m;
    double phi_rad;
} sim_pose_t;

/* A pinhole camera without skew.  alpha_* are focal lengths in pixels; x0_px
 * is the true principal point relative to the assumed one (pixels, x only:
 * the paper's calibration study shifts x0). */
typedef struct {
    double alpha_x_px;
    double alpha_y_px;
    double x0_px;
    int width_px;   /* image size, for random pixels and the optional clip */
    int height_px;
} sim_camera_t;

/* Plane n^T X = -d in the world, |n| = 1, d > 0 (n points from the plane
 * towards the target camera). */
typedef struct {
    double n[3];
    double d_m;
} sim_plane_t;

/* A camera with focal length f_mm, square pixels of pixel_mm and the
 * principal point x0_px off the image centre; 640x480 unless changed after. */
void sim_camera_make(sim_camera_t *cam, double f_mm, double pixel_mm,
                     double x0_px);

/* R(phi) of eq. (3), world -> camera.  phi in radians. */
void sim_rot(double phi_rad, double R[9]);

/* Project world point X (metres) into the camera at `pose`.
 * p: centred pixels (x, y).  depth_m (may be NULL): Z in that camera.
 * Returns 0, or -1 when the point is at or nearer than SIM_MIN_DEPTH_M. */
int sim_project(const sim_camera_t *cam, const sim_pose_t *pose,
                const double X[3], double p[2], double *depth_m);

/* The true homography, eq. (2): H = K R (I + c n^T / d) K^-1, with K the
 * camera (principal point (x0_px, 0) in centred pixels), h22 = 1. */
void sim_h_eq2(const sim_camera_t *cam, const sim_plane_t *pl,
               const sim_pose_t *pose, double H[9]);

/* The closed form of eq. (5) (principal point at the centre), h22 = 1. */
void sim_h_eq5(double alpha_x_px, double alpha_y_px, const sim_plane_t *pl,
               const sim_pose_t *pose, double H[9]);

/* Apply H to a centred pixel: (xo, yo) = dehom(H (x, y, 1)).
 * Returns the third homogeneous coordinate (<= 0: behind the camera). */
double sim_h_apply(const double H[9], double x, double y, double *xo,
                   double *yo);

/* Image of the target camera centre (the world origin) in the camera at
 * `pose`, homogeneous: e = K R (0 - c).  e[2] > 0 when the target position
 * is in front of the camera.  Its x in pixels is e[0] / e[2]. */
void sim_epipole(const sim_camera_t *cam, const sim_pose_t *pose,
                 double e[3]);

/* Determinant of a 3x3 matrix. */
double sim_det3(const double A[9]);

/* Wrap an angle to (-pi, pi] (radians). */
double sim_wrap_pi(double a_rad);

#ifdef __cplusplus
}
#endif

#endif /* SIM_GEOMETRY_H */
