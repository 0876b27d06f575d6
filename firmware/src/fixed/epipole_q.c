/*
 * epipole_q.c - the epipole from plane plus parallax in fixed point
 * (epipole_q.h): the Q directions and tests under the decisions of
 * epipole.inc (written once for both cores).  epipole.c's comments say
 * why each step is made; here they say where the fixed-point version
 * differs and why it stays in range.
 */
#include <string.h>

#include "epipole_cone_q.h"
#include "epipole_q.h"

/* epipole.c's DIR_MIN2 (1e-12 on the squared direction, scaled units) on
 * a direction d = d' 2^(sh - 79 + s) (d' the reduced integers, n2 =
 * |d'|^2 in [2^58, 2^61]): n2 2^E > 1e-12 with E = 2 (sh + s) - 158 is
 * true for E >= -97 (2^-39 > 1e-12), false for E <= -102 (2^-41 < 1e-12),
 * and between, n2 > floor(1e-12 2^-E), these. */
static const uint64_t DIR_MIN2_N2[4] = {2535301200456458752u, 1267650600228229376u,
                                        633825300114114688u, 316912650057057344u};

static SPVS_Q_INLINE int dir_usable(uint64_t n2, int E)
{
    if (E >= -97) {
        return 1;
    }
    if (E <= -102) {
        return 0;
    }
    return n2 > DIR_MIN2_N2[E + 101];
}

/* (dx, dz) as a unit vector in Q30, |u| within 2^-27 of 1 (the
 * reciprocal square root's error plus 1/2 unit).  The vector is first
 * reduced to d' = d 2^-sh with max(|d'_x|, |d'_z|) in [2^29, 2^30]
 * (rounded, or shifted left exactly), so n2 = |d'|^2 is in [2^58, 2^61]
 * and the rsqrt's half is 30 or 31; each product d' y is below 2^61.
 * Returns 0 (u = 0) for d = 0. */
static SPVS_Q_INLINE int unit(int64_t dx, int64_t dz, int32_t *ux, int32_t *uz, int *sh_out,
                              uint64_t *n2_out)
{
    const uint64_t m = spvs_q_abs64(dx) | spvs_q_abs64(dz);
    if (m == 0u) {
        *ux = 0;
        *uz = 0;
        return 0;
    }
    const int sh = spvs_q_bits(m) - 30;
    int32_t x, z;
    if (sh > 0) {
        x = spvs_q_rsh32(dx, sh);
        z = spvs_q_rsh32(dz, sh);
    } else {
        x = (int32_t)(dx * ((int64_t)1 << -sh));
        z = (int32_t)(dz * ((int64_t)1 << -sh));
    }
    const uint64_t n2 = (uint64_t)((int64_t)x * x) + (uint64_t)((int64_t)z * z);
    /* spvs_q_rsqrt's normalisation where n2 has 59 to 62 bits: F = n2
     * 2^-60 (half 30) for 59 or 60 bits, n2 2^-62 (half 31) for 61 or 62,
     * decided by the high word; two constant shifts, not a 64-bit shift by
     * a variable amount. */
    const int half = (uint32_t)(n2 >> 32) < ((uint32_t)1 << 28) ? 30 : 31;
    const uint32_t y = spvs_q_rsqrt_f(half == 30 ? (uint32_t)(n2 >> 28) : (uint32_t)(n2 >> 30));
    if (half == 30) {
        *ux = (int32_t)spvs_q_rsh((int64_t)x * y, 30);
        *uz = (int32_t)spvs_q_rsh((int64_t)z * y, 30);
    } else {
        *ux = (int32_t)spvs_q_rsh((int64_t)x * y, 31);
        *uz = (int32_t)spvs_q_rsh((int64_t)z * y, 31);
    }
    *sh_out = sh;
    *n2_out = n2;
    return 1;
}

/* Per candidate: l = p_cur x q with q = H p_tgt rounded per point
 * (spvs_q_hp), l1 = y_cur q3 - q2 and l3 = x_cur q2 - y_cur q1 in int64
 * Q(79 - s) (each product below 2^60, each difference below 2^61), the
 * signed direction sign(y_cur) (l3, -l1) as a Q30 unit vector, or 0 when
 * epipole.c's DIR_MIN2 test fails on it (the same quantity: the lines'
 * integers are the float lines' values times 2^(79 - s)).  A zero vector
 * has a zero dot product with every other, so it neither supports nor
 * gets support (epipole.c's test on n2 at each use). */
