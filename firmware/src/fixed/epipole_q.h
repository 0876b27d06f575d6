/*
 * epipole_q.h - the epipole from plane plus parallax in fixed point: the
 * estimator of epipole.h on Q26 points and a Q27 H (private; formats and
 * ranges in docs/FIXED.md).  Also the per-point transfer and the integer
 * square roots that the off-plane stage (offplane_q.h) shares.
 *
 * The flow, the bounds and the statuses are epipole.inc's (shared with
 * epipole.c): one line direction per candidate, a 1-point consensus over at most
 * SPVS_EPIPOLE_MAX_HYP hypotheses, the median angle of the supporters
 * around the best one, e_x clamped at SPVS_EPIPOLE_MAX_PX, the median
 * parallax of the supporters.
 *
 * Formats (value = integer 2^-f):
 *   points        Q26 scaled units (the Q store's rows), |c| <= 16;
 *   H             Q27 scaled units, h22 = 1, every entry in (-16, 16);
 *   q = H p_tgt   exact in int64 Q53 (|q| < 528), then per point rounded
 *                 to Q(53 - s) with s the least shift that brings
 *                 max(|q1|, |q2|, |q3|) to 2^30 or below (s in 0..33): a
 *                 per-point scale, which the line's direction and the
 *                 transfer's ratio do not see;
 *   lines         l = p_cur x q in int64 Q(79 - s), exact on the rounded q
 *                 (each product below 2^60, each sum below 2^61);
 *   directions    unit vectors in Q30 (|u| within 2^-27 of 1), from an
 *                 integer reciprocal square root; the epipole itself is
 *                 such a direction (dir_x, dir_z), so an epipole at
 *                 infinity (dir_z = 0) is representable;
 *   sines         cross products of unit vectors, Q30;
 *   transfer      du, dv in Q26 scaled units (Q17 pixels), saturated at
 *                 |.| < 2^31 (32 scaled units, 16,384 px);
 *   pixels out    e_x and the parallax in Q16 pixels: |e_x| <= 20,000 px
 *                 (SPVS_EPIPOLE_MAX_PX), parallax below 2^15 px.
 * Nothing here reads a float; thresholds come in Q (the caller converts
 * them once per frame, e.g. with spvs_q_from_ieee).
 */
#ifndef SPVS_FIXED_EPIPOLE_Q_H
#define SPVS_FIXED_EPIPOLE_Q_H

#include "points_q.h"

/* SPVS_EPIPOLE_MAX_PX (20,000 px) as an integer, and in Q16 pixels. */
#define SPVS_Q_EPIPOLE_MAX_PX 20000
#define SPVS_Q_EPIPOLE_MAX_Q16 ((int32_t)SPVS_Q_EPIPOLE_MAX_PX << 16)
/* One pixel in Q16. */
#define SPVS_Q16_ONE 65536

typedef struct {
    int32_t e_x_q16;      /* x of the epipole, Q16 centred pixels, clamped */
    int32_t dir_x;        /* signed direction of (e_x, e_z), Q30 unit      */
    int32_t dir_z;        /*   dir_z > 0: the target is in front           */
    int32_t parallax_q16; /* median |p_cur - H p_tgt| of the supporters,   */
                          /*   Q16 pixels (0 when none has w > 0)          */
    uint16_t n_support;   /* candidates that agree with the estimate       */
} spvs_q_epipole_t;

/* Caller-owned scratch for one estimate (off the stack): the candidates'
 * unit directions, u[i] = (x, z), side by side so that one load reads
 * both, and a zero one after an odd count (the consensus reads two a
 * step); then (written behind the reads) the supporters' sines in u[k][0]
 * and parallaxes in u[k][1].  One entry more than the candidates, which
 * the consensus's moving end may point one past before it is capped. */
typedef struct {
    int32_t u[SPVS_MAX_OFFPLANE + 1][2];
} spvs_q_epipole_work_t;

/* spvs_epipole_estimate in fixed point.
 * H:           Q27, scaled units, h22 = 1 (every entry in (-16, 16)).
 * pts:         the frame's points as rows, Q26 scaled units.
 * cand:        indices of the candidates (n_cand <= SPVS_MAX_OFFPLANE).
 * sin_tol2_q30: the squared sine of the support cone, Q30, in [0, 2^31)
 *              (float's sin_tol2 converted once: spvs_q_from_ieee(.., 30)).
 * min_support, support_out, the statuses: as spvs_epipole_estimate's
 * (SPVS_OK, SPVS_E_ARG, SPVS_E_NO_PARALLAX for too few candidates or
 * supporters, or all candidates on the horizon row).  A clamped e_x is
 * SPVS_OK as in float.
 * Bounds: n_cand directions, SPVS_EPIPOLE_MAX_HYP x n_cand pair tests,
 * two insertion sorts of at most n_cand int32. */
