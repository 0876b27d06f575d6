/*
 * offplane_q.c - the off-plane memory and the frame's off-plane candidates
 * in fixed point (offplane_q.h): the Q tests under the decisions of
 * offplane.inc (written once for both cores), whose comments say why each
 * step is made; here they say where the fixed-point version differs.
 */
#include "offplane_q.h"
#include "offplane_test_q.h"

/* num 2^e / det (id = 1 / det) in Q27, rounded, saturated (flagged). */
static int32_t hi_entry(int64_t num, int32_t e, spvs_qf_t id, uint32_t *sat)
{
    return spvs_qf_to_q32(spvs_qf_mul(spvs_qf_from_i64(num, e), id), SPVS_QH, sat);
}

/* spvs_h_inverse in Q27: det = h11 h33 - h13 h31 exact in Q54 (each
 * product below 2^62), refused as in float at |det| <= 1e-9 (18,014,398.5
 * in Q54); the entries, adj(H) / det, from one spvs_qf_t reciprocal
 * (relative 2^-28) and rounded to Q27.  Returns 1 when Hi is usable, 0
 * when H has no inverse or an entry of Hi is outside (-16, 16) (then
 * *out_of_range = 1). */
static int inverse_q(const int32_t H[9], int32_t Hi[9], int *out_of_range)
{
    const int64_t a = H[0], b = H[1], c = H[2], g = H[6], h = H[7], i = H[8];
    const int64_t det = a * i - c * g;
    *out_of_range = 0;
    if (spvs_q_abs64(det) <= 18014398u) {
        return 0;
    }
    uint32_t sat = 0;
    const spvs_qf_t id = spvs_qf_recip(spvs_qf_from_i64(det, -54), &sat);
    /* Entries of H are Q27 (exponent -27), the 2 x 2 minors Q54 (each
     * product below 2^62, each difference below 2^63). */
    Hi[0] = hi_entry(i, -27, id, &sat);
    Hi[1] = hi_entry(c * h - b * i, -54, id, &sat);
    Hi[2] = hi_entry(-c, -27, id, &sat);
    Hi[6] = hi_entry(-g, -27, id, &sat);
    Hi[7] = hi_entry(b * g - a * h, -54, id, &sat);
    Hi[8] = hi_entry(a, -27, id, &sat);
    Hi[3] = 0;
    Hi[4] = (int32_t)1 << SPVS_QH;
    Hi[5] = 0;
    if (sat != 0u) {
        *out_of_range = 1;
        return 0;
    }
    return 1;
}

/* offplane.c's off_plane on a Q26 row: the forward error above the
 * threshold, and the back one too where Hi is given (a back transfer
 * behind the camera does not count against it). */
static int off_plane(const int32_t H[9], const int32_t *Hi, const int32_t q[4],
                     spvs_q_off_thr_t t)
{
    if (spvs_q_off_above(H, q, &t) != 1) {
        return 0;
    }
    if (Hi != 0) {
        const int32_t back[4] = {q[2], q[3], q[0], q[1]};
        if (spvs_q_off_above(Hi, back, &t) == 0) {
            return 0;
        }
    }
    return 1;
}

/* ---- the fixed-point core's side of offplane.inc ---------------------------- */

typedef spvs_q_offplane_t op_t;
typedef spvs_q_plane_h_t op_est_t;
typedef int32_t op_h_t;
typedef spvs_q_off_thr_t op_thr_t;
typedef int32_t op_px_t; /* Q16 px */
typedef int64_t op_wide_t;
#define SPVS_CORE_NAME(float_name, fixed_name) fixed_name

/* The counter and the collect's H and threshold (none yet). */
static void reset_note(spvs_q_offplane_t *o)
{
    o->hi_out_of_range = 0;
    for (uint32_t i = 0; i < 9u; i++) {
        o->cand_H[i] = 0;
    }
    o->cand_thr = -1;
}

static spvs_q_off_thr_t thr_of(int32_t offplane_q16)
{
    return spvs_q_off_thr(offplane_q16);
}

