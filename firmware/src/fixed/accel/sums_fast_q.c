/*
 * fixed/accel/sums_fast_q.c - the fixed-point tie-break cost and the sums
 * of the linear fits with their integer fast paths (points_q.h:
 * spvs_q_pts_cost, spvs_q_pts_sum, spvs_q_lin_move, spvs_q_sum_fast),
 * built where SPVS_ACCEL is ON in place of fixed/sums_q.c.  Each path
 * takes its formats from bounds over the frame and sends a point beyond
 * them to the exact terms (sums_q.h), which are the reference's; a fast
 * term is within the bounds its comment states of the exact one
 * (docs/FIXED.md).  The compiler steering (SPVS_Q_NOINLINE,
 * spvs_q_opaque32) keeps the Cortex-M3's loops in registers.
 */
#include "../sums_q.h"


/* The tie-break cost's fast path, one point at a time in the loop of
 * spvs_q_pts_cost: w = w27 2^26 + wr (w27 its floor in Q27, 0 <= wr <
 * 2^26), so u w - h1 . p 2^26 is (u w27 - h1 . p) 2^26 + u wr.  With
 * |w| < 16 (2^57 in Q53, tested) w27 is in int32, and as |h| < 2^31 and
 * |p| <= 2^30 each product is below 2^61 and every partial sum of ex53 =
 * u w27 - h1 . p 2^26 below 2^63: exact in int64 for any H (ey53 alike).
 * Where |ex53|, |ey53| < 2^47 (tested), the residual in Q34 is
 * floor(ex53 2^-19) + floor(u wr 2^-45), below 2^28 + 2^11 in magnitude
 * and within 2 units of the exact residual (|u wr| < 2^56, so the second
 * floor is of a value below 2^11); their squares, below 2^56.01 each, are
 * summed unrounded in Q68 over a block of COST_BLOCK points (below 2^63)
 * and the block's sum rounded to Q52 once.  A term is then within 2^-32
 * (|ex| + |ey|) + 2^-66 of the exact one (scaled units): for a residual of
 * a pixel (2^-9 scaled units), 2^-23 relative, finer than a float32 sum's
 * rounding.  A point beyond either range (|eps| of 8 px or more, or
 * |w| >= 16) takes its term from the exact residuals (q_e2,
 * spvs_q_cost_exact). */
#define COST_BLOCK 32u


uint64_t spvs_q_pts_cost(const spvs_q_store_t *st, uint16_t n, const int32_t Hq[9],
                         const uint8_t *mask, uint32_t *sat)
{
    /* The rows of H as q_w and q_ex53 read them: -h11, -h12, -h13 2^26 and
     * h33 2^26 (|h| < 2^31: no overflow). */
    const int64_t one26 = (int64_t)1 << 26;
    const int32_t h6 = Hq[6], h7 = Hq[7], nh0 = -Hq[0], nh1 = -Hq[1];
    const int64_t h8c = (int64_t)Hq[8] * one26, nh2c = -((int64_t)Hq[2] * one26);
    uint64_t sum = 0;
    const int32_t *p = st->v;
    const uint8_t *m = mask;
    const uint8_t *const mend = mask + n;
    /* Bound: n / COST_BLOCK + 1 blocks of at most COST_BLOCK points. */
    while (m != mend) {
        const uint8_t *const me = (size_t)(mend - m) > COST_BLOCK ? m + COST_BLOCK : mend;
        int64_t acc = 0; /* Q68, below 2^62.1 */
        /* Bound: COST_BLOCK points. */
        for (; m != me; m++, p += 4) {
            if (!*m) {
                continue;
            }
            const int64_t w = q_w(h8c, h6, h7, p);
            /* |w| < 2^57 on its high word: in [-2^25, 2^25). */
            if ((uint32_t)((int32_t)(w >> 32) + 0x2000000) < 0x4000000u) {
                /* Opaque: after the tests the compiler would take these
                 * for their 64-bit sources and multiply in 64 x 64 bits. */
                const int32_t w27 = spvs_q_opaque32((int32_t)(w >> 26));
                const int32_t wr = spvs_q_opaque32((int32_t)((uint32_t)w & 0x3FFFFFFu));
                const int64_t ex53 = q_ex53(nh2c, nh0, nh1, p, w27);
                const int64_t ey53 = q_ey53(p, w27);
                /* |ex53|, |ey53| < 2^47 on their high words, in
                 * [-2^15, 2^15): one comparison for both. */
                const int32_t xh = (int32_t)(ex53 >> 32), yh = (int32_t)(ey53 >> 32);
                if (((uint32_t)(xh + 0x8000) | (uint32_t)(yh + 0x8000)) < 0x10000u) {
                    /* Q34, with u wr and v wr (below 2^56) as high words
                     * shifted by a constant. */
                    const int32_t ex = spvs_q_opaque32(
                        (int32_t)(ex53 >> 19) + ((int32_t)(((int64_t)p[2] * wr) >> 32) >> 13));
                    const int32_t ey = spvs_q_opaque32(
                        (int32_t)(ey53 >> 19) + ((int32_t)(((int64_t)p[3] * wr) >> 32) >> 13));
                    acc += (int64_t)ex * ex;
                    acc += (int64_t)ey * ey;
                    continue;
                }
            }
            if (!spvs_q_cost_add(&sum, spvs_q_cost_exact(Hq, p, sat), sat)) {
                return UINT64_MAX;
            }
        }
        if (!spvs_q_cost_add(&sum, ((uint64_t)acc + ((uint64_t)1 << 15)) >> 16, sat)) {
            return UINT64_MAX;
        }
    }
    return sum;
}


/* ---- SPVS_T_LIN's fast path ----------------------------------------------- */

/* 2^61 / m for m in [2^30, 2^31), within about 2^-28 relative and at most
 * 2^31 - 1 (2^61 / 2^30 itself is one unit above): a 32-bit division of
 * 2^32 by m's top 16 bits (17 bits, one UDIV on the Cortex-M3) and one
 * Newton step in signed 32 x 32 -> 64-bit products. */
