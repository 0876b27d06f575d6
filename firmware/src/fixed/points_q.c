/*
 * points_q.c - the estimator's per-point kernels in fixed point
 * (points_q.h; formats, ranges and error bounds in docs/FIXED.md).
 *
 * The per-point arithmetic is that of h_point.inc, rewritten for integers:
 * the stages whose range a Q format holds are exact (w and h1 . p in int64
 * Q53), the residuals are formed exactly from those rounded to 31 bits,
 * and the stages whose range grows without bound (the Sampson error's
 * terms, the fits' weights 1 / w and (J J^T)^-1) are in spvs_qf_t.
 */
#include <string.h>

#include "../core_util.h"
#include "point_q.h"
#include "sums_q.h"

/* Scaled coordinates are below 2^30 in Q26 (points_q.h). */

/* ---- conversions --------------------------------------------------------- */


uint32_t spvs_q_h_from_real(const spvs_real H[9], int32_t Hq[9])
{
    uint32_t sat = 0;
    for (int k = 0; k < 9; k++) {
        Hq[k] = spvs_q_from_ieee(spvs_q_real_parts(H[k]), SPVS_QH, &sat, 0);
        /* +-16 itself is outside (-16, 16): it would clamp to 2^31 - 1. */
        sat |= (Hq[k] == SPVS_Q_I32_MAX || Hq[k] == SPVS_Q_I32_MIN) ? SPVS_Q_SAT : 0u;
    }
    return sat;
}

spvs_qf_t spvs_q_t2_from_real(spvs_real t2, uint32_t *sat)
{
    return spvs_qf_from_ieee(spvs_q_real_parts(t2), sat);
}

/* ---- the loader ---------------------------------------------------------- */

/* A pixel coordinate as Q26 scaled units: pixels in Q(26 - log2 scale) are
 * the same integers.  Flags a coordinate above SPVS_MAX_COORD_PX (compared
 * before rounding: a value just above the limit that rounds down to it is
 * still out) with SPVS_Q_SAT, NaN or infinity with SPVS_Q_NONFINITE. */
#if !SPVS_USE_DOUBLE
/* spvs_q_from_ieee for a float32 in Qf, in 32-bit operations only (the
 * same result, rounding and flags): the frame's 4 N conversions are the
 * loader's whole cost, and on the Cortex-M3 the general conversion's
 * 64-bit shifts by a per-value amount cost about 120 instructions each.
 * The 24-bit mantissa shifted left by s <= 7 stays below 2^31; s > 7 is
 * beyond int32 (saturated); a right shift of 25 or more leaves 0. */
static int32_t from_f32(spvs_real c, int f, uint32_t *sat, int *below)
{
    uint32_t b;
    memcpy(&b, &c, sizeof b);
    const uint32_t ex = (b >> 23) & 0xffu;
    const int neg = (int)(b >> 31);
    *below = 0;
    if (ex == 0xffu) {
        *sat |= SPVS_Q_NONFINITE;
        return 0;
    }
    const uint32_t mant = ex == 0u ? (b & 0x7fffffu) : ((b & 0x7fffffu) | 0x800000u);
    const int s = (ex == 0u ? 1 : (int)ex) - 150 + f;
    uint32_t mag;
    if (s > 7) {
        if (mant == 0u) {
            return 0;
        }
        *sat |= SPVS_Q_SAT;
        return neg ? SPVS_Q_I32_MIN : SPVS_Q_I32_MAX;
    }
    if (s >= 0) {
        mag = mant << s;
    } else if (s <= -25) {
        *below = mant != 0u;
        return 0;
    } else {
        const int r = -s;
        const uint32_t half = (uint32_t)1 << (r - 1);
        const uint32_t rem = mant & ((half << 1) - 1u);
        mag = (mant >> r) + (rem >= half ? 1u : 0u);
        *below = rem != 0u && rem < half;
    }
    return neg ? -(int32_t)mag : (int32_t)mag;
}
#endif

/* |q|, with INT32_MIN (a clamped value) as INT32_MAX. */
static SPVS_Q_INLINE int32_t q_abs_clamp(int32_t q)
{
    return q < 0 ? (q == SPVS_Q_I32_MIN ? SPVS_Q_I32_MAX : -q) : q;
}

