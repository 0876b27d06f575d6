/*
 * fit_q.c - the solves of the estimator's linear fits in fixed point
 * (fit_q.h; docs/FIXED.md): the two-stage linear fit's 3 x 3 systems by
 * their adjugate and the joint fit's 6 x 6 normal equations by a Cholesky
 * factor, both on the equilibrated matrix in Q30, in integers with shared
 * exponents (no spvs_qf_t operation).
 *
 * A system N x = b of n = 3 or 6 unknowns comes as block floating point:
 * N = M 2^e0 (every entry of the matrix in block 0 of the sums) and
 * b = B 2^e1 (block 1), M and B int64 mantissas below 2^62.  Formats and
 * bounds of both solves:
 *   P        diag(2^-h_i) with h_i = bitlen(M_ii) / 2, so that
 *            v_i = M_ii 2^-2h_i lies in [1/2, 2): an equilibration by
 *            powers of two, exact.  The exact one, D = diag(M_ii^-1/2), is
 *            P G with G = diag(v_i^-1/2) in (0.7, 1.42]; neither solve
 *            needs G (the Cholesky factor of G N'' G is G L), and a pivot
 *            of D M D is the pivot of N'' over v_i, which is how the floor
 *            is tested;
 *   N''      P M P in Q30 int32, each entry M_ij 2^-(h_i + h_j - 30)
 *            rounded (|error| <= 2^-31): N''_ii = v_i and, N being
 *            positive semi-definite, |N''_ij| <= sqrt(v_i v_j) < 2 (an
 *            entry of 2 or more is not positive definite: refused);
 *   c        P b 2^-e0, normalised once: c_i = C_i 2^Ec with |C_i| <= 2^29
 *            (2^30 for the 3 x 3), the largest above half that (rounding:
 *            at most 2^-29 of the largest entry, 2^-30 for the 3 x 3);
 *   pivots   refused below 2^-20 v_i (PIVOT_FLOOR_SHIFT: the pivot of the
 *            exactly equilibrated matrix below 2^-20; N is then singular
 *            within the precision kept; a pivot of zero or less is one);
 *   result   x_i = y_i 2^-h_i for the solution y of N'' y = c, rounded to
 *            Q27 (|error| <= 2^-28), plus the weight model's entry for the
 *            joint fit, in int64; outside (-16, 16) refused.
 * The 6 x 6 Cholesky solve (sys_chol, sys_subst):
 *   L        N'' = L L^T, Q30 int32, lower triangle packed; row i's
 *            squared norm, summed exactly in int64 Q60 as each entry is
 *            made, must stay below N''_ii (else the pivot would not be
 *            positive: refused), so |L_ij| < sqrt(2) and, by Cauchy-Schwarz
 *            on the computed rows, every partial dot product of two rows is
 *            below 2 2^60 and every accumulation N''_ij 2^30 - sum below
 *            4 2^60 = 2^62: int64 never overflows;
 *   p_i      N''_ii 2^30 - (row i's squared norm), exact in Q60;
 *   1/L_ii   r_i 2^-q_i from rsqrt_q60 (relative error below 2^-28.6),
 *            r_i < 2^31, q_i = bitlen(p_i) / 2 in [20, 30];
 *   L_ij     (accumulation) r_j 2^-(30 + q_j) from a 64 x 32-bit product
 *            (mul_r, narrow): relative 2^-28.6 from r_j, a backward error
 *            of that order on N''_ij;
 *   z, y     the forward and back substitutions in int32 with one block
 *            exponent each (BLOCK_BITS): |entry| <= 2^29, so each step's
 *            accumulation (the entry 2^30 minus at most 5 products below
 *            2^30.5 2^29) stays below 2^62; an entry that comes out above
 *            2^29 shifts the whole block right and raises its exponent
 *            (the block's error stays 2^-29 of its largest entry).
 * The 3 x 3 adjugate solve (fit_adj): the cofactors exact in int64, the
 * pivots and the determinant from them, one reciprocal (bounds there).
 * So the solution's error is a few cond(N') 2^-29 relative to the largest
 * entry of the equilibrated solution, where float's Cholesky and adjugate
 * lose cond 2^-24 (test_fixed_fit measures both).  No division
 * instruction and no bit-by-bit square root: one Newton reciprocal square
 * root per pivot of the 6 x 6, one Newton reciprocal per 3 x 3.
 */