/* The collect's H and threshold, whose forward tests remember reuses. */
static void collect_note(spvs_q_offplane_t *o, const spvs_q_plane_h_t *e, int32_t offplane_q16)
{
    for (uint32_t i = 0; i < 9u; i++) {
        o->cand_H[i] = e->H[i];
    }
    o->cand_thr = offplane_q16;
}

static void pts_row(const spvs_q_plane_h_t *e, uint16_t i, int32_t row[4])
{
    spvs_q_pts_row(&e->pts, i, row);
}

static const int32_t *est_h(const spvs_q_plane_h_t *e)
{
    return e->H;
}

/* H's inverse in Q27, or 0; an inverse outside Q27's range is counted. */
static const int32_t *inverse_of(spvs_q_offplane_t *o, const spvs_q_plane_h_t *e, int32_t Hi[9])
{
    int oor = 0;
    const int32_t *hi = inverse_q(e->H, Hi, &oor) ? Hi : 0;
    if (oor && o->hi_out_of_range < UINT16_MAX) {
        o->hi_out_of_range++;
    }
    return hi;
}

static int64_t cand_err2(const int32_t H[9], const int32_t row[4])
{
    return spvs_q_transfer_err2(H, row);
}

/* The error's root in Q16 px: the square root is monotone (to its
 * 2^-27), so the median of the errors is the root of float's median of
 * their squares. */
static int32_t err_value(int64_t e2)
{
    return spvs_q_sqrt_q52_px16((uint64_t)e2);
}

static int32_t median_px(int32_t *v, uint16_t n)
{
    return spvs_q_select_i32(v, 1u, n, n / 2u);
}

/* The transfer error, current minus transferred, in Q16 pixels (Q26
 * scaled units times SPVS_COORD_SCALE, 2^9, are Q17 pixels): horizontal,
 * and along the current point's radius (the dot product in Q52 over the
 * radius in Q26; every term under 2^60 for points within 2^15 px). */
static int cand_dir(const int32_t H[9], const int32_t row[4], const int32_t *lateral,
                    int32_t *d)
{
    int32_t du, dv;
    if (!spvs_q_transfer(H, row, &du, &dv)) {
        return 0;
    }
    if (lateral == 0) {
        *d = (int32_t)spvs_q_rsh(-(int64_t)du, 1);
        return 1;
    }
    /* The error less the horizontal part, in Q26 scaled units (Q16 px
     * times 2). */
    const int64_t ex = -(int64_t)du - 2 * (int64_t)*lateral, ey = -(int64_t)dv;
    const int64_t x = row[2], y = row[3];
    const int64_t r = (int64_t)spvs_q_isqrt64((uint64_t)(x * x + y * y));
    uint32_t sat = 0;
    *d = r > 0 ? spvs_q_sat32(spvs_q_rsh((ex * x + ey * y) / r, 1), &sat) : 0;
    return 1;
}

static int32_t median_of(int32_t *v, uint16_t n)
{
    return spvs_q_select_i32(v, 1u, n, n / 2u);
}

static int32_t parallax_none(void)
{
    return -SPVS_Q16_ONE;
}

/* Where e->H and the threshold are the collect's, the candidates it tested
 * (from n_cand_known on) passed the forward test: the same computation. */
static uint32_t trusted_from(const spvs_q_offplane_t *o, const spvs_q_plane_h_t *e,
                             int32_t offplane_q16)
{
    uint32_t same = o->cand_thr == offplane_q16;
    for (uint32_t i = 0; i < 9u; i++) {
        same &= (uint32_t)(o->cand_H[i] == e->H[i]);
    }
    return same ? o->n_cand_known : SPVS_MAX_OFFPLANE;
}

static int above_thr(const spvs_q_plane_h_t *e, const int32_t row[4],
                     const spvs_q_off_thr_t *thr)
{
    return spvs_q_off_above(e->H, row, thr) == 1;
}

#include "../offplane.inc"