static SPVS_Q_NOINLINE int32_t load_coord(spvs_real c, int px_frac, int32_t lim, uint32_t *bad)
{
    uint32_t f = 0;
    int below = 0;
#if SPVS_USE_DOUBLE
    const int32_t q = spvs_q_from_ieee(spvs_q_real_parts(c), px_frac, &f, &below);
#else
    const int32_t q = from_f32(c, px_frac, &f, &below);
#endif
    const int32_t a = q_abs_clamp(q);
    *bad |= (f & SPVS_Q_NONFINITE) | ((a > lim || (a == lim && below)) ? SPVS_Q_SAT : 0u);
    return q;
}

/* load_coord, with *mag = |result| (INT32_MIN as INT32_MAX).  A float32
 * whose shift s (mantissa to Q(px_frac)) is in -24..7 is a normal number
 * (0 and 255 as exponents put s far outside), and its Q value is the
 * 24-bit mantissa rounded at a fixed position with no flag to set unless
 * it reaches lim: there the 32-bit mantissa (bit 31 the implicit one)
 * shifted right by 7 - s in 0..31 is the value times 2, and adding one
 * before halving rounds half up (ties away from zero on the magnitude),
 * the general conversion's rounding.  The magnitude is at most 2^(24 + s),
 * so for s up to s_max (2^(24 + s_max) below lim) it cannot reach lim and
 * is not compared with it.  Everything else (larger or smaller
 * magnitudes, subnormals, NaN and infinity) takes the general path. */
static SPVS_Q_INLINE int32_t load_coord_mag(spvs_real c, int px_frac, int32_t lim, int s_max,
                                            uint32_t *bad, int32_t *mag)
{
#if !SPVS_USE_DOUBLE
    uint32_t b;
    memcpy(&b, &c, sizeof b);
    const int s = (int)((b >> 23) & 0xffu) - 150 + px_frac;
    if ((uint32_t)(s + 24) <= (uint32_t)(s_max + 24)) {
        const uint32_t m8 = (b << 8) | 0x80000000u;
        const uint32_t a = ((m8 >> (7 - s)) + 1u) >> 1;
        const int32_t sg = (int32_t)b >> 31;
        *mag = (int32_t)a;
        return ((int32_t)a ^ sg) - sg;
    }
#else
    (void)s_max;
#endif
    const int32_t q = load_coord(c, px_frac, lim, bad);
    *mag = q_abs_clamp(q);
    return q;
}

/* The loader's constants for SPVS_COORD_SCALE and SPVS_MAX_COORD_PX: the
 * pixels' fraction bits px_frac (pixels in Q(px_frac) are scaled units in
 * Q26), the limit lim (SPVS_MAX_COORD_PX in Q(px_frac), <= 2^30) and the
 * largest s of load_coord_mag's fixed-position rounding whose magnitudes
 * (at most 2^(24 + s)) stay below lim: 2^(24 + s) <= 2^(floor(log2 lim) -
 * 1), at most 7 (the shift 7 - s). */
#define LOAD_PX_FRAC (SPVS_QC - (31 - spvs_q_clz32((uint32_t)SPVS_COORD_SCALE)))
#define LOAD_LIM ((int32_t)(((int64_t)SPVS_MAX_COORD_PX << SPVS_QC) / SPVS_COORD_SCALE))
#define LOAD_S_LG (31 - spvs_q_clz32((uint32_t)LOAD_LIM) - 25)
#define LOAD_S_MAX (LOAD_S_LG > 7 ? 7 : LOAD_S_LG)

#if !SPVS_USE_DOUBLE
/* The match's fast path takes the 16 binades s = LOAD_S_MAX - 15 ..
 * LOAD_S_MAX of load_coord_mag's (at the default scale, magnitudes from
 * 1/16 px to below 4,096 px): a power of two, so that one OR of the four
 * biased exponents tests them all.  d = exponent - LOAD_E_LO, unsigned,
 * is below 16 exactly there (0 and 255 as exponents are far outside). */
#define LOAD_E_LO ((uint32_t)(LOAD_S_MAX - 15 + 150 - LOAD_PX_FRAC))

/* A feature index's part of that OR: below 16 exactly when the index is
 * below SPVS_MAX_FEATURES (a shift where that is a multiple of 16). */