#include "fit_q.h"

/* A pivot of N'' below 2^-20 v_i, i.e. p_i (Q60) below N''_ii (Q30)
 * 2^10, is refused. */
#define PIVOT_FLOOR_SHIFT 10
/* Entries of the right side and the substitutions' blocks: |v| <= 2^29. */
#define BLOCK_BITS 29
/* The 3 x 3 right side, which no substitution follows: |C_i| <= 2^30. */
#define ADJ_C_BITS 30
/* Q27 entries of H in (-16, 16): |v| < 2^31. */
#define H_MAX_Q27 ((int64_t)SPVS_Q_I32_MAX)

/* homography.c's DET_EPS (1e-7) as a spvs_qf_t (1801439851 2^-54: its
 * mantissa rounded up to 31 bits). */
static const spvs_qf_t Q_DET_EPS = {0x6B5FCA6B, -54};

/* Term indices of the systems' entries: (r, c) of the 3 x 3 fit (the
 * upper triangle of q q^T, homography.c solve_fit; right side 6-8) and of
 * the 6 x 6 normal matrix (homography.c unpack_normal: the blocks N11,
 * N13, N33 of q = (x^2, x y, x, y^2, y, 1) in terms 0-5, 6-11, 12-17;
 * right side 18-23).  In both layouts the matrix is block 0 of the sums
 * and the right side block 1 (split = the right side's first term). */
static const uint8_t FIT_IX[3][6] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
static const uint8_t LIN_IX[6][6] = {{0, 1, 2, 6, 7, 8},    {1, 3, 4, 7, 9, 10},
                                     {2, 4, 5, 8, 10, 11},  {6, 7, 8, 12, 13, 14},
                                     {7, 9, 10, 13, 15, 16}, {8, 10, 11, 14, 16, 17}};
#define FIT_RHS 6
#define LIN_RHS 18
#define NSYS 6

/* Lower triangle packed by rows: (i, j), j <= i. */
#define TRI(i, j) ((i) * ((i) + 1) / 2 + (j))

/* One system's work: 84 + 24 + 24 + 12 = 144 B. */
typedef struct {
    int32_t L[NSYS * (NSYS + 1) / 2]; /* N'', then its factor off the diagonal, Q30 */
    int32_t v[NSYS];                  /* C, then z = L^-1 c, then y = L^-T z: blocks */
    uint32_t r[NSYS];                 /* 1 / L_ii = r_i 2^-q_i */
    uint8_t q[NSYS];
    uint8_t h[NSYS];                  /* P = diag(2^-h_i) */
} q_sys_t;

/* sqrt(1/2) in Q31, rounded. */
#define RSQRT2_Q31 1518500250u

/* F^-1/2 over [1/2, 1) in 64 pieces of width 1/128, Q15: on each piece
 * the harmonic mean of its ends' values, so the seed's relative error is
 * at most 0.39 % (at F = 1/2). */
static const uint16_t RSQRT_SEED[64] = {
    46161, 45808, 45462, 45124, 44793, 44470, 44153, 43843, 43540, 43243, 42952, 42666, 42386,
    42112, 41843, 41579, 41320, 41066, 40816, 40571, 40330, 40093, 39861, 39633, 39408, 39187,
    38970, 38757, 38547, 38340, 38136, 37936, 37739, 37545, 37354, 37166, 36981, 36798, 36618,
    36441, 36266, 36094, 35924, 35756, 35591, 35428, 35268, 35109, 34953, 34798, 34646, 34496,
    34347, 34201, 34056, 33913, 33772, 33633, 33496, 33360, 33225, 33093, 32962, 32832};

