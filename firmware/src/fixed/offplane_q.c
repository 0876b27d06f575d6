/*
 * offplane_q.c - the off-plane memory and the frame's off-plane candidates
 * in fixed point (offplane_q.h).  offplane.c's comments say why each step
 * is made; here they say where the fixed-point version differs.
 */
#include "offplane_q.h"

void spvs_q_offplane_reset(spvs_q_offplane_t *o)
{
    SPVS_ASSERT(o != 0);
    for (uint32_t i = 0; i < SPVS_MAX_FEATURES; i++) {
        o->score[i] = 0;
    }
    o->n_known = 0;
    o->n_cand = 0;
    o->n_cand_known = 0;
    o->hi_out_of_range = 0;
}

int spvs_q_offplane_known(const spvs_q_offplane_t *o, uint16_t f)
{
    return f < SPVS_MAX_FEATURES && o->score[f] >= SPVS_OFFPLANE_ON;
}

uint16_t spvs_q_offplane_split(const spvs_q_offplane_t *o, const spvs_match_t *m, uint16_t n,
                               uint16_t order[SPVS_MAX_MATCHES])
{
    uint16_t back = n;
    uint16_t n_plane = 0;
    for (uint16_t i = 0; i < n; i++) {
        const uint16_t f = m[i].feature < SPVS_MAX_FEATURES ? m[i].feature : 0u;
        if (o->score[f] >= SPVS_OFFPLANE_ON) {
            order[--back] = i;
        } else {
            order[n_plane++] = i;
        }
    }
    return n_plane;
}

/* offplane_q16^2 in Q52 scaled units^2: (2 offplane_q16)^2 (Q16 pixels
 * are Q25 scaled units), below 2^64 for any int32; negative is 0. */
static uint64_t off2_q52(int32_t offplane_q16)
{
    const uint64_t o = offplane_q16 > 0 ? 2u * (uint64_t)offplane_q16 : 0u;
    return o * o;
}

/* 1 when e2 (spvs_q_transfer_err2: -1 for w <= SPVS_W_EPS) exceeds off2;
 * float's e2 > off2 with e2 = -1 is false too. */
static SPVS_Q_INLINE int above(int64_t e2, uint64_t off2)
{
    return e2 >= 0 && (uint64_t)e2 > off2;
}

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

/* offplane.c's off_plane on a Q26 row: the forward error above off2, and
 * the back one too where Hi is given. */
static SPVS_Q_INLINE int off_plane(const int32_t H[9], const int32_t *Hi, const int32_t q[4],
                                   uint64_t off2)
{
    if (!above(spvs_q_transfer_err2(H, q), off2)) {
        return 0;
    }
    if (Hi != 0) {
        const int32_t back[4] = {q[2], q[3], q[0], q[1]};
        const int64_t b2 = spvs_q_transfer_err2(Hi, back);
        if (b2 >= 0 && !above(b2, off2)) {
            return 0;
        }
    }
    return 1;
}

static SPVS_Q_INLINE void take(spvs_q_offplane_t *o, uint16_t i)
{
    o->cand[o->n_cand] = i;
    o->cand_ord[o->n_cand] = o->n_cand;
    o->n_cand++;
}

void spvs_q_offplane_collect(spvs_q_offplane_t *o, const spvs_q_plane_h_t *e,
                             int32_t offplane_q16)
{
    const uint64_t off2 = off2_q52(offplane_q16);
    o->n_cand = 0;
    for (uint16_t i = e->n_plane; i < e->n_pts && o->n_cand < SPVS_MAX_OFFPLANE; i++) {
        spvs_q_pts_row(&e->pts, i, o->cand_pts[o->n_cand]);
        take(o, i);
    }
    o->n_cand_known = o->n_cand;
    int32_t Hi[9];
    int oor = 0;
    const int32_t *hi = inverse_q(e->H, Hi, &oor) ? Hi : 0;
    if (oor && o->hi_out_of_range < UINT16_MAX) {
        o->hi_out_of_range++;
    }
    for (uint16_t i = 0; i < e->n_plane && o->n_cand < SPVS_MAX_OFFPLANE; i++) {
        if (e->mask[i]) {
            continue;
        }
        int32_t *const q = o->cand_pts[o->n_cand];
        spvs_q_pts_row(&e->pts, i, q);
        if (off_plane(e->H, hi, q, off2)) {
            take(o, i);
        }
    }
}

int32_t spvs_q_offplane_known_parallax_q16(const spvs_q_offplane_t *o, const int32_t H[9],
                                           int32_t *scratch)
{
    uint16_t nv = 0;
    for (uint16_t k = 0; k < o->n_cand_known; k++) {
        const int64_t e2 = spvs_q_transfer_err2(H, o->cand_pts[k]);
        if (e2 < 0) {
            continue;
        }
        scratch[nv++] = spvs_q_sqrt_q52_px16((uint64_t)e2);
    }
    if (nv == 0) {
        return -SPVS_Q16_ONE;
    }
    /* The square root is monotone (to its 2^-27), so the median of the
     * errors is the root of float's median of their squares. */
    spvs_q_sort_i32(scratch, nv);
    return scratch[nv / 2];
}

void spvs_q_offplane_remember(spvs_q_offplane_t *o, const spvs_q_plane_h_t *e, int e_ok,
                              int32_t parallax_q16, int32_t offplane_q16)
{
    const uint64_t off2 = off2_q52(offplane_q16);
    if (e_ok) {
        for (uint16_t k = 0; k < o->n_cand; k++) {
            int8_t *score = &o->score[e->feat[o->cand[k]]];
            if (o->support[k] && *score < SPVS_OFFPLANE_MAX &&
                above(spvs_q_transfer_err2(e->H, o->cand_pts[k]), off2)) {
                (*score)++;
                o->n_known = (uint16_t)(o->n_known + (*score == SPVS_OFFPLANE_ON));
            }
        }
    }
    if ((int64_t)parallax_q16 > (int64_t)SPVS_PARALLAX_CLEAR * offplane_q16) {
        for (uint16_t i = 0; i < e->n_plane; i++) {
            int8_t *score = &o->score[e->feat[i]];
            if (e->mask[i] && *score > SPVS_OFFPLANE_MIN) {
                o->n_known = (uint16_t)(o->n_known - (*score == SPVS_OFFPLANE_ON));
                (*score)--;
            }
        }
    }
}