static SPVS_Q_INLINE int32_t q_recip_fast(uint32_t m)
{
    /* ~2^61 / m to 2^-14, below 2^31 (m >> 15 >= 2^15). */
    const int32_t y0 = (int32_t)((0xFFFFFFFFu / (m >> 15)) << 14);
    /* y1 = y0 (2 - m y0 2^-61) = y0 - y0 (m y0 - 2^61) 2^-61; the
     * deviation is below 2^48, kept to 2^-29 of it (its low 29 bits). */
    const int64_t dev = (int64_t)((uint64_t)m * (uint32_t)y0) - ((int64_t)1 << 61);
    const int32_t dh = (int32_t)(dev >> 29);
    /* y1 lies in (2^30, 2^31] for every m of the range (checked on all
     * 2^30 of them), so it is formed in 32 bits, and only 2^31 (at
     * m = 2^30) is brought down to 2^31 - 1, by its top bit. */
    const uint32_t y1 = (uint32_t)y0 - (uint32_t)(((int64_t)y0 * dh) >> 32);
    return (int32_t)(y1 - (y1 >> 31));
}

/* The fast path's formats for one sum (block floating point with the set
 * as the block; docs/FIXED.md).  Per point, in integers with constant
 * shifts only (one CLZ and one 32-bit shift by a per-point amount):
 *   w = h3 . p (Q53), w27 = w 2^-26 (Q27), ex = u w27 - h1 . p and
 *   ey = v w27 - y 2^27 (Q53), kept to Q36 (a point with |eps| >= 2^-5
 *   scaled units, 16 px, takes the exact path);
 *   P (the Jacobian's block) and w in Q28; a = |P row 1|^2 + w^2, b, c
 *   (J J^T) in Q24 (high words); det = a b - c^2 (Q48) normalised to 31 bits,
 *   its reciprocal by q_recip_fast;
 *   W = adj(J J^T) / det in Q(qr), qr = 30 - kw with |W| <= 1 / w_lo^2 <=
 *   2^kw, so every entry is below 2^30;
 *   the right side: b1 = (W eps)_1, b2 in Q(qr + 4) (|b| <= 2 |W| 2^-5),
 *   b3 = -(u b1 + v b2) in Q(qr + 2) (|u|, |v| < 2), times (x, y, 1) in
 *   Q21;
 *   the normal matrix: h_point.inc's a[0] = w11 in Q(qr - 2), a[1] in
 *   Q(qr - 4), a[2] in Q(qr - 6) (each below 2^28), times q = (x^2, x y,
 *   x, y^2, y, 1) in Q24 (each below 2^25);
 *   the squared Sampson error (term 24, and SPVS_T_SAMPSON's sum on the
 *   same bounds): (ex b1 + ey b2) 2^-10 in Q(qr + 30), below 2^52.
 * So every term is below 2^53 and a sum of at most 512 below 2^62; the
 * blocks are aligned when merged (lin_merge's callers).  The bounds over
 * the frame that make this hold: w_lo >= 1/4 and w_hi < 4 (w over the
 * frame from |h31|, |h32| and the largest |x|, |y|), the Jacobian's
 * entries below 4, |u|, |v| < 2, x^2, y^2 < 2 and n <= 512; where one
 * fails, ok = 0 and every point takes the exact path. */
typedef struct {
    int ok;
    int32_t qr;
    int32_t nh0, nh1; /* -h11, -h12 (|h| < 2^31: no overflow) */
    /* -h13 and h33 times 2^26, Q53: the constant terms, so that each
     * per-point sum starts from one and multiply-accumulates. */
    int64_t nh2c, h8c;
} q_lin_t;

#define LIN_EB 5 /* |eps| < 2^-LIN_EB scaled units on the fast path */

/* The bounds over a set of points that the sums' fast paths take their
 * formats from: the largest |x_tgt|, |y_tgt| (X, Y) and |x_cur|, |y_cur|
 * (U, V) in Q26, and w's least and largest values (Q53). */
typedef struct {
    int64_t X, Y, U, V;
    int64_t w_lo, w_hi;
} q_box_t;

/* The box of a frame whose largest coordinates are tgt_max and cur_max,
 * w bounded through |h31| X + |h32| Y. */
static q_box_t box_of(const int32_t tgt_max[2], const int32_t cur_max[2], const int32_t *h)
{
    q_box_t b;
    b.X = tgt_max[0];
    b.Y = tgt_max[1];
    b.U = cur_max[0];
    b.V = cur_max[1];
    const int64_t h8c = (int64_t)h[8] * ((int64_t)1 << 26);
    const int64_t spread = (int64_t)h_mag(h[6]) * b.X + (int64_t)h_mag(h[7]) * b.Y;
    b.w_lo = h8c - spread;
    b.w_hi = h8c + spread;
    return b;
}

/* The box of the flagged points among the first n: their own largest
 * coordinates and w's exact range.  A sum takes it where the frame's box
 * fails the fast path's bounds (a mismatch far out, or a frame whose
 * corners see the plane at a grazing w while the flagged points do not),
 * so that one point outside the range does not send the whole set to the
 * exact path.  Bound: n points. */
static q_box_t box_used(const spvs_q_store_t *st, const int32_t *h, const uint8_t *use,
                        uint16_t n)
{
    q_box_t b;
    b.X = b.Y = b.U = b.V = 0;
    const int64_t h8c = (int64_t)h[8] * ((int64_t)1 << 26);
    b.w_lo = b.w_hi = h8c;
    for (uint16_t i = 0; i < n; i++) {
        if (!use[i]) {
            continue;
        }
        const int32_t *p = &st->v[4u * i];
        const int64_t w = q_w(h8c, h[6], h[7], p);
        b.w_lo = w < b.w_lo ? w : b.w_lo;
        b.w_hi = w > b.w_hi ? w : b.w_hi;
        const int64_t ax = (int64_t)h_mag(p[0]), ay = (int64_t)h_mag(p[1]);
        const int64_t au = (int64_t)h_mag(p[2]), av = (int64_t)h_mag(p[3]);
        b.X = ax > b.X ? ax : b.X;
        b.Y = ay > b.Y ? ay : b.Y;
        b.U = au > b.U ? au : b.U;
        b.V = av > b.V ? av : b.V;
    }
    return b;
}

