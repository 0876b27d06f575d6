/*
 * offplane.c - the off-plane memory and the frame's off-plane candidates
 * (offplane.h).
 */
#include <math.h>

#include "core_util.h"
#include "points.h"
#include "spvs/homography.h"
#include "spvs/offplane.h"

void spvs_offplane_reset(spvs_offplane_t *o)
{
    SPVS_ASSERT(o != 0);
    for (uint32_t i = 0; i < SPVS_MAX_FEATURES; i++) {
        o->score[i] = 0;
    }
    o->n_known = 0;
    o->n_cand = 0;
    o->n_cand_known = 0;
}

int spvs_offplane_known(const spvs_offplane_t *o, uint16_t f)
{
    return f < SPVS_MAX_FEATURES && o->score[f] >= SPVS_OFFPLANE_ON;
}

uint16_t spvs_offplane_split(const spvs_offplane_t *o, const spvs_match_t *m, uint16_t n,
                             uint16_t order[SPVS_MAX_MATCHES])
{
    uint16_t back = n;
    uint16_t n_plane = 0;
    for (uint16_t i = 0; i < n; i++) {
        /* An index out of range reads feature 0's entry; the loader refuses
         * such a frame. */
        const uint16_t f = m[i].feature < SPVS_MAX_FEATURES ? m[i].feature : 0u;
        if (o->score[f] >= SPVS_OFFPLANE_ON) {
            order[--back] = i;
        } else {
            order[n_plane++] = i;
        }
    }
    return n_plane;
}

/* 1 when point q (a row, scaled units) is off the plane of H: its transfer
 * error above off2 forward, and back under Hi when H has an inverse.
 * Where H stretches the image (points seen at a grazing angle), a plane
 * point's noise is magnified in the current image and its forward error is
 * large; its error back in the target image is not.  An off-plane point's
 * parallax shows in both, so both must exceed the threshold. */
static SPVS_ALWAYS_INLINE int off_plane(const spvs_real H[9], const spvs_real *Hi,
                                        const spvs_real q[4], spvs_real off2)
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

/* Takes point i of the estimate as candidate o->n_cand: its index, its
 * row and its place in the epipole's order. */
static SPVS_ALWAYS_INLINE void take(spvs_offplane_t *o, uint16_t i)
{
    o->cand[o->n_cand] = i;
    o->cand_ord[o->n_cand] = o->n_cand;
    o->n_cand++;
}

void spvs_offplane_collect(spvs_offplane_t *o, const spvs_plane_h_t *e, spvs_real offplane_px)
{
    const spvs_real off = offplane_px * (SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
    const spvs_real off2 = off * off;
    /* Each point is copied as a row straight into the next candidate's
     * slot, which the next point overwrites when it is not taken. */
    o->n_cand = 0;
    for (uint16_t i = e->n_plane; i < e->n_pts && o->n_cand < SPVS_MAX_OFFPLANE; i++) {
        spvs_pts_row(&e->pts, i, o->cand_pts[o->n_cand]);
        take(o, i);
    }
    o->n_cand_known = o->n_cand;
    spvs_real Hi[9];
    const spvs_real *hi = spvs_h_inverse(e->H_sc, Hi) == SPVS_OK ? Hi : 0;
    for (uint16_t i = 0; i < e->n_plane && o->n_cand < SPVS_MAX_OFFPLANE; i++) {
        if (e->mask[i]) {
            continue;
        }
        spvs_real *const q = o->cand_pts[o->n_cand];
        spvs_pts_row(&e->pts, i, q);
        if (off_plane(e->H_sc, hi, q, off2)) {
            take(o, i);
        }
    }
}

spvs_real spvs_offplane_known_parallax_px(const spvs_offplane_t *o, const spvs_real H_sc[9],
                                          spvs_real *scratch)
{
    uint16_t nv = 0;
    for (uint16_t k = 0; k < o->n_cand_known; k++) {
        const spvs_real e2 = spvs_h_transfer_err2(H_sc, o->cand_pts[k]);
        if (e2 < SPVS_R(0.0)) {
            continue;
        }
        scratch[nv++] = e2;
    }
    if (nv == 0) {
        return SPVS_R(-1.0);
    }
    spvs_sort_small(scratch, nv);
    return (spvs_real)SPVS_COORD_SCALE * SPVS_SQRT(scratch[nv / 2]);
}

void spvs_offplane_remember(spvs_offplane_t *o, const spvs_plane_h_t *e, int e_ok,
                            spvs_real parallax_px, spvs_real offplane_px)
{
    const spvs_real off = offplane_px * (SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
    const spvs_real off2 = off * off;
    if (e_ok) {
        for (uint16_t k = 0; k < o->n_cand; k++) {
            int8_t *score = &o->score[e->feat[o->cand[k]]];
            if (o->support[k] && *score < SPVS_OFFPLANE_MAX &&
                spvs_h_transfer_err2(e->H_sc, o->cand_pts[k]) > off2) {
                (*score)++;
                o->n_known = (uint16_t)(o->n_known + (*score == SPVS_OFFPLANE_ON));
            }
        }
    }
    /* A plane inlier while the scene shows clear parallax is a plane point. */
    if (parallax_px > (spvs_real)SPVS_PARALLAX_CLEAR * offplane_px) {
        for (uint16_t i = 0; i < e->n_plane; i++) {
            int8_t *score = &o->score[e->feat[i]];
            if (e->mask[i] && *score > SPVS_OFFPLANE_MIN) {
                o->n_known = (uint16_t)(o->n_known - (*score == SPVS_OFFPLANE_ON));
                (*score)--;
            }
        }
    }
}