static SPVS_Q_INLINE uint32_t load_feat_over(uint32_t f)
{
    return SPVS_MAX_FEATURES % 16 == 0 ? f / (uint32_t)(SPVS_MAX_FEATURES / 16)
                                       : (f >= (uint32_t)SPVS_MAX_FEATURES ? 16u : 0u);
}

/* The biased exponent of a float32 with bits b, less LOAD_E_LO. */
static SPVS_Q_INLINE uint32_t load_d(uint32_t b)
{
    return ((b >> 23) & 0xffu) - LOAD_E_LO;
}

/* load_coord_mag's fixed-position rounding of a float32 with bits b whose
 * load_d is in 0..15 (its shift 7 - s is 7 - LOAD_S_MAX + 15 - d), with
 * b's sign, into *r.  Returned: the magnitude doubled, before its halving
 * (2 a or 2 a + 1), which orders the magnitudes as they are. */
static SPVS_Q_INLINE uint32_t load_fast(uint32_t b, int32_t *r)
{
    const uint32_t m8 = (b << 8) | 0x80000000u;
    const uint32_t a2 = (m8 >> ((uint32_t)(22 - LOAD_S_MAX) - load_d(b))) + 1u;
    const int32_t sg = (int32_t)b >> 31;
    *r = ((int32_t)(a2 >> 1) ^ sg) - sg;
    return a2;
}
#endif

/* 2 |q| for load_fast's maxima, |q| taken at most to COORD_LIM + 1 (the
 * store's bound is COORD_LIM beyond that): below 2^32. */
static SPVS_Q_INLINE uint32_t load_umag2(int32_t q)
{
    const uint32_t sg = (uint32_t)(q >> 31);
    const uint32_t a = ((uint32_t)q ^ sg) - sg;
    return 2u * (a > (uint32_t)COORD_LIM ? (uint32_t)COORD_LIM + 1u : a);
}

/* One match outside the fast path (a magnitude beyond its binades, NaN,
 * infinity, a subnormal or 0, or a feature index out of range): its four
 * coordinates by load_coord_mag into r[0..3], its flags into *bad. */
static SPVS_Q_NOINLINE void load_match_slow(int32_t *r, const spvs_match_t *mi, uint32_t *bad)
{
    int32_t a;
    r[0] = load_coord_mag(mi->x_tgt, LOAD_PX_FRAC, LOAD_LIM, LOAD_S_MAX, bad, &a);
    r[1] = load_coord_mag(mi->y_tgt, LOAD_PX_FRAC, LOAD_LIM, LOAD_S_MAX, bad, &a);
    r[2] = load_coord_mag(mi->x_cur, LOAD_PX_FRAC, LOAD_LIM, LOAD_S_MAX, bad, &a);
    r[3] = load_coord_mag(mi->y_cur, LOAD_PX_FRAC, LOAD_LIM, LOAD_S_MAX, bad, &a);
    *bad |= mi->feature >= SPVS_MAX_FEATURES ? SPVS_Q_SAT : 0u;
}

/* The frame's largest magnitudes while it loads, doubled (load_fast,
 * load_umag2). */
typedef struct {
    uint32_t xm, ym, um, vm;
} load_max_t;

/* Match mi into slot k: its feature index and its four coordinates, the
 * maxima updated; a match outside the fast path ORs its flags into *bad. */