SPVS_NODISCARD int spvs_q_epipole_estimate(const int32_t H[9], const int32_t (*pts)[4],
                                           const uint16_t *cand, uint16_t n_cand,
                                           int32_t sin_tol2_q30, uint16_t min_support,
                                           spvs_q_epipole_t *out, uint8_t *support_out,
                                           spvs_q_epipole_work_t *work);

/* ---- shared with offplane_q.c ---------------------------------------------- */

/* SPVS_W_EPS (1e-6) in Q53, rounded down (points_q.c's constant). */
#define SPVS_Q_W_EPS_Q53 ((int64_t)9007199254)

/* x 2^-s rounded to nearest (ties up) for s in 0..63, inline (the
 * per-point shifts; q.h's spvs_q_rshift_rnd64 is a call at -Os).  With
 * y = floor(x 2^(1 - s)), floor(x 2^-s + 1/2) = ceil(y / 2) = (y >> 1) +
 * (y & 1): one shift by a variable amount (a 64-bit one is several
 * instructions on the Cortex-M3) and one by 1, and nothing overflows. */
static SPVS_Q_INLINE int64_t spvs_q_rsh(int64_t x, int s)
{
    if (s == 0) {
        return x;
    }
    const int64_t y = x >> (s - 1);
    return (y >> 1) + (y & 1);
}

/* spvs_q_rsh where the result is known to fit: |x| < 2^(30 + s), s in
 * 0..33, so floor(x 2^-(s - 1)) lies within int32 and is the low word of
 * the 64-bit shift, made from x's two words with 32-bit shifts (the
 * 64-bit shift by a variable amount costs about twice as many
 * instructions on the Cortex-M3).  The same value as spvs_q_rsh. */
static SPVS_Q_INLINE int32_t spvs_q_rsh32(int64_t x, int s)
{
    const uint32_t lo = (uint32_t)x;
    const uint32_t hi = (uint32_t)(x >> 32);
    if (s == 0) {
        return (int32_t)lo;
    }
    const int n = s - 1;
    const uint32_t y = n == 0 ? lo : (n >= 32 ? hi : (lo >> n) | (hi << (32 - n)));
    const int32_t yi = (int32_t)y;
    return (yi >> 1) + (yi & 1);
}

/* Bits of the magnitude m (0 for 0), inline: one or two CLZ. */
static SPVS_Q_INLINE int spvs_q_bits(uint64_t m)
{
    const uint32_t hi = (uint32_t)(m >> 32);
    return hi != 0u ? 64 - spvs_q_clz32(hi) : 32 - spvs_q_clz32((uint32_t)m);
}

/* 2^61 / m for m in [2^30, 2^31), within 2^-28 relative, in (2^30, 2^31]:
 * a 32-bit division of 2^32 - 1 by m's top 16 bits (relative error below
 * 2^-15, one UDIV) and one Newton step y (2 - m y 2^-61), which squares
 * it (2^-30) plus the step's truncations (2^-30).  The deviation m y0 -
 * 2^61 is below 2^47 in magnitude, so its top bits (>> 29) fit 18 bits
 * and their product with y0 49 bits. */
static SPVS_Q_INLINE uint32_t spvs_q_recip31(uint32_t m)
{
    const uint32_t y0 = (0xFFFFFFFFu / (m >> 15)) << 14;
    const int64_t dev = (int64_t)((uint64_t)m * y0) - ((int64_t)1 << 61);
    const int32_t d29 = spvs_q_opaque32((int32_t)(dev >> 29));
    const int64_t y1 = (int64_t)y0 - (((int64_t)spvs_q_opaque32((int32_t)y0) * d29) >> 32);
    return y1 > (int64_t)0x80000000u ? 0x80000000u : (uint32_t)y1;
}

/* q = H p_tgt of row p: w exact (Q53) and q rounded to Q(53 - s). */
typedef struct {
    int64_t w;
    int32_t q1, q2, q3;
    int32_t s;
} spvs_q_hp_t;

/* Ranges: |h| < 2^31, |p| <= 2^30, so each product is below 2^61 and w,
 * g = h1 . p below 2^62 + 2^57; y 2^27 is below 2^57. */