/* The formats for a set of n points within the box b. */
static q_lin_t lin_prep_b(const q_box_t *b, const int32_t *h, uint16_t n)
{
    q_lin_t L;
    L.ok = 0;
    L.qr = 0;
    const int64_t one26 = (int64_t)1 << 26;
    L.nh2c = -((int64_t)h[2] * one26);
    L.h8c = (int64_t)h[8] * one26;
    L.nh0 = -h[0];
    L.nh1 = -h[1];
    const int64_t a0 = (int64_t)h_mag(h[0]), a1 = (int64_t)h_mag(h[1]);
    const int64_t a6 = (int64_t)h_mag(h[6]), a7 = (int64_t)h_mag(h[7]);
    const int64_t X = b->X, Y = b->Y;
    const int64_t U = b->U, V = b->V;
    const int64_t two27 = (int64_t)1 << 27; /* 2 scaled units, Q26 */
    const int64_t q_lim = (int64_t)1 << 25; /* 2 in Q24 */
    if (n > 512u || U >= two27 || V >= two27 || ((X * X) >> 28) >= q_lim ||
        ((Y * Y) >> 28) >= q_lim) {
        return L;
    }
    const int64_t w_lo = b->w_lo, w_hi = b->w_hi;
    if (w_lo < ((int64_t)1 << 51) || w_hi >= ((int64_t)1 << 55)) {
        return L;
    }
    /* The Jacobian's entries (h_point.inc's p, q, r, s) below 4, Q53. */
    const int64_t four = (int64_t)1 << 55;
    if (U * a6 + a0 * one26 >= four || U * a7 + a1 * one26 >= four || V * a6 >= four ||
        V * a7 + ((int64_t)1 << 53) >= four) {
        return L;
    }
    /* |W| <= 1 / w_lo^2 <= 2^kw, kw in 0..4. */
    const int kw = 2 * (27 - (spvs_q_bitlen64((uint64_t)(w_lo >> 26)) - 1));
    L.qr = 30 - kw;
    L.ok = 1;
    return L;
}

/* The formats for the flagged points among the first n: from the frame's
 * box, or where that fails the fast path's bounds and use is not NULL,
 * from the flagged points' own box (box_used).  Not inlined: the boxes
 * stay out of the sums' frames. */
static SPVS_Q_NOINLINE q_lin_t lin_prep(const spvs_q_store_t *st, const int32_t *h,
                                        const uint8_t *use, uint16_t n)
{
    q_box_t b = box_of(st->tgt_max, st->cur_max, h);
    q_lin_t L = lin_prep_b(&b, h, n);
    if (!L.ok && use != NULL) {
        b = box_used(st, h, use, n);
        L = lin_prep_b(&b, h, n);
    }
    return L;
}

/* x 2^k for a 32-bit value and k in -31..31 (floor for k < 0); callers
 * bound the result. */
static SPVS_Q_INLINE int32_t q_shift32(int32_t x, int k)
{
    return k >= 0 ? (int32_t)((uint32_t)x << k) : x >> -k;
}

/* One point's weights on the fast path (lin_fast's and the Sampson sum's
 * common part): the residuals ex, ey (Q36), W = (J J^T)^-1 (w11, w12,
 * w22 in Q(qr)) and W eps (b1, b2 in Q(qr + 4)). */
typedef struct {
    int32_t ex, ey;
    int32_t w11, w12, w22;
    int32_t b1, b2;
} q_lw_t;

/* q_lw_t of point p; 0 when its residual is beyond the fast path's range
 * (*o is then not set). */