static SPVS_Q_INLINE void load_match(spvs_q_store_t *st, uint16_t *feat, uint16_t k,
                                     const spvs_match_t *mi, load_max_t *mx, uint32_t *bad)
{
    const uint16_t f = mi->feature;
    feat[k] = f;
    int32_t *const r = &st->v[4u * k];
    uint32_t ax, ay, au, av;
#if !SPVS_USE_DOUBLE
    uint32_t bx, by, bu, bv;
    memcpy(&bx, &mi->x_tgt, sizeof bx);
    memcpy(&by, &mi->y_tgt, sizeof by);
    memcpy(&bu, &mi->x_cur, sizeof bu);
    memcpy(&bv, &mi->y_cur, sizeof bv);
    /* The exponents' test first; the conversions take opaque copies of
     * the bits, so that each exponent is made again there rather than
     * kept (fewer values live at once). */
    if ((load_d(bx) | load_d(by) | load_d(bu) | load_d(bv) | load_feat_over(f)) < 16u) {
        ax = load_fast((uint32_t)spvs_q_opaque32((int32_t)bx), &r[0]);
        ay = load_fast((uint32_t)spvs_q_opaque32((int32_t)by), &r[1]);
        au = load_fast((uint32_t)spvs_q_opaque32((int32_t)bu), &r[2]);
        av = load_fast((uint32_t)spvs_q_opaque32((int32_t)bv), &r[3]);
    } else
#endif
    {
        load_match_slow(r, mi, bad);
        ax = load_umag2(r[0]);
        ay = load_umag2(r[1]);
        au = load_umag2(r[2]);
        av = load_umag2(r[3]);
    }
    mx->xm = ax > mx->xm ? ax : mx->xm;
    mx->ym = ay > mx->ym ? ay : mx->ym;
    mx->um = au > mx->um ? au : mx->um;
    mx->vm = av > mx->vm ? av : mx->vm;
}

/* The store's bound from a doubled maximum: at most COORD_LIM. */
static int32_t load_bound(uint32_t m2)
{
    const uint32_t a = m2 >> 1;
    return a > (uint32_t)COORD_LIM ? COORD_LIM : (int32_t)a;
}

uint32_t spvs_q_pts_load(spvs_q_store_t *st, uint16_t *feat, const spvs_match_t *m, uint16_t n,
                         uint16_t n_plane, const uint16_t *order, uint16_t stride)
{
    uint32_t bad = 0;
    load_max_t mx = {0u, 0u, 0u, 0u};
    if (order == 0) {
        /* spvs_slot_source without order[]: the position alone, kept as
         * a byte offset into m[] (no multiply per match). */
        const unsigned char *const mb = (const unsigned char *)m;
        const uint32_t step = (uint32_t)stride * (uint32_t)sizeof *m;
        const uint32_t span = (uint32_t)n_plane * (uint32_t)sizeof *m;
        uint32_t off = 0;
        /* Bound: n slots. */
        for (uint16_t k = 0; k < n; k++) {
            load_match(st, feat, k, (const spvs_match_t *)(const void *)(mb + off), &mx, &bad);
            off += step;
            off = off >= span ? off - span : off;
        }
    } else {
        uint16_t pos = 0;
        /* Bound: n slots. */
        for (uint16_t k = 0; k < n; k++) {
            load_match(st, feat, k, &m[spvs_slot_source(k, n_plane, order, stride, &pos)], &mx,
                       &bad);
        }
    }
    /* On a bad frame the clamped values are not in range: keep the bound
     * meaningful anyway. */
    st->cur_max[0] = load_bound(mx.um);
    st->cur_max[1] = load_bound(mx.vm);
    st->tgt_max[0] = load_bound(mx.xm);
    st->tgt_max[1] = load_bound(mx.ym);
    return bad;
}

void spvs_q_pts_row(const spvs_q_store_t *st, uint16_t i, int32_t row[4])
{
    const int32_t *const v = &st->v[4u * i];
    row[0] = v[0];
    row[1] = v[1];
    row[2] = v[2];
    row[3] = v[3];
}

/* |eps|^2 of one point, from the exact residuals (q_eps): the cost's term,
 * as a spvs_qf_t (relative error <= 2^-30). */
static spvs_qf_t q_e2(const int32_t *h, const int32_t *p)
{
    q_eps_t r;
    q_eps(h, p, &r);
    const int s2 = spvs_q_norm_shift(spvs_q_abs64(r.ex) | spvs_q_abs64(r.ey), 30);
    const int32_t ex2 = (int32_t)spvs_q_rshift_rnd64(r.ex, s2);
    const int32_t ey2 = (int32_t)spvs_q_rshift_rnd64(r.ey, s2);
    return spvs_qf_from_i64((int64_t)ex2 * ex2 + (int64_t)ey2 * ey2, -2 * (79 - r.s1 - s2));
}



/* The term of a point beyond cost's fast path, in Q52; out of line. */
SPVS_Q_NOINLINE uint64_t spvs_q_cost_exact(const int32_t *h, const int32_t *p, uint32_t *sat)
{
    return (uint64_t)spvs_qf_to_q64(q_e2(h, p), SPVS_QCOST, sat);
}