/* 1 / sqrt(p 2^-60) for p in [2^39, 2^61) as r 2^-q, r in (2^29.5,
 * 2^30.5], q = bitlen(p) / 2 in [20, 30]; relative error below 2^-28.6.
 * With b the bit length, f = p's leading 31 bits (truncated: relative
 * 2^-30, 2^-31 on the root) is F = f 2^-31 in [1/2, 1), p 2^-60 =
 * F 2^(b - 60), and F^-1/2 comes from Newton's y <- y (3 - F y^2) / 2 in
 * Q30 from the table's seed (e <= 0.39 %), two steps: 1.5 e^2 each,
 * 2.3e-5, 7.9e-10, plus the roundings (on 31-bit inputs, every 41st
 * mantissa at every b, measured 1.87e-9 = 2^-29.0 at most, so 2^-28.6
 * with the truncation).  An odd b takes one more product with
 * sqrt(1/2).  Bounds, y in (0, 1.42] in Q30 (Newton's
 * iterates never pass the root but by the rounding): y^2 >> 31 < 2^30;
 * F y^2 below 1.01 2^60; t = 3 2^60 - F y^2 in (1.9, 2.1) 2^60, so
 * t >> 30 < 2^32; y (t >> 30) < 3 2^60: every product is 32 x 32 -> 64
 * bits. */
static SPVS_Q_INLINE uint32_t rsqrt_q60(uint64_t p, uint8_t *q_out)
{
    /* p >= 2^39: its high word is not zero. */
    const int b = 64 - spvs_q_clz32((uint32_t)(p >> 32));
    const uint32_t f = (uint32_t)(p >> (b - 31));
    uint32_t y = (uint32_t)RSQRT_SEED[(f >> 24) & 63u] << 15;
    /* Bound: 2 steps. */
    for (int it = 0; it < 2; it++) {
        const uint32_t y2 = (uint32_t)(((uint64_t)y * y + (1u << 30)) >> 31);    /* Q29 */
        const uint64_t t = ((uint64_t)3 << 60) - (uint64_t)f * y2;                /* Q60 */
        y = (uint32_t)(((uint64_t)y * (uint32_t)((t + (1u << 29)) >> 30) + (1u << 30)) >> 31);
    }
    if ((b & 1) != 0) {
        y = (uint32_t)(((uint64_t)y * RSQRT2_Q31 + (1u << 30)) >> 31);
    }
    *q_out = (uint8_t)(b / 2);
    return y;
}

/* x 2^-s rounded to nearest (ties up) for s in 1..63: the rounding half
 * is added after the first shift, so nothing overflows.  Two shifts and
 * an add, inline (spvs_q_rshift_rnd64 also clamps s and takes s <= 0). */
static SPVS_Q_INLINE int64_t rsh_rnd(int64_t x, int s)
{
    return ((x >> (s - 1)) + 1) >> 1;
}

/* The bit length of x < 2^63 (0 for 0) from one of its words. */
static SPVS_Q_INLINE int bitlen63(uint64_t x)
{
    const uint32_t xh = (uint32_t)(x >> 32);
    return xh != 0u ? 64 - spvs_q_clz32(xh) : 32 - spvs_q_clz32((uint32_t)x);
}

/* x 2^-sh rounded to nearest (ties up) into *out for sh in 1..32; 0
 * (and *out untouched) when the result is not within +-(2^31 - 1).  In
 * 32-bit words: t = floor(x 2^-(sh - 1)) as th:w, the result the bits
 * 32..1 of t + 1, which fits when t + 1's high word is 0 or -1; every
 * shift count stays in 0..31. */
