/*
 * synth.h - synthetic planar-motion geometry for the core's unit tests
 * (double precision, DESIGN.md section 1 conventions).
 *
 *   H = K R (I + c n^T / d) K^-1  (eq. 2), K = diag(a, a, 1), h22 = 1,
 *   R(phi) of eq. (3), c = (x, 0, z), plane n^T X = -d.
 */
#ifndef SPVS_TEST_SYNTH_H
#define SPVS_TEST_SYNTH_H

#include <math.h>
#include <stdint.h>

#include "spvs/spvs.h"

#define SYNTH_PI 3.14159265358979323846

typedef struct {
    double x, z, phi; /* metres, metres, radians */
} synth_pose_t;

typedef struct {
    double n[3]; /* unit normal */
    double d;    /* metres, > 0 */
} synth_plane_t;

/* Deterministic generator for test data (xorshift64*). */
static inline double synth_uniform(uint64_t *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

static inline double synth_gauss(uint64_t *s)
{
    double u1 = synth_uniform(s), u2 = synth_uniform(s);
    if (u1 < 1e-300) {
        u1 = 1e-300;
    }
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

static inline void synth_plane(synth_plane_t *pl, double nx, double ny, double nz, double d)
{
    double l = sqrt(nx * nx + ny * ny + nz * nz);
    pl->n[0] = nx / l;
    pl->n[1] = ny / l;
    pl->n[2] = nz / l;
    pl->d = d;
}

/* World point -> camera at pose: X_c = R (X - c). */
static inline void synth_to_cam(const synth_pose_t *p, const double X[3], double Xc[3])
{
    double c = cos(p->phi), s = sin(p->phi);
    double dx = X[0] - p->x, dy = X[1], dz = X[2] - p->z;
    Xc[0] = c * dx + s * dz;
    Xc[1] = dy;
    Xc[2] = -s * dx + c * dz;
}

/* Eq. (2) with K = diag(a, a, 1). */
static inline void synth_H(const synth_pose_t *p, const synth_plane_t *pl, double a, double H[9])
{
    double c = cos(p->phi), s = sin(p->phi);
    double R[9] = {c, 0, s, 0, 1, 0, -s, 0, c};
    double cv[3] = {p->x, 0, p->z};
    double M[9], A[9];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            M[i * 3 + j] = (i == j ? 1.0 : 0.0) + cv[i] * pl->n[j] / pl->d;
        }
    }
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            double acc = 0;
            for (int k = 0; k < 3; k++) {
                acc += R[i * 3 + k] * M[k * 3 + j];
            }
            A[i * 3 + j] = acc;
        }
    }
    double K[3] = {a, a, 1}, Ki[3] = {1 / a, 1 / a, 1};
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            H[i * 3 + j] = K[i] * A[i * 3 + j] * Ki[j];
        }
    }
    double h22 = H[4];
    for (int k = 0; k < 9; k++) {
        H[k] /= h22;
    }
}

/* A plane point seen at target pixel (u, v): the ray's cut with the plane. */
static inline int synth_plane_point(const synth_plane_t *pl, double a, double u, double v, double X[3])
{
    double r[3] = {u / a, v / a, 1.0};
    double nr = pl->n[0] * r[0] + pl->n[1] * r[1] + pl->n[2] * r[2];
    if (!(nr < -1e-9)) {
        return 0;
    }
    double t = -pl->d / nr;
    X[0] = t * r[0];
    X[1] = t * r[1];
    X[2] = t * r[2];
    return 1;
}

/* Project X into the camera at pose; returns 0 when behind it. */
static inline int synth_project(const synth_pose_t *p, double a, const double X[3], double px[2])
{
    double Xc[3];
    synth_to_cam(p, X, Xc);
    if (Xc[2] < 0.1) {
        return 0;
    }
    px[0] = a * Xc[0] / Xc[2];
    px[1] = a * Xc[1] / Xc[2];
    return 1;
}

/* Mean transfer error (pixels) of the four image corners under Ha vs Hb. */
static inline double synth_corner_err(const double Ha[9], const double Hb[9])
{
    const double cx[4] = {-320, 320, 320, -320}, cy[4] = {-240, -240, 240, 240};
    double e = 0;
    for (int k = 0; k < 4; k++) {
        double wa = Ha[6] * cx[k] + Ha[7] * cy[k] + Ha[8];
        double wb = Hb[6] * cx[k] + Hb[7] * cy[k] + Hb[8];
        double ua = (Ha[0] * cx[k] + Ha[1] * cy[k] + Ha[2]) / wa;
        double va = (Ha[3] * cx[k] + Ha[4] * cy[k] + Ha[5]) / wa;
        double ub = (Hb[0] * cx[k] + Hb[1] * cy[k] + Hb[2]) / wb;
        double vb = (Hb[3] * cx[k] + Hb[4] * cy[k] + Hb[5]) / wb;
        e += sqrt((ua - ub) * (ua - ub) + (va - vb) * (va - vb));
    }
    return e / 4;
}

/* Build a frame: n_plane plane points and n_off off-plane points (depth
 * 15..40 m, nearer than the plane) seen by the target camera, imaged from
 * pose with Gaussian noise sigma on the current image.  Features are
 * 0..n-1, plane points first.  Returns the number of matches written. */
static inline uint16_t synth_frame(const synth_pose_t *pose, const synth_plane_t *pl, double a,
                                   int n_plane, int n_off, double sigma, uint64_t *rng,
                                   spvs_match_t *m, uint8_t *on_plane)
{
    uint16_t k = 0;
    for (int i = 0; i < n_plane + n_off; i++) {
        double X[3], pc[2];
        int tries = 0;
        for (;;) {
            double u = (synth_uniform(rng) - 0.5) * 640, v = (synth_uniform(rng) - 0.5) * 480;
            int ok;
            if (i < n_plane) {
                ok = synth_plane_point(pl, a, u, v, X);
            } else {
                double zdep = 15 + 25 * synth_uniform(rng);
                X[0] = u / a * zdep;
                X[1] = v / a * zdep;
                X[2] = zdep;
                ok = (pl->n[0] * X[0] + pl->n[1] * X[1] + pl->n[2] * X[2] > -pl->d);
            }
            if (ok && synth_project(pose, a, X, pc) && fabs(pc[0]) < 4000 && fabs(pc[1]) < 4000) {
                m[k].x_tgt = (spvs_real)u;
                m[k].y_tgt = (spvs_real)v;
                m[k].x_cur = (spvs_real)(pc[0] + sigma * synth_gauss(rng));
                m[k].y_cur = (spvs_real)(pc[1] + sigma * synth_gauss(rng));
                m[k].feature = (uint16_t)i;
                if (on_plane) {
                    on_plane[k] = (uint8_t)(i < n_plane);
                }
                k++;
                break;
            }
            if (++tries > 1000) {
                break;
            }
        }
    }
    return k;
}

#endif /* SPVS_TEST_SYNTH_H */
