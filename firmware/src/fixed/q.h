/*
 * q.h - the fixed-point arithmetic of the core's Q-format kernels (private:
 * not installed, not part of the API; docs/FIXED.md).
 *
 * Values are int32 in a Q format named by its fractional bits (Qf: the
 * integer v stands for v 2^-f); products and sums are formed in int64.
 * Nothing here allocates, recurses or loops without a stated bound, and no
 * function reads a float or double: a float's bits are converted with
 * integer operations only, so a Cortex-M3 build links no __aeabi_f* or
 * __aeabi_d* helper.
 *
 * Overflow is never silent.  Every function that can leave its range takes
 * `uint32_t *sat` and ORs SPVS_Q_SAT into it when it clamps (a sticky flag:
 * the caller clears it once, runs a stage, and tests it once); the others
 * state the input range under which they cannot overflow.
 *
 * Rounding: "rnd" is to nearest with ties towards +infinity (add half an
 * ulp, then an arithmetic shift), |error| <= 1/2 ulp of the result;
 * "trunc" is towards -infinity (a plain arithmetic shift), error in
 * (-1, 0] ulp.
 *
 * Where one Q format cannot hold a stage's range (the Sampson weights, the
 * sums of the linear fits), the kernels use spvs_qf_t below: a 31-bit
 * mantissa with its own exponent (block floating point with a block of
 * one), whose every operation has a relative error of at most 2^-30.
 */
#ifndef SPVS_FIXED_Q_H
#define SPVS_FIXED_Q_H

#include <stdint.h>
#include <string.h>

#include "spvs/common.h"

/* Sticky flag bits (OR-ed into *sat). */
#define SPVS_Q_SAT 1u       /* a result was clamped to its format's range    */
#define SPVS_Q_NONFINITE 2u /* a float input was NaN or infinite             */
#define SPVS_Q_DIV0 4u      /* a division by zero (result clamped)           */

/* Compiler steering: SPVS_Q_INLINE marks the kernels' per-point helpers,
 * SPVS_Q_NOINLINE a helper whose frame (or register pressure) should stay
 * out of its caller's, and spvs_q_opaque32() a 32-bit value that a product
 * should take as it is.  The reference path is plain C (an inline
 * function, a function, the value itself); where the accelerators are
 * built, accel/steer_q.h makes them the attributes and the barrier that
 * keep the Cortex-M3's loops in registers and its products 32 x 32 bits
 * (docs/EMBEDDED.md). */
#if SPVS_ACCEL
#include "accel/steer_q.h"
#else
#define SPVS_Q_INLINE inline
#define SPVS_Q_NOINLINE
static inline int32_t spvs_q_opaque32(int32_t x)
{
    return x;
}
#endif

#define SPVS_Q_I32_MAX INT32_MAX
#define SPVS_Q_I32_MIN INT32_MIN
#define SPVS_Q_I64_MAX INT64_MAX
#define SPVS_Q_I64_MIN INT64_MIN

/* ---- counting bits ------------------------------------------------------ */

/* Leading zeros of x (32 for x = 0).  One CLZ instruction on Cortex-M3. */
static inline int spvs_q_clz32(uint32_t x)
{
#if defined(__GNUC__) || defined(__clang__)
    return x == 0u ? 32 : __builtin_clz(x);
#else
    int n = 0;
    /* Bound: 32 steps. */
    for (uint32_t m = 0x80000000u; m != 0u && (x & m) == 0u; m >>= 1) {
        n++;
    }
    return n;
#endif
}

/* Leading zeros of x (64 for x = 0): two 32-bit counts. */
static inline int spvs_q_clz64(uint64_t x)
{
    const uint32_t hi = (uint32_t)(x >> 32);
    return hi != 0u ? spvs_q_clz32(hi) : 32 + spvs_q_clz32((uint32_t)x);
}

/* |x| as unsigned (exact also for INT64_MIN). */
static inline uint64_t spvs_q_abs64(int64_t x)
{
    return x < 0 ? 0u - (uint64_t)x : (uint64_t)x;
}

