/*
 * epipole.c - the epipole from plane plus parallax (paper, section 3.3):
 * the float directions and tests under the decisions of epipole.inc
 * (written once for this core and the fixed-point one).
 */
#include <math.h>

#include "spvs/epipole.h"
#include "spvs/homography.h"
#include "core_util.h"

/* A candidate whose line direction is shorter than this (scaled units) lies
 * too close to the horizon row or has too little parallax to say anything. */
#define DIR_MIN2 SPVS_R(1.0e-12)

/* Per candidate: the line l = p_cur x (H p_tgt) holds the epipole
 * e = (e_x, 0, e_z), so l1 e_x + l3 e_z = 0; with gamma > 0 the signed
 * direction of (e_x, e_z) is sign(y_cur) (l3, -l1) (see epipole.h).  The
 * directions go to work->dx, dz and their squared norms to work->n2. */
static inline void line_directions(const spvs_real H[9], const spvs_real (*pts)[4],
                                   const uint16_t *cand, uint16_t n_cand, uint8_t *support_out,
                                   spvs_epipole_work_t *work)
{
    for (uint16_t i = 0; i < n_cand; i++) {
        const spvs_real *p = pts[cand[i]];
        spvs_real q1 = H[0] * p[0] + H[1] * p[1] + H[2];
        spvs_real q2 = p[1];
        spvs_real q3 = H[6] * p[0] + H[7] * p[1] + H[8];
        spvs_real l1 = p[3] * q3 - q2;
        spvs_real l3 = p[2] * q2 - p[3] * q1;
        spvs_real sg = p[3] < SPVS_R(0.0) ? SPVS_R(-1.0) : SPVS_R(1.0);
        const spvs_real dx = sg * l3;
        const spvs_real dz = -sg * l1;
        work->dx[i] = dx;
        work->dz[i] = dz;
        work->n2[i] = dx * dx + dz * dz;
        if (support_out) {
            support_out[i] = 0;
        }
    }
}

/* The estimate from the supporters of hypothesis `best`: each supporter's
 * angle from the hypothesis b, as tan(delta_i) = cross(b, d_i) /
 * dot(b, d_i); the median angle turns b onto the estimate.  A mismatch that
 * fell inside the consensus cone moves a median by one rank at most.
 * Storage: the tangents go to n2[] and the squared parallaxes to dz[],
 * entry k <= i written only after entry i was read; the hypothesis is kept
 * in locals. */