/* ---- the sums of the linear fits ------------------------------------------ */

spvs_qf_t spvs_q_sums_term(const spvs_q_sums_t *s, int k)
{
    if (k < 0 || k >= s->nt) {
        return spvs_qf_from_i64(0, 0);
    }
    return spvs_qf_from_i64(s->m[k], s->e[blk_of(s, k)]);
}

/* Adds term t to sum k of a block-floating-point accumulator (sub = 0) or
 * subtracts it (sub = 1).  Invariant: every |m| < 2^62.  A term more than
 * 2^30 above the block's unit first shifts the block right (raising its
 * exponent), so the term's share is below 2^61 and the result below 2^63
 * in magnitude either way; a result that reaches 2^62 shifts the block by
 * one.  Terms below the unit are rounded to it (the block keeps 62 bits
 * of its largest sum).  The share is rounded before its sign is applied,
 * so subtracting a term added before at the same exponent undoes the add
 * exactly (round to nearest with ties up is not odd: rnd(-x) can differ
 * from -rnd(x)). */
void spvs_q_acc_add(spvs_q_sums_t *s, int k, spvs_qf_t t, int sub)
{
    if (t.m == 0) {
        return;
    }
    const int b = blk_of(s, k);
    int lo, hi;
    blk_range(s, b, &lo, &hi);
    int32_t d = t.e - s->e[b];
    if (d > 30) {
        const int32_t sh = d - 30;
        for (int j = lo; j < hi; j++) {
            s->m[j] = spvs_q_rshift_rnd64(s->m[j], sh > 63 ? 63 : (int)sh);
        }
        s->e[b] += sh;
        d = 30;
    }
    const int64_t add = d >= 0 ? (int64_t)t.m * ((int64_t)1 << d)
                               : spvs_q_rshift_rnd64(t.m, d < -63 ? 63 : (int)-d);
    const int64_t r = sub ? s->m[k] - add : s->m[k] + add;
    s->m[k] = r;
    if (spvs_q_abs64(r) >= ((uint64_t)1 << 62)) {
        for (int j = lo; j < hi; j++) {
            s->m[j] = spvs_q_rshift_rnd64(s->m[j], 1);
        }
        s->e[b] += 1;
    }
}

static spvs_qf_t qf_c(int32_t q) /* a Q26 coordinate */
{
    return spvs_qf_from_i64(q, -SPVS_QC);
}

/* SPVS_T_FIT_Y and SPVS_T_FIT_X terms of one point (h_point.inc):
 * q = sc (x, y, 1), sc = v / w or 1 / w, r = y / w or u.  Not inlined:
 * its spvs_qf_t temporaries stay out of spvs_q_pts_sum's frame, under
 * which spvs_q_terms_lin's own frame comes on the LIN sums' exact path. */
SPVS_Q_NOINLINE void spvs_q_terms_fit(int kind, const q_eps_t *r, const int32_t *p,
                                      spvs_q_sums_t *s)
{
    uint32_t z = 0;
    const spvs_qf_t iw = spvs_qf_recip(spvs_qf_from_i64(r->w, -53), &z);
    const spvs_qf_t x = qf_c(p[0]), y = qf_c(p[1]);
    const spvs_qf_t sc = kind == SPVS_T_FIT_Y ? spvs_qf_mul(qf_c(p[3]), iw) : iw;
    const spvs_qf_t rr = kind == SPVS_T_FIT_Y ? spvs_qf_mul(y, iw) : qf_c(p[2]);
    const spvs_qf_t q0 = spvs_qf_mul(sc, x), q1 = spvs_qf_mul(sc, y), q2 = sc;
    spvs_q_acc_add(s, 0, qf_sq(q0), 0);
    spvs_q_acc_add(s, 1, spvs_qf_mul(q0, q1), 0);
    spvs_q_acc_add(s, 2, spvs_qf_mul(q0, q2), 0);
    spvs_q_acc_add(s, 3, qf_sq(q1), 0);
    spvs_q_acc_add(s, 4, spvs_qf_mul(q1, q2), 0);
    spvs_q_acc_add(s, 5, qf_sq(q2), 0);
    spvs_q_acc_add(s, 6, spvs_qf_mul(q0, rr), 0);
    spvs_q_acc_add(s, 7, spvs_qf_mul(q1, rr), 0);
    spvs_q_acc_add(s, 8, spvs_qf_mul(q2, rr), 0);
}