static SPVS_Q_NOINLINE void line_directions(const int32_t H[9], const int32_t (*pts)[4],
                                            const uint16_t *cand, uint16_t n_cand,
                                            uint8_t *support_out, spvs_q_epipole_work_t *work)
{
    /* The flags cleared first, out of the loop: a byte store may alias
     * anything, so in the loop it would make H and the points be read
     * again after it. */
    if (support_out) {
        memset(support_out, 0, n_cand);
    }
    /* On pointers: the candidate's index and its direction. */
    int32_t(*d)[2] = work->u;
    for (const uint16_t *c = cand; c < cand + n_cand; c++, d++) {
        const int32_t *p = pts[*c];
        const spvs_q_hp_t h = spvs_q_hp(H, p);
        /* 2^26 opaque: l1 as two multiplies rather than a 64-bit shift. */
        const int64_t l1 = (int64_t)p[3] * h.q3 - (int64_t)h.q2 * spvs_q_opaque32((int32_t)1 << 26);
        const int64_t l3 = (int64_t)p[2] * h.q2 - (int64_t)p[3] * h.q1;
        const int neg = p[3] < 0;
        int sh = 0;
        uint64_t n2 = 0;
        if (unit(neg ? -l3 : l3, neg ? l1 : -l1, &(*d)[0], &(*d)[1], &sh, &n2) &&
            !dir_usable(n2, 2 * (sh + h.s) - 158)) {
            (*d)[0] = 0;
            (*d)[1] = 0;
        }
    }
    /* A zero direction after an odd count, which the accelerated count
     * (spvs_q_cone_count) may read: it supports none. */
    if ((n_cand & 1u) != 0u) {
        work->u[n_cand][0] = 0;
        work->u[n_cand][1] = 0;
    }
}

/* cos of the angle whose sine is s (Q30), for a supporter (dot > 0, so
 * the cosine is the positive root): sqrt(2^60 - s^2), floor, Q30. */
static int64_t cos_of(int32_t s)
{
    const int64_t s2 = (int64_t)s * s;
    const int64_t one = (int64_t)1 << 60;
    return s2 >= one ? 0 : (int64_t)spvs_q_sqrt_floor((uint64_t)(one - s2));
}

/* The median turn of b = (bx, bz) by the supporters' sines v[2 i], i < n
 * (n >= 1, reordered here) as (c, s), the turn's cosine and sine up to one
 * positive factor, Q30 (|.| <= 2^31).  epipole.c turns b by the median
 * of tan(delta_i) (their mean for an even n).  The tangent is monotone
 * in the sine over (-90, 90) degrees, so the median element is the same;
 * for an odd n the turn is (cos, sin) of it, with no division; for an
 * even n, (1, (t1 + t2) / 2) is along (2 c1 c2, s1 c2 + s2 c1). */
static void median_turn(int32_t *v, uint16_t n, int64_t *c, int64_t *s)
{
    const int32_t s2 = spvs_q_select_i32(v, 2u, n, n / 2u);
    if ((n & 1u) != 0u) {
        *s = s2;
        *c = cos_of(s2);
        return;
    }
    /* The element below the median in sorted order: the largest of those
     * spvs_q_select_i32 left below it.  Bound: n / 2 steps. */
    int32_t s1 = v[0];
    for (uint32_t i = 1; i < n / 2u; i++) {
        s1 = v[2u * i] > s1 ? v[2u * i] : s1;
    }
    const int64_t c1 = cos_of(s1), c2 = cos_of(s2);
    *c = (c1 * c2) >> 29;
    *s = (s1 * c2 + s2 * c1) >> 30;
}

/* e_x = SPVS_COORD_SCALE dir_x / dir_z in Q16 pixels, clamped at
 * SPVS_EPIPOLE_MAX_PX as epipole.c does (|e_x| >= the limit: 512 |x| >=
 * 20000 |z|, exact in int64, with the sign of x / z).  The quotient is
 * below 20000 2^16 < 2^31 when not clamped; one 64-by-32-bit division. */
static int32_t e_x_q16(int32_t dx, int32_t dz)
{
    const int64_t ax = (int64_t)spvs_q_abs64(dx), az = (int64_t)spvs_q_abs64(dz);
    if (ax * SPVS_COORD_SCALE >= (int64_t)SPVS_Q_EPIPOLE_MAX_PX * az) {
        return ((dx < 0) != (dz < 0)) ? -SPVS_Q_EPIPOLE_MAX_Q16 : SPVS_Q_EPIPOLE_MAX_Q16;
    }
    uint32_t sat = 0;
    _Static_assert(SPVS_COORD_SCALE == 512, "e_x's shift assumes a scale of 2^9");
    return spvs_q_div64_32((int64_t)dx * ((int64_t)1 << 25), dz, &sat);
}

/* epipole.c's refine: the supporters of hypothesis `best` (the same test
 * as the consensus, so the same set), their sines about b = u[best]
 * (Q30) into u[k][0] and parallaxes (Q16 px) into u[k][1], entry k <= i written
 * after entry i was read; the median turn, the epipole's direction and
 * e_x, the median parallax (the upper median, as epipole.c). */