static SPVS_Q_INLINE int narrow(int64_t x, int sh, int32_t *out)
{
    const uint32_t lo = (uint32_t)x;
    const int32_t hi = spvs_q_opaque32((int32_t)(x >> 32));
    const uint32_t w = (lo >> (sh - 1)) | (((uint32_t)hi << 1) << (32 - sh));
    const uint32_t u = w + 1u;
    const int32_t th = (hi >> (sh - 1)) + (u == 0u ? 1 : 0);
    const uint32_t r = (u >> 1) | ((uint32_t)th << 31);
    if ((uint32_t)(th + 1) > 1u || r == 0x80000000u) {
        return 0;
    }
    *out = (int32_t)r;
    return 1;
}

/* floor(acc r 2^-32): with a shift by q - 2 (in 18..28) after it, a
 * value (Q60, or a block in Q30) times 1 / L_ii = r 2^-q, in Q30 or the
 * block's units.  |acc| < 2^62.1, r < 2^31: two 32 x 32 products (hi r
 * exact, the low word's product's high word), the result below 2^61.1
 * (and below 2^43 after the shift). */
static SPVS_Q_INLINE int64_t mul_r(int64_t acc, uint32_t r)
{
    const int32_t hi = spvs_q_opaque32((int32_t)(acc >> 32));
    const uint32_t lo = (uint32_t)acc;
    return (int64_t)hi * (int32_t)r + (int64_t)(((uint64_t)lo * r) >> 32);
}

/* Entry (i, j) of N'' from M_ij, sh = h_i + h_j - 30 <= 32: M_ij 2^-sh
 * rounded.  0 when it is 2 or more in magnitude (the diagonal, below 2
 * before rounding, is clamped to its largest Q30 value instead). */
static SPVS_Q_INLINE int equil_entry(int64_t m, int sh, int diag, int32_t *out)
{
    if (sh > 0) {
        if (narrow(m, sh, out)) {
            return 1;
        }
        /* The diagonal, below 2 before rounding, may round to 2. */
        if (diag) {
            *out = SPVS_Q_I32_MAX;
            return 1;
        }
        return 0;
    }
    /* A left shift (sh >= -30) only for an entry that will fit. */
    if ((spvs_q_abs64(m) >> (31 + sh)) != 0u) {
        return 0;
    }
    *out = (int32_t)((uint64_t)m << -sh);
    return 1;
}

/* P, N'' = P M P (Q30) and C (|C_i| <= 2^cbits, the largest above
 * 2^(cbits - 1)), *ec the right side's block exponent.  0
 * when a diagonal entry is not positive, an entry of N'' is 2 or more in
 * magnitude (N is then not positive definite) or the sums are not in the
 * systems' layout. */
static SPVS_Q_NOINLINE int sys_equil(const spvs_q_sums_t *s, int n, const uint8_t (*ix)[6],
                                     int rb, int cbits, q_sys_t *q, int32_t *ec)
{
    if ((int)s->split != rb) {
        return 0;
    }
    /* Bound: n <= 6 unknowns. */
    int amax = -64;
    for (int i = 0; i < n; i++) {
        const int64_t d = s->m[ix[i][i]];
        if (d <= 0) {
            return 0;
        }
        q->h[i] = (uint8_t)(bitlen63((uint64_t)d) / 2);
        const int a = bitlen63(spvs_q_abs64(s->m[rb + i])) - q->h[i];
        amax = a > amax ? a : amax;
    }
    for (int i = 0; i < n; i++) {
        int32_t *li = &q->L[TRI(i, 0)];
        const uint8_t *row = ix[i];
        const int hi = (int)q->h[i] - 30;
        for (int j = 0; j <= i; j++) {
            if (!equil_entry(s->m[row[j]], hi + q->h[j], i == j, &li[j])) {
                return 0;
            }
        }
    }
    /* C_i = B_i 2^-(h_i + amax - cbits): the largest below 2^cbits
     * (after rounding at most 2^cbits), no left shift leaves cbits bits. */
    for (int i = 0; i < n; i++) {
        const int sh = q->h[i] + amax - cbits;
        const int64_t b = s->m[rb + i];
        q->v[i] = (int32_t)(sh > 0 ? (sh > 63 ? 0 : rsh_rnd(b, sh))
                                   : (int64_t)((uint64_t)b << -sh));
    }
    *ec = amax - cbits + s->e[1] - s->e[0];
    return 1;
}