/* SPVS_T_LIN terms of one point (h_point.inc): the joint fit of rows 1
 * and 3 at the Sampson weights W = (J J^T)^-1 = adj(J J^T) / det of H,
 * added to s (sub = 0) or subtracted (sub = 1, spvs_q_lin_move). */
/* Not inlined: its spvs_qf_t temporaries stay out of spvs_q_pts_sum's
 * frame, which the fast path uses alone. */
SPVS_Q_NOINLINE void spvs_q_terms_lin(const int32_t *h, const q_eps_t *r, const int32_t *p,
                                      spvs_q_sums_t *s, int sub)
{
    uint32_t z = 0;
    const spvs_qf_t x = qf_c(p[0]), y = qf_c(p[1]), u = qf_c(p[2]), v = qf_c(p[3]);
    const spvs_qf_t w = spvs_qf_from_i64(r->w, -53);
    const spvs_qf_t ex = spvs_qf_from_i64(r->ex, -(79 - r->s1));
    const spvs_qf_t ey = spvs_qf_from_i64(r->ey, -(79 - r->s1));
    spvs_qf_t P[4];
    q_jac(h, p, P);
    const spvs_qf_t ww = qf_sq(w);
    const spvs_qf_t pq = spvs_qf_add(qf_sq(P[0]), qf_sq(P[1]));
    const spvs_qf_t rs = spvs_qf_add(qf_sq(P[2]), qf_sq(P[3]));
    const spvs_qf_t ja = spvs_qf_add(pq, ww), jb = spvs_qf_add(rs, ww);
    const spvs_qf_t jc = spvs_qf_add(spvs_qf_mul(P[0], P[2]), spvs_qf_mul(P[1], P[3]));
    /* det(J J^T) without cancellation (q_sampson). */
    const spvs_qf_t dp = spvs_qf_sub(spvs_qf_mul(P[0], P[3]), spvs_qf_mul(P[1], P[2]));
    const spvs_qf_t den = spvs_qf_add(spvs_qf_mul(ww, spvs_qf_add(ww, spvs_qf_add(pq, rs))),
                                      qf_sq(dp));
    const spvs_qf_t id = spvs_qf_recip(den, &z);
    const spvs_qf_t w11 = spvs_qf_mul(jb, id), w12 = spvs_qf_neg(spvs_qf_mul(jc, id));
    const spvs_qf_t w22 = spvs_qf_mul(ja, id);
    const spvs_qf_t uw = spvs_qf_add(spvs_qf_mul(u, w11), spvs_qf_mul(v, w12));
    const spvs_qf_t vw = spvs_qf_add(spvs_qf_mul(u, w12), spvs_qf_mul(v, w22));
    const spvs_qf_t a[3] = {w11, spvs_qf_neg(uw),
                            spvs_qf_add(spvs_qf_mul(u, uw), spvs_qf_mul(v, vw))};
    const spvs_qf_t q[5] = {qf_sq(x), spvs_qf_mul(x, y), x, qf_sq(y), y};
    for (int m = 0; m < 3; m++) {
        for (int k = 0; k < 5; k++) {
            spvs_q_acc_add(s, 6 * m + k, spvs_qf_mul(a[m], q[k]), sub);
        }
        spvs_q_acc_add(s, 6 * m + 5, a[m], sub);
    }
    const spvs_qf_t b1 = spvs_qf_add(spvs_qf_mul(w11, ex), spvs_qf_mul(w12, ey));
    const spvs_qf_t c1 = spvs_qf_add(spvs_qf_mul(w12, ex), spvs_qf_mul(w22, ey));
    const spvs_qf_t b3 = spvs_qf_neg(spvs_qf_add(spvs_qf_mul(u, b1), spvs_qf_mul(v, c1)));
    spvs_q_acc_add(s, 18, spvs_qf_mul(b1, x), sub);
    spvs_q_acc_add(s, 19, spvs_qf_mul(b1, y), sub);
    spvs_q_acc_add(s, 20, b1, sub);
    spvs_q_acc_add(s, 21, spvs_qf_mul(b3, x), sub);
    spvs_q_acc_add(s, 22, spvs_qf_mul(b3, y), sub);
    spvs_q_acc_add(s, 23, b3, sub);
    /* eps^T W eps as h_point.inc forms it (ex b1 + ey b2).  W is positive
     * definite, so the two products cancel only as far as its condition
     * number allows (that of J J^T = w^2 I + P P^T, at most
     * 1 + |P|^2 / w^2). */
    spvs_q_acc_add(s, 24, spvs_qf_add(spvs_qf_mul(ex, b1), spvs_qf_mul(ey, c1)), sub);
}

