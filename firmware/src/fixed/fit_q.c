/*
 * fit_q.c - the solves of the estimator's linear fits in fixed point
 * (fit_q.h; docs/FIXED.md): the two-stage linear fit's 3 x 3 systems and
 * the joint fit's 6 x 6 normal equations, each equilibrated and solved by
 * a Cholesky factor in Q30, in integers with shared exponents.
 *
 * A system N x = b of n = 3 or 6 unknowns comes as block floating point:
 * N = M 2^e0 (every entry of the matrix in block 0 of the sums) and
 * b = B 2^e1 (block 1), M and B int64 mantissas below 2^62.  Formats and
 * bounds:
 *   P        diag(2^-h_i) with h_i = bitlen(M_ii) / 2, so that
 *            v_i = M_ii 2^-2h_i lies in [1/2, 2): the equilibration by a
 *            power of two, exact.  The exact one, D = diag(M_ii^-1/2),
 *            is P G with G = diag(v_i^-1/2) in (0.7, 1.42]; Cholesky does
 *            not need it (the factor of G N'' G is G L), and the pivot of
 *            D M D is the pivot of N'' over v_i, which is how the floor is
 *            tested;
 *   N''      P M P in Q30 int32, each entry M_ij >> (h_i + h_j - 30)
 *            rounded (|error| <= 2^-31): N''_ii = v_i and, N being
 *            positive semi-definite, |N''_ij| <= sqrt(v_i v_j) < 2 (an
 *            entry of 2 or more is not positive definite: refused);
 *   L        N'' = L L^T, Q30 int32, lower triangle packed; row i's
 *            squared norm, summed exactly in int64 Q60 as each entry is
 *            made, must stay below N''_ii (else the pivot would not be
 *            positive: refused), so |L_ij| < sqrt(2) and, by Cauchy-Schwarz
 *            on the computed rows, every partial dot product of two rows is
 *            below 2 2^60 and every accumulation N''_ij 2^30 - sum below
 *            4 2^60 = 2^62: int64 never overflows;
 *   pivots   p_i = N''_ii 2^30 - (row i's squared norm), exact in Q60,
 *            refused below 2^-20 v_i (PIVOT_FLOOR_SHIFT: the pivot of the
 *            exactly equilibrated matrix below 2^-20; N is then singular
 *            within the precision kept);
 *   1/L_ii   r_i 2^-q_i from rsqrt_q60 (relative error below 2^-29),
 *            r_i < 2^31, q_i = bitlen(p_i) / 2 in [20, 30];
 *   L_ij     (accumulation) r_j 2^-(30 + q_j), a 64 x 32-bit product
 *            (mul_inv): relative 2^-29 from r_j, a backward error of that
 *            order on N''_ij;
 *   c        P b 2^-e0, normalised once: c_i = C_i 2^Ec, |C_i| <= 2^29,
 *            the largest entry at least 2^28 (an absolute error of 2^-29
 *            of the largest entry);
 *   z, y     the forward and back substitutions in int32 with one block
 *            exponent each (BLOCK_BITS): |entry| <= 2^29, so each step's
 *            accumulation (the entry 2^30 minus at most 5 products below
 *            2^30.5 2^29) stays below 2^62; an entry that comes out above
 *            2^29 shifts the whole block right and raises its exponent
 *            (the block's error stays 2^-29 of its largest entry);
 *   result   x_i = y_i 2^(Ey - h_i), rounded to Q27 (|error| <= 2^-28),
 *            plus the weight model's entry for the joint fit, in int64;
 *            outside (-16, 16) refused.
 * So the solution's error is about cond(N') 2^-28 relative to the largest
 * entry of the equilibrated solution, where float's Cholesky and adjugate
 * lose cond 2^-24 (test_fixed_fit measures both).  No division
 * instruction, no bit-by-bit square root and no spvs_qf_t arithmetic
 * except one product's conversion for the 3 x 3 systems' determinant
 * test: one Newton reciprocal square root per pivot.
 */
#include "fit_q.h"

/* A pivot of N'' below 2^-20 v_i, i.e. p_i (Q60) below N''_ii (Q30)
 * 2^10, is refused. */
#define PIVOT_FLOOR_SHIFT 10
/* Entries of the right side and the substitutions' blocks: |v| <= 2^29. */
#define BLOCK_BITS 29
/* Q27 entries of H in (-16, 16): |v| < 2^31. */
#define H_MAX_Q27 ((int64_t)SPVS_Q_I32_MAX)
#define Q31_LIM ((int64_t)1 << 31)

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