static SPVS_Q_INLINE spvs_q_hp_t spvs_q_hp(const int32_t H[9], const int32_t p[4])
{
    spvs_q_hp_t r;
    r.w = (int64_t)H[6] * p[0] + (int64_t)H[7] * p[1] + (int64_t)H[8] * ((int64_t)1 << 26);
    const int64_t g = (int64_t)H[0] * p[0] + (int64_t)H[1] * p[1] +
                      (int64_t)H[2] * ((int64_t)1 << 26);
    const int64_t y = (int64_t)p[1] * ((int64_t)1 << 27);
    const uint64_t m = spvs_q_abs64(r.w) | spvs_q_abs64(g) | spvs_q_abs64(y);
    const int b = spvs_q_bits(m);
    r.s = b > 30 ? b - 30 : 0;
    /* Each |q| <= 2^30 after the rounding (a magnitude below 2^30 2^s
     * rounds to at most 2^30). */
    r.q1 = spvs_q_rsh32(g, r.s);
    r.q2 = spvs_q_rsh32(y, r.s);
    r.q3 = spvs_q_rsh32(r.w, r.s);
    return r;
}

/* A transfer component q_k / w - c in Q26 from n = q_k - c w (Q(26 + f))
 * and 1 / w = r 2^(k - 61) (w in Qf): n31 r 2^(k - 61 + t) with n = n31
 * 2^t, saturated at +-(2^31 - 1) (32 scaled units). */
static SPVS_Q_INLINE int32_t spvs_q_ratio(int32_t n31, uint32_t r, int sh)
{
    const int64_t v = spvs_q_rsh((int64_t)n31 * r, sh);
    return v > SPVS_Q_I32_MAX ? SPVS_Q_I32_MAX : (v < -SPVS_Q_I32_MAX ? -SPVS_Q_I32_MAX : (int32_t)v);
}

/* The general path of spvs_q_transfer: q rounded per point (spvs_q_hp),
 * the numerators exact on it (Q(79 - s)) and rounded to 30 bits. */
static SPVS_Q_INLINE void spvs_q_transfer_gen(const int32_t H[9], const int32_t p[4], int32_t *du,
                                              int32_t *dv)
{
    const spvs_q_hp_t h = spvs_q_hp(H, p);
    /* w > 2^33 and s <= 33 (the largest |q| is below 2^63), so q3 >= 1. */
    const int64_t nx = (int64_t)h.q1 * ((int64_t)1 << 26) - (int64_t)p[2] * h.q3;
    const int64_t ny = (int64_t)h.q2 * ((int64_t)1 << 26) - (int64_t)p[3] * h.q3;
    const int bn = spvs_q_bits(spvs_q_abs64(nx) | spvs_q_abs64(ny));
    const int t = bn > 30 ? bn - 30 : 0;
    const int k = spvs_q_clz32((uint32_t)h.q3) - 1;
    const uint32_t r = spvs_q_recip31((uint32_t)h.q3 << k); /* 1/q3 = r 2^(k-61) */
    /* nx / q3 = nx30 r 2^(t + k - 61), with t <= 31 (|nx| < 2^61) and
     * k <= 30: the shift is not negative, the product at most 2^61. */
    *du = spvs_q_ratio((int32_t)spvs_q_rsh(nx, t), r, 61 - t - k);
    *dv = spvs_q_ratio((int32_t)spvs_q_rsh(ny, t), r, 61 - t - k);
}

/* The fast path's ratio n28 / w28 in Q26 with 1 / w28 = r 2^(k - 61):
 * the product n28 r shifted by a constant 30, rounded (n28 r < 2^61, so
 * it stays below 2^31), is the ratio in Q(31 - k) units, brought to Q26
 * by 5 - k: rounded right for k <= 5 (w28 >= 2^25, w >= 1/8), left and
 * saturated at +-(2^31 - 1) beyond (exact).  Error at most 1/2 unit of
 * Q(31 - k) plus 1/2 unit of Q26 for k < 5. */
static SPVS_Q_INLINE int32_t spvs_q_ratio_fast(int32_t n28, int32_t r, int k)
{
    const int32_t hi = (int32_t)(((int64_t)n28 * r + ((int64_t)1 << 29)) >> 30);
    if (k <= 5) {
        return k == 5 ? hi : (hi >> (5 - k)) + ((hi >> (4 - k)) & 1);
    }
    const int up = k - 5;
    const int32_t lim = SPVS_Q_I32_MAX >> up;
    return hi > lim ? SPVS_Q_I32_MAX : (hi < -lim ? -SPVS_Q_I32_MAX : hi * (1 << up));
}