/* N'' = L L^T in place, Q30 (bounds in the file's comment), and each
 * pivot's 1 / L_ii.  0 when a pivot is below the floor. */
static SPVS_Q_NOINLINE int sys_chol(int n, q_sys_t *q)
{
    /* Bound: n (n + 1) / 2 <= 21 entries, each at most 5 products. */
    for (int i = 0; i < n; i++) {
        int32_t *li = &q->L[TRI(i, 0)];
        const int64_t dii = (int64_t)li[i] * ((int64_t)1 << 30);
        int64_t sq = 0;
        for (int j = 0; j < i; j++) {
            const int32_t *lj = &q->L[TRI(j, 0)];
            const int32_t *lk = li;
            int64_t dot = 0;
            /* Row j of L ends where entry (j, j) stands. */
            while (lk < li + j) {
                dot += (int64_t)*lk++ * *lj++;
            }
            int32_t l;
            if (!narrow(mul_r((int64_t)li[j] * ((int64_t)1 << 30) - dot, q->r[j]), q->q[j] - 2,
                        &l)) {
                return 0;
            }
            /* The row's squared norm, exact: at least N''_ii means a pivot
             * of zero or less. */
            sq += (int64_t)l * l;
            if (sq >= dii) {
                return 0;
            }
            li[j] = l;
        }
        const int64_t p = dii - sq;
        if (p < (int64_t)li[i] * ((int64_t)1 << PIVOT_FLOOR_SHIFT)) {
            return 0;
        }
        q->r[i] = rsqrt_q60((uint64_t)p, &q->q[i]);
    }
    return 1;
}

/* The block's entries lo..hi and v = t 2^-sh (above 2^29) shifted right
 * together until v is at most 2^29; the shift. */
static SPVS_Q_NOINLINE int blk_renorm(q_sys_t *q, int64_t t, int sh, int i, int lo, int hi)
{
    const int64_t v = spvs_q_rshift_rnd64(t, sh);
    /* |v| < 2^(29 + s): at most 2^29 after rounding. */
    const int s = spvs_q_norm_shift(spvs_q_abs64(v), BLOCK_BITS);
    q->v[i] = (int32_t)spvs_q_rshift_rnd64(v, s);
    /* Bound: at most 5 entries. */
    for (int k = lo; k <= hi; k++) {
        q->v[k] = spvs_q_rshift_rnd32(q->v[k], s);
    }
    return s;
}

/* Entry i of a block from its accumulation acc (Q30 in the block's
 * units): acc / L_ii; when it leaves BLOCK_BITS the block's entries
 * lo..hi (those already made) and it shift right together; *sb: the
 * block's exponent above the start's. */
static SPVS_Q_INLINE void blk_put(q_sys_t *q, int i, int64_t acc, int lo, int hi, int32_t *sb)
{
    const int64_t t = mul_r(acc, q->r[i]);
    const int sh = q->q[i] - 2;
    int32_t v;
    if (narrow(t, sh, &v) && (uint32_t)v + (1u << BLOCK_BITS) <= (2u << BLOCK_BITS)) {
        q->v[i] = v;
        return;
    }
    *sb += blk_renorm(q, t, sh, i, lo, hi);
}

/* v <- L^-T L^-1 v: C into y, whose block exponent is Ec + the return
 * value.  Each entry not yet made is in the first block (z's: C's, y's:
 * z's) and joins the new one by the difference of their exponents. */