static SPVS_Q_INLINE int lin_wt(const int32_t *h, const int32_t *p, const q_lin_t *L, q_lw_t *o)
{
    const int32_t u = p[2], v = p[3];
    const int64_t w = q_w(L->h8c, h[6], h[7], p);
    const int32_t w27 = (int32_t)(w >> 26);
    const int64_t ex53 = q_ex53(L->nh2c, L->nh0, L->nh1, p, w27);
    const int64_t ey53 = q_ey53(p, w27);
    /* |ex53|, |ey53| < 2^(53 - LIN_EB): their high words in [-2^16,
     * 2^16) (one comparison for both), less the one value that lets
     * through, -2^48 (high word -2^16, low word 0). */
    SPVS_STATIC_ASSERT(LIN_EB == 5, "the high-word test is for 2^48");
    const int32_t xh = (int32_t)(ex53 >> 32), yh = (int32_t)(ey53 >> 32);
    if (((uint32_t)(xh + 0x10000) | (uint32_t)(yh + 0x10000)) >= 0x20000u) {
        return 0;
    }
    if ((xh == -0x10000 && (uint32_t)ex53 == 0u) || (yh == -0x10000 && (uint32_t)ey53 == 0u)) {
        return 0;
    }
    const int32_t ex = (int32_t)(ex53 >> 17), ey = (int32_t)(ey53 >> 17); /* Q36 */
    /* P (below 4) and w (below 4), Q28: their squares' sums below 3 2^60,
     * whose high words are J J^T in Q24. */
    /* (u h31 - h11 2^26) 2^-25 rounded down is (u h31) 2^-25 rounded down
     * less 2 h11, exact in int32: |u h31| and |h11| 2^26 are below 2^55
     * on this path (lin_prep). */
    const int32_t P0 = (int32_t)(((int64_t)u * h[6]) >> 25) + 2 * L->nh0;
    const int32_t P1 = (int32_t)(((int64_t)u * h[7]) >> 25) + 2 * L->nh1;
    const int32_t P2 = (int32_t)(((int64_t)v * h[6]) >> 25);
    const int32_t P3 = (int32_t)(((int64_t)v * h[7]) >> 25) - (1 << 28);
    const int32_t w28 = w27 * 2;
    /* w28^2 in each sum as a multiply-accumulate of its own (w28 made
     * opaque once, so the two products are not shared through a 64-bit
     * addition, which costs more on the Cortex-M3). */
    const int32_t w28b = spvs_q_opaque32(w28);
    const int32_t ja = spvs_q_opaque32(
        (int32_t)(((int64_t)P0 * P0 + (int64_t)P1 * P1 + (int64_t)w28 * w28) >> 32));
    const int32_t jb = spvs_q_opaque32(
        (int32_t)(((int64_t)P2 * P2 + (int64_t)P3 * P3 + (int64_t)w28b * w28b) >> 32));
    const int32_t jc = spvs_q_opaque32((int32_t)(((int64_t)P0 * P2 + (int64_t)P1 * P3) >> 32));
    /* det >= w^4 >= 2^-8: at least 2^40 in Q48, below 2^60. */
    const uint64_t det = (uint64_t)((int64_t)ja * jb - (int64_t)jc * jc);
    /* det's bits - 31, in 10..29 (its high word is at least 2^8). */
    const uint32_t dh = (uint32_t)(det >> 32);
    const int sh = 33 - spvs_q_clz32(dh);
    /* det >> sh in 32-bit words (sh in 10..29: no shift count leaves
     * 0..31). */
    const uint32_t m = ((uint32_t)det >> sh) | (dh << (32 - sh));
    const int32_t r = q_recip_fast(m); /* 1 / det = r 2^(-13 - sh) */
    /* W in Q(qr): (adj entry Q24 times r) 2^-32, then 2^(qr - 5 - sh). */
    const int k = L->qr - 5 - sh;
    const int32_t w11 = q_shift32((int32_t)(((int64_t)jb * r) >> 32), k);
    const int32_t w12 = -q_shift32((int32_t)(((int64_t)jc * r) >> 32), k);
    const int32_t w22 = q_shift32((int32_t)(((int64_t)ja * r) >> 32), k);
    o->ex = ex;
    o->ey = ey;
    o->w11 = w11;
    o->w12 = w12;
    o->w22 = w22;
    o->b1 = spvs_q_opaque32((int32_t)(((int64_t)w11 * ex + (int64_t)w12 * ey) >> 32));
    o->b2 = spvs_q_opaque32((int32_t)(((int64_t)w12 * ex + (int64_t)w22 * ey) >> 32));
    return 1;
}

/* F[0..2] += (a0 b0, a1 b1, a2 b2) in int64; returns F + 3.  The fast
 * paths' sums are multiply-accumulates into memory, and on Thumb-2 one
 * LDM and one STM move three of them (six words, the register pairs of
 * three SMLAL), where the compiler's LDRD and STRD per sum take two
 * instructions more for each: the instruction count, not the cycles, is
 * the Cortex-M3's figure (docs/FIXED.md).  The same sums in C elsewhere.
 * The six registers are fixed because LDM fills its list in ascending
 * order; r7 is left out (the frame pointer of an unoptimised build), and
 * these six left the compiler's allocation around the calls the fewest
 * spills at -Os. */
static SPVS_Q_INLINE int64_t *acc3(int64_t *F, int32_t a0, int32_t b0, int32_t a1, int32_t b1,
                                   int32_t a2, int32_t b2)
{
#if defined(__GNUC__) && defined(__thumb2__) && !defined(__clang__)
    __asm__("ldm %[F], {r1, r2, r8, r9, r10, r11}\n\t"
            "smlal r1, r2, %[a0], %[b0]\n\t"
            "smlal r8, r9, %[a1], %[b1]\n\t"
            "smlal r10, r11, %[a2], %[b2]\n\t"
            "stmia %[F]!, {r1, r2, r8, r9, r10, r11}"
            : [F] "+r"(F), "+m"(*(int64_t(*)[3])F)
            : [a0] "r"(a0), [b0] "r"(b0), [a1] "r"(a1), [b1] "r"(b1), [a2] "r"(a2),
              [b2] "r"(b2)
            : "r1", "r2", "r8", "r9", "r10", "r11");
    return F;
#else
    F[0] += (int64_t)a0 * b0;
    F[1] += (int64_t)a1 * b1;
    F[2] += (int64_t)a2 * b2;
    return F + 3;
#endif
}

/* The squared Sampson error eps^T W eps = ex b1 + ey b2 of a point on the
 * fast path (SPVS_T_LIN's term 24 and the SPVS_T_SAMPSON sum, the same
 * bits in both), in Q(qr + 30): |ex|, |ey| <= 2^31 and |b1|, |b2| <= 2^30
 * (high words of sums below 2^62), so ex b1 + ey b2 (Q(qr + 40)) is at
 * most 2^62 in magnitude; 2^-10 of it (one constant 64-bit shift) is at
 * most 2^52, and a sum of 512 of them below 2^62. */
static SPVS_Q_INLINE int64_t lin_cost_term(const q_lw_t *o)
{
    return ((int64_t)o->ex * o->b1 + (int64_t)o->ey * o->b2) >> 10;
}

/* Where lin_fast keeps term 6 m + k (m = 0..2, k = 0..5) of the normal
 * matrix, a[m] q[k]: by columns of q (lin_fast_merge puts them back in
 * spvs_q_sums_t's order).  Terms 18-24 keep their places. */
#define LIN_COL(m, k) (3 * (k) + (m))