/* spvs_q_transfer's first half, shared with the off-plane stage's
 * threshold test: w and g exact in Q53, SPVS_Q_TF_BEHIND for w <=
 * SPVS_W_EPS, SPVS_Q_TF_GEN where the fast path's bounds fail, else
 * SPVS_Q_TF_FAST with its Q28 values (below). */
#define SPVS_Q_TF_BEHIND 0
#define SPVS_Q_TF_FAST 1
#define SPVS_Q_TF_GEN 2
typedef struct {
    int32_t nx28, ny28; /* the numerators n 2^-26 rounded, |.| <= 2^30 */
    int32_t w28;        /* w in Q28, in (2^8, 2^30)                     */
} spvs_q_tf_t;

/* spvs_q_transfer_front on the row's values (target x, y, current x, y),
 * for a caller that also takes the row the other way round. */
static SPVS_Q_INLINE int spvs_q_transfer_front_v(const int32_t H[9], int32_t tx, int32_t ty,
                                                 int32_t cx, int32_t cy, spvs_q_tf_t *f)
{
    const int64_t w = (int64_t)H[6] * tx + (int64_t)H[7] * ty + (int64_t)H[8] * ((int64_t)1 << 26);
    if (w <= SPVS_Q_W_EPS_Q53) {
        return SPVS_Q_TF_BEHIND;
    }
    const int64_t g = (int64_t)H[0] * tx + (int64_t)H[1] * ty + (int64_t)H[2] * ((int64_t)1 << 26);
    const int64_t b55 = (int64_t)1 << 55, b56 = (int64_t)1 << 56;
    if (w < b55 && (uint64_t)(g + b55) < (uint64_t)b55 * 2u) {
        const int32_t w28 = spvs_q_opaque32((int32_t)((w + ((int64_t)1 << 24)) >> 25));
        const int32_t g28 = (int32_t)((g + ((int64_t)1 << 24)) >> 25);
        /* Q54: |g28 2^26| < 2^56, |x_cur w28| < 2^60. */
        const int64_t nx = (int64_t)g28 * ((int64_t)1 << 26) - (int64_t)cx * w28;
        /* 2^28 opaque: ny two multiplies rather than a 64-bit shift and a
         * multiply. */
        const int64_t ny = (int64_t)ty * spvs_q_opaque32((int32_t)1 << 28) - (int64_t)cy * w28;
        if ((uint64_t)(nx + b56) < (uint64_t)b56 * 2u && (uint64_t)(ny + b56) < (uint64_t)b56 * 2u) {
            f->w28 = w28;
            f->nx28 = spvs_q_opaque32((int32_t)((nx + ((int64_t)1 << 25)) >> 26));
            f->ny28 = spvs_q_opaque32((int32_t)((ny + ((int64_t)1 << 25)) >> 26));
            return SPVS_Q_TF_FAST;
        }
    }
    return SPVS_Q_TF_GEN;
}

static SPVS_Q_INLINE int spvs_q_transfer_front(const int32_t H[9], const int32_t p[4],
                                               spvs_q_tf_t *f)
{
    return spvs_q_transfer_front_v(H, p[0], p[1], p[2], p[3], f);
}

/* The fast path's second half: 1 / w28 = r 2^(k - 61) with k in 0..22,
 * r clamped below 2^31 (2^-31 relative); n28 / w28 in Q26 is
 * n28 r 2^(k - 35): spvs_q_ratio_fast. */
static SPVS_Q_INLINE void spvs_q_transfer_fast(const spvs_q_tf_t *f, int32_t *du, int32_t *dv)
{
    const int k = spvs_q_clz32((uint32_t)f->w28) - 1;
    const uint32_t r0 = spvs_q_recip31((uint32_t)f->w28 << k);
    const int32_t r = spvs_q_opaque32(r0 > 0x7FFFFFFFu ? 0x7FFFFFFF : (int32_t)r0);
    *du = spvs_q_ratio_fast(f->nx28, r, k);
    *dv = spvs_q_ratio_fast(f->ny28, r, k);
}