static inline void refine(const spvs_real H[9], const spvs_real (*pts)[4], const uint16_t *cand,
                          uint16_t n_cand, const spvs_real *tol2, uint16_t best,
                          spvs_epipole_t *out, uint8_t *support_out, spvs_epipole_work_t *work)
{
    const spvs_real *dx = work->dx;
    spvs_real *dz = work->dz;
    spvs_real *n2 = work->n2;
    const spvs_real hx = dx[best];
    const spvs_real hz = dz[best];
    const spvs_real n2_best = n2[best];
    const spvs_real bn = SPVS_SQRT(n2_best);
    const spvs_real bx = hx / bn;
    const spvs_real bz = hz / bn;
    spvs_real *tans = n2;
    spvs_real *par = dz;
    uint16_t n_t = 0;
    uint16_t n_par = 0;
    for (uint16_t i = 0; i < n_cand; i++) {
        const spvs_real n2_i = n2[i];
        const spvs_real dxi = dx[i];
        const spvs_real dzi = dz[i];
        if (!(n2_i > DIR_MIN2)) {
            continue;
        }
        spvs_real dot = dxi * hx + dzi * hz;
        spvs_real crs = dxi * hz - dzi * hx;
        if (!(dot > SPVS_R(0.0) && crs * crs <= *tol2 * n2_i * n2_best)) {
            continue;
        }
        if (support_out) {
            support_out[i] = 1;
        }
        /* dot(b, d_i) > 0 here, so the division is safe. */
        tans[n_t++] = (bx * dzi - bz * dxi) / (bx * dxi + bz * dzi);
        spvs_real e2 = spvs_h_transfer_err2(H, pts[cand[i]]);
        if (e2 >= SPVS_R(0.0)) {
            par[n_par++] = e2;
        }
    }
    spvs_sort_small(tans, n_t);
    spvs_real tmed = (n_t & 1u) ? tans[n_t / 2]
                                : SPVS_R(0.5) * (tans[n_t / 2 - 1] + tans[n_t / 2]);
    /* The direction at angle atan(tmed) from b: b + tmed b_perp, with b_perp
     * b turned by +90 degrees. */
    spvs_real ex = bx - tmed * bz;
    spvs_real ez = bz + tmed * bx;
    spvs_real inv = SPVS_R(1.0) / SPVS_SQRT(ex * ex + ez * ez);
    out->dir_x = ex * inv;
    out->dir_z = ez * inv;

    const spvs_real scale = (spvs_real)SPVS_COORD_SCALE;
    const spvs_real lim = SPVS_EPIPOLE_MAX_PX / scale;
    if (SPVS_FABS(ex) >= lim * SPVS_FABS(ez)) {
        spvs_real sgn = ((ex < SPVS_R(0.0)) != (ez < SPVS_R(0.0))) ? SPVS_R(-1.0) : SPVS_R(1.0);
        out->e_x_px = sgn * SPVS_EPIPOLE_MAX_PX;
    } else {
        out->e_x_px = scale * ex / ez;
    }

    spvs_sort_small(par, n_par);
    if (n_par > 0) {
        out->parallax_px = scale * SPVS_SQRT(par[n_par / 2]);
    }
}

/* ---- the float core's side of epipole.inc --------------------------------- */

typedef spvs_epipole_t ep_t;
typedef spvs_epipole_work_t ep_work_t;
typedef spvs_real ep_h_t;
typedef spvs_real ep_tol_in_t;
typedef spvs_real ep_tol_t;

static void clear_estimate(spvs_epipole_t *out)
{
    out->e_x_px = SPVS_R(0.0);
    out->dir_x = SPVS_R(0.0);
    out->dir_z = SPVS_R(0.0);
    out->parallax_px = SPVS_R(0.0);
    out->n_support = 0;
}

static int tol_of(spvs_real sin_tol2, spvs_real *tol2)
{
    *tol2 = sin_tol2;
    return 1;
}

static int hyp_usable(const spvs_epipole_work_t *work, uint16_t j)
{
    return work->n2[j] > DIR_MIN2;
}

/* The usable candidates within the angle whose squared sine is tol2 of
 * candidate j's direction, pointing the same way (no square roots, no
 * divisions); every one is counted. */
static inline uint16_t support_count(const spvs_epipole_work_t *work, uint16_t n_cand, uint16_t j,
                                     const spvs_real *tol2, uint32_t need)
{
    (void)need;
    const spvs_real *dx = work->dx, *dz = work->dz, *n2 = work->n2;
    uint16_t support = 0;
    for (uint16_t i = 0; i < n_cand; i++) {
        if (!(n2[i] > DIR_MIN2)) {
            continue;
        }
        spvs_real dot = dx[i] * dx[j] + dz[i] * dz[j];
        spvs_real crs = dx[i] * dz[j] - dz[i] * dx[j];
        if (dot > SPVS_R(0.0) && crs * crs <= *tol2 * n2[i] * n2[j]) {
            support++;
        }
    }
    return support;
}

#include "epipole.inc"

int spvs_epipole_estimate(const spvs_real H[9], const spvs_real (*pts)[4],
                          const uint16_t *cand, uint16_t n_cand,
                          spvs_real sin_tol2, uint16_t min_support,
                          spvs_epipole_t *out, uint8_t *support_out,
                          spvs_epipole_work_t *work)
{
    return estimate_epipole(H, pts, cand, n_cand, sin_tol2, min_support, out, support_out, work);
}