/* Bits needed for the magnitude m (0 for m = 0): 64 - clz. */
static inline int spvs_q_bitlen64(uint64_t m)
{
    return 64 - spvs_q_clz64(m);
}

/* ---- shifts ------------------------------------------------------------- */

/* x 2^-s rounded to nearest (ties up), s in 0..63 (s >= 64 is taken as
 * 63).  Never overflows: the rounding bit is added after the shift. */
static inline int64_t spvs_q_rshift_rnd64(int64_t x, int s)
{
    if (s <= 0) {
        return x;
    }
    if (s > 63) {
        s = 63;
    }
    return (x >> s) + ((x >> (s - 1)) & 1);
}

/* x 2^-s rounded to nearest (ties up), s in 0..31 (larger is 31). */
static inline int32_t spvs_q_rshift_rnd32(int32_t x, int s)
{
    if (s <= 0) {
        return x;
    }
    if (s > 31) {
        s = 31;
    }
    return (x >> s) + ((x >> (s - 1)) & 1);
}

/* x 2^s for s in 0..62, saturated to int64 (flagged). */
static inline int64_t spvs_q_lshift_sat64(int64_t x, int s, uint32_t *sat)
{
    if (s <= 0 || x == 0) {
        return x;
    }
    const int room = spvs_q_clz64(spvs_q_abs64(x)) - 1;
    if (s > room) {
        *sat |= SPVS_Q_SAT;
        return x < 0 ? SPVS_Q_I64_MIN : SPVS_Q_I64_MAX;
    }
    return (int64_t)((uint64_t)x << s);
}

/* ---- saturation and saturating arithmetic ------------------------------ */

/* x clamped to int32 (flagged when clamped). */
static inline int32_t spvs_q_sat32(int64_t x, uint32_t *sat)
{
    if (x > SPVS_Q_I32_MAX) {
        *sat |= SPVS_Q_SAT;
        return SPVS_Q_I32_MAX;
    }
    if (x < SPVS_Q_I32_MIN) {
        *sat |= SPVS_Q_SAT;
        return SPVS_Q_I32_MIN;
    }
    return (int32_t)x;
}

/* a + b and a - b in the same Q format, saturated (exact otherwise). */
static inline int32_t spvs_q_add32(int32_t a, int32_t b, uint32_t *sat)
{
    return spvs_q_sat32((int64_t)a + b, sat);
}
static inline int32_t spvs_q_sub32(int32_t a, int32_t b, uint32_t *sat)
{
    return spvs_q_sat32((int64_t)a - b, sat);
}

/* a + b in int64, saturated: overflow is detected on the unsigned sum (the
 * signs of a and b agree and the sum's differs). */
static inline int64_t spvs_q_add64(int64_t a, int64_t b, uint32_t *sat)
{
    const uint64_t s = (uint64_t)a + (uint64_t)b;
    if (((~((uint64_t)a ^ (uint64_t)b)) & ((uint64_t)a ^ s)) >> 63) {
        *sat |= SPVS_Q_SAT;
        return a < 0 ? SPVS_Q_I64_MIN : SPVS_Q_I64_MAX;
    }
    return (int64_t)s;
}

/* a b 2^-s: a in Qfa, b in Qfb gives Q(fa + fb - s); rnd, saturated to
 * int32.  s in 0..62.  |error| <= 1/2 ulp unless clamped. */
static inline int32_t spvs_q_mul32(int32_t a, int32_t b, int s, uint32_t *sat)
{
    return spvs_q_sat32(spvs_q_rshift_rnd64((int64_t)a * b, s), sat);
}

/* a b exactly in int64 (|a b| < 2^62 for any int32 a, b). */
static inline int64_t spvs_q_mul64(int32_t a, int32_t b)
{
    return (int64_t)a * b;
}

/* ---- normalisation ------------------------------------------------------ */

/* The right shift that brings a magnitude m below 2^bits (0 if it is
 * already): bitlen(m) - bits, at least 0. */
