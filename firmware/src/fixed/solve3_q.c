/*
 * solve3_q.c - the 3-point minimal solver of the planar-motion H in fixed
 * point (points_q.h, spvs_q_solve3; docs/FIXED.md).
 *
 * The float solver (homography.c, spvs_h_solve3_strided) in integers.  P
 * has the rows (x_tgt, y_tgt, 1) of the three points.  Row 3 solves
 * P h3 = w with w_i = y_tgt / y_cur (the y-equations y_cur (h3 . p) = y_tgt
 * divided by y_cur, as float's adj(D) / det(D) does), row 1 solves
 * P h1 = b with b_i = x_cur w_i (the x-equations h1 . p = x_cur w), both by
 * Cramer's rule on P's cofactors c_ij, so with one reciprocal of det P:
 *   - det P and the cofactors c_i2 exact in int64 (Q52);
 *   - w_i to 31 bits (a reciprocal of y_cur, one product), the three at the
 *     largest one's scale in int32 (block floating point), b_i = x_cur w_i
 *     likewise at its own scale in 30 bits;
 *   - the numerators of adj(P) b: the first two exact in int64 from the
 *     coordinates and the differences of b (sum_i c_i0 b_i =
 *     sum_k y_k (b_{k-1} - b_{k+1}), sum_i c_i1 b_i = -sum_k x_k (...)), the
 *     third from the c_i2 rounded to 30 bits;
 *   - each entry its numerator times 1 / |det P| (32 bits) in one 64 x 32-bit
 *     product, rounded to Q27 by a shift fixed per solve and row.
 * The degenerate decisions are the float solver's, made on the Q store's
 * exact values: det P, the sign and size of every w and the 16 bound of
 * every entry exactly but for rounding at the bound itself, det(D P) on a
 * lower bound within 2^-29 of it.  No loop, and no division but the four
 * 32-bit ones that seed the reciprocals.
 *
 * Error of an entry h (value), with cond = max|c_ij| / |det P| (so
 * sum_i |c_ij| / |det P| <= 3 cond), wmax = max w_i, bmax = max |b_i|:
 *   2^-28 (the rounding to Q27) + 2^-30 |h| (1 / |det P|: dm truncated,
 *   r floored) + 3 cond (the right side's error) + for h13, h33 3 cond
 *   2^-30 (wmax or bmax) (the c_i2 rounded to 30 bits),
 * the right side's error being 1.5 2^-30 wmax for row 3 (t floored, then
 * rounded at the block's scale, the largest w_i at least 2^30 units) and
 * 1.5 2^-30 |x_cur| wmax + 2^-29 bmax for row 1 (w's error times x_cur,
 * then b rounded and clamped at its scale); the 64 x 32-bit products'
 * truncation adds below 2^-50 of that.  tests/test_fixed_solve3.c asserts
 * this bound on every entry.
 */
#include "../core_util.h"
#include "points_q.h"

/* |det P| > DET_EPS of homography.c (1e-7) iff |det| in Q52 exceeds
 * floor(1e-7 2^52) = 450359962 (1e-7 2^52 = 450359962.74). */
#define DET_EPS_Q52 ((int64_t)450359962)
/* w_i = y_tgt / y_cur > SPVS_W_EPS (1e-6) iff the signs agree and
 * 10^6 |y_tgt| > |y_cur|, exact in int64 (10^6 2^30 < 2^50). */
#define W_EPS_INV ((int64_t)1000000)
/* floor(1e-7 2^86) and floor(1e-7 2^87) (neither product is an integer):
 * |det(D P)| = p 2^-K > 1e-7 for a mantissa p in [2^62, 2^64) (q_ddp_ok). */
#define DDP_T86 UINT64_C(7737125245533626718)
#define DDP_T87 UINT64_C(15474250491067253436)
/* w < 2^10 iff its exponent (q_w_t.e) is at least this (below). */
#define W_E_MIN 53