/* One point's SPVS_T_LIN terms on the fast path into F (in LIN_COL's
 * layout): terms 0-5 in Q(qr + 22), 6-11 in Q(qr + 20), 12-17 in
 * Q(qr + 18), 18-20 in Q(qr + 25), 21-23 in Q(qr + 23), 24 in Q(qr + 30).
 * Returns 0, leaving F as it was, when the point's residual is beyond the
 * path's range. */
/* Not inlined: in spvs_q_pts_sum's loop beside the exact path it gets
 * fewer registers (about 1 % more instructions on the M3 inlined). */
static SPVS_Q_NOINLINE int lin_fast(const int32_t *h, const int32_t *p, const q_lin_t *L,
                                    int64_t F[SPVS_H_LIN_SUMS])
{
    q_lw_t o;
    if (!lin_wt(h, p, L, &o)) {
        return 0;
    }
    const int32_t x = p[0], y = p[1], u = p[2], v = p[3];
    const int32_t w11 = o.w11, w12 = o.w12, w22 = o.w22, b1 = o.b1, b2 = o.b2;
    /* u and v times 16 (below 2^31 as |u|, |v| < 2): products with them
     * have in their high words the product 2^-28. */
    const int32_t u16 = u * 16, v16 = v * 16;
    F[24] += lin_cost_term(&o);
    /* The right side: b1, b2 in Q(qr + 4), b3 in Q(qr + 2). */
    const int32_t b3 = spvs_q_opaque32(-(int32_t)(((int64_t)u16 * b1 + (int64_t)v16 * b2) >> 32));
    const int32_t x21 = x >> 5, y21 = y >> 5;
    /* The normal matrix: uw = u w11 + v w12 and vw in Q(qr - 2). */
    const int32_t uw = spvs_q_opaque32((int32_t)(((int64_t)u16 * w11 + (int64_t)v16 * w12) >> 32));
    const int32_t vw = spvs_q_opaque32((int32_t)(((int64_t)u16 * w12 + (int64_t)v16 * w22) >> 32));
    const int32_t a0 = w11 >> 2, a1 = -(uw >> 2);
    const int32_t a2 = (int32_t)(((int64_t)u16 * uw + (int64_t)v16 * vw) >> 32) >> 2;
    /* F's layout (LIN_COL): the normal matrix by columns of q = (x^2,
     * x y, x, y^2, y, 1) in Q24, each column's three terms beside each
     * other, so that each q is made just before its three sums and is not
     * kept beside the others (acc3 steps through F); then the right side.
     * x 4 and y 4 (below 2^31 as x^2, y^2 < 2) give x^2 2^-28 as a high
     * word. */
    const int32_t x4 = x * 4, y4 = y * 4;
    int64_t *f = F;
    const int32_t qxx = (int32_t)(((int64_t)x4 * x4) >> 32);
    f = acc3(f, a0, qxx, a1, qxx, a2, qxx);
    const int32_t qxy = (int32_t)(((int64_t)x4 * y4) >> 32);
    f = acc3(f, a0, qxy, a1, qxy, a2, qxy);
    const int32_t qx = x >> 2;
    f = acc3(f, a0, qx, a1, qx, a2, qx);
    const int32_t qyy = (int32_t)(((int64_t)y4 * y4) >> 32);
    f = acc3(f, a0, qyy, a1, qyy, a2, qyy);
    const int32_t qy = y >> 2;
    f = acc3(f, a0, qy, a1, qy, a2, qy);
    f = acc3(f, a0, 1 << 24, a1, 1 << 24, a2, 1 << 24);
    f = acc3(f, b1, x21, b1, y21, b1, 1 << 21);
    (void)acc3(f, b3, x21, b3, y21, b3, 1 << 21);
    return 1;
}

/* ---- SPVS_T_FIT_Y and SPVS_T_FIT_X's fast path ------------------------------ */

/* The formats of a FIT sum's fast path (the two-stage linear fit's terms,
 * h_point.inc: q = sc (x, y, 1), sc = v / w or 1 / w, r = y / w or u),
 * from the frame's bounds and row 3 of H.  Per point: w as for SPVS_T_LIN,
 * 1 / w by one CLZ and q_recip_fast in Q28; sc in Q26 as a high word (v
 * times 16, below 2^31 as |v| < 2); then, with 32-bit shifts fixed for the
 * set, sc 2^a and the coordinates 2^b (each below 2^31) whose products'
 * high words are q0, q1 in Q(qq), q2 = sc in Q(qq), r in Q(qr).  qq and qr
 * are the largest that keep |q| and |r| below 2^26, so each product below
 * 2^52 and a sum of up to 512 of them below 2^61.  ok = 0 where the bounds
 * fail (w outside [1/4, 16) over the set, |u|, |v| or |x|, |y| of 2 or
 * more, n > 512): every point takes the exact path. */
typedef struct {
    int ok;
    int a, b;         /* the left shifts of sc and of x, y */
    int s2l, s2r;     /* sc into Q(qq): left, then right (one of them 0) */
    int srl, srr;     /* r into Q(qr) likewise */
    int32_t qq, qr;   /* the formats */
    int32_t h6, h7;   /* h31, h32 (Q27): w's, read with the formats */
    int64_t h8c;      /* h33 2^26, Q53 */
} q_fit_t;