static inline int spvs_q_norm_shift(uint64_t m, int bits)
{
    const int s = spvs_q_bitlen64(m) - bits;
    return s > 0 ? s : 0;
}

/* ---- division, square root, reciprocal ---------------------------------- */

/* n / d rounded to nearest (ties away from zero), saturated to int32; d = 0
 * gives the clamp of n's sign (flagged SPVS_Q_DIV0 | SPVS_Q_SAT).  With n
 * in Q(fn) and d in Q(fd) the quotient is in Q(fn - fd): shift n left
 * first (spvs_q_lshift_sat64) for more fractional bits.  Uses the
 * compiler's integer 64-bit division (__aeabi_ldivmod on Cortex-M3, an
 * integer helper), so it is meant for per-frame work, not per point. */
static inline int32_t spvs_q_div64_32(int64_t n, int32_t d, uint32_t *sat)
{
    if (d == 0) {
        *sat |= SPVS_Q_DIV0 | SPVS_Q_SAT;
        return n < 0 ? SPVS_Q_I32_MIN : SPVS_Q_I32_MAX;
    }
    const uint64_t an = spvs_q_abs64(n);
    const uint64_t ad = spvs_q_abs64(d);
    /* |n| / |d| rounded half away: (2 |n| + |d|) / (2 |d|) without the
     * doubling overflowing. */
    uint64_t q = an / ad;
    const uint64_t r = an - q * ad;
    q += (r >= ad - r) ? 1u : 0u;
    const int neg = (n < 0) != (d < 0);
    if (q > (uint64_t)SPVS_Q_I32_MAX + (uint64_t)neg) {
        *sat |= SPVS_Q_SAT;
        return neg ? SPVS_Q_I32_MIN : SPVS_Q_I32_MAX;
    }
    return neg ? (int32_t)(0 - (int64_t)q) : (int32_t)q;
}

/* floor(sqrt(x)) for any uint64 x (exact: r^2 <= x < (r + 1)^2), bit by bit.
 * For x in Q(2f) the root is in Qf.  Bound: 32 steps. */
static inline uint32_t spvs_q_isqrt64(uint64_t x)
{
    uint64_t r = 0;
    uint64_t bit = (uint64_t)1 << 62;
    /* Bound: 32 halvings of `bit` by 4. */
    while (bit > x) {
        bit >>= 2;
    }
    while (bit != 0u) {
        if (x >= r + bit) {
            x -= r + bit;
            r = (r >> 1) + bit;
        } else {
            r >>= 1;
        }
        bit >>= 2;
    }
    return (uint32_t)r;
}

/* 2^61 / m for a normalised m in [2^30, 2^31), in (2^30, 2^31]: the
 * reciprocal of f = m 2^-31 in [1/2, 1) as y = 1/f in Q30.  Linear seed
 * 48/17 - 32/17 f (relative error <= 1/17), then three Newton steps
 * y <- y (2 - f y), each squaring the relative error: 2^-30.9 after the
 * third, plus rounding; |result - 2^61 / m| <= 4 ulp (asserted by the
 * tests over random and edge m). */
static inline uint32_t spvs_q_recip_norm(uint32_t m)
{
    /* 48/17 and 32/17 in Q30; f in Q31 times Q30 is Q61, >> 31 is Q30. */
    const uint64_t c48 = 3031741621u; /* round(48/17 2^30) */
    const uint64_t c32 = 2021161081u; /* round(32/17 2^30) */
    uint64_t y = c48 - ((c32 * m) >> 31);
    /* Bound: 3 steps. */
    for (int it = 0; it < 3; it++) {
        const uint64_t fy = ((uint64_t)m * y) >> 31;         /* Q30, near 1 */
        const uint64_t corr = ((uint64_t)2 << 30) - fy;      /* Q30         */
        y = (y * corr + ((uint64_t)1 << 29)) >> 30;         /* Q30         */
    }
    return y > 0x80000000u ? 0x80000000u : (uint32_t)y;
}