/* Bits needed for m (0 for m = 0): one CLZ on the word that holds them. */
static SPVS_Q_INLINE int q_bitlen(uint64_t m)
{
    const uint32_t hi = (uint32_t)(m >> 32);
    return hi != 0u ? 64 - spvs_q_clz32(hi) : 32 - spvs_q_clz32((uint32_t)m);
}

/* x 2^-s rounded (ties up) for s in [0, 31] where |x| < 2^62 and the result
 * fits int32: the rounding add cannot overflow, and only the low word of
 * the shifted sum is kept (its high word then repeats the sign). */
static SPVS_Q_INLINE int32_t q_rnd_shift(int64_t x, int s)
{
    const uint64_t y = (uint64_t)x + (((uint32_t)1 << s) >> 1);
    const uint32_t lo = (uint32_t)y, hi = (uint32_t)(y >> 32);
    /* hi << 1 << (31 - s): no shift by 32 for s = 0. */
    return (int32_t)((lo >> s) | ((hi << 1) << (31 - s)));
}

/* floor(2^63 / m) for m in [2^31, 2^32), in (2^31, 2^32], clamped to
 * 2^32 - 1 (m = 2^31 only, relative error 2^-32): never above 2^63 / m,
 * and at most 2^-31 of it below.  The seed is 2^63 / m to relative
 * eps in [-2^-15, 2^-16] (a 32-bit division by m's top 16 bits, at least
 * 2^15); r0 (1 + eps + eps^2) leaves eps^3 < 2^-44, the truncations of
 * eps and eps^2 (Q45) and of the product one unit: r is floor(2^63 / m) or
 * one off, and the exact remainder 2^63 - m r (|.| < 2 m) says which. */
static uint32_t q_recip63(uint32_t m)
{
    const uint32_t r0 = (0xFFFFFFFFu / (m >> 16)) << 15;
    /* 2^63 eps = 2^63 - m r0, |.| <= 2^48: eps in Q45 fits int32. */
    const int64_t e = (int64_t)(((uint64_t)1 << 63) - (uint64_t)m * r0);
    const int32_t eq = (int32_t)(e >> 18);
    const int32_t e2 = (int32_t)(((int64_t)eq * eq) >> 45);
    /* r0 (eq + e2) < 2^32 (2^30 + 2^15) < 2^63. */
    int64_t r = (int64_t)r0 + (((int64_t)r0 * (eq + e2)) >> 45);
    const int64_t rem = (int64_t)(((uint64_t)1 << 63) - (uint64_t)m * (uint64_t)r);
    if (rem < 0) {
        r--;
    } else if (rem >= (int64_t)m) {
        r++;
    }
    return r > (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)r;
}

/* w = y / v for magnitudes y, v in [1, 2^30] (a point's |y_tgt|, |y_cur|):
 * w = t 2^-e with t in [2^62 - 2^32, 2^63) and t 2^-e <= w < t 2^-e
 * (1 + 2^-31); vm = v 2^lv in [2^31, 2^32) (exact) for det(D P). */
typedef struct {
    uint64_t t;
    int32_t e;
    uint32_t vm;
    int32_t lv;
} q_w_t;

static SPVS_Q_INLINE void q_w(uint32_t y, uint32_t v, q_w_t *q)
{
    const int ly = spvs_q_clz32(y), lv = spvs_q_clz32(v);
    uint32_t a = y << ly;
    const uint32_t b = v << lv;
    int ea = ly;
    /* a in [b/2, b), so t = a floor(2^63 / b) in [2^62 - a, 2^63); y has
     * at most 31 bits, so a is even and a / 2 exact. */
    if (a >= b) {
        a >>= 1;
        ea--;
    }
    q->t = (uint64_t)a * q_recip63(b);
    q->e = 63 + ea - lv;
    q->vm = b;
    q->lv = lv;
}