static q_fit_t fit_prep_b(int kind, const q_box_t *bx_, const int32_t *h, uint16_t n)
{
    q_fit_t F;
    F.ok = 0;
    F.a = F.b = F.s2l = F.s2r = F.srl = F.srr = 0;
    F.qq = F.qr = 0;
    const int64_t one26 = (int64_t)1 << 26;
    F.h8c = (int64_t)h[8] * one26;
    F.h6 = h[6];
    F.h7 = h[7];
    const int64_t X = bx_->X, Y = bx_->Y;
    const int64_t U = bx_->U, V = bx_->V;
    const int64_t two27 = (int64_t)1 << 27;
    if (n > 512u || U >= two27 || V >= two27 || X >= two27 || Y >= two27) {
        return F;
    }
    const int64_t w_lo = bx_->w_lo, w_hi = bx_->w_hi;
    if (w_lo < ((int64_t)1 << 51) || w_hi >= ((int64_t)1 << 57)) {
        return F;
    }
    /* Bounds as powers of two: 1 / w < 2^(28 - bw), |sc| < 2^lsc,
     * max(|x|, |y|, 1) <= 2^lc, |r| < 2^lr. */
    const int bw = spvs_q_bitlen64((uint64_t)(w_lo >> 26));
    const int fy = kind == SPVS_T_FIT_Y;
    const int lsc = fy ? spvs_q_bitlen64((uint64_t)V) - bw + 2 : 28 - bw;
    const int bx = spvs_q_bitlen64((uint64_t)(X > Y ? X : Y));
    const int lc = bx > 26 ? bx - 26 : 0;
    const int lr = fy ? spvs_q_bitlen64((uint64_t)Y) - bw + 2 : spvs_q_bitlen64((uint64_t)U) - 26;
    const int lq = lsc + lc;
    F.qq = 26 - lq;
    F.qr = 26 - lr;
    /* hi((sc 2^a) (x 2^b)) = q0 in Q(26 + 26 + a + b - 32): a + b = qq - 20,
     * with sc 2^a < 2^(31) (a <= 5 - lsc) and x 2^b < 2^31 (b <= 31 - bx). */
    F.a = 5 - lsc;
    F.b = F.qq - 20 - F.a;
    const int s2 = F.qq - 26, sr = F.qr - 26;
    if (F.a < 0 || F.b < 0 || F.b > 31 - bx || s2 < -31 || s2 > 31 || sr < -31 || sr > 31) {
        return F;
    }
    F.s2l = s2 > 0 ? s2 : 0;
    F.s2r = s2 < 0 ? -s2 : 0;
    F.srl = sr > 0 ? sr : 0;
    F.srr = sr < 0 ? -sr : 0;
    F.ok = 1;
    return F;
}

/* fit_prep_b's formats for the flagged points, from the frame's box or
 * their own, as lin_prep. */
static SPVS_Q_NOINLINE q_fit_t fit_prep(int kind, const spvs_q_store_t *st, const int32_t *h,
                                        const uint8_t *use, uint16_t n)
{
    q_box_t b = box_of(st->tgt_max, st->cur_max, h);
    q_fit_t F = fit_prep_b(kind, &b, h, n);
    if (!F.ok && use != NULL) {
        b = box_used(st, h, use, n);
        F = fit_prep_b(kind, &b, h, n);
    }
    return F;
}

/* One point's FIT terms on the fast path into G: terms 0-5 in Q(2 qq),
 * 6-8 in Q(qq + qr). */
static SPVS_Q_INLINE void fit_fast(int kind, const int32_t *p, const q_fit_t *F, int64_t G[9])
{
    const int32_t x = p[0], y = p[1];
    const int64_t w = q_w(F->h8c, F->h6, F->h7, p);
    const int32_t w27 = (int32_t)(w >> 26); /* in [2^25, 2^31) */
    /* 1 / w: w27 2^(n - 1) in [2^30, 2^31), so 1 / w = r 2^(n - 35), and in
     * Q28 r 2^(n - 7) with n in 1..6: 1 / w to 2^-28 absolute, at least 24
     * bits (w below 16). */
    const int nz = spvs_q_clz32((uint32_t)w27);
    const int32_t r = q_recip_fast((uint32_t)w27 << (nz - 1));
    const int32_t iw = r >> (7 - nz); /* Q28, below 2^30 */
    const int32_t sc = kind == SPVS_T_FIT_Y
                           ? spvs_q_opaque32((int32_t)(((int64_t)(p[3] * 16) * iw) >> 32))
                           : iw >> 2; /* Q26 */
    const int32_t rr = kind == SPVS_T_FIT_Y
                           ? spvs_q_opaque32((int32_t)(((int64_t)(y * 16) * iw) >> 32))
                           : p[2]; /* Q26 */
    /* The shifts keep the values below 2^31 (fit_prep), so the unsigned
     * left shifts are the products by powers of two. */
    const int32_t sca = (int32_t)((uint32_t)sc << F->a);
    const int32_t xb = (int32_t)((uint32_t)x << F->b), yb = (int32_t)((uint32_t)y << F->b);
    const int32_t q0 = spvs_q_opaque32((int32_t)(((int64_t)sca * xb) >> 32));
    const int32_t q1 = spvs_q_opaque32((int32_t)(((int64_t)sca * yb) >> 32));
    const int32_t q2 = (int32_t)((uint32_t)sc << F->s2l) >> F->s2r;
    const int32_t rq = (int32_t)((uint32_t)rr << F->srl) >> F->srr;
    int64_t *g = acc3(G, q0, q0, q0, q1, q0, q2);
    g = acc3(g, q1, q1, q1, q2, q2, q2);
    (void)acc3(g, q0, rq, q1, rq, q2, rq);
}

/* fit_fast over the flagged points among the first n, for one kind (a
 * constant at each call, so each kind gets its own loop).  Returns the
 * number of flagged points.  Bound: n points. */
static SPVS_Q_INLINE int32_t fit_all(int kind, const spvs_q_store_t *st, const uint8_t *use,
                                     uint16_t n, const q_fit_t *F, int64_t G[9])
{
    int32_t cnt = 0;
    for (uint16_t i = 0; i < n; i++) {
        if (use[i]) {
            fit_fast(kind, &st->v[4u * i], F, G);
            cnt++;
        }
    }
    return cnt;
}

/* fit_all for each kind, out of line: the loop's values then have the
 * registers to themselves rather than spvs_q_pts_sum's. */