/* ---- block floating point: spvs_qf_t ------------------------------------ */

/* value = m 2^e, m = 0 or |m| in [2^30, 2^31).  e is kept in int32: the
 * kernels' chains of at most a few dozen operations on inputs with
 * |e| < 200 move it by at most 64 per operation, far from overflow. */
struct spvs_qf {
    int32_t m;
    int32_t e;
};
typedef struct spvs_qf spvs_qf_t;

#define SPVS_QF_ZERO_E (-100000)

/* v 2^e as a spvs_qf_t, rnd to 31 bits (relative error <= 2^-31). */
static inline spvs_qf_t spvs_qf_from_i64(int64_t v, int32_t e)
{
    spvs_qf_t r;
    if (v == 0) {
        r.m = 0;
        r.e = SPVS_QF_ZERO_E;
        return r;
    }
    const int len = spvs_q_bitlen64(spvs_q_abs64(v));
    int s = len - 31;
    if (s > 0) {
        v = spvs_q_rshift_rnd64(v, s);
        /* Rounding up may carry to 2^31 (positive side only). */
        if (v >= ((int64_t)1 << 31)) {
            v >>= 1;
            s++;
        }
    } else {
        v = (int64_t)((uint64_t)v << (-s));
    }
    /* A negative value can round to exactly -2^31: keep |m| < 2^31. */
    if (v < -((int64_t)1 << 31) + 1) {
        v = -((int64_t)1 << 30);
        s++;
    }
    r.m = (int32_t)v;
    r.e = e + s;
    return r;
}

/* a b, relative error <= 2^-31.  Both mantissas normalised, so |a.m b.m|
 * is in [2^60, 2^62): one of two fixed shifts normalises it, with no
 * count of leading zeros. */
static inline spvs_qf_t spvs_qf_mul(spvs_qf_t a, spvs_qf_t b)
{
    spvs_qf_t r;
    if (a.m == 0 || b.m == 0) {
        r.m = 0;
        r.e = SPVS_QF_ZERO_E;
        return r;
    }
    const int64_t p = (int64_t)a.m * b.m;
    int s = 30 + (int)(spvs_q_abs64(p) >> 61);
    int64_t v = (p >> s) + ((p >> (s - 1)) & 1);
    /* Rounding may reach 2^31 in magnitude: keep |m| < 2^31. */
    if (v >= ((int64_t)1 << 31) || v <= -((int64_t)1 << 31)) {
        v /= 2;
        s++;
    }
    r.m = (int32_t)v;
    r.e = a.e + b.e + s;
    return r;
}

/* a + b: both aligned to the larger exponent with 30 extra bits, so the
 * sum before rounding is exact to 2^-61 of the larger operand; the result
 * then rounds to 31 bits (relative error <= 2^-31 of the result, plus
 * 2^-61 of max(|a|, |b|)). */
static inline spvs_qf_t spvs_qf_add(spvs_qf_t a, spvs_qf_t b)
{
    if (a.m == 0) {
        return b;
    }
    if (b.m == 0) {
        return a;
    }
    if (a.e < b.e) {
        const spvs_qf_t t = a;
        a = b;
        b = t;
    }
    const int32_t d = a.e - b.e;
    if (d > 62) {
        return a;
    }
    const int64_t big = (int64_t)a.m * ((int64_t)1 << 30);
    const int64_t small = spvs_q_rshift_rnd64((int64_t)b.m * ((int64_t)1 << 30), (int)d);
    return spvs_qf_from_i64(big + small, a.e - 30);
}

static inline spvs_qf_t spvs_qf_neg(spvs_qf_t a)
{
    a.m = -a.m;
    return a;
}

static inline spvs_qf_t spvs_qf_sub(spvs_qf_t a, spvs_qf_t b)
{
    return spvs_qf_add(a, spvs_qf_neg(b));
}

