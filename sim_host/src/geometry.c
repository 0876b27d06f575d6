/* geometry.c - camera, pose and homography of the simulation (geometry.h). */
#include "sim/geometry.h"

#include <math.h>
#include <stddef.h>

#define SIM_PI 3.14159265358979323846

static void mat3_mul(const double A[9], const double B[9], double C[9])
{
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] +
                           A[3 * i + 2] * B[6 + j];
        }
    }
}

void sim_camera_make(sim_camera_t *cam, double f_mm, double pixel_mm,
                     double x0_px)
{
    cam->alpha_x_px = f_mm / pixel_mm;
    cam->alpha_y_px = f_mm / pixel_mm;
    cam->x0_px = x0_px;
    cam->width_px = 640;
    cam->height_px = 480;
}

void sim_rot(double phi_rad, double R[9])
{
    double c = cos(phi_rad), s = sin(phi_rad);
    R[0] = c;   R[1] = 0.0; R[2] = s;
    R[3] = 0.0; R[4] = 1.0; R[5] = 0.0;
    R[6] = -s;  R[7] = 0.0; R[8] = c;
}

int sim_project(const sim_camera_t *cam, const sim_pose_t *pose,
                const double X[3], double p[2], double *depth_m)
{
    double R[9];
    sim_rot(pose->phi_rad, R);
    double d[3] = { X[0] - pose->x_m, X[1], X[2] - pose->z_m };
    double Xc = R[0] * d[0] + R[2] * d[2];
    double Yc = d[1];
    double Zc = R[6] * d[0] + R[8] * d[2];
    if (depth_m != NULL) {
        *depth_m = Zc;
    }
    if (!(Zc > SIM_MIN_DEPTH_M)) {
        return -1;
    }
    p[0] = cam->alpha_x_px * Xc / Zc + cam->x0_px;
    p[1] = cam->alpha_y_px * Yc / Zc;
    return 0;
}

void sim_h_eq2(const sim_camera_t *cam, const sim_plane_t *pl,
               const sim_pose_t *pose, double H[9])
{
    const double ax = cam->alpha_x_px, ay = cam->alpha_y_px, x0 = cam->x0_px;
    const double K[9] = { ax, 0.0, x0, 0.0, ay, 0.0, 0.0, 0.0, 1.0 };
    const double Kinv[9] = { 1.0 / ax, 0.0, -x0 / ax, 0.0, 1.0 / ay, 0.0,
                             0.0, 0.0, 1.0 };
    const double c[3] = { pose->x_m, 0.0, pose->z_m };
    double R[9], M[9], T[9], U[9];
    sim_rot(pose->phi_rad, R);
    /* M = I + c n^T / d */
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            M[3 * i + j] = (i == j ? 1.0 : 0.0) + c[i] * pl->n[j] / pl->d_m;
        }
    }
    mat3_mul(K, R, T);
    mat3_mul(T, M, U);
    mat3_mul(U, Kinv, H);
    double h22 = H[4];
    for (int i = 0; i < 9; ++i) {
        H[i] /= h22;
    }
}

void sim_h_eq5(double alpha_x_px, double alpha_y_px, const sim_plane_t *pl,
               const sim_pose_t *pose, double H[9])
{
    const double x = pose->x_m, z = pose->z_m;
    const double c = cos(pose->phi_rad), s = sin(pose->phi_rad);
    const double nx = pl->n[0] / pl->d_m, ny = pl->n[1] / pl->d_m,
                 nz = pl->n[2] / pl->d_m;
    const double a = x * c + z * s;   /* x of R c: along the camera x axis */
    const double b = -x * s + z * c;  /* z of R c: along the optical axis  */
    H[0] = c + a * nx;
    H[1] = (alpha_x_px / alpha_y_px) * a * ny;
    H[2] = alpha_x_px * (s + a * nz);
    H[3] = 0.0;
    H[4] = 1.0;
    H[5] = 0.0;
    H[6] = (-s + b * nx) / alpha_x_px;
    H[7] = b * ny / alpha_y_px;
    H[8] = c + b * nz;
}

double sim_h_apply(const double H[9], double x, double y, double *xo,
                   double *yo)
{
    double u = H[0] * x + H[1] * y + H[2];
    double v = H[3] * x + H[4] * y + H[5];
    double w = H[6] * x + H[7] * y + H[8];
    *xo = u / w;
    *yo = v / w;
    return w;
}

void sim_epipole(const sim_camera_t *cam, const sim_pose_t *pose, double e[3])
{
    /* R (0 - c) with c = (x, 0, z), then K. */
    double c = cos(pose->phi_rad), s = sin(pose->phi_rad);
    double ex = -(c * pose->x_m + s * pose->z_m);
    double ez = -(-s * pose->x_m + c * pose->z_m);
    e[0] = cam->alpha_x_px * ex + cam->x0_px * ez;
    e[1] = 0.0;
    e[2] = ez;
}

double sim_det3(const double A[9])
{
    return A[0] * (A[4] * A[8] - A[5] * A[7]) -
           A[1] * (A[3] * A[8] - A[5] * A[6]) +
           A[2] * (A[3] * A[7] - A[4] * A[6]);
}

double sim_wrap_pi(double a_rad)
{
    double a = fmod(a_rad, 2.0 * SIM_PI);
    if (a <= -SIM_PI) {
        a += 2.0 * SIM_PI;
    } else if (a > SIM_PI) {
        a -= 2.0 * SIM_PI;
    }
    return a;
}