static SPVS_Q_NOINLINE int32_t sys_subst(int n, q_sys_t *q)
{
    int32_t sz = 0, sy;
    /* Bound: n (n - 1) / 2 <= 15 products each way. */
    for (int i = 0; i < n; i++) {
        const int32_t *li = &q->L[TRI(i, 0)];
        const int32_t *vk = q->v;
        int64_t dot = 0;
        while (vk < q->v + i) {
            dot += (int64_t)*li++ * *vk++;
        }
        const int32_t c = sz == 0 ? q->v[i] : spvs_q_rshift_rnd32(q->v[i], (int)sz);
        blk_put(q, i, (int64_t)c * ((int64_t)1 << 30) - dot, 0, i - 1, &sz);
    }
    sy = sz;
    for (int i = n - 1; i >= 0; i--) {
        int64_t dot = 0;
        /* Column i below the diagonal: L_ki at TRI(k, i), k > i. */
        int t = TRI(i + 1, i);
        for (int k = i + 1; k < n; k++) {
            dot += (int64_t)q->L[t] * q->v[k];
            t += k + 1;
        }
        const int32_t z = sy == sz ? q->v[i] : spvs_q_rshift_rnd32(q->v[i], (int)(sy - sz));
        blk_put(q, i, (int64_t)z * ((int64_t)1 << 30) - dot, i + 1, n - 1, &sy);
    }
    return sy;
}

/* The solution of the sums' system: q->v in a block of exponent *ey,
 * entry i's value v_i 2^(*ey - h_i).  0 when it is refused. */
static int sys_solve(const spvs_q_sums_t *s, int n, const uint8_t (*ix)[6], int rb, q_sys_t *q,
                     int32_t *ey)
{
    int32_t ec;
    if (!sys_equil(s, n, ix, rb, BLOCK_BITS, q, &ec) || !sys_chol(n, q)) {
        return 0;
    }
    *ey = ec + sys_subst(n, q);
    return 1;
}

/* base + v 2^s in Q27 (v a block entry, |v| <= 2^29, rounded) into
 * *out; 0 when outside (-16, 16).  A left shift above 32 leaves only 0 in
 * range; a right shift above 31 rounds v to 0. */
static SPVS_Q_INLINE int q27_add(int32_t base, int32_t v, int32_t s, int32_t *out)
{
    int64_t x = 0;
    if (s <= 0) {
        x = spvs_q_rshift_rnd32(v, s < -31 ? 31 : (int)-s);
    } else if (s <= 32) {
        x = (int64_t)v * ((int64_t)1 << s);
    } else if (v != 0) {
        return 0;
    }
    const int64_t r = base + x;
    if ((uint64_t)(r + H_MAX_Q27) > (uint64_t)(2 * H_MAX_Q27)) {
        return 0;
    }
    *out = (int32_t)r;
    return 1;
}

/* (x >> 1) for products: the cofactors in Q59, so that a difference of
 * two products below 4 2^60 stays below 2^62. */
static SPVS_Q_INLINE int64_t prod59(int32_t a, int32_t b)
{
    return ((int64_t)a * b) >> 1;
}

/* floor(a b 2^-32) for |a| < 2^62, any b: hi b exact plus the low
 * word's product's high word (lo b < 2^63 in magnitude). */
static SPVS_Q_INLINE int64_t mul_s(int64_t a, int32_t b)
{
    const int32_t hi = spvs_q_opaque32((int32_t)(a >> 32));
    const uint32_t lo = (uint32_t)a;
    return (int64_t)hi * b + (((int64_t)lo * b) >> 32);
}

/* The value v (a positive int64) as m 2^k, m in [2^30, 2^31) (truncated:
 * relative error below 2^-30). */
static SPVS_Q_INLINE uint32_t norm31(int64_t v, int *k)
{
    const int b = bitlen63((uint64_t)v);
    *k = b - 31;
    return b > 31 ? (uint32_t)((uint64_t)v >> (b - 31)) : (uint32_t)v << (31 - b);
}

/* 2^61 / m for m in [2^30, 2^31), to about 1 ulp, below 2^31:
 * spvs_q_recip_norm (within 4 ulp) and one Newton correction on the
 * exact residual 2^61 - m y (|e| < 2^34, so (e >> 8) y < 2^57). */