/* 1 / a; a = 0 gives the largest value of a's sign and flags
 * SPVS_Q_DIV0.  Relative error <= 2^-28 (spvs_q_recip_norm). */
static inline spvs_qf_t spvs_qf_recip(spvs_qf_t a, uint32_t *sat)
{
    spvs_qf_t r;
    if (a.m == 0) {
        *sat |= SPVS_Q_DIV0;
        r.m = SPVS_Q_I32_MAX;
        r.e = 1000;
        return r;
    }
    const uint32_t mag = a.m < 0 ? (uint32_t)(-(int64_t)a.m) : (uint32_t)a.m;
    const uint32_t y = spvs_q_recip_norm(mag); /* 2^61 / mag */
    const int64_t sy = a.m < 0 ? -(int64_t)y : (int64_t)y;
    return spvs_qf_from_i64(sy, -61 - a.e);
}

/* Sign of a: -1, 0 or 1. */
static inline int spvs_qf_sign(spvs_qf_t a)
{
    return (a.m > 0) - (a.m < 0);
}

/* 1 when a <= b, exactly on the represented values. */
static inline int spvs_qf_le(spvs_qf_t a, spvs_qf_t b)
{
    const int sa = spvs_qf_sign(a), sb = spvs_qf_sign(b);
    if (sa != sb) {
        return sa < sb;
    }
    if (sa == 0) {
        return 1;
    }
    /* Same sign, both normalised: the exponent orders the magnitudes. */
    if (a.e != b.e) {
        return sa > 0 ? a.e < b.e : a.e > b.e;
    }
    return a.m <= b.m;
}

/* a as an int64 in Qf (value a 2^f), rnd; saturated (flagged). */
static inline int64_t spvs_qf_to_q64(spvs_qf_t a, int f, uint32_t *sat)
{
    if (a.m == 0) {
        return 0;
    }
    const int32_t s = a.e + f;
    if (s >= 0) {
        return spvs_q_lshift_sat64(a.m, s > 62 ? 63 : (int)s, sat);
    }
    return spvs_q_rshift_rnd64(a.m, s < -63 ? 63 : (int)-s);
}

/* a as an int32 in Qf, rnd, saturated (flagged). */
static inline int32_t spvs_qf_to_q32(spvs_qf_t a, int f, uint32_t *sat)
{
    return spvs_q_sat32(spvs_qf_to_q64(a, f, sat), sat);
}

/* ---- IEEE-754 bits to Q, with integer operations only ------------------- */

/* A binary float's parts: (-1)^neg mant 2^exp2 (mant an integer).  Set
 * from float or double bits by the two functions below. */
typedef struct {
    uint64_t mant;
    int32_t exp2;
    int neg;
    int nonfinite;
} spvs_q_ieee_t;

static inline spvs_q_ieee_t spvs_q_ieee_f32(uint32_t bits)
{
    spvs_q_ieee_t r;
    const uint32_t ex = (bits >> 23) & 0xffu;
    const uint32_t fr = bits & 0x7fffffu;
    r.neg = (int)(bits >> 31);
    r.nonfinite = ex == 0xffu;
    r.mant = ex == 0u ? fr : (fr | 0x800000u);
    r.exp2 = (ex == 0u ? 1 : (int32_t)ex) - 127 - 23;
    return r;
}

static inline spvs_q_ieee_t spvs_q_ieee_f64(uint64_t bits)
{
    spvs_q_ieee_t r;
    const uint32_t ex = (uint32_t)(bits >> 52) & 0x7ffu;
    const uint64_t fr = bits & 0xfffffffffffffu;
    r.neg = (int)(bits >> 63);
    r.nonfinite = ex == 0x7ffu;
    r.mant = ex == 0u ? fr : (fr | ((uint64_t)1 << 52));
    r.exp2 = (ex == 0u ? 1 : (int32_t)ex) - 1023 - 52;
    return r;
}

/* The core's scalar (float, or double with SPVS_USE_DOUBLE) as its IEEE
 * parts, read through its bits: how every fixed-point stage takes the
 * float API's values without a floating-point operation. */
