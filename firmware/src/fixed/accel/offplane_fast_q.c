/*
 * accel/offplane_fast_q.c - the off-plane transfer test, accelerated
 * (offplane_test_q.h): most rows are decided from a bound on the
 * transfer's exact ratio in 32-bit words, without the reciprocal and the
 * two scaled ratios that the transfer takes; the rest by the transfer
 * itself, as in the reference (offplane_test_q.c).  The same answer for
 * every row.
 */
#include "../epipole_q.h"
#include "../offplane_test_q.h"

/* The bound decides where o is in [2^13, 2^27) (0.06 px to 1,024 px):
 * there Q (below) is below 2^31 for every w28 of the transfer's fast path
 * (at most 2^30), so the test is in 32-bit words and products. */
#define OFF_FAST_MIN ((uint32_t)1 << 13)
#define OFF_FAST_MAX ((uint32_t)1 << 27)

spvs_q_off_thr_t spvs_q_off_thr(int32_t offplane_q16)
{
    spvs_q_off_thr_t t;
    const uint32_t o = offplane_q16 > 0 ? 2u * (uint32_t)offplane_q16 : 0u;
    t.off2 = (uint64_t)o * o;
    t.o_fast = o >= OFF_FAST_MIN && o < OFF_FAST_MAX ? o : 0u;
    return t;
}

/* The transfer's squared error, out of line: flash holds one copy. */
static SPVS_Q_NOINLINE int64_t err2_call(const int32_t H[9], const int32_t p[4])
{
    return spvs_q_transfer_err2(H, p);
}

/* On the transfer's fast path the ratio's exact value d = n28 / w28
 * (Q26: d 2^26) gives e = |d|^2 2^52 = A 2^52 / w28^2 with A = nx28^2 +
 * ny28^2 (below 2^61), and e > off2 is A > t^2 with t = o w28 2^-26,
 * where Q = floor(o w28 2^-26) <= t < Q + 1 (o w28 < 2^57).
 * spvs_q_transfer's du is within 2^-27 |d| + 1 unit of d 2^26 for w28 >=
 * 2^25 (k <= 5 in spvs_q_ratio_fast: the reciprocal's 2^-28 and its
 * clamp's 2^-31, 1/2 unit of Q(31 - k), 1/2 of Q26), so its e2 is within
 * 2^-26 e + 2.9 sqrt(e) + 2 of e.  With o >= 2^13, A above (Q + 1 +
 * (Q + 1) / 2^8)^2 makes e > off2 (1 + 2^-7) and e2 > off2; A below
 * (Q - Q / 2^8 - 1)^2 makes e < off2 (1 - 2^-8) and e2 < off2.  Between,
 * and off the fast path, the transfer decides. */
int spvs_q_off_above(const int32_t H[9], const int32_t p[4], const spvs_q_off_thr_t *t)
{
    spvs_q_tf_t f;
    const int path = spvs_q_transfer_front(H, p, &f);
    if (path == SPVS_Q_TF_BEHIND) {
        return -1;
    }
    if (path == SPVS_Q_TF_FAST && t->o_fast != 0u && f.w28 >= ((int32_t)1 << 25)) {
        const uint64_t A =
            (uint64_t)((int64_t)f.nx28 * f.nx28) + (uint64_t)((int64_t)f.ny28 * f.ny28);
        /* o < 2^27 and w28 <= 2^30: Q < 2^31.  w28 opaque, so that the
         * product is one UMULL (GCC otherwise extends w28's sign). */
        const uint32_t uw = (uint32_t)spvs_q_opaque32(f.w28);
        const uint32_t Q = (uint32_t)(((uint64_t)t->o_fast * uw) >> 26);
        const uint32_t hi = Q + 1u + ((Q + 1u) >> 8); /* below 2^31.01 */
        if (A > (uint64_t)hi * hi) {
            return 1;
        }
        const uint32_t lo = Q - (Q >> 8);
        if (lo >= 1u && A < (uint64_t)(lo - 1u) * (lo - 1u)) {
            return 0;
        }
    }
    /* Near the threshold or off the fast path (rare): w > SPVS_W_EPS, so
     * e2 is not negative. */
    return (uint64_t)err2_call(H, p) > t->off2;
}