/* The squared Sampson error of one point num / den (q_sampson, from the
 * exact residuals r): num and den rounded to 31 bits after sums of
 * squares (no cancellation, relative 2^-29 each), one reciprocal (2^-28)
 * and one product (2^-31): relative error below 2^-26. */
/* Not inlined: its temporaries stay out of spvs_q_pts_sum's frame. */
SPVS_Q_NOINLINE spvs_qf_t spvs_q_sampson_term(const int32_t *h, const q_eps_t *r,
                                                const int32_t *p)
{
    spvs_qf_t num, den;
    q_sampson_nd(h, p, r, &num, &den);
    /* den >= w^4 > 0 for a point in front: no division by zero. */
    uint32_t z = 0;
    return spvs_qf_mul(num, spvs_qf_recip(den, &z));
}

/* q_eps as a call, for the per-point paths where its size matters more
 * than a call's few instructions (the Sampson sum, the moved point). */
SPVS_Q_NOINLINE void spvs_q_eps_call(const int32_t *h, const int32_t *p, q_eps_t *r)
{
    q_eps(h, p, r);
}


/* One point's squared Sampson error from its exact residuals
 * (spvs_q_sampson_term) into out's term 0; 0 when w <= SPVS_W_EPS (out
 * unchanged). */
SPVS_Q_NOINLINE int spvs_q_sampson_exact(const int32_t *h, const int32_t *p, spvs_q_sums_t *out)
{
    q_eps_t r;
    spvs_q_eps_call(h, p, &r);
    if (r.w <= W_EPS_Q53) {
        return 0;
    }
    spvs_q_acc_add(out, 0, spvs_q_sampson_term(h, &r, p), 0);
    return 1;
}


/* One point's terms on the exact path (spvs_q_terms_lin or spvs_q_terms_fit) into s;
 * 0 when w <= SPVS_W_EPS (s unchanged).  Out of line, so that
 * spvs_q_pts_sum's loop over the points keeps its own values in
 * registers. */
SPVS_Q_NOINLINE int spvs_q_sum_exact_point(int kind, const int32_t *h, const int32_t *p,
                                           spvs_q_sums_t *s)
{
    q_eps_t r;
    spvs_q_eps_call(h, p, &r);
    if (r.w <= W_EPS_Q53) {
        return 0;
    }
    if (kind == SPVS_T_LIN) {
        spvs_q_terms_lin(h, &r, p, s, 0);
    } else {
        spvs_q_terms_fit(kind, &r, p, s);
    }
    return 1;
}


int spvs_q_sums_clear(spvs_terms_t kind, spvs_q_sums_t *out)
{
    const int lin = kind == SPVS_T_LIN, samp = kind == SPVS_T_SAMPSON;
    if (kind != SPVS_T_FIT_Y && kind != SPVS_T_FIT_X && !lin && !samp) {
        return -2;
    }
    /* The blocks of spvs_q_sums_t. */
    out->nt = (uint8_t)(lin ? SPVS_H_LIN_SUMS : (samp ? 1 : SPVS_NT_FIT));
    out->split = (uint8_t)(lin ? 18 : (samp ? 1 : 6));
    out->split2 = (uint8_t)(lin ? SPVS_H_LIN_COST : out->nt);
    /* A block starts far below any term, so the first term sets its unit. */
    out->e[0] = out->e[1] = out->e[2] = -4000;
    for (int k = 0; k < SPVS_H_LIN_SUMS; k++) {
        out->m[k] = 0;
    }
    return 0;
}
