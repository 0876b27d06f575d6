/*
 * fixed/accel/load_fast_q.c - the fixed-point loader with its 32-bit fast
 * paths (points_q.h: spvs_q_pts_load), built where SPVS_ACCEL is ON in
 * place of fixed/load_q.c: a float32 coordinate is converted in 32-bit
 * operations (from_f32), and a match whose four coordinates lie in 16
 * binades by a fixed-position rounding (load_fast), each with the general
 * conversion's result, rounding and flags (the same store bit for bit:
 * test_fixed_q's loader tests, the closed loops with SPVS_ACCEL=OFF).  The
 * frame's slots are walked by a byte offset instead of an index times the
 * match size.
 */
#include <string.h>

#include "../load_q.h"

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

static SPVS_Q_NOINLINE int32_t load_coord(spvs_real c, int px_frac, int32_t lim, uint32_t *bad)
{
    uint32_t f = 0;
    int below = 0;
#if SPVS_USE_DOUBLE
    const int32_t q = spvs_q_from_ieee(spvs_q_real_parts(c), px_frac, &f, &below);
#else
    const int32_t q = from_f32(c, px_frac, &f, &below);
#endif
    *bad |= load_flags(q, f, below, lim);
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
    load_max(mx, ax, ay, au, av);
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
    load_finish(st, &mx);
    return bad;
}

