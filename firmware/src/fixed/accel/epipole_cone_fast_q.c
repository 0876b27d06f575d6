/*
 * accel/epipole_cone_fast_q.c - the epipole's support test, accelerated
 * (epipole_cone_q.h): the cone test on the cross product's high word, a
 * count that stops where it can no longer reach `need`, two directions a
 * step, and square roots from an estimate corrected to the floor.  The
 * same supporters, consensus and roots as the reference
 * (epipole_cone_q.c).
 */
#include "../epipole_cone_q.h"
#include "../epipole_q.h"

/* floor(sqrt(x)), exact, as spvs_q_isqrt64 (whose 32 steps of 64-bit
 * operations cost about 1,500 instructions on the Cortex-M3): an estimate
 * from spvs_q_rsqrt (sqrt(F) = F y, relative error below 2^-27, so within
 * 2^4 of the root below 2^31) corrected by exact squares until r^2 <= x <
 * (r + 1)^2, which makes it the floor whatever the estimate's error.  x
 * below 2^62 (the root below 2^31, no square overflows); larger x, or a
 * correction that has not converged in ISQRT_STEPS steps, take
 * spvs_q_isqrt64. */
#define ISQRT_STEPS 64
uint32_t spvs_q_sqrt_floor(uint64_t x)
{
    if (x == 0u || x >= ((uint64_t)1 << 62)) {
        return spvs_q_isqrt64(x);
    }
    int half;
    uint32_t f;
    const uint32_t y = spvs_q_rsqrt(x, &half, &f);
    /* sqrt(x) = sqrt(F) 2^half, sqrt(F) = f y 2^-62, half in 1..31. */
    const uint64_t sf = ((uint64_t)f * y) >> 32; /* Q30, below 2^31 */
    uint64_t r = half >= 30 ? sf << (half - 30) : sf >> (30 - half);
    /* Bound: ISQRT_STEPS corrections. */
    for (int k = 0; k < ISQRT_STEPS; k++) {
        if (r * r > x) {
            r--;
        } else if ((r + 1u) * (r + 1u) <= x) {
            r++;
        } else {
            return (uint32_t)r;
        }
    }
    return spvs_q_isqrt64(x);
}

/* The cone test (supports, below): unit direction (xi, zi) lies within
 * the cone k around (xj, zj) when dot > 0 and cross^2 <= tol.  dot and
 * cross are Q60 (|.| < 2^61 for |u| <= 2^30 (1 + 2^-27)); the test on
 * cross is floor(|cross| 2^-29)^2 <= tol (|cross| to Q31, below 2^32,
 * squared in Q62): exact up to 2^-31 on the sine (2^-30 sin on sin^2,
 * 1e-8 of the default 0.01).  With c = floor(|cross| 2^-29) and cmax =
 * floor(sqrt(tol)), c^2 <= tol is c <= cmax, that is |cross| <= k.lim.
 * cross's high word ch decides it in 32 bits but at two values: ch in
 * [-lh, lh - 1] puts |cross| below lh 2^32 <= lim (inside), ch above lh
 * or below -lh - 1 puts it above (lh + 1) 2^32 > lim (outside); ch = lh
 * or -lh - 1 takes the 64-bit comparison (cone_edge).  The same decision
 * as the squares', with neither a square nor an absolute value per
 * pair. */
static SPVS_Q_NOINLINE int cone_edge(int64_t crs, const spvs_q_cone_t *k)
{
    return (uint64_t)crs + k->lim <= 2u * k->lim;
}

/* 1 when direction d supports (xj, zj): the cone test above, with nxj =
 * -xj (|xj| <= 2^30 (1 + 2^-27), so no overflow), so that cross is one
 * multiply and one multiply-accumulate, and the cross test first, which
 * most pairs fail.  With u1 = ch + lh + 1 (unsigned), ch's range
 * [-lh - 1, lh] is u1 in [0, 2 lh + 1], that is u1 < 2 lh1 (lh1 = lh +
 * 1), tested as u1 >> 1 < lh1 (one shifted comparison against the one
 * constant); the inside, u1 in [1, 2 lh], is u1 != 0 and (u1 + 1) >> 1 <
 * lh1; 0 and 2 lh + 1 are the edges.  A zero direction supports none
 * (dot = 0). */
static SPVS_Q_INLINE int supports(const int32_t d[2], int32_t xj, int32_t nxj, int32_t zj,
                                  uint32_t lh1, const spvs_q_cone_t *k)
{
    const int32_t xi = d[0], zi = d[1];
    const int64_t crs = (int64_t)xi * zj + (int64_t)zi * nxj;
    const uint32_t u1 = (uint32_t)(int32_t)(crs >> 32) + lh1;
    if ((u1 >> 1) >= lh1) {
        return 0;
    }
    const int64_t dot = (int64_t)xi * xj + (int64_t)zi * zj;
    if (dot <= 0) {
        return 0;
    }
    return (u1 != 0u && ((u1 + 1u) >> 1) < lh1) || cone_edge(crs, k);
}

/* The supporters of direction (xj, zj) among the n unit directions u,
 * where they can reach need (at least 1): the consensus's inner loop, in
 * a function of its own so that its few values stay in registers, two
 * directions a step (u[n] is zero for an odd n, so the last step may read
 * it).
 * The scan stops where the supporters found and the directions left
 * cannot reach need: at the first step that starts at or after end =
 * min(n, n + 1 - need + support), one more a supporter.  A count that
 * reaches need - 1 scans to n, so a count of need or more is exact; a
 * smaller one is returned as found, and stays below need (the one
 * direction a step may take past end adds at most 1 where the count is
 * at most need - 2). */
uint16_t spvs_q_cone_count(const int32_t (*u)[2], uint16_t n, int32_t xj, int32_t zj,
                           const spvs_q_cone_t *k, uint32_t need)
{
    if (need > n) {
        return 0;
    }
    const uint32_t lh1 = k->lh + 1u;
    const int32_t nxj = -xj;
    uint32_t support = 0;
    /* On a pointer, whose end moves; n + 1 - need >= 1 directions. */
    const int32_t(*const last)[2] = &u[n];
    const int32_t(*end)[2] = &u[n + 1u - need];
    /* Bound: end <= last, (n + 1) / 2 steps.  A supporter moves end by
     * one, then caps it at last: in between it is at most &u[n + 1], a
     * pointer one past the spare entry. */
    do {
        if (supports(u[0], xj, nxj, zj, lh1, k)) {
            support++;
            end++;
            end = end > last ? last : end;
        }
        if (supports(u[1], xj, nxj, zj, lh1, k)) {
            support++;
            end++;
            end = end > last ? last : end;
        }
        u += 2;
    } while (u < end);
    return (uint16_t)support;
}

int spvs_q_cone_supports(const int32_t d[2], int32_t xj, int32_t zj, const spvs_q_cone_t *k)
{
    return supports(d, xj, -xj, zj, k->lh + 1u, k);
}