/* The transfer residual (du, dv) = H p_tgt / w - p_cur of row p in Q26
 * scaled units, saturated at +-(2^31 - 1) (32 scaled units); 0 when
 * w <= SPVS_W_EPS (float's spvs_h_transfer_err2 returns -1 there), else 1.
 * w and g = h1 . p are exact in Q53.  The fast path (|w|, |g| below
 * 2^55, 4 scaled units, and the numerators n = g - x_cur w, y - y_cur w
 * below 4 scaled units, 2,048 px: every image point of a planar-motion
 * H, mismatches included) takes w and g to Q28 by one constant shift
 * (|.| < 2^30, w28 >= 2^8 since w > 2^33), n = g28 2^26 - x_cur w28
 * (Q54, exact on them, 32 x 32-bit products) to Q28 by another, and
 * 1 / w28 from spvs_q_recip31 after one CLZ (spvs_q_ratio_fast): no
 * 64-bit shift by a per-point amount.  Error: w28, g28, n28 within 2^-29,
 * so |du| moves by at most 2^-29 (1 + |x_cur| + 1 + |du|) / w, plus
 * 2^-28 |du| (the reciprocal) and the rounding to Q26: about 3e-6 px for
 * w ~ 1 in the image, 8e-6 px at w = 1/2
 * (measured in test_fixed_epipole).  Elsewhere the general path (spvs_q_transfer_gen):
 * q per point to 30 bits, its rounding (2^-31 of max |q|) moving du by
 * at most 2^-30 max(1, |u|, |v|) (1 + |x_cur| + |du|). */
static SPVS_Q_INLINE int spvs_q_transfer(const int32_t H[9], const int32_t p[4], int32_t *du,
                                         int32_t *dv)
{
    spvs_q_tf_t f;
    const int path = spvs_q_transfer_front(H, p, &f);
    if (path == SPVS_Q_TF_BEHIND) {
        return 0;
    }
    if (path == SPVS_Q_TF_FAST) {
        spvs_q_transfer_fast(&f, du, dv);
    } else {
        spvs_q_transfer_gen(H, p, du, dv);
    }
    return 1;
}

/* One Newton step of spvs_q_rsqrt: y (3 - F y^2) / 2 from y and y2 =
 * y^2 2^-30 (Q30, at most 2^32). */
static SPVS_Q_INLINE uint32_t spvs_q_rsqrt_step(uint32_t f, uint32_t y, uint64_t y2)
{
    const uint64_t t = ((uint64_t)3 << 62) - (uint64_t)f * y2; /* Q62 */
    return (uint32_t)(((uint64_t)y * (uint32_t)(t >> 32)) >> 31);
}

/* spvs_q_rsqrt's Newton steps on F in [1/4, 1) as f (Q32). */
static SPVS_Q_INLINE uint32_t spvs_q_rsqrt_f(uint32_t f)
{
    /* F^-1/2 over [1/4, 1) in 12 pieces of 1/16, Q15, the value at each
     * piece's middle: relative error at most 6.1 % (the first piece). */
    static const uint16_t seed[12] = {61788, 55889, 51411, 47861, 44957, 42525,
                                      40450, 38651, 37073, 35673, 34421, 33292};
    const uint32_t s0 = seed[(f >> 28) - 4u];
    /* The first step from y = s0 2^15, whose y^2 2^-30 is s0^2 exactly
     * (one 32-bit multiply), then the other two; written out, so that no
     * loop counter takes a register or a stack slot. */
    uint32_t y = spvs_q_rsqrt_step(f, s0 << 15, s0 * s0);
    y = spvs_q_rsqrt_step(f, y, ((uint64_t)y * y) >> 30);
    return spvs_q_rsqrt_step(f, y, ((uint64_t)y * y) >> 30);
}

/* 1 / sqrt(x) for x > 0 as y 2^-30 2^-(*half): y in (2^29.9, 2^31], *half
 * in 1..32.  x = F 2^(2 half) with F in [1/4, 1) kept to 32 bits (f),
 * Newton's y <- y (3 - F y^2) / 2 three times from the seed: 6.1 %, then
 * 5.6e-3, 4.7e-5, 3.3e-9, plus three truncations of 2^-30 each: relative
 * error below 2^-27.  Newton's iterates never exceed the root (but by
 * rounding), so y <= 2^31; every product is 32 x 32 -> 64 bits:
 * y^2 <= 2^62, f y2 < 3 2^62 (F y^2 < 3), y (t >> 32) < 2^31 3 2^30.
 * *f_out: f (F in Q32). */
