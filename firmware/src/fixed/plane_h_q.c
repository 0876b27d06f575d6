/*
 * plane_h_q.c - the robust planar-motion homography in fixed point
 * (plane_h_q.h): the flow of plane_h.inc (written once for both cores) on
 * the Q store and the Q kernels.  The comments of plane_h.inc say why each
 * step is made; here they say only where the fixed-point version differs.
 */
#include <string.h>

#include "../core_util.h"
#include "fit_q.h"
#include "plane_h_q.h"
#include "ransac_q.h"

/* ---- the fixed-point core's side of plane_h.inc ------------------------------ */

typedef spvs_q_plane_h_t ph_t;
typedef int32_t ph_h_t;
typedef spvs_q_sums_t ph_sums_t;
typedef spvs_qf_t ph_val_t;
typedef spvs_qf_t ph_thr_arg_t; /* the squared threshold, scaled units */
typedef uint32_t ph_conf_t;
typedef const void *ph_rthr_t;
typedef uint64_t ph_cost_t;
typedef spvs_q_estimator_t ph_estimator_t;
typedef spvs_q_ransac_opts_t ph_opts_t;
#define SPVS_CORE_NAME(float_name, fixed_name) fixed_name

/* plane_h.c's coord_error on the value's IEEE parts, without a float
 * operation. */
static int coord_error(spvs_real c)
{
    const spvs_q_ieee_t v = spvs_q_real_parts(c);
    if (v.nonfinite) {
        return SPVS_E_NONFINITE;
    }
    /* |c| > SPVS_MAX_COORD_PX, an integer: its nearest integer is above it,
     * or equal to it with the magnitude rounded down. */
    uint32_t sat = 0;
    int below = 0;
    const int32_t r = spvs_q_from_ieee(v, 0, &sat, &below);
    const int64_t a = r < 0 ? -(int64_t)r : r;
    if (sat != 0u || a > SPVS_MAX_COORD_PX || (a == SPVS_MAX_COORD_PX && below)) {
        return SPVS_E_RANGE;
    }
    return SPVS_OK;
}

static int fit_linear(const spvs_q_plane_h_t *e, const uint8_t *mask, uint16_t m, int32_t *H)
{
    return spvs_q_fit_linear(&e->pts, mask, m, H);
}

/* The joint linear fit's BFP sums; usable with at least three points. */
static int lin_sums(const spvs_q_plane_h_t *e, const uint8_t *mask, const int32_t hw[9],
                    spvs_q_sums_t *sums)
{
    return spvs_q_pts_sum(SPVS_T_LIN, hw, &e->pts, mask, e->n_plane, sums) >= 3;
}

static spvs_qf_t lin_cost(const spvs_q_sums_t *sums)
{
    return spvs_q_sums_term(sums, SPVS_H_LIN_COST);
}

/* The summed squared Sampson error of e->mask's inliers under H (scaled
 * units^2); *ok = 0 when one is behind the camera. */
static spvs_qf_t sampson_cost(const spvs_q_plane_h_t *e, const int32_t H[9], int *ok)
{
    spvs_q_sums_t c;
    *ok = spvs_q_pts_sum(SPVS_T_SAMPSON, H, &e->pts, e->mask, e->n_plane, &c) >= 0;
    return spvs_q_sums_term(&c, 0);
}

/* a < b, as !(b <= a). */
static int val_lt(spvs_qf_t a, spvs_qf_t b)
{
    return !spvs_qf_le(b, a);
}

static spvs_q_sums_t *lin_sums_of(spvs_q_plane_h_t *e)
{
    return &e->lin_sums;
}

static int32_t *h_of(spvs_q_plane_h_t *e)
{
    return e->H;
}

static void set_threshold(spvs_q_plane_h_t *e, spvs_qf_t t2)
{
    e->thr = spvs_q_thr(t2);
}

static const void *ransac_thr(const spvs_q_plane_h_t *e)
{
    return &e->thr;
}

/* The tie-break cost; a saturated sum (above 2^12 scaled units^2, far
 * beyond any consensus's) compares as the largest, which it is. */
static uint64_t tie_cost(const spvs_q_plane_h_t *e, const int32_t *H, const uint8_t *mask)
{
    uint32_t sat = 0;
    return spvs_q_pts_cost(&e->pts, e->n_plane, H, mask, &sat);
}

#include "../plane_h.inc"
