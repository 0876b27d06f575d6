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
    for (uint32_t i = 0; i < 9u; i++) {
        o->cand_H[i] = 0;
    }
    o->cand_thr = -1;
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

/* The fast test below decides where o is in [2^13, 2^27) (0.06 px to
 * 1,024 px): there Q (below) is below 2^31 for every w28 of the fast
 * path (at most 2^30), so the test is in 32-bit words and products. */
#define OFF_FAST_MIN ((uint32_t)1 << 13)
#define OFF_FAST_MAX ((uint32_t)1 << 27)

/* The threshold: o = 2 offplane_q16, offplane_px in Q26 scaled units
 * (Q16 pixels are Q25 scaled units), below 2^32; off2 = o^2 in Q52
 * scaled units^2, below 2^64; negative is 0.  o_fast is o where the fast
 * test decides, else 0: that range decided once per frame. */
typedef struct {
    uint64_t off2;
    uint32_t o_fast;
} off_thr_t;

static off_thr_t off_thr(int32_t offplane_q16)
{
    off_thr_t t;
    const uint32_t o = offplane_q16 > 0 ? 2u * (uint32_t)offplane_q16 : 0u;
    t.off2 = (uint64_t)o * o;
    t.o_fast = o >= OFF_FAST_MIN && o < OFF_FAST_MAX ? o : 0u;
    return t;
}

/* Whether the squared transfer error of row p under H exceeds off2:
 * -1 for w <= SPVS_W_EPS (float's e2 = -1, above no threshold), else 1
 * when spvs_q_transfer's du^2 + dv^2 > off2, 0 when not; the same answer
 * as computing that transfer, which takes a reciprocal and two scaled
 * ratios, where most points are far from the threshold.
 * On the fast path the ratio's exact value d = n28 / w28 (Q26: d 2^26)
 * gives e = |d|^2 2^52 = A 2^52 / w28^2 with A = nx28^2 + ny28^2 (below
 * 2^61), and e > off2 is A > t^2 with t = o w28 2^-26, where
 * Q = floor(o w28 2^-26) <= t < Q + 1 (o w28 < 2^57).  spvs_q_transfer's
 * du is within 2^-27 |d| + 1 unit of d 2^26 for w28 >= 2^25 (k <= 5 in
 * spvs_q_ratio_fast: the reciprocal's 2^-28 and its clamp's 2^-31, 1/2
 * unit of Q(31 - k), 1/2 of Q26), so its e2 is within 2^-26 e +
 * 2.9 sqrt(e) + 2 of e.  With o >= 2^13, A above (Q + 1 + (Q + 1) / 2^8)^2
 * makes e > off2 (1 + 2^-7) and e2 > off2; A below (Q - Q / 2^8 - 1)^2
 * makes e < off2 (1 - 2^-8) and e2 < off2.  Between, and off the fast
 * path, the transfer decides. */
static SPVS_Q_NOINLINE int64_t err2_call(const int32_t H[9], const int32_t p[4])
{
    return spvs_q_transfer_err2(H, p);
}