static inline spvs_q_ieee_t spvs_q_real_parts(spvs_real x)
{
#if SPVS_USE_DOUBLE
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return spvs_q_ieee_f64(b);
#else
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    return spvs_q_ieee_f32(b);
#endif
}

/* The value as an int32 in Qf, rounded to nearest (ties away from zero),
 * saturated (SPVS_Q_SAT) and SPVS_Q_NONFINITE for NaN or infinity (result
 * 0).  *below (may be NULL) is set to 1 when |result| < |value| (the
 * magnitude was rounded down), else 0. */
static inline int32_t spvs_q_from_ieee(spvs_q_ieee_t v, int f, uint32_t *sat, int *below)
{
    int dummy;
    int *const b = below != 0 ? below : &dummy;
    *b = 0;
    if (v.nonfinite) {
        *sat |= SPVS_Q_NONFINITE;
        return 0;
    }
    if (v.mant == 0u) {
        return 0;
    }
    const int32_t s = v.exp2 + f;
    uint64_t mag;
    if (s >= 0) {
        if (s > 62 || spvs_q_bitlen64(v.mant) + s > 31) {
            *sat |= SPVS_Q_SAT;
            return v.neg ? SPVS_Q_I32_MIN : SPVS_Q_I32_MAX;
        }
        mag = v.mant << s;
    } else if (s < -63) {
        *b = 1;
        return 0;
    } else {
        const int r = (int)-s;
        const uint64_t q = v.mant >> r;
        const uint64_t rem = v.mant - (q << r);
        const uint64_t half = (uint64_t)1 << (r - 1);
        mag = q + (rem >= half ? 1u : 0u);
        *b = rem != 0u && rem < half;
    }
    if (mag > (uint64_t)SPVS_Q_I32_MAX + (uint64_t)v.neg) {
        *sat |= SPVS_Q_SAT;
        return v.neg ? SPVS_Q_I32_MIN : SPVS_Q_I32_MAX;
    }
    return v.neg ? (int32_t)(0 - (int64_t)mag) : (int32_t)mag;
}

/* The value as a spvs_qf_t (relative error <= 2^-31); NaN or infinity
 * flags SPVS_Q_NONFINITE and gives 0. */
static inline spvs_qf_t spvs_qf_from_ieee(spvs_q_ieee_t v, uint32_t *sat)
{
    if (v.nonfinite) {
        *sat |= SPVS_Q_NONFINITE;
        v.mant = 0u;
    }
    /* Keep the top 62 bits of the mantissa (a double's 53 fit). */
    const int64_t m = (int64_t)v.mant;
    return spvs_qf_from_i64(v.neg ? -m : m, v.exp2);
}

/* ---- Q to IEEE-754 bits, with integer operations only ------------------- */

/* The bits of the binary float nearest to x 2^-f (ties to even, as the
 * FPU rounds), for a format of mant_bits stored mantissa bits and an
 * exponent field of exp_bits (23 and 8 for float, 52 and 11 for double).
 * Any int64 x and f in -1000..1000: a value beyond the format's largest
 * finite one gives infinity, one below its smallest subnormal 0 (never
 * for the core's outputs, whose ranges the formats hold: docs/FIXED.md).
 * So the fixed-point core writes the float fields of the public API
 * (spvs_output_t) without a floating-point helper. */
