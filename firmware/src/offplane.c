/*
 * offplane.c - the off-plane memory and the frame's off-plane candidates
 * (offplane.h): the float tests under the decisions of offplane.inc
 * (written once for this core and the fixed-point one).
 */
#include <math.h>

#include "core_util.h"
#include "points.h"
#include "spvs/homography.h"
#include "spvs/offplane.h"

/* 1 when point q (a row, scaled units) is off the plane of H: its transfer
 * error above off2 forward, and back under Hi when H has an inverse.
 * Where H stretches the image (points seen at a grazing angle), a plane
 * point's noise is magnified in the current image and its forward error is
 * large; its error back in the target image is not.  An off-plane point's
 * parallax shows in both, so both must exceed the threshold. */
static inline int off_plane(const spvs_real H[9], const spvs_real *Hi, const spvs_real q[4],
                            spvs_real off2)
{
    if (!(spvs_h_transfer_err2(H, q) > off2)) {
        return 0;
    }
    if (Hi != 0) {
        const spvs_real back[4] = {q[2], q[3], q[0], q[1]};
        const spvs_real b2 = spvs_h_transfer_err2(Hi, back);
        if (b2 >= SPVS_R(0.0) && !(b2 > off2)) {
            return 0;
        }
    }
    return 1;
}

/* ---- the float core's side of offplane.inc -------------------------------- */

typedef spvs_offplane_t op_t;
typedef spvs_plane_h_t op_est_t;
typedef spvs_real op_h_t;
typedef spvs_real op_thr_t; /* the squared threshold, scaled units^2 */
typedef spvs_real op_px_t;
typedef spvs_real op_wide_t;
#define SPVS_CORE_NAME(float_name, fixed_name) float_name

static void reset_note(spvs_offplane_t *o)
{
    (void)o;
}

static spvs_real thr_of(spvs_real offplane_px)
{
    const spvs_real off = offplane_px * (SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
    return off * off;
}

static void collect_note(spvs_offplane_t *o, const spvs_plane_h_t *e, spvs_real offplane_px)
{
    (void)o;
    (void)e;
    (void)offplane_px;
}

static void pts_row(const spvs_plane_h_t *e, uint16_t i, spvs_real row[4])
{
    spvs_pts_row(&e->pts, i, row);
}

static const spvs_real *est_h(const spvs_plane_h_t *e)
{
    return e->H_sc;
}

static const spvs_real *inverse_of(spvs_offplane_t *o, const spvs_plane_h_t *e, spvs_real Hi[9])
{
    (void)o;
    return spvs_h_inverse(e->H_sc, Hi) == SPVS_OK ? Hi : 0;
}

static spvs_real cand_err2(const spvs_real H[9], const spvs_real row[4])
{
    return spvs_h_transfer_err2(H, row);
}

static spvs_real err_value(spvs_real e2)
{
    return e2;
}

/* The median of the squared errors, its root in pixels. */
static spvs_real median_px(spvs_real *v, uint16_t n)
{
    spvs_sort_small(v, n);
    return (spvs_real)SPVS_COORD_SCALE * SPVS_SQRT(v[n / 2]);
}

static int cand_dir(const spvs_real H[9], const spvs_real row[4], const spvs_real *lateral,
                    spvs_real *d)
{
    const spvs_real w = H[6] * row[0] + H[7] * row[1] + H[8];
    if (!(w > SPVS_W_EPS)) {
        return 0;
    }
    const spvs_real scale = (spvs_real)SPVS_COORD_SCALE;
    const spvs_real du = scale * (row[2] - (H[0] * row[0] + H[1] * row[1] + H[2]) / w);
    if (lateral == 0) {
        *d = du;
        return 1;
    }
    const spvs_real dv = scale * (row[3] - row[1] / w);
    const spvs_real r = SPVS_SQRT(row[2] * row[2] + row[3] * row[3]);
    *d = r > SPVS_R(0.0) ? ((du - *lateral) * row[2] + dv * row[3]) / r : SPVS_R(0.0);
    return 1;
}

static spvs_real median_of(spvs_real *v, uint16_t n)
{
    spvs_sort_small(v, n);
    return v[n / 2];
}

static spvs_real parallax_none(void)
{
    return SPVS_R(-1.0);
}

static uint32_t trusted_from(const spvs_offplane_t *o, const spvs_plane_h_t *e,
                             spvs_real offplane_px)
{
    (void)o;
    (void)e;
    (void)offplane_px;
    return SPVS_MAX_OFFPLANE;
}

static int above_thr(const spvs_plane_h_t *e, const spvs_real row[4], const spvs_real *off2)
{
    return spvs_h_transfer_err2(e->H_sc, row) > *off2;
}

#include "offplane.inc"