static SPVS_Q_INLINE uint32_t spvs_q_rsqrt(uint64_t x, int *half, uint32_t *f_out)
{
    const int b = spvs_q_bits(x);
    const int e = b + (b & 1);
    const uint32_t f = e >= 32 ? (uint32_t)(x >> (e - 32)) : (uint32_t)(x << (32 - e));
    *half = e / 2;
    *f_out = f;
    return spvs_q_rsqrt_f(f);
}

/* sqrt(x) for x in Q52 (scaled units^2) as Q16 pixels: sqrt(x) 2^-26
 * scaled units times SPVS_COORD_SCALE; x < 2^63 gives < 2^31.  sqrt(F) =
 * F y (Q30) keeps the reciprocal's relative error (2^-27), plus 1/2 unit.
 * 0 for x = 0. */
static SPVS_Q_INLINE int32_t spvs_q_sqrt_q52_px16(uint64_t x)
{
    if (x == 0u) {
        return 0;
    }
    int half;
    uint32_t f;
    const uint32_t y = spvs_q_rsqrt(x, &half, &f);
    const uint64_t sf = ((uint64_t)f * y) >> 32; /* sqrt(F) in Q30, < 2^30 */
    /* sqrt(x) in Q26 scaled units = sf 2^(half - 30); Q16 pixels are
     * Q26 scaled units times 2^(9 - 10) (SPVS_COORD_SCALE = 2^9). */
    SPVS_STATIC_ASSERT(SPVS_COORD_SCALE == 512, "the pixel conversion assumes a scale of 2^9");
    const int sh = half - 31;
    const int64_t v = sh >= 0 ? (int64_t)(sf << sh) : spvs_q_rsh((int64_t)sf, -sh);
    return v > SPVS_Q_I32_MAX ? SPVS_Q_I32_MAX : (int32_t)v;
}

/* The squared transfer error of row p under H in Q52 scaled units^2
 * (below 2^63), or -1 when w <= SPVS_W_EPS. */
static SPVS_Q_INLINE int64_t spvs_q_transfer_err2(const int32_t H[9], const int32_t p[4])
{
    int32_t du, dv;
    if (!spvs_q_transfer(H, p, &du, &dv)) {
        return -1;
    }
    return (int64_t)((uint64_t)((int64_t)du * du) + (uint64_t)((int64_t)dv * dv));
}

/* Sorts v[0..n) ascending (insertion sort, no recursion; bound: n^2 / 2
 * moves, n <= SPVS_MAX_OFFPLANE). */
static inline void spvs_q_sort_i32(int32_t *v, uint16_t n)
{
    /* Pointers, not 16-bit indices, in the inner loop: each index step
     * would be truncated to 16 bits again. */
    for (uint32_t i = 1; i < n; i++) {
        const int32_t key = v[i];
        int32_t *q = &v[i];
        while (q > v && q[-1] > key) {
            *q = q[-1];
            q--;
        }
        *q = key;
    }
}

/* The k-th smallest of the n values v[i stride], i < n (k < n <=
 * SPVS_MAX_OFFPLANE), with them reordered so that those before k are at
 * most it and those after at least it: the value a sort would put at k,
 * for the medians, which need no full sort (Hoare's FIND, as in Wirth,
 * "Algorithms + Data Structures = Programs", 1976).  Each pass moves l up
 * or r down past the pivot's position, so at most n passes, each at most
 * n + 2 steps of i and j. */
static inline int32_t spvs_q_select_i32(int32_t *v, uint32_t stride, uint32_t n, uint32_t k)
{
    int32_t l = 0, r = (int32_t)n - 1;
    const int32_t kk = (int32_t)k;
    /* Bound: n passes (above). */
    while (l < r) {
        const int32_t x = v[(uint32_t)kk * stride];
        int32_t i = l, j = r;
        /* Bound: i only grows and j only falls, each within [l, r]
         * (v[k] stops both scans in the first sweep, the swapped pair in
         * the later ones). */
        do {
            while (v[(uint32_t)i * stride] < x) {
                i++;
            }
            while (x < v[(uint32_t)j * stride]) {
                j--;
            }
            if (i <= j) {
                const int32_t t = v[(uint32_t)i * stride];
                v[(uint32_t)i * stride] = v[(uint32_t)j * stride];
                v[(uint32_t)j * stride] = t;
                i++;
                j--;
            }
        } while (i <= j);
        if (j < kk) {
            l = i;
        }
        if (kk < i) {
            r = j;
        }
    }
    return v[(uint32_t)kk * stride];
}

#endif /* SPVS_FIXED_EPIPOLE_Q_H */