static inline uint64_t spvs_q_ieee_bits(int64_t x, int f, int mant_bits, int exp_bits)
{
    const uint64_t sign = x < 0 ? (uint64_t)1 << (mant_bits + exp_bits) : 0u;
    const uint64_t mag = spvs_q_abs64(x);
    if (mag == 0u) {
        return sign;
    }
    const int bias = (1 << (exp_bits - 1)) - 1;
    const int emax_field = (1 << exp_bits) - 1;
    /* mag 2^-f = 1.xxx 2^e with e = bitlen - 1 - f. */
    const int len = spvs_q_bitlen64(mag);
    int e = len - 1 - f;
    int field = e + bias;
    /* The mantissa's bits kept: mant_bits + 1 for a normal number, fewer
     * for a subnormal (field <= 0). */
    int keep = mant_bits + 1;
    if (field <= 0) {
        keep = mant_bits + field;
        field = 0;
        if (keep < 0) {
            return sign;
        }
    }
    /* The top `keep` bits of mag, rounded to nearest even. */
    const int drop = len - keep;
    uint64_t m;
    if (drop <= 0) {
        m = mag << (-drop);
    } else {
        const uint64_t q = drop >= 64 ? 0u : mag >> drop;
        const uint64_t rem = drop >= 64 ? mag : mag - (q << drop);
        const uint64_t half = drop >= 65 ? 0u : (uint64_t)1 << (drop - 1);
        m = q + ((rem > half || (rem == half && (q & 1u) != 0u)) ? 1u : 0u);
    }
    /* Rounding up may carry into a new bit: a normal number one binade up,
     * or a subnormal that became the smallest normal. */
    if (field == 0) {
        if (m >> mant_bits != 0u) {
            field = 1;
        }
        return sign | ((uint64_t)field << mant_bits) | (m & (((uint64_t)1 << mant_bits) - 1u));
    }
    if (m >> (mant_bits + 1) != 0u) {
        m >>= 1;
        field++;
    }
    if (field >= emax_field) {
        return sign | ((uint64_t)emax_field << mant_bits);
    }
    return sign | ((uint64_t)field << mant_bits) | (m & (((uint64_t)1 << mant_bits) - 1u));
}

/* ---- the core's scalar compared on its bits (the parameters' rules) ---- */

/* The spvs_real at field as an integer with the order of the values.  An
 * IEEE-754 number of either sign bit orders as its magnitude bits (the
 * sign cleared) read as an unsigned integer, infinity above every finite
 * value; the key is those bits, negated for a negative sign, so keys
 * compare exactly as the values do, +0 and -0 equal (a double's bits
 * below 2^63 fit an int64).  Returns 0 for a NaN (magnitude bits above
 * infinity's), which compares false with everything. */
static inline int spvs_q_real_key(const void *field, int64_t *key)
{
#if SPVS_USE_DOUBLE
    uint64_t b;
    memcpy(&b, field, sizeof b);
    const uint64_t mag = b & ~((uint64_t)1 << 63), inf = (uint64_t)0x7ff << 52;
    const int neg = (int)(b >> 63);
#else
    uint32_t b;
    memcpy(&b, field, sizeof b);
    const uint64_t mag = b & 0x7fffffffu, inf = 0x7f800000u;
    const int neg = (int)(b >> 31);
#endif
    *key = neg ? -(int64_t)mag : (int64_t)mag;
    return mag <= inf;
}

/* lo < x < hi for the spvs_real at field (lo_incl, hi_incl: <=); false for
 * a NaN, as the float comparisons are. */
static inline int spvs_q_key_in(const void *field, int64_t lo, int lo_incl, int64_t hi,
                                int hi_incl)
{
    int64_t k;
    return spvs_q_real_key(field, &k) && (lo_incl ? k >= lo : k > lo) &&
           (hi_incl ? k <= hi : k < hi);
}

/* lo < x < hi for the spvs_real at x (lo_incl, hi_incl: <=; hi NULL: no
 * upper bound, +infinity included), on the keys of the bits; false for a
 * NaN, as the float comparisons are. */
static inline int spvs_q_real_in(const void *x, const spvs_real *lo, int lo_incl,
                                 const spvs_real *hi, int hi_incl)
{
    int64_t k_lo, k_hi = SPVS_Q_I64_MAX;
    (void)spvs_q_real_key(lo, &k_lo);
    if (hi != 0 && !spvs_q_real_key(hi, &k_hi)) {
        return 0;
    }
    return spvs_q_key_in(x, k_lo, lo_incl, k_hi, hi_incl);
}

#endif /* SPVS_FIXED_Q_H */