static SPVS_Q_NOINLINE int32_t fit_all_y(const spvs_q_store_t *st, const uint8_t *use,
                                         uint16_t n, const q_fit_t *F, int64_t G[9])
{
    return fit_all(SPVS_T_FIT_Y, st, use, n, F, G);
}

static SPVS_Q_NOINLINE int32_t fit_all_x(const spvs_q_store_t *st, const uint8_t *use,
                                         uint16_t n, const q_fit_t *F, int64_t G[9])
{
    return fit_all(SPVS_T_FIT_X, st, use, n, F, G);
}

int spvs_q_sum_fast(spvs_terms_t kind, const spvs_q_store_t *st, const int32_t Hq[9],
                    uint16_t n)
{
    if (kind == SPVS_T_LIN || kind == SPVS_T_SAMPSON) {
        return lin_prep(st, Hq, NULL, n).ok;
    }
    return kind == SPVS_T_FIT_Y || kind == SPVS_T_FIT_X ? fit_prep((int)kind, st, Hq, NULL, n).ok
                                                        : 0;
}

/* Adds a fast path's sums F (s->nt of them, block b's exponent e0, e1 or
 * e2) into the BFP sums s (sub = 0), or subtracts them (sub = 1): each
 * block at the larger exponent, one more where a result would reach 2^62
 * (both operands are below 2^62, so the result is below 2^63).  F's
 * share is rounded before its sign is applied, so subtracting what was
 * added at the same exponents undoes it exactly.  Empty blocks are left
 * as they are. */
/* One block of lin_merge: m[j] 2^-ds + F[j] 2^-df (sub = 0) or minus it
 * (sub = 1), each shift rounded, for j < n; returns 1 when a result
 * reached 2^62 in magnitude (the bits at or above 62 of their
 * magnitudes, ORed).  No call where the shift or the value is 0 (the
 * common cases: a fresh s, F at the larger exponent).  Bound: n <= 25. */
static SPVS_Q_INLINE int merge_run(int64_t *m, const int64_t *F, int n, int ds, int df, int sub)
{
    uint64_t mag = 0;
    /* The common case, F at the larger exponent and m at it too or all 0
     * (a fresh s), in a loop that calls nothing. */
    uint64_t any = 0;
    for (int j = 0; j < n && ds != 0; j++) {
        any |= (uint64_t)m[j];
    }
    if (df == 0 && (ds == 0 || any == 0u)) {
        for (int j = 0; j < n; j++) {
            const int64_t r = m[j] + (sub ? -F[j] : F[j]);
            m[j] = r;
            mag |= spvs_q_abs64(r);
        }
        return mag >= ((uint64_t)1 << 62);
    }
    for (int j = 0; j < n; j++) {
        int64_t f = df == 0 ? F[j] : spvs_q_rshift_rnd64(F[j], df);
        if (sub) {
            f = -f;
        }
        const int64_t mj = m[j];
        const int64_t r = (ds == 0 || mj == 0 ? mj : spvs_q_rshift_rnd64(mj, ds)) + f;
        m[j] = r;
        mag |= spvs_q_abs64(r);
    }
    return mag >= ((uint64_t)1 << 62);
}

static void lin_merge(spvs_q_sums_t *s, const int64_t *F, int32_t e0, int32_t e1, int32_t e2,
                      int sub)
{
    for (int b = 0; b < 3; b++) {
        int lo, hi;
        blk_range(s, b, &lo, &hi);
        if (lo >= hi) {
            continue;
        }
        const int32_t eFb = b == 0 ? e0 : (b == 1 ? e1 : e2);
        const int32_t e = s->e[b] > eFb ? s->e[b] : eFb;
        const int ds = (int)(e - s->e[b] > 63 ? 63 : e - s->e[b]);
        const int df = (int)(e - eFb > 63 ? 63 : e - eFb);
        /* The sums (each below 2^63 in magnitude, so int64 holds them),
         * then, only where one reached 2^62, the block one bit down: the
         * same as rounding each sum once by one bit. */
        const int big = merge_run(&s->m[lo], &F[lo], hi - lo, ds, df, sub);
        if (big) {
            for (int j = lo; j < hi; j++) {
                s->m[j] = spvs_q_rshift_rnd64(s->m[j], 1);
            }
        }
        s->e[b] = e + big;
    }
}


/* One point's squared Sampson error on the fast path into *acc
 * (lin_cost_term, Q(qr + 30)); 0, leaving *acc as it was, when the
 * point's residual is beyond the path's range.  Not inlined, as
 * lin_fast. */
static SPVS_Q_NOINLINE int sampson_fast(const int32_t *h, const int32_t *p, const q_lin_t *L,
                                        int64_t *acc)
{
    q_lw_t o;
    if (!lin_wt(h, p, L, &o)) {
        return 0;
    }
    *acc += lin_cost_term(&o);
    return 1;
}


/* lin_fast's sums F (formats of qr, LIN_COL's layout) into s, added
 * (sub = 0) or subtracted (sub = 1).  One exponent per block: terms 0-11
 * and 18-20 brought to the units of 12-17 and 21-23 first (they are below
 * 2^62 before, as are these); term 24 is a block of its own. */
static void lin_fast_merge(spvs_q_sums_t *s, const int64_t F[SPVS_H_LIN_SUMS], int32_t qr,
                           int sub)
{
    int64_t G[SPVS_H_LIN_SUMS];
    for (int k = 0; k < 6; k++) {
        G[k] = spvs_q_rshift_rnd64(F[LIN_COL(0, k)], 4);
        G[6 + k] = spvs_q_rshift_rnd64(F[LIN_COL(1, k)], 2);
        G[12 + k] = F[LIN_COL(2, k)];
    }
    for (int j = 18; j < 21; j++) {
        G[j] = spvs_q_rshift_rnd64(F[j], 2);
    }
    for (int j = 21; j < SPVS_H_LIN_SUMS; j++) {
        G[j] = F[j];
    }
    lin_merge(s, G, -(qr + 18), -(qr + 23), -(qr + 30), sub);
}