static SPVS_Q_INLINE int transfer_above(const int32_t H[9], int32_t tx, int32_t ty, int32_t cx,
                                        int32_t cy, off_thr_t t)
{
    spvs_q_tf_t f;
    const int path = spvs_q_transfer_front_v(H, tx, ty, cx, cy, &f);
    if (path == SPVS_Q_TF_BEHIND) {
        return -1;
    }
    if (path == SPVS_Q_TF_FAST) {
        if (t.o_fast != 0u && f.w28 >= ((int32_t)1 << 25)) {
            const uint64_t A = (uint64_t)((int64_t)f.nx28 * f.nx28) +
                               (uint64_t)((int64_t)f.ny28 * f.ny28);
            /* o < 2^27 and w28 <= 2^30: Q < 2^31.  w28 opaque, so that the
             * product is one UMULL (GCC otherwise extends w28's sign). */
            const uint32_t uw = (uint32_t)spvs_q_opaque32(f.w28);
            const uint32_t Q = (uint32_t)(((uint64_t)t.o_fast * uw) >> 26);
            const uint32_t hi = Q + 1u + ((Q + 1u) >> 8); /* below 2^31.01 */
            if (A > (uint64_t)hi * hi) {
                return 1;
            }
            const uint32_t lo = Q - (Q >> 8);
            if (lo >= 1u && A < (uint64_t)(lo - 1u) * (lo - 1u)) {
                return 0;
            }
        }
    }
    /* Near the threshold or off the fast path (rare): the transfer itself,
     * out of line (it repeats the first half), so that flash holds one
     * copy of it; w > SPVS_W_EPS, so its e2 is not negative. */
    const int32_t row[4] = {tx, ty, cx, cy};
    return (uint64_t)err2_call(H, row) > t.off2;
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
 * the back one too where Hi is given (a back transfer behind the camera
 * does not count against it).  One loop over the two tests, so that the
 * transfer is inlined once. */
static SPVS_Q_INLINE int off_plane(const int32_t H[9], const int32_t *Hi, const int32_t q[4],
                                   off_thr_t t)
{
    /* The row's values, which the back test takes the other way round
     * (current to target), swapped in place of a copy of the row. */
    int32_t tx = q[0], ty = q[1], cx = q[2], cy = q[3];
    const int32_t *M = H;
    /* Bound: two tests, forward and back. */
    for (int dir = 0; dir < 2; dir++) {
        const int a = transfer_above(M, tx, ty, cx, cy, t);
        if (dir == 0 ? a != 1 : a == 0) {
            return 0;
        }
        if (Hi == 0) {
            break;
        }
        M = Hi;
        const int32_t x = tx, y = ty;
        tx = cx;
        ty = cy;
        cx = x;
        cy = y;
    }
    return 1;
}

/* transfer_above as a call, for the few supporters spvs_q_offplane_remember
 * tests (one copy of the transfer in flash rather than another inline). */
static SPVS_Q_NOINLINE int transfer_above_call(const int32_t H[9], const int32_t p[4],
                                               const off_thr_t *t)
{
    return transfer_above(H, p[0], p[1], p[2], p[3], *t);
}

/* The first i' >= i below n with mask[i'] == 0, or n: the scan over the
 * inliers, most of the plane's points, in a loop of its own, inline (a
 * call a rejected point cost more than the loop's registers; bound: n -
 * i steps). */
static SPVS_Q_INLINE uint16_t next_rejected(const uint8_t *mask, uint32_t i, uint32_t n)
{
    while (i < n && mask[i] != 0u) {
        i++;
    }
    return (uint16_t)i;
}

/* Candidate n is match i (the order of the candidates is their index);
 * returns n + 1.  The count is the caller's local: a store into the
 * uint16 lists may alias o->n_cand, which would then be read again. */
static SPVS_Q_INLINE uint32_t take(spvs_q_offplane_t *o, uint32_t n, uint16_t i)
{
    o->cand[n] = i;
    o->cand_ord[n] = (uint16_t)n;
    return n + 1u;
}

void spvs_q_offplane_collect(spvs_q_offplane_t *o, const spvs_q_plane_h_t *e,
                             int32_t offplane_q16)
{
    const off_thr_t thr = off_thr(offplane_q16);
    for (uint32_t i = 0; i < 9u; i++) {
        o->cand_H[i] = e->H[i];
    }
    o->cand_thr = offplane_q16;
    uint32_t n_cand = 0;
    for (uint16_t i = e->n_plane; i < e->n_pts && n_cand < SPVS_MAX_OFFPLANE; i++) {
        spvs_q_pts_row(&e->pts, i, o->cand_pts[n_cand]);
        n_cand = take(o, n_cand, i);
    }
    o->n_cand_known = (uint16_t)n_cand;
    int32_t Hi[9];
    int oor = 0;
    const int32_t *hi = inverse_q(e->H, Hi, &oor) ? Hi : 0;
    if (oor && o->hi_out_of_range < UINT16_MAX) {
        o->hi_out_of_range++;
    }
    const uint16_t n_plane = e->n_plane;
    for (uint16_t i = next_rejected(e->mask, 0, n_plane); i < n_plane;
         i = next_rejected(e->mask, i + 1u, n_plane)) {
        if (n_cand >= SPVS_MAX_OFFPLANE) {
            break;
        }
        int32_t *const q = o->cand_pts[n_cand];
        spvs_q_pts_row(&e->pts, i, q);
        if (off_plane(e->H, hi, q, thr)) {
            n_cand = take(o, n_cand, i);
        }
    }
    o->n_cand = (uint16_t)n_cand;
}

int32_t spvs_q_offplane_known_parallax_q16(const spvs_q_offplane_t *o, const int32_t H[9],
                                           int32_t *scratch)
{
    uint16_t nv = 0;
    for (uint16_t k = 0; k < o->n_cand_known; k++) {
        const int64_t e2 = err2_call(H, o->cand_pts[k]);
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
    return spvs_q_select_i32(scratch, 1u, nv, nv / 2u);
}

void spvs_q_offplane_remember(spvs_q_offplane_t *o, const spvs_q_plane_h_t *e, int e_ok,
                              int32_t parallax_q16, int32_t offplane_q16)
{
    const off_thr_t thr = off_thr(offplane_q16);
    /* The count and the bounds in locals: every store into the int8
     * scores may alias them, so the compiler would reload them per
     * point; the count in 32 bits, which no step truncates. */
    uint32_t n_known = o->n_known;
    int8_t *const scores = o->score;
    const uint16_t *const feat = e->feat;
    if (e_ok) {
        /* The collect's forward test, the same computation, passed for the
         * candidates it tested where H and the threshold are the same. */
        uint32_t same = o->cand_thr == offplane_q16;
        for (uint32_t i = 0; i < 9u; i++) {
            same &= (uint32_t)(o->cand_H[i] == e->H[i]);
        }
        const uint32_t tested = same ? o->n_cand_known : SPVS_MAX_OFFPLANE;
        const uint32_t n_cand = o->n_cand;
        for (uint32_t k = 0; k < n_cand; k++) {
            if (!o->support[k]) {
                continue;
            }
            int8_t *score = &scores[feat[o->cand[k]]];
            if (*score < SPVS_OFFPLANE_MAX &&
                (k >= tested || transfer_above_call(e->H, o->cand_pts[k], &thr) == 1)) {
                (*score)++;
                n_known += (uint32_t)(*score == SPVS_OFFPLANE_ON);
            }
        }
    }
    if ((int64_t)parallax_q16 > (int64_t)SPVS_PARALLAX_CLEAR * offplane_q16) {
        const uint32_t n_plane = e->n_plane;
        const uint8_t *const mask = e->mask;
        for (uint32_t i = 0; i < n_plane; i++) {
            if (!mask[i]) {
                continue;
            }
            int8_t *score = &scores[feat[i]];
            const int32_t sc = *score;
            if (sc > SPVS_OFFPLANE_MIN) {
                n_known -= (uint32_t)(sc == SPVS_OFFPLANE_ON);
                *score = (int8_t)(sc - 1);
            }
        }
    }
    /* At most SPVS_MAX_FEATURES: the count of the scores at or above
     * SPVS_OFFPLANE_ON, kept in 32 bits in the loops. */
    o->n_known = (uint16_t)n_known;
}