/* The top 32 bits of p in [2^62, 2^64), truncated; *k less the shift. */
static SPVS_Q_INLINE uint32_t q_top32(uint64_t p, int *k)
{
    if ((p >> 63) != 0u) {
        *k -= 32;
        return (uint32_t)(p >> 32);
    }
    *k -= 31;
    return (uint32_t)(p >> 31);
}

/* |det(D P)| = |y_cur0 y_cur1 y_cur2 det P| > DET_EPS (homography.c), with
 * dm the top 32 bits of |det P| (Q52, bit length L).  The product of the
 * exact |y_cur| mantissas and dm, truncated to 32 bits twice, is p 2^-K
 * with p in [2^62, 2^64): a lower bound within 3 2^-31 of |det(D P)|, so
 * the test is exact but where |det(D P)| is within 2^-29 above 1e-7. */
static int q_ddp_ok(const q_w_t q[3], uint32_t dm, int L)
{
    /* v_i = vm_i 2^-(lv_i + 78) scaled units (Q26 with the shift), det P =
     * dm 2^(L - 84). */
    int k = 162 - L + q[0].lv + q[1].lv + q[2].lv;
    const uint32_t m1 = q_top32((uint64_t)q[0].vm * q[1].vm, &k);
    const uint32_t m2 = q_top32((uint64_t)m1 * q[2].vm, &k);
    const uint64_t p = (uint64_t)m2 * dm;
    /* p 2^-85 >= 2^-23 > 1e-7 > 2^-24 > p 2^-88. */
    return k <= 85 || (k == 86 && p > DDP_T86) || (k == 87 && p > DDP_T87);
}

/* The numerators of adj(P) b: n_j = sum_i c_ij b_i.  b_i int32 with every
 * difference in int32; |y|, |x| <= 2^30 (Q26), so each product of the first
 * two is below 2^61; |c2n| <= 2^30 (the c_i2 scaled), |b| < 2^31: every sum
 * below 3 2^61 < 2^63. */
static SPVS_Q_INLINE void q_adj(const int32_t *const p[3], const int32_t c2n[3],
                                const int32_t b[3], int64_t n[3])
{
    const int32_t d0 = b[2] - b[1], d1 = b[0] - b[2], d2 = b[1] - b[0];
    n[0] = (int64_t)p[0][1] * d0 + (int64_t)p[1][1] * d1 + (int64_t)p[2][1] * d2;
    n[1] = -((int64_t)p[0][0] * d0 + (int64_t)p[1][0] * d1 + (int64_t)p[2][0] * d2);
    n[2] = (int64_t)c2n[0] * b[0] + (int64_t)c2n[1] * b[1] + (int64_t)c2n[2] * b[2];
}

/* An entry outside s in [1, 63] (q_entry): n r 2^(-32 - s) for s in
 * [-14, 0] or [64, 111], |pr| < 2^63.  Such shifts need a determinant or
 * right sides far from the usual scale: kept out of the common path. */
static SPVS_Q_NOINLINE int32_t q_entry_far(int64_t pr, int s, uint32_t *sat)
{
    if (s > 0) {
        /* |pr| 2^-64 < 1/2 rounds to 0. */
        return 0;
    }
    const int64_t lim = (int64_t)1 << (31 + s);
    if (pr >= lim || pr <= -lim) {
        *sat = 1u;
        return 0;
    }
    return (int32_t)(pr * ((int64_t)1 << -s));
}

/* An entry: pr = n r 2^-32 (r = floor(2^63 / dm) < 2^32, |n| < 2^63, so
 * |pr| < 2^63), then pr 2^-s rounded to Q27, s in [-14, 111] (the callers'
 * range).  An entry outside (-16, 16), |Q27| >= 2^31, sets *sat.  For s in
 * [1, 63] the shift is made on the two 32-bit words of pr: q = pr 2^-s
 * truncated to 32 bits, top the bits above it (which must repeat q's sign
 * for the entry to fit) and rb the rounding bit. */