static void refine(const int32_t H[9], const int32_t (*pts)[4], const uint16_t *cand,
                   uint16_t n_cand, const spvs_q_cone_t *k, uint16_t best, spvs_q_epipole_t *out,
                   uint8_t *support_out, spvs_q_epipole_work_t *work)
{
    const int32_t bx = work->u[best][0], bz = work->u[best][1];
    /* The supporters first, in a loop of the test alone (the consensus's,
     * so the same set), then their sines and parallaxes: entry t written
     * after entry sup[t] >= t was read, and sup rising. */
    uint8_t sup[SPVS_MAX_OFFPLANE];
    uint32_t n_t = 0;
    for (uint32_t i = 0; i < n_cand; i++) {
        if (spvs_q_cone_supports(work->u[i], bx, bz, k)) {
            sup[n_t++] = (uint8_t)i;
        }
    }
    uint32_t n_par = 0;
    for (uint32_t t = 0; t < n_t; t++) {
        const uint32_t i = sup[t];
        const int32_t xi = work->u[i][0], zi = work->u[i][1];
        if (support_out) {
            support_out[i] = 1;
        }
        /* cross(b, d_i) in Q60 to Q30: |.| <= 2^30 (1 + 2^-26). */
        work->u[t][0] = (int32_t)spvs_q_rsh((int64_t)bx * zi - (int64_t)bz * xi, 30);
        int32_t du, dv;
        if (spvs_q_transfer(H, pts[cand[i]], &du, &dv)) {
            const uint64_t e2 = (uint64_t)((int64_t)du * du) + (uint64_t)((int64_t)dv * dv);
            work->u[n_par++][1] = spvs_q_sqrt_q52_px16(e2);
        }
    }
    int64_t c, s;
    median_turn(&work->u[0][0], (uint16_t)n_t, &c, &s);
    /* b turned: (bx c - bz s, bz c + bx s), each product below 2^61 (1 +
     * 2^-26), the sums below 2^63. */
    int sh;
    uint64_t n2;
    (void)unit(bx * c - bz * s, bz * c + bx * s, &out->dir_x, &out->dir_z, &sh, &n2);
    out->e_x_q16 = e_x_q16(out->dir_x, out->dir_z);
    if (n_par > 0) {
        out->parallax_q16 = spvs_q_select_i32(&work->u[0][1], 2u, n_par, n_par / 2u);
    }
}

/* ---- the fixed-point core's side of epipole.inc ----------------------------- */

typedef spvs_q_epipole_t ep_t;
typedef spvs_q_epipole_work_t ep_work_t;
typedef int32_t ep_h_t;
typedef int32_t ep_tol_in_t; /* sin^2, Q30 */
typedef spvs_q_cone_t ep_tol_t;

static void clear_estimate(spvs_q_epipole_t *out)
{
    out->e_x_q16 = 0;
    out->dir_x = 0;
    out->dir_z = 0;
    out->parallax_q16 = 0;
    out->n_support = 0;
}

spvs_q_cone_t spvs_q_cone(uint64_t tol)
{
    spvs_q_cone_t k;
    k.tol = tol;
    k.lim = (((uint64_t)spvs_q_sqrt_floor(tol) + 1u) << 29) - 1u;
    k.lh = (uint32_t)(k.lim >> 32);
    return k;
}

/* The cone from sin^2 in Q30 (tol Q62, below 2^63).  A negative tolerance
 * admits no candidate, as float's crs^2 <= tol2 n2 n2 never holds then. */
static int tol_of(int32_t sin_tol2_q30, spvs_q_cone_t *k)
{
    if (sin_tol2_q30 < 0) {
        return 0;
    }
    *k = spvs_q_cone((uint64_t)sin_tol2_q30 << 32);
    return 1;
}

/* line_directions makes an unusable direction zero. */
static int hyp_usable(const spvs_q_epipole_work_t *work, uint16_t j)
{
    return !(work->u[j][0] == 0 && work->u[j][1] == 0);
}

static uint16_t support_count(const spvs_q_epipole_work_t *work, uint16_t n_cand, uint16_t j,
                              const spvs_q_cone_t *k, uint32_t need)
{
    return spvs_q_cone_count(work->u, n_cand, work->u[j][0], work->u[j][1], k, need);
}

#include "../epipole.inc"

int spvs_q_epipole_estimate(const int32_t H[9], const int32_t (*pts)[4], const uint16_t *cand,
                            uint16_t n_cand, int32_t sin_tol2_q30, uint16_t min_support,
                            spvs_q_epipole_t *out, uint8_t *support_out,
                            spvs_q_epipole_work_t *work)
{
    return estimate_epipole(H, pts, cand, n_cand, sin_tol2_q30, min_support, out, support_out,
                            work);
}