/* One system's work (about 190 B). */
typedef struct {
    int32_t L[NSYS * (NSYS + 1) / 2]; /* N'', then its factor off the diagonal, Q30 */
    int32_t v[NSYS];                  /* C, then z = L^-1 c, then y = L^-T z: blocks */
    uint32_t r[NSYS];                 /* 1 / L_ii = r_i 2^-q_i */
    uint32_t pf[NSYS];                /* the pivots' 31-bit mantissas (Q31) */
    uint8_t q[NSYS];
    uint8_t pb[NSYS];                 /* the pivots' bit lengths */
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
 * 2^30.5], q = bitlen(p) / 2 in [20, 30]; relative error below 2^-28.9.
 * With b the bit length, f = p's leading 31 bits (truncated: relative
 * 2^-30, 2^-31 on the root) is F = f 2^-31 in [1/2, 1), p 2^-60 =
 * F 2^(b - 60), and F^-1/2 comes from Newton's y <- y (3 - F y^2) / 2 in
 * Q30 from the table's seed (e <= 0.39 %), two steps: 1.5 e^2 each,
 * 2.3e-5, 7.9e-10, plus the roundings (test_fixed_fit measures the
 * whole: 2^-29.2 over every 97th mantissa).  An odd b takes one more
 * product with sqrt(1/2).  Bounds, y in (0, 1.42] in Q30 (Newton's
 * iterates never pass the root but by the rounding): y^2 >> 31 < 2^30;
 * F y^2 below 1.01 2^60; t = 3 2^60 - F y^2 in (1.9, 2.1) 2^60, so
 * t >> 30 < 2^32; y (t >> 30) < 3 2^60: every product is 32 x 32 -> 64
 * bits.  *f_out, *b_out: f and b (the 3 x 3 determinant). */
static SPVS_Q_NOINLINE uint32_t rsqrt_q60(uint64_t p, uint8_t *q_out, uint32_t *f_out,
                                          uint8_t *b_out)
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
    *f_out = f;
    *b_out = (uint8_t)b;
    return y;
}

/* x 2^-s rounded to nearest (ties up) for s in 1..63: the rounding half
 * is added after the first shift, so nothing overflows.  Two shifts and
 * an add, inline (spvs_q_rshift_rnd64 also clamps s and takes s <= 0). */
