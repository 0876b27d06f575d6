/*
 * offplane_q.c - the off-plane memory and the frame's off-plane candidates
 * in fixed point (offplane_q.h): the Q tests under the decisions of
 * offplane.inc (written once for both cores), whose comments say why each
 * step is made; here they say where the fixed-point version differs.
 */
#include "offplane_q.h"

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

/* ---- the fixed-point core's side of offplane.inc ---------------------------- */

typedef spvs_q_offplane_t op_t;
typedef spvs_q_plane_h_t op_est_t;
typedef int32_t op_h_t;
typedef off_thr_t op_thr_t;
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

static off_thr_t thr_of(int32_t offplane_q16)
{
    return off_thr(offplane_q16);
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
    return err2_call(H, row);
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

static int above_thr(const spvs_q_plane_h_t *e, const int32_t row[4], const off_thr_t *thr)
{
    return transfer_above_call(e->H, row, thr) == 1;
}

#include "../offplane.inc"