static SPVS_Q_INLINE uint32_t recip61(uint32_t m)
{
    const uint32_t y = spvs_q_recip_norm(m);
    const int64_t e = (int64_t)(((uint64_t)1 << 61) - (uint64_t)m * y);
    const int64_t r = (int64_t)y + (((e >> 8) * (int64_t)y) >> 53);
    /* 2^31 (m = 2^30) is clamped: mul_r takes r below 2^31. */
    return r > SPVS_Q_I32_MAX ? (uint32_t)SPVS_Q_I32_MAX : (uint32_t)r;
}

/* The 3 x 3 system by its adjugate: N'' (Q30, sys_equil) and c = C 2^Ec.
 * Bounds and errors:
 *   A        adj(N'') from exact products in Q59 (each below 2^61,
 *            differences below 2^62), kept in int64;
 *   pivots   of the Cholesky factor, from the cofactors: p1 = A22 / a00
 *            and p2 = det / A22; the exactly equilibrated ones are
 *            p1 / v1 and p2 / v2, refused below 2^-20 as the 6 x 6
 *            solve's (exact for p1, to a unit of Q57 for p2);
 *   det      sum_j floor(A_0j a_0j 2^-32) (mul_s) in Q57, each term below
 *            2^61 (so det >= 2^14 once p2 passes: A22 >= 2^37 by p1,
 *            a22 >= 2^29);
 *   solution t_i = sum_j floor(A_ij C_j 2^-32), below 3 2^60, times
 *            1 / det (recip61 of det's 31-bit mantissa: relative 2^-30
 *            twice), T_i below 2^60.6, rounded to Q27 once.
 * Every product keeps 59 bits or more, so the adjugate's error is the
 * rounding of N'' and C (2^-31 of an entry, 2^-30 of C's largest)
 * amplified by the inverse's size: a few cond(N'') 2^-31 of max|y|. */