static SPVS_Q_INLINE int64_t rsh_rnd(int64_t x, int s)
{
    return ((x >> (s - 1)) + 1) >> 1;
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

/* P, N'' = P M P (Q30) and C, *ec the right side's block exponent.  0
 * when a diagonal entry is not positive, an entry of N'' is 2 or more in
 * magnitude (N is then not positive definite) or the sums are not in the
 * systems' layout. */
static SPVS_Q_NOINLINE int sys_equil(const spvs_q_sums_t *s, int n, const uint8_t (*ix)[6], int rb, q_sys_t *q,
                     int32_t *ec)
{
    if ((int)s->split != rb) {
        return 0;
    }
    /* Bound: n <= 6 unknowns. */
    for (int i = 0; i < n; i++) {
        const int64_t d = s->m[ix[i][i]];
        if (d <= 0) {
            return 0;
        }
        q->h[i] = (uint8_t)(spvs_q_bitlen64((uint64_t)d) / 2);
    }
    int amax = -64;
    for (int i = 0; i < n; i++) {
        int32_t *li = &q->L[TRI(i, 0)];
        const int hi = (int)q->h[i] - 30;
        for (int j = 0; j <= i; j++) {
            if (!equil_entry(s->m[ix[i][j]], hi + q->h[j], i == j, &li[j])) {
                return 0;
            }
        }
        const int a = spvs_q_bitlen64(spvs_q_abs64(s->m[rb + i])) - q->h[i];
        amax = a > amax ? a : amax;
    }
    /* C_i = B_i 2^-(h_i + amax - 29): the largest below 2^29 (after
     * rounding at most 2^29), no left shift leaves 29 bits. */
    for (int i = 0; i < n; i++) {
        const int sh = q->h[i] + amax - BLOCK_BITS;
        const int64_t b = s->m[rb + i];
        q->v[i] = (int32_t)(sh > 0 ? (sh > 63 ? 0 : rsh_rnd(b, sh))
                                   : (int64_t)((uint64_t)b << -sh));
    }
    *ec = amax - BLOCK_BITS + s->e[1] - s->e[0];
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
            int64_t dot = 0;
            for (int k = 0; k < j; k++) {
                dot += (int64_t)li[k] * lj[k];
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
        q->r[i] = rsqrt_q60((uint64_t)p, &q->q[i], &q->pf[i], &q->pb[i]);
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
    if (narrow(t, sh, &v) && (uint32_t)(v + (1 << BLOCK_BITS)) <= (2u << BLOCK_BITS)) {
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
        int64_t dot = 0;
        for (int k = 0; k < i; k++) {
            dot += (int64_t)li[k] * q->v[k];
        }
        const int32_t c = sz == 0 ? q->v[i] : spvs_q_rshift_rnd32(q->v[i], (int)sz);
        blk_put(q, i, (int64_t)c * ((int64_t)1 << 30) - dot, 0, i - 1, &sz);
    }
    sy = sz;
    for (int i = n - 1; i >= 0; i--) {
        int64_t dot = 0;
        for (int k = i + 1; k < n; k++) {
            dot += (int64_t)q->L[TRI(k, i)] * q->v[k];
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
    if (!sys_equil(s, n, ix, rb, q, &ec) || !sys_chol(n, q)) {
        return 0;
    }
    *ey = ec + sys_subst(n, q);
    return 1;
}

/* base + v 2^s in Q27; SPVS_Q_SAT into *sat when outside (-16, 16). */
static int32_t q27_add(int32_t base, int32_t v, int32_t s, uint32_t *sat)
{
    const int64_t x = s >= 0 ? spvs_q_lshift_sat64(v, s > 62 ? 63 : (int)s, sat)
                             : spvs_q_rshift_rnd64(v, s < -63 ? 63 : (int)-s);
    const int64_t r = spvs_q_add64(base, x, sat);
    if (r > H_MAX_Q27 || r < -H_MAX_Q27) {
        *sat |= SPVS_Q_SAT;
        return 0;
    }
    return (int32_t)r;
}

/* det(N) <= DET_EPS for a factored 3 x 3 system: det(N) = 2^(3 e0)
 * det(M), det(M) = det(N'') 2^(2 sum h_i), det(N'') the product of the
 * pivots (each its truncated mantissa: the product's relative error is
 * below 2^-28). */
static int det3_small(const q_sys_t *q, int32_t e0)
{
    const uint32_t m01 = (uint32_t)(((uint64_t)q->pf[0] * q->pf[1]) >> 31);
    const uint32_t m = (uint32_t)(((uint64_t)m01 * q->pf[2]) >> 31);
    /* p_i 2^-60 = pf_i 2^(pb_i - 91); m = pf_0 pf_1 pf_2 2^-62. */
    int32_t e = 62 + 3 * e0;
    for (int i = 0; i < 3; i++) {
        e += (int32_t)q->pb[i] - 91 + 2 * (int32_t)q->h[i];
    }
    return spvs_qf_le(spvs_qf_from_i64(m, e), Q_DET_EPS);
}

int spvs_q_fit_solve(const spvs_q_sums_t *s, int32_t x[3])
{
    q_sys_t q;
    int32_t ey;
    /* float's solve3x3 refuses |det| <= DET_EPS (det > 0 here). */
    if (!sys_solve(s, 3, FIT_IX, FIT_RHS, &q, &ey) || det3_small(&q, s->e[0])) {
        return SPVS_E_DEGENERATE;
    }
    uint32_t sat = 0;
    int32_t h[3];
    for (int j = 0; j < 3; j++) {
        h[j] = q27_add(0, q.v[j], ey - q.h[j] + SPVS_QH, &sat);
    }
    if (sat != 0) {
        return SPVS_E_DEGENERATE;
    }
    for (int j = 0; j < 3; j++) {
        x[j] = h[j];
    }
    return SPVS_OK;
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
    uint32_t sat = 0;
    int32_t h[9];
    for (int k = 0; k < 9; k++) {
        h[k] = Hw[k];
    }
    for (int k = 0; k < 6; k++) {
        h[at[k]] = q27_add(Hw[at[k]], q.v[k], ey - q.h[k] + SPVS_QH, &sat);
    }
    if (sat != 0) {
        return SPVS_E_DEGENERATE;
    }
    for (int k = 0; k < 9; k++) {
        Hq[k] = h[k];
    }
    return SPVS_OK;
}