/* SPVS_T_SAMPSON's sum: the points in SPVS_T_LIN's fast-path range (the
 * same bounds, lin_prep) through sampson_fast, the others num / den from
 * their exact residuals (spvs_q_sampson_term).  Returns the number of flagged
 * points, or -1 at the first with w <= SPVS_W_EPS.  Not inlined: its
 * frame stays out of spvs_q_pts_sum's.  Bound: n points. */
static SPVS_Q_NOINLINE int32_t sampson_sum(const int32_t *h, const spvs_q_store_t *st,
                                           const uint8_t *use, uint16_t n, spvs_q_sums_t *out)
{
    const q_lin_t L = lin_prep(st, h, use, n);
    int64_t F = 0;
    int32_t used = 0, exact = 0;
    /* L.ok tested once (as spvs_q_pts_sum's LIN loop).  Bound: n points. */
    if (L.ok) {
        for (uint16_t i = 0; i < n; i++) {
            if (!use[i]) {
                continue;
            }
            const int32_t *p = &st->v[4u * i];
            used++;
            /* w >= 1/4 on the fast path: never behind the camera. */
            if (!sampson_fast(h, p, &L, &F)) {
                if (!spvs_q_sampson_exact(h, p, out)) {
                    return -1;
                }
                exact++;
            }
        }
    } else {
        for (uint16_t i = 0; i < n; i++) {
            if (!use[i]) {
                continue;
            }
            used++;
            if (!spvs_q_sampson_exact(h, &st->v[4u * i], out)) {
                return -1;
            }
        }
        exact = used;
    }
    if (used > exact) {
        lin_merge(out, &F, -(L.qr + 30), 0, 0, 0);
    }
    return used;
}


int32_t spvs_q_pts_sum(spvs_terms_t kind, const int32_t Hq[9], const spvs_q_store_t *st,
                       const uint8_t *use, uint16_t n, spvs_q_sums_t *out)
{
    if (spvs_q_sums_clear(kind, out) != 0) {
        return -2;
    }
    const int lin = kind == SPVS_T_LIN, samp = kind == SPVS_T_SAMPSON;
    if (samp) {
        return sampson_sum(Hq, st, use, n, out);
    }
    int32_t used = 0;
    /* SPVS_T_LIN: the points in the fast path's range into F, the others
     * through the exact terms; merged at the end. */
    const q_lin_t L = lin ? lin_prep(st, Hq, use, n) : (q_lin_t){0};
    const q_fit_t FT = lin ? (q_fit_t){0} : fit_prep((int)kind, st, Hq, use, n);
    if (FT.ok) {
        /* Every point on the fast path (w >= 1/4: none behind the camera). */
        int64_t G[SPVS_NT_FIT] = {0};
        const int32_t cnt = kind == SPVS_T_FIT_Y ? fit_all_y(st, use, n, &FT, G)
                                                 : fit_all_x(st, use, n, &FT, G);
        lin_merge(out, G, -2 * FT.qq, -(FT.qq + FT.qr), 0, 0);
        return kind == SPVS_T_FIT_X ? 0 : cnt;
    }
    int64_t F[SPVS_H_LIN_SUMS] = {0};
    int32_t exact = 0;
    /* Bound: n points.  L.ok is tested once, so that the fast path's
     * points pay only for lin_fast's call. */
    if (L.ok) {
        for (uint16_t i = 0; i < n; i++) {
            if (!use[i]) {
                continue;
            }
            const int32_t *p = &st->v[4u * i];
            used++;
            /* w >= 1/4 on the fast path: never behind the camera. */
            if (!lin_fast(Hq, p, &L, F)) {
                if (!spvs_q_sum_exact_point((int)kind, Hq, p, out)) {
                    return -1;
                }
                exact++;
            }
        }
    } else {
        for (uint16_t i = 0; i < n; i++) {
            if (!use[i]) {
                continue;
            }
            used++;
            if (!spvs_q_sum_exact_point((int)kind, Hq, &st->v[4u * i], out)) {
                return -1;
            }
        }
        exact = used;
    }
    if (used > exact) {
        lin_fast_merge(out, F, L.qr, 0);
    }
    return kind == SPVS_T_FIT_X ? 0 : used;
}


/* spvs_q_lin_move's fast path: the point's terms by lin_fast, in the
 * formats lin_prep gives a frame of this one point (its own w bounds the
 * weights), merged into s.  0 (s unchanged) where the point is outside
 * the path's range.  Not inlined: its frame (F) stays out of the exact
 * path's. */
static SPVS_Q_NOINLINE int lin_move_fast(const int32_t *h, const int32_t *p, spvs_q_sums_t *s,
                                         int sub)
{
    /* |p| <= 2^30 (the store's range): the negations cannot overflow. */
    const int32_t tm[2] = {p[0] < 0 ? -p[0] : p[0], p[1] < 0 ? -p[1] : p[1]};
    const int32_t cm[2] = {p[2] < 0 ? -p[2] : p[2], p[3] < 0 ? -p[3] : p[3]};
    const q_box_t b = box_of(tm, cm, h);
    const q_lin_t L = lin_prep_b(&b, h, 1);
    int64_t F[SPVS_H_LIN_SUMS] = {0};
    if (!L.ok || !lin_fast(h, p, &L, F)) {
        return 0;
    }
    lin_fast_merge(s, F, L.qr, sub);
    return 1;
}


int spvs_q_lin_move(const int32_t Hw[9], const int32_t p[4], int add, spvs_q_sums_t *s)
{
    const int sub = add ? 0 : 1;
    /* The same path for the same point and weights, so a removal undoes
     * the add that came before it.  The fast path's range has w >= 1/4. */
    if (lin_move_fast(Hw, p, s, sub)) {
        return 1;
    }
    return spvs_q_lin_move_exact(Hw, p, sub, s);
}