static SPVS_Q_INLINE int32_t q_entry(int64_t n, uint32_t r, int s, uint32_t *sat)
{
    const int64_t pr = (int64_t)(int32_t)(n >> 32) * (int64_t)r +
                       (int64_t)(((uint64_t)(uint32_t)n * r) >> 32);
    if (s < 1 || s > 63) {
        return q_entry_far(pr, s, sat);
    }
    const int32_t hi = (int32_t)(pr >> 32);
    const uint32_t lo = (uint32_t)pr;
    int32_t q, top;
    uint32_t rb;
    if (s < 32) {
        q = (int32_t)((lo >> s) | ((uint32_t)hi << (32 - s)));
        top = hi >> s;
        rb = (lo >> (s - 1)) & 1u;
    } else {
        q = hi >> (s - 32);
        top = q >> 31;
        rb = s == 32 ? lo >> 31 : ((uint32_t)hi >> (s - 33)) & 1u;
    }
    /* q + rb wraps to INT32_MIN exactly when it is 2^31; -2^31 itself is
     * -16, outside the open interval too. */
    const int32_t h = (int32_t)((uint32_t)q + rb);
    if (top != (q >> 31) || h == INT32_MIN) {
        *sat = 1u;
        return 0;
    }
    return h;
}

/* The rows' right sides w (Q(f)) and b = x_cur w (Q(*fb)), both in int32:
 * every w_i in (0, 2^31) (the largest in [2^30, 2^31)), negated with
 * det P so that the numerators carry its sign; every b_i in
 * [-2^30, 2^30).  Returns f. */
static int q_sides(const int32_t *const p[3], const q_w_t q[3], int neg, int32_t w[3],
                   int32_t b[3], int *fb)
{
    int emin = q[0].e < q[1].e ? q[0].e : q[1].e;
    emin = emin < q[2].e ? emin : q[2].e;
    int64_t u[3];
    uint64_t umax = 0;
    for (int i = 0; i < 3; i++) {
        /* t 2^(emin - e_i - 32) rounded; e_i - emin <= 29 (w in
         * (1e-6, 2^10)), t >> 31 < 2^32. */
        const uint32_t v = (uint32_t)(q[i].t >> 31) >> (q[i].e - emin);
        uint32_t wi = (v >> 1) + (v & 1u);
        wi = wi > (uint32_t)INT32_MAX ? (uint32_t)INT32_MAX : wi;
        w[i] = neg ? -(int32_t)wi : (int32_t)wi;
        /* |x_cur| <= 2^30: |u| < 2^61. */
        u[i] = (int64_t)p[i][2] * w[i];
        umax |= spvs_q_abs64(u[i]);
    }
    /* k1 in [0, 31]: every |u 2^-k1| <= 2^30 after rounding. */
    int k1 = q_bitlen(umax) - 30;
    k1 = k1 > 0 ? k1 : 0;
    for (int i = 0; i < 3; i++) {
        const int32_t bi = q_rnd_shift(u[i], k1);
        b[i] = bi > ((int32_t)1 << 30) - 1 ? ((int32_t)1 << 30) - 1 : bi;
    }
    *fb = emin - 32 + SPVS_QC - k1;
    return emin - 32;
}

