/*
 * plane_h.c - the robust planar-motion homography (plane_h.h): the loading
 * of a frame, RANSAC's callbacks, the LO step, the inlier re-selection and
 * the final refit, their flow written once for this core and the
 * fixed-point one in plane_h.inc.  The loops over the points are
 * points.c's.
 */
#include <math.h>
#include <string.h>

#include "core_util.h"
#include "h_fit.h"
#include "spvs/homography.h"
#include "spvs/plane_h.h"

/* The estimator's view of its points for the fits (h_fit.h). */
static spvs_pts_in_t source(const spvs_plane_h_t *e)
{
    const spvs_pts_in_t in = {0, &e->pts};
    return in;
}

/* ---- the float core's side of plane_h.inc --------------------------------- */

typedef spvs_plane_h_t ph_t;
typedef spvs_real ph_h_t;
typedef spvs_real ph_sums_t;
typedef spvs_real ph_val_t;
typedef spvs_real ph_thr_arg_t; /* inlier_px */
typedef spvs_real ph_conf_t;
typedef spvs_real ph_rthr_t;
typedef spvs_real ph_cost_t;
typedef spvs_estimator_t ph_estimator_t;
typedef spvs_ransac_opts_t ph_opts_t;
#define SPVS_CORE_NAME(float_name, fixed_name) float_name

/* A coordinate's status: SPVS_E_NONFINITE (NaN or infinite),
 * SPVS_E_RANGE (beyond SPVS_MAX_COORD_PX) or SPVS_OK. */
static int coord_error(spvs_real c)
{
    if (!spvs_is_finite(c)) {
        return SPVS_E_NONFINITE;
    }
    return SPVS_FABS(c) > (spvs_real)SPVS_MAX_COORD_PX ? SPVS_E_RANGE : SPVS_OK;
}

static int fit_linear(const spvs_plane_h_t *e, const uint8_t *mask, uint16_t m, spvs_real *H)
{
    const spvs_pts_in_t in = source(e);
    return spvs_hf_fit_linear(&in, mask, m, H);
}

static int lin_sums(const spvs_plane_h_t *e, const uint8_t *mask, const spvs_real hw[9],
                    spvs_real *sums)
{
    const spvs_pts_in_t in = source(e);
    return spvs_hf_lin_sums(&in, mask, e->n_plane, hw, sums) == SPVS_OK;
}

static spvs_real lin_cost(const spvs_real *sums)
{
    return sums[SPVS_H_LIN_COST];
}

/* The summed squared Sampson error of the inliers in e->mask under H;
 * SPVS_REAL_MAX when one is behind the camera (always comparable). */
static spvs_real sampson_cost(const spvs_plane_h_t *e, const spvs_real H[9], int *ok)
{
    const spvs_pts_in_t in = source(e);
    spvs_real c;
    *ok = 1;
    return spvs_pts_sum(SPVS_T_SAMPSON, H, &in, e->mask, e->n_plane, &c) < 0 ? SPVS_REAL_MAX : c;
}

static int val_lt(spvs_real a, spvs_real b)
{
    return a < b;
}

static spvs_real *lin_sums_of(spvs_plane_h_t *e)
{
    return e->lin_sums;
}

static spvs_real *h_of(spvs_plane_h_t *e)
{
    return e->H_sc;
}

/* inlier_px pixels as the squared threshold in scaled units. */
static void set_threshold(spvs_plane_h_t *e, spvs_real inlier_px)
{
    const spvs_real t = inlier_px * (SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
    e->t2 = t * t;
}

static spvs_real ransac_thr(const spvs_plane_h_t *e)
{
    return e->t2;
}

static spvs_real tie_cost(const spvs_plane_h_t *e, const spvs_real *H, const uint8_t *mask)
{
    return spvs_pts_cost(&e->pts, e->n_plane, H, mask);
}

#include "plane_h.inc"

/* ---- the estimate from a given H (spvs_plane_h_adopt) ---------------------- */

int spvs_plane_h_adopt(spvs_plane_h_t *e, const spvs_real H_sc[9], spvs_real inlier_px)
{
    SPVS_ASSERT(e != 0 && H_sc != 0);
    if (!spvs_finite3x2(H_sc, H_sc + 6)) {
        return SPVS_E_DEGENERATE;
    }
    for (int k = 0; k < 9; k++) {
        e->H_sc[k] = H_sc[k];
    }
    e->H_sc[3] = SPVS_R(0.0);
    e->H_sc[4] = SPVS_R(1.0);
    e->H_sc[5] = SPVS_R(0.0);
    set_threshold(e, inlier_px);
    e->n_inliers = spvs_pts_score(&e->pts, e->n_plane, e->H_sc, e->t2, 0, e->mask);
    return e->n_inliers < SPVS_MIN_INLIERS ? SPVS_E_NO_CONSENSUS : SPVS_OK;
}