static int fit_adj(const q_sys_t *q, int32_t ec, int32_t e0, int32_t x[3])
{
    const int32_t a00 = q->L[0], a10 = q->L[1], a11 = q->L[2];
    const int32_t a20 = q->L[3], a21 = q->L[4], a22 = q->L[5];
    /* Symmetric: 00, 01, 02, 11, 12, 22. */
    const int64_t A[6] = {prod59(a11, a22) - prod59(a21, a21), prod59(a20, a21) - prod59(a10, a22),
                          prod59(a10, a21) - prod59(a11, a20), prod59(a00, a22) - prod59(a20, a20),
                          prod59(a10, a20) - prod59(a00, a21), prod59(a00, a11) - prod59(a10, a10)};
    /* p1 / v1 = A22 / (a00 a11) below 2^-20 (Q59: a00 a11 2^-21). */
    if (A[5] < ((int64_t)a00 * a11) >> 21) {
        return SPVS_E_DEGENERATE;
    }
    const int64_t det = mul_s(A[0], a00) + mul_s(A[1], a10) + mul_s(A[2], a20);
    /* p2 / v2 = det / (A22 a22) below 2^-20 (det <= 0 included). */
    if (det < mul_s(A[5], a22) >> 20) {
        return SPVS_E_DEGENERATE;
    }
    /* float's solve3x3 refuses |det(N)| <= DET_EPS: det(N) = det(N'')
     * 2^(2 sum h_i + 3 e0), det(N'') = det 2^-57. */
    int k;
    const uint32_t dm = norm31(det, &k);
    const int32_t de = k - 57 + 2 * ((int32_t)q->h[0] + q->h[1] + q->h[2]) + 3 * e0;
    if (de < Q_DET_EPS.e || (de == Q_DET_EPS.e && (int32_t)dm <= Q_DET_EPS.m)) {
        return SPVS_E_DEGENERATE;
    }
    /* y_i = t_i / det 2^(30 + Ec) = T_i 2^(1 - k + Ec), T_i = t_i r 2^-32,
     * x_i = y_i 2^-h_i; x_i in Q27 is T_i 2^-sh. */
    static const uint8_t AI[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
    const uint32_t r = recip61(dm);
    int32_t h[3];
    for (int i = 0; i < 3; i++) {
        const uint8_t *ai = AI[i];
        const int64_t t = mul_s(A[ai[0]], q->v[0]) + mul_s(A[ai[1]], q->v[1]) +
                          mul_s(A[ai[2]], q->v[2]);
        const int64_t T = mul_r(t, r);
        const int32_t sh = k - 28 - ec + (int32_t)q->h[i];
        if (sh >= 1 && sh <= 32) {
            if (!narrow(T, (int)sh, &h[i])) {
                return SPVS_E_DEGENERATE;
            }
            continue;
        }
        uint32_t sat = 0;
        const int64_t v = sh <= 0 ? spvs_q_lshift_sat64(T, sh < -62 ? 63 : (int)-sh, &sat)
                                  : spvs_q_rshift_rnd64(T, sh > 63 ? 63 : (int)sh);
        if (sat != 0 || (uint64_t)(v + H_MAX_Q27) > (uint64_t)(2 * H_MAX_Q27)) {
            return SPVS_E_DEGENERATE;
        }
        h[i] = (int32_t)v;
    }
    for (int i = 0; i < 3; i++) {
        x[i] = h[i];
    }
    return SPVS_OK;
}

int spvs_q_fit_solve(const spvs_q_sums_t *s, int32_t x[3])
{
    q_sys_t q;
    int32_t ec;
    if (!sys_equil(s, 3, FIT_IX, FIT_RHS, ADJ_C_BITS, &q, &ec)) {
        return SPVS_E_DEGENERATE;
    }
    return fit_adj(&q, ec, s->e[0], x);
}

int spvs_q_fit_linear(const spvs_q_store_t *st, const uint8_t *use, uint16_t n, int32_t Hq[9])
{
    /* Row 3: the y transfer error at the weights of Hq (homography.c). */
    spvs_q_sums_t s;
    const int32_t used = spvs_q_pts_sum(SPVS_T_FIT_Y, Hq, st, use, n, &s);
    if (used < 0) {
        return SPVS_E_DEGENERATE;
    }
    if (used < 3) {
        return SPVS_E_TOO_FEW;
    }
    int32_t h3[3];
    if (spvs_q_fit_solve(&s, h3) != SPVS_OK) {
        return SPVS_E_DEGENERATE;
    }
    /* Row 1 given row 3: the x transfer error, exactly. */
    const int32_t Hw[9] = {0, 0, 0, 0, 0, 0, h3[0], h3[1], h3[2]};
    if (spvs_q_pts_sum(SPVS_T_FIT_X, Hw, st, use, n, &s) < 0) {
        return SPVS_E_DEGENERATE;
    }
    int32_t h1[3];
    if (spvs_q_fit_solve(&s, h1) != SPVS_OK) {
        return SPVS_E_DEGENERATE;
    }
    for (int j = 0; j < 3; j++) {
        Hq[j] = h1[j];
        Hq[6 + j] = h3[j];
    }
    return SPVS_OK;
}

int spvs_q_lin_solve(const spvs_q_sums_t *s, const int32_t Hw[9], int32_t Hq[9])
{
    q_sys_t q;
    int32_t ey;
    if (!sys_solve(s, 6, LIN_IX, LIN_RHS, &q, &ey)) {
        return SPVS_E_DEGENERATE;
    }
    /* The step d moves h11 h12 h13 and h31 h32 h33 (homography.c,
     * add_step). */
    static const uint8_t at[6] = {0, 1, 2, 6, 7, 8};
    int32_t h[9];
    for (int k = 0; k < 9; k++) {
        h[k] = Hw[k];
    }
    for (int k = 0; k < 6; k++) {
        if (!q27_add(Hw[at[k]], q.v[k], ey - q.h[k] + SPVS_QH, &h[at[k]])) {
            return SPVS_E_DEGENERATE;
        }
    }
    for (int k = 0; k < 9; k++) {
        Hq[k] = h[k];
    }
    return SPVS_OK;
}