int spvs_q_solve3(const spvs_q_store_t *st, const uint16_t idx[3], int32_t Hq[9])
{
    const int32_t *const p[3] = {&st->v[4u * idx[0]], &st->v[4u * idx[1]],
                                 &st->v[4u * idx[2]]};
    /* The cofactors c_i2 (2 x 2 minors, Q52, |.| < 2^61) and det P, their
     * sum: twice the target triangle's area, |det P| <= 32^2 scaled
     * units^2, below 2^62 in Q52. */
    const int64_t c2[3] = {(int64_t)p[1][0] * p[2][1] - (int64_t)p[2][0] * p[1][1],
                           (int64_t)p[2][0] * p[0][1] - (int64_t)p[0][0] * p[2][1],
                           (int64_t)p[0][0] * p[1][1] - (int64_t)p[1][0] * p[0][1]};
    const int64_t det = c2[0] + c2[1] + c2[2];
    const uint64_t ad = spvs_q_abs64(det);
    if (ad <= (uint64_t)DET_EPS_Q52) {
        return SPVS_E_DEGENERATE;
    }
    /* Every w_i = y_tgt / y_cur must exceed SPVS_W_EPS (exact; the float
     * solver tests h3 . p_tgt, which is w_i); a w_i of 2^10 or more puts an
     * entry of h3 at 2^10 / 33 or more (|h3 . p| <= max|h3| (|x| + |y| + 1),
     * |x|, |y| <= 16), outside (-16, 16). */
    q_w_t q[3];
    for (int i = 0; i < 3; i++) {
        const int32_t y = p[i][1], v = p[i][3];
        const uint32_t ay = (uint32_t)(y < 0 ? -y : y), av = (uint32_t)(v < 0 ? -v : v);
        if (v == 0 || (y ^ v) < 0 || (uint64_t)W_EPS_INV * ay <= av) {
            return SPVS_E_DEGENERATE;
        }
        q_w(ay, av, &q[i]);
        if (q[i].e < W_E_MIN) {
            return SPVS_E_DEGENERATE;
        }
    }
    /* |det P| = dm 2^(L - 32) to 2^-31, L in [29, 63]. */
    const int L = q_bitlen(ad);
    const uint32_t dm = (uint32_t)((ad << (64 - L)) >> 32);
    if (!q_ddp_ok(q, dm, L)) {
        return SPVS_E_DEGENERATE;
    }
    const uint32_t r = q_recip63(dm);
    /* The c_i2 to 30 bits: c2n = c_i2 2^-s2 rounded, s2 in [0, 31]. */
    int s2 = q_bitlen(spvs_q_abs64(c2[0]) | spvs_q_abs64(c2[1]) | spvs_q_abs64(c2[2])) - 30;
    s2 = s2 > 0 ? s2 : 0;
    const int32_t c2n[3] = {q_rnd_shift(c2[0], s2), q_rnd_shift(c2[1], s2),
                            q_rnd_shift(c2[2], s2)};
    int32_t w[3], b[3];
    int fb;
    const int f = q_sides(p, q, det < 0, w, b, &fb);
    /* n_j r 2^-32 = n_j / |det P| 2^(L - 1); n_0, n_1 in Q(26 + f), n_2 in
     * Q(52 - s2 + f) (f = fb for row 1): the shifts to Q27 are
     * L + f - 54 and L + f - 28 - s2, in [-14, 111] over f in [21, 50],
     * fb in [16, 76]. */
    int64_t n3[3], n1[3];
    q_adj(p, c2n, w, n3);
    q_adj(p, c2n, b, n1);
    uint32_t sat = 0;
    int32_t h1[3], h3[3];
    for (int j = 0; j < 3; j++) {
        const int sj = j < 2 ? -54 : -28 - s2;
        h3[j] = q_entry(n3[j], r, L + f + sj, &sat);
        h1[j] = q_entry(n1[j], r, L + fb + sj, &sat);
    }
    /* An entry outside (-16, 16) is outside the kernels' range: no
     * consensus keeps such a model (docs/FIXED.md). */
    if (sat != 0) {
        return SPVS_E_DEGENERATE;
    }
    Hq[0] = h1[0];
    Hq[1] = h1[1];
    Hq[2] = h1[2];
    Hq[3] = 0;
    Hq[4] = (int32_t)1 << SPVS_QH;
    Hq[5] = 0;
    Hq[6] = h3[0];
    Hq[7] = h3[1];
    Hq[8] = h3[2];
    return SPVS_OK;
}
