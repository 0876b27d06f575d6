/*
 * fixed/accel/score_fast_q.c - the fixed-point inlier count with its
 * integer filters (points_q.h: spvs_q_thr, spvs_q_pts_score), built where
 * SPVS_ACCEL is ON in place of the reference count of fixed/score_q.c.
 *
 * Each point goes first to the fast test on 32-bit high words (q_fast),
 * then to the band's Sampson test in 32-bit integers (q_band_sampson),
 * then to the exact test, which tries the 30-bit integer stage
 * (q_sampson30) before point_q.h's reference arithmetic.  Every filter
 * decides only outside its proved rounding slack, so every decision is
 * the reference test's (q_inlier_ref): the same masks and counts
 * (test_fixed_q, and the closed loops of the fixed build with
 * SPVS_ACCEL=OFF).  The compiler steering here (SPVS_Q_NOINLINE,
 * spvs_q_opaque32, a volatile model pointer) keeps the Cortex-M3's loop
 * in registers; it changes no result.
 */
#include "../../core_util.h"
#include "../point_q.h"

/* x[0..n) (each below 2^62 in magnitude) to 30 bits at one shift: out[k]
 * = floor(x[k] 2^-s), in [-2^30, 2^30), with s = bitlen(max |x|) - 30 (at
 * least 0, at most 32) returned. */
static SPVS_Q_NOINLINE int q_to30(const int64_t *x, int n, int32_t *out)
{
    uint64_t m = 0;
    for (int k = 0; k < n; k++) {
        m |= spvs_q_abs64(x[k]);
    }
    const int s = spvs_q_norm_shift(m, 30);
    for (int k = 0; k < n; k++) {
        out[k] = (int32_t)(x[k] >> s);
    }
    return s;
}

/* L <= P 2^k (the integers L, P < 2^64, any k) exactly: ceil(L 2^-k) <= P
 * for k >= 0, L <= floor(P 2^k) below. */
static SPVS_Q_INLINE int q_le_scaled(uint64_t L, uint64_t P, int32_t k)
{
    if (k >= 64) {
        return L == 0u || P != 0u;
    }
    if (k >= 0) {
        const uint64_t rem = k == 0 ? 0u : L & ((((uint64_t)1) << k) - 1u);
        return (L >> k) + (rem != 0u) <= P;
    }
    return k > -64 && L <= (P >> -k);
}

/* The Sampson test of one point in integers at 30 bits, before the
 * exact test's spvs_qf_t arithmetic (q_inlier_exact): 1 (an inlier), 0
 * (not), or -1 where it cannot decide.  r holds the point's residuals
 * (q_eps, w > 0).  With J J^T = w^2 I + P P^T (q_sampson):
 *   num = |v|^2, v = (w eps, adj(P) eps),
 *   den = |u|^2, u = (w^2, w P_11, w P_12, w P_21, w P_22, det P),
 * and the point is an inlier when num <= t2 den.
 *
 * The values.  w and P (exact in Q53, q_jac) are taken to 30 bits at one
 * shift ka, eps (Q(79 - s1)) at another, kb, each by a floor: each is
 * then within 1 of its exact value in its new unit (eps within 2: q_eps
 * rounded it by under 1 unit, at most 1 after the shift), and every
 * magnitude is at most M = 2^30.  From these int32 values v and u are
 * exact in int64 (each entry at most 2^61); they differ from the exact
 * ones, in the units 2^(ka + kb) and 2^(2 ka), by
 *   |v - V| <= ||K|| |de| + ||dK|| |eps| <= 6^(1/2) (M + 1) 2 2^(1/2)
 *              + 6^(1/2) 2^(1/2) M < 2^34,
 *   |u - U| <= |w| |dz| + |dw| |z| + |d det| <= 5^(1/2) (2 M + 1)
 *              + 4 M + 2 < 2^34
 * (K = (w I; adj(P)), z = (w, P), each d a change of at most 1 an entry,
 * 2 for eps).  v's entries are then taken to 30 bits at one shift sv,
 * u's at su, again by floors, which adds under 2 (four entries) and
 * 6^(1/2) (six) to the norms.  So, in those units, |v'| is within
 * ev = 2^34 2^-sv + 3 of |V| 2^-sv and |u'| within eu = 2^34 2^-su + 3
 * of |U| 2^-su.  With |v'| <= 2^31 and |u'| <= 6^(1/2) 2^30 < 2^32:
 *   inlier   when (num + ev 2^32 + ev^2) (1 + 2^-20) <= (den - eu 2^33) t,
 *            which bounds (|V| + ...)^2 <= (|U| - ...)^2 t;
 *   outlier  when num - ev 2^32 > (den + eu 2^33 + eu^2) (1 + 2^-20) t;
 * t = t2 2^(2 (su - sv + ka - kb + 26 - s1)) bringing t2 to the units of
 * num / den.  Each decided point's exact squared Sampson error is at least
 * 2^-20 (relative) from t2, beyond the exact test's own error (below 1e-7,
 * points_q.h): its decisions are the exact test's.  den t is bounded below
 * (inlier) or above (outlier) by den's top 32 bits times t2's mantissa.
 * The test leaves the points within about 2^-20 of the threshold, and
 * those where sv or su is 20 or less (ev or eu above 2^14: v or u far
 * below its size, as where w is far below P, which the count's range
 * does not give). */
static int q_sampson30(const int32_t *h, const int32_t *p, const q_eps_t *r, spvs_qf_t t2)
{
    /* w and P exact in Q53 (q_jac53), below 2^62; eps. */
    const int64_t a[5] = {r->w, q_jac53(h, p, 0), q_jac53(h, p, 1), q_jac53(h, p, 2),
                          q_jac53(h, p, 3)};
    const int64_t eps[2] = {r->ex, r->ey};
    int32_t z[5], e[2];
    const int ka = q_to30(a, 5, z), kb = q_to30(eps, 2, e);
    const int32_t w = z[0], p0 = z[1], p1 = z[2], p2 = z[3], p3 = z[4];
    /* v and u, exact from the 30-bit values, then to 30 bits again. */
    const int64_t v[4] = {(int64_t)w * e[0], (int64_t)w * e[1],
                          (int64_t)p3 * e[0] - (int64_t)p1 * e[1],
                          (int64_t)p0 * e[1] - (int64_t)p2 * e[0]};
    const int64_t u[6] = {(int64_t)w * w,   (int64_t)w * p0, (int64_t)w * p1,
                          (int64_t)w * p2,  (int64_t)w * p3,
                          (int64_t)p0 * p3 - (int64_t)p1 * p2};
    int32_t vs[4], us[6];
    const int sv = q_to30(v, 4, vs), su = q_to30(u, 6, us);
    if (sv <= 20 || su <= 20 || t2.m <= 0) {
        return -1;
    }
    uint64_t num = 0, den = 0;
    for (int k = 0; k < 4; k++) {
        num += (uint64_t)((int64_t)vs[k] * vs[k]);
    }
    for (int k = 0; k < 6; k++) {
        den += (uint64_t)((int64_t)us[k] * us[k]);
    }
    /* sv, su in 21..32: ev, eu <= 2^13 + 3, and every margin below fits
     * its word (num <= 2^62, den < 6 2^60). */
    const uint64_t ev = ((uint64_t)1 << (34 - sv)) + 3u;
    const uint64_t eu = ((uint64_t)1 << (34 - su)) + 3u;
    const uint64_t tm = (uint64_t)t2.m;
    /* t = tm 2^(k - 31) (the comment's t): den t is bounded by den's top
     * bits (den 2^-31, below 2^32, rounded down or up) times tm (below
     * 2^31), times 2^k. */
    const int32_t k = t2.e + 2 * (su - sv + ka - kb + 26 - r->s1) + 31;
    const uint64_t li = num + (ev << 32) + ev * ev;
    const uint64_t di = den > (eu << 33) ? den - (eu << 33) : 0u;
    if (di != 0u && q_le_scaled(li + (li >> 20) + 1u, (di >> 31) * tm, k)) {
        return 1;
    }
    const uint64_t lo = num > (ev << 32) ? num - (ev << 32) : 0u;
    const uint64_t d0 = den + (eu << 33) + eu * eu;
    const uint64_t dout = d0 + (d0 >> 20) + 1u;
    if (lo != 0u && !q_le_scaled(lo, ((dout >> 31) + 1u) * tm, k)) {
        return 0;
    }
    return -1;
}

/* The exact test of one point (the slow path): residuals exact (q_eps),
 * decided by q_sampson30 where it can, else the Sampson error in
 * spvs_qf_t.  1 for an inlier. */
static int q_inlier_exact(const int32_t *h, const int32_t *p, spvs_qf_t t2)
{
    q_eps_t r;
    q_eps(h, p, &r);
    if (r.w <= 0) {
        return 0;
    }
    const int d = q_sampson30(h, p, &r, t2);
    if (d >= 0) {
        return d;
    }
    return q_inlier_qf(h, p, &r, t2);
}


/* c2 of the band test for H on the frame (points.c, band_c2) in Q42, the
 * units of the fast test's E: t2 times a bound of |P|_F^2 over the frame's
 * points from their largest |u|, |v|.  Each entry's bound is exact in Q53
 * (< 2^62); its high word, rounded up, is a Q21 bound (<= 2^30), so the
 * squares sum to a Q42 bound below 2^62 without rounding down.  The
 * product with t2 is bounded above in integers, then raised by 2^-20 and
 * one unit (the margin over the exact test's error).  Saturates at 2^62 (no
 * band test: E never exceeds it). */
static int64_t band_c2(const spvs_q_store_t *st, const int32_t *h, spvs_qf_t t2)
{
    const uint64_t um = (uint32_t)st->cur_max[0], vm = (uint32_t)st->cur_max[1];
    /* Each entry's high word rounded up (<= 2^30), squared (written out:
     * no array). */
    const uint32_t e0 = (uint32_t)((um * h_mag(h[6]) + (h_mag(h[0]) << 26)) >> 32) + 1u;
    const uint32_t e1 = (uint32_t)((um * h_mag(h[7]) + (h_mag(h[1]) << 26)) >> 32) + 1u;
    const uint32_t e2 = (uint32_t)((vm * h_mag(h[6])) >> 32) + 1u;
    const uint32_t e3 = (uint32_t)((vm * h_mag(h[7]) + ((uint64_t)1 << 53)) >> 32) + 1u;
    const uint64_t b = (uint64_t)e0 * e0 + (uint64_t)e1 * e1 + (uint64_t)e2 * e2 +
                       (uint64_t)e3 * e3;
    /* t2 b in Q42 is t2.m b 2^t2.e, bounded above in integers: b's top
     * 32 bits rounded up (bu 2^sb >= b), their product with the 31-bit
     * mantissa below 2^63, shifted by t2.e + sb (rounded up). */
    const int64_t lim = (int64_t)1 << 62;
    if (t2.m <= 0) {
        return lim;
    }
    const int bl = spvs_q_bitlen64(b);
    const int sb = bl > 32 ? bl - 32 : 0;
    const uint64_t pr = (uint64_t)t2.m * ((b >> sb) + 1u);
    const int32_t k = t2.e + sb;
    int64_t c2;
    if (k >= 0) {
        if (k >= 62 || pr >= ((uint64_t)lim >> k)) {
            return lim;
        }
        c2 = (int64_t)(pr << k);
    } else {
        c2 = k <= -63 ? 1 : (int64_t)(pr >> -k) + 1;
    }
    if (c2 >= lim - (lim >> 20)) {
        return lim;
    }
    return c2 + (c2 >> 20) + 1;
}

spvs_q_thr_t spvs_q_thr(spvs_qf_t t2)
{
    spvs_q_thr_t thr;
    thr.t2 = t2;
    thr.T = 0;
    thr.fast = 0;
    if (t2.m <= 0) {
        return thr;
    }
    /* t = sqrt(t2) as a 31-bit mantissa R 2^re, rounded down. */
    uint64_t tm = (uint64_t)t2.m;
    int32_t te = t2.e;
    if (te & 1) {
        tm <<= 1;
        te -= 1;
    }
    /* sqrt(tm 2^32) in [2^30.5, 2^32): halve once more into 31 bits. */
    const uint32_t root = spvs_q_isqrt64(tm << 32) >> 1;
    const int32_t re = (te - 32) / 2 + 1;
    /* T = floor(t 2^26) = floor(R 2^(re + 26)); t < 2 makes re + 26 <= -3
     * for R >= 2^29.5, so T is R shifted right, below 2^28. */
    const int32_t k = re + 26;
    if (k > -3) {
        return thr;
    }
    thr.T = k < -31 ? 0 : (int32_t)(root >> -k);
    thr.fast = 1;
    return thr;
}


/* The fast test of one model (points between the two shortcuts take the
 * band's Sampson test, q_band_sampson; those it leaves, and every point of
 * a model outside the fast test's range, go to the exact test).
 *
 * Per point it needs only 32 x 32 -> 64-bit products, 64-bit sums, one
 * constant shift and high words, so that on a core without a 64-bit
 * shifter (the Cortex-M3) no shift depends on the model:
 *   w   = h3 . p                 Q53, exact (as q_eps);
 *   w27 = floor(w 2^-26)         Q27 in int32 (|w| < 16: checked per model);
 *   ex  = u w27 - h1 . p         Q53 in int64, ey = v w27 - y 2^27 likewise;
 *   exh = floor(ex 2^-32)        their high words: Q21 scaled units;
 *   tw  = floor(T w27 2^-32)     t |w| in Q21, T = floor(t 2^26);
 * and E = exh^2 + eyh^2, TW = tw^2, c2 (the band's bound, hp_inlier) in
 * Q42.  Each of exh, eyh and tw is within D = 2 units of its exact value
 * (exh: the floor of w27 moves u w27 by |u| < 2^30 units of Q53, under a
 * quarter unit of Q21, and its own floor by one; tw: the floors of T and of
 * w27 by under half a unit each, its own by one), so E and TW are within
 * slack = 2 D (|exh| + |eyh| + tw) + 4 D^2 of the exact ones: the test
 * decides only outside it, and its decisions are the exact test's.  At the
 * default threshold (t = 2.45 px) an inlier's |ex| at the threshold is
 * about 10^4 units, so only points within about 4e-4 of it (relative)
 * reach the exact test through the slack.
 * fast = 0 where a bound does not hold: |w| >= 16, |eps| >= 2^62 in Q53
 * (beyond 2^9 scaled units), or t >= 2 scaled units (1,024 px).
 *
 * Only the last is a bound of the test itself: the first two are bounds of
 * w and eps over the frame, which spare the count's loop a test per point.
 * A wild hypothesis breaks them while most of its points are in range (a
 * large |h31| makes w reach 16 in a corner of the image), so where only
 * they fail the model is checked (chk = 1): each point takes the same
 * tests once its own 0 < w < 16 and |ex|, |ey| < 2^62 are tested
 * (q_checked), and only the points outside those go to the exact test. */
typedef struct {
    int fast;
    int chk; /* fast = 0, the point's ranges tested per point (q_checked) */
    int32_t T;
    int32_t nh0, nh1; /* -h11, -h12 (|h| < 2^31: no overflow) */
    int64_t nh2c;     /* -h13 2^26, Q53: ex's constant term */
    int64_t h8c;      /* h33 2^26, Q53: w's constant term */
    uint64_t c2s;     /* c2 + 16 D^2 (q_fast's form), or above 2^62: no band test */
    /* The band's Sampson test (q_band_sampson): sfast = -1 until its
     * constants are made (sampson_prep, at the model's first band point),
     * then 1 (on) or 0 (off: the band goes to the exact test). */
    int sfast;
    const spvs_q_store_t *st; /* the frame, for sampson_prep */
    const int32_t *h;         /* the model (Q27), for sampson_prep */
    int64_t wb;               /* the bound of w over the points tested, Q53 */
    int sh;                   /* the values' shift: Q(21 - sh) */
    int32_t a6, a7;     /* t' h31, t' h32 in Q27 (t' = T 2^-26), rounded */
    int64_t c0, c1, c3; /* t' h11, t' h12 and t' in Q53, exact */
    /* One residual's magnitude beyond which a point is out whatever the
     * other (q_far_bound), Q21; UINT32_MAX: no such bound. */
    uint32_t far;
} q_model_t;

#define Q_FAST_D 2

/* The band's Sampson test (points the two shortcuts leave: |eps| between
 * about t w and t (w^2 + |P|^2)^(1/2)), in integers.  With
 * omega = t w, Pi = t P (P as q_jac) and eps, all in Q(21 - sh),
 *   num = omega^2 |eps|^2 + |adj(Pi) eps|^2 = |v|^2,
 *         v = (omega eps, adj(Pi) eps),
 *   den = omega^4 + omega^2 |Pi|_F^2 + det(Pi)^2 = |u|^2,
 *         u = (omega^2, omega Pi_11, .., omega Pi_22, det(Pi)),
 * are q_sampson's num and den times t^2 and t^4 (and one power of two), so
 * num <= den is the point's test num <= t2 den.  Its seven values are
 * within D = 17/8 units of their exact ones:
 *   eps   exh, eyh (q_inlier): under 5/4;
 *   omega tw (q_inlier): the floors of w27 and of T move it by under 1/16
 *         and 1/2 (|w| < 16), its own floor by under 1;
 *   Pi    the high word of u a6 - c0 (Pi_11; Pi_12, Pi_21, Pi_22 alike):
 *         this is t' P_11 2^-32 (Q53) plus u times a6's rounding (under
 *         2^29), and t' P_11 is within 2^-26 |P_11| < 2^32 of t P_11
 *         (|P_11| < 32 over the frame, sampson_prep): under 9/8, with the
 *         floor under 17/8;
 * and the shift by sh >= 1 makes that at most (17/8) / 2 plus under 1
 * (the floors of the high word and of the shift are one floor).  Every
 * value is in [-2^15, 2^15 - 1] (checked per point: the OR of their
 * magnitudes, less one for a negative value, is below 2^15),
 * so every product below is exact in its type: a0 = Pi_22 eps_x - Pi_12
 * eps_y, a1 and det(Pi) within +-(2^31 - 2^15) (2^31 would need one
 * factor to be +2^15); omega^2 < 2^30, |eps|^2 <= 2^31, each half of
 * |Pi|_F^2 at most 2^31; num below 2^61 + 2^63, den below 2^60 + 2^63.
 *
 * The error bound.  With m >= every |value| and each within D of the
 * exact one (upper case: exact, lower case: computed), v = K(omega, Pi)
 * eps for the 4 x 2 matrix K = (omega I; adj(Pi)), ||K|| <= (omega^2 +
 * |Pi|_F^2)^(1/2) <= 5^(1/2) m, so
 *   |v - V| <= ||K|| |eps - EPS| + ||K(delta)|| |EPS|
 *           <= 10^(1/2) D (2 m + D);
 * u's first five entries are omega (omega, Pi): within 5^(1/2) D (2 m +
 * D); det(pi) - det(pi - delta) = tr(adj(pi) delta) - det(delta), within
 * 2 m 2 D + 2 D^2.  So |v| and |u| are together within
 *   E = (10^(1/2) + 5^(1/2)) D (2 m + D) + 4 m D + 2 D^2 <= 15 D m + 8 D^2
 * of the exact |V| and |U|, which is below 32 m + 37 for D = 17/8.  The
 * test decides with E* = E + 2048:
 *   inlier   when num + E* 2 Gh <= den, Gh = omega^2 + |Pi|_F^2 / 2 (up):
 *            then num <= den, |v| <= |u| <= Gh (AM-GM on den's two factors
 *            omega^2 + sigma_i^2), so |u| - |v| >= E* and
 *            |U| - |V| >= 2048;
 *   outlier  when num > den + E* 2 Hh, Hh = (|eps|^2 + omega^2 + |Pi|_F^2)
 *            / 2 (up) >= |eps| ||K|| >= |v| >= |u|: |V| - |U| > 2048;
 * and sends every other point to the exact test.  |U| < 3 2^30 + 2^21 <
 * 2^32, so a decided point's exact squared Sampson error is at least
 * 2^-21 (relative) from t2: the exact test's own arithmetic (below 1e-7,
 * points_q.h) decides it the same way.  2 E* < 2^22 and Gh, Hh < 2^32:
 * each bound is one 32 x 32 -> 64-bit product.  The test leaves undecided
 * the points within about 10 E* / |u| (relative) of the threshold: at the
 * default threshold (t near 12,400 units of Q21, values near 2^13 to 2^15)
 * well under 1 %. */
#define Q_BAND_LIM 0x8000 /* 2^15 */

/* x ^ (x >> 31): |x| for x >= 0, |x| - 1 below (one instruction). */
static SPVS_Q_INLINE uint32_t q_mag(int32_t x)
{
    return (uint32_t)(x ^ (x >> 31));
}

/* The threshold's T (0 <= T < 2^28) times a bound b over the frame (Q53,
 * 0 <= b < 2^58) taken in Q27: t b in Q21, below 2^28, by one 32 x 32 ->
 * 64-bit multiply (sampson_prep, q_far_bound). */
static SPVS_Q_INLINE uint32_t t_hi(int32_t T, int64_t b)
{
    return (uint32_t)(((uint64_t)(uint32_t)T * (uint32_t)(b >> 26)) >> 32);
}

/* The constants of the band's Sampson test of the model H (md->h) on the
 * frame: a6, a7, c0, c1, c3 (q_model_t) and the shift sh that brings
 * t (w^2 + |P|_F^2)^(1/2) over the frame below 2^15 (an estimate from
 * the frame's bounds; a point beyond it goes to the exact test).  Off (sfast = 0) unless each |P_k| < 32 over the
 * frame (its Q53 bound e[k] < 2^58: a checked model's band points too) and
 * t' |h31|, t' |h32| < 16 (a6, a7 in int32); the sh estimate is all that
 * these bounds give, each point's own range is tested (mo below).
 * T < 2^28 and |h| < 2^31: T h < 2^59, and
 * per point |u a6| < 2^61, |c0|, |c1| < 2^59, c3 = T 2^27 < 2^55, so each
 * Pi's int64 sum is below 2^62. */
static SPVS_Q_NOINLINE void sampson_prep(q_model_t *md)
{
    const int32_t *h = md->h;
    const spvs_q_store_t *st = md->st;
    const int64_t wb = md->wb;
    md->sfast = 0;
    const int64_t T = md->T;
    const uint64_t um = (uint32_t)st->cur_max[0], vm = (uint32_t)st->cur_max[1];
    const uint64_t e[4] = {um * h_mag(h[6]) + (h_mag(h[0]) << 26),
                           um * h_mag(h[7]) + (h_mag(h[1]) << 26), vm * h_mag(h[6]),
                           vm * h_mag(h[7]) + ((uint64_t)1 << 53)};
    /* t w and t |P_k| over the frame in Q21: T (< 2^28) times a Q27 bound
     * (w's below 2^31, P_k's below 2^32), each below 2^28; their squares
     * sum below 5 2^56. */
    const uint32_t tw = t_hi((int32_t)T, wb);
    uint64_t m2 = (uint64_t)tw * tw;
    for (int k = 0; k < 4; k++) {
        if (e[k] >= ((uint64_t)1 << 58)) {
            return;
        }
        const uint32_t tp = t_hi((int32_t)T, (int64_t)e[k]);
        m2 += (uint64_t)tp * tp;
    }
    const int64_t a6 = spvs_q_rshift_rnd64(T * h[6], 26);
    const int64_t a7 = spvs_q_rshift_rnd64(T * h[7], 26);
    const int64_t lim31 = (int64_t)1 << 31;
    if (a6 >= lim31 || a6 < -lim31 || a7 >= lim31 || a7 < -lim31) {
        return;
    }
    /* The least sh with m2 2^(-2 sh) < 2^30: m2's bit length at most
     * 30 + 2 sh. */
    const int bl = spvs_q_bitlen64(m2);
    md->sh = bl > 30 ? (bl - 29) / 2 : 0;
    md->a6 = (int32_t)a6;
    md->a7 = (int32_t)a7;
    md->c0 = T * h[0];
    md->c1 = T * h[1];
    md->c3 = T * ((int64_t)1 << 27);
    md->sfast = 1;
}

/* The bound far of q_model_t: where |exh| > far (or |eyh| > far), q_fast
 * finds the point beyond, whatever the other residual.  With a the one
 * magnitude and b the other, q_fast's outlier test is
 *   a^2 + b^2 + 13 D^2 > c2s + (tw + D)^2 + 2 D (a + b),
 * and a^2 + b^2 - 2 D (a + b) >= (a - D)^2 - 2 D^2 (as (b - D)^2 >= 0), so
 * (a - D)^2 + 11 D^2 > c2s + (tw + D)^2 is sufficient; with tw <= twb over the frame (T times w's bound), a > far =
 * D + X^(1/2), X = c2s + (twb + D)^2, satisfies it.  X^(1/2) is bounded
 * above without a root: s = 2^k >= X^(1/2) from X's bit length, then one
 * Newton step (s + X / s) / 2 >= X^(1/2) (AM-GM), X / s a shift rounded
 * up.  UINT32_MAX where c2s leaves no outlier test (2^62 or more) or the
 * bound does not fit. */
static uint32_t q_far_bound(uint64_t c2s, int32_t T, int64_t wb)
{
    const uint64_t lim = (uint64_t)1 << 62;
    if (c2s >= lim) {
        return UINT32_MAX;
    }
    /* T < 2^28 and wb < 2^57: twb < 2^27. */
    const uint32_t twb = t_hi(T, wb) + 1u + Q_FAST_D;
    const uint64_t X = c2s + (uint64_t)twb * twb;
    const int k = (spvs_q_bitlen64(X) + 1) / 2;
    const uint64_t r = (((uint64_t)1 << k) + (X >> k) + 2u) >> 1;
    return r >= ((uint64_t)1 << 31) ? UINT32_MAX : (uint32_t)r + Q_FAST_D;
}


/* The rows of H as q_w, q_hw and spvs_q_pts_cost read them: -h11, -h12, -h13
 * 2^26 and h33 2^26 (|h| < 2^31: no overflow). */
static SPVS_Q_INLINE void model_rows(q_model_t *md, const int32_t *h)
{
    const int64_t one26 = (int64_t)1 << 26;
    md->nh0 = -h[0];
    md->nh1 = -h[1];
    md->nh2c = -((int64_t)h[2] * one26);
    md->h8c = (int64_t)h[8] * one26;
}


static q_model_t model_prep(const spvs_q_store_t *st, const int32_t *h, const spvs_q_thr_t *thr)
{
    q_model_t md;
    md.fast = 0;
    md.chk = 0;
    md.h = h;
    model_rows(&md, h);
    if (!thr->fast) {
        return md;
    }
    md.T = thr->T;
    /* c2 + 4 D^2 in Q42 (the units of E), plus the 12 D^2 of q_fast's
     * completed squares; 2^62 (beyond any E) means "no band test": every
     * point not inside goes to the exact test.  T rounded down makes TW
     * fall short of t^2 w^2 only within the slack.  A bound of |P| over
     * the frame: it holds for a checked model's points too. */
    const int64_t c2 = band_c2(st, h, thr->t2);
    md.c2s = (uint64_t)c2 + (c2 < ((int64_t)1 << 62) ? 4u * Q_FAST_D * Q_FAST_D : 0u) +
             12u * Q_FAST_D * Q_FAST_D;
    md.sfast = -1;
    md.st = st;
    const uint64_t X = (uint32_t)st->tgt_max[0], Y = (uint32_t)st->tgt_max[1];
    const uint64_t U = (uint32_t)st->cur_max[0], V = (uint32_t)st->cur_max[1];
    /* Exact Q53 bounds (each < 2^62 + 2^57, as q_eps). */
    const int64_t wb = (int64_t)(h_mag(h[6]) * X + h_mag(h[7]) * Y + (h_mag(h[8]) << 26));
    const int64_t gb = (int64_t)(h_mag(h[0]) * X + h_mag(h[1]) * Y + (h_mag(h[2]) << 26));
    const int64_t yb = (int64_t)(Y << 27);
    const int64_t lim57 = (int64_t)1 << 57;
    const int64_t lim62 = (int64_t)1 << 62;
    /* |u w27| <= U (wb 2^-26 + 1) < 2^30 2^31 = 2^61, and gb, yb < 2^62 +
     * 2^57: |ex|, |ey| < 2^62 is tested in pieces that cannot overflow
     * (w27b only where wb < 2^57). */
    const uint64_t w27b = wb < lim57 ? (uint32_t)(wb >> 26) + 1u : 0u;
    if (wb >= lim57 || gb >= lim62 || (int64_t)(U * w27b) >= lim62 - gb ||
        (int64_t)(V * w27b) >= lim62 - yb) {
        /* Checked per point: q_checked passes only w < 2^57, the bound
         * sampson_prep then takes; no far bound (score_fast_mask's). */
        md.chk = 1;
        md.wb = lim57 - 1;
        md.far = UINT32_MAX;
        return md;
    }
    md.fast = 1;
    md.wb = wb;
    md.far = q_far_bound(md.c2s, md.T, wb);
    return md;
}


/* The outcomes of the fast test of one point. */
enum { Q_EXACT = -1, Q_OUT = 0, Q_IN = 1, Q_BAND = 2 };


/* The fast test's high words of one point with w > 0 (model_prep's
 * comment): exh, eyh and tw, Q21, made from w27 (kept for the band's
 * test). */
typedef struct {
    int32_t exh, eyh;
    uint32_t tw;
    int32_t w27;
} q_hw_t;

static SPVS_Q_INLINE q_hw_t q_hw27(const int32_t *p, const q_model_t *md, int32_t w27)
{
    q_hw_t r;
    r.w27 = w27;
    r.exh = (int32_t)(q_ex53(md->nh2c, md->nh0, md->nh1, p, w27) >> 32);
    r.eyh = (int32_t)(q_ey53(p, w27) >> 32);
    r.tw = (uint32_t)(((int64_t)md->T * w27) >> 32);
    return r;
}

static SPVS_Q_INLINE q_hw_t q_hw(const int32_t *p, const q_model_t *md, int64_t w)
{
    return q_hw27(p, md, (int32_t)(w >> 26));
}

/* The band's Sampson test of one point of the band (q_fast: Q_BAND), with
 * the bounds of sampson_prep's comment above: 1 (an inlier), 0 (not), or
 * Q_EXACT where it cannot decide or the model is outside its range.  w27
 * is the point's floor(w 2^-26) (q_hw), which every caller has made.  Out
 * of line, and its high words made again from w27 (about 10
 * instructions), so that the loop over the points keeps none of them
 * alive. */
static SPVS_Q_NOINLINE int q_band_sampson(const int32_t *p, q_model_t *md, int32_t w27)
{
    /* Made at the model's first band point; one test once it is on. */
    if (md->sfast <= 0) {
        if (md->sfast < 0) {
            sampson_prep(md);
        }
        if (!md->sfast) {
            return Q_EXACT;
        }
    }
    const q_hw_t r = q_hw27(p, md, w27);
    const int sh = md->sh;
    const int64_t u = p[2], v = p[3];
    /* Pi in Q21, then Q(21 - sh): high words of sums below 2^62. */
    const int32_t p0 = spvs_q_opaque32((int32_t)((u * md->a6 - md->c0) >> 32) >> sh);
    const int32_t p1 = spvs_q_opaque32((int32_t)((u * md->a7 - md->c1) >> 32) >> sh);
    const int32_t p2 = spvs_q_opaque32((int32_t)((v * md->a6) >> 32) >> sh);
    const int32_t p3 = spvs_q_opaque32((int32_t)((v * md->a7 - md->c3) >> 32) >> sh);
    const int32_t e0 = spvs_q_opaque32(r.exh >> sh), e1 = spvs_q_opaque32(r.eyh >> sh);
    const int32_t om = spvs_q_opaque32((int32_t)(r.tw >> sh));
    /* m = mo + 1 >= every |value|; mo < 2^15 keeps each in [-2^15,
     * 2^15 - 1]. */
    const uint32_t mo =
        (uint32_t)om | q_mag(e0) | q_mag(e1) | q_mag(p0) | q_mag(p1) | q_mag(p2) | q_mag(p3);
    if (mo >= (uint32_t)Q_BAND_LIM) {
        return Q_EXACT;
    }
    /* Exact in int32 / uint32 (the ranges above). */
    const int32_t a0 = p3 * e0 - p1 * e1;
    const int32_t a1 = p0 * e1 - p2 * e0;
    const int32_t dt = p0 * p3 - p1 * p2;
    const uint32_t ww = (uint32_t)(om * om);
    const uint32_t ee = (uint32_t)(e0 * e0) + (uint32_t)(e1 * e1);
    const uint32_t q01 = (uint32_t)(p0 * p0) + (uint32_t)(p1 * p1);
    const uint32_t q23 = (uint32_t)(p2 * p2) + (uint32_t)(p3 * p3);
    /* Each sum a chain of 32 x 32 -> 64-bit multiply-accumulates: the
     * opaque copies keep GCC from factoring ww out into a 64-bit sum. */
    const uint32_t ww0 = (uint32_t)spvs_q_opaque32((int32_t)ww);
    const uint32_t ww1 = (uint32_t)spvs_q_opaque32((int32_t)ww);
    const uint32_t ww2 = (uint32_t)spvs_q_opaque32((int32_t)ww);
    const uint64_t num = (uint64_t)((int64_t)a0 * a0 + (int64_t)a1 * a1) + (uint64_t)ww0 * ee;
    const uint64_t den = (uint64_t)ww * ww + (uint64_t)ww1 * q01 + (uint64_t)ww2 * q23 +
                         (uint64_t)((int64_t)dt * dt);
    /* 2 E* = 2 (32 (mo + 1) + 37 + 2048) rounded up; Gh and Hh rounded
     * up (each halving's floor loses under 1/2). */
    const uint32_t e2 = 64u * mo + 4240u;
    const uint32_t ph = (q01 >> 1) + (q23 >> 1) + 1u;
    if (num + (uint64_t)e2 * (ww + ph) <= den) {
        return 1;
    }
    const uint32_t hh = ((ee + ww) >> 1) + ph + 1u;
    if (num > den + (uint64_t)e2 * hh) {
        return 0;
    }
    return Q_EXACT;
}

/* The fast test of one point: Q_IN for a point clearly inside |eps| <= t w
 * (an inlier, since the Sampson error is at most the transfer error),
 * Q_OUT behind the camera or clearly beyond t2 (w^2 + |P|^2) (an outlier),
 * Q_BAND for the rest (the band's Sampson test, then the exact test).
 * Both shortcuts are exact in real arithmetic and are taken only outside
 * the rounding slack, so the decisions are the exact test's.  q_fast_hw
 * takes a point with w > 0 from its high words; q_fast makes them (into
 * *r, which the band's test reads, where w > 0). */
static SPVS_Q_INLINE int q_fast_hw(const q_hw_t *r, const q_model_t *md)
{
    /* Squares of magnitudes: unsigned 32 x 32 -> 64 products. */
    const uint32_t ax = (uint32_t)(r->exh < 0 ? -r->exh : r->exh);
    const uint32_t ay = (uint32_t)(r->eyh < 0 ? -r->eyh : r->eyh);
    /* E + 13 D^2: both tests below compare it, so the constants are
     * folded into squares (integers: the same decisions as the plain
     * forms in the comments). */
    const uint64_t E13 =
        (uint64_t)(13 * Q_FAST_D * Q_FAST_D) + (uint64_t)ax * ax + (uint64_t)ay * ay;
    /* Inside: E + slack <= TW.  Where E <= TW, ax and ay are at most tw,
     * so slack <= 2 D 3 tw + 4 D^2 (tw < 2^27), and testing
     * E + 6 D tw + 4 D^2 <= tw^2, which is E + 13 D^2 <= (tw - 3 D)^2, is
     * sufficient (tw < 3 D fails both forms: (tw - 3 D)^2 <= 9 D^2). */
    const int32_t ti = (int32_t)r->tw - 3 * Q_FAST_D;
    if (E13 <= (uint64_t)((int64_t)ti * ti)) {
        return Q_IN;
    }
    /* Beyond: E > TW + c2 + 4 D^2 + 2 D (ax + ay + tw), that is
     * E + 13 D^2 > (tw + D)^2 + 2 D (ax + ay) + c2 + 16 D^2 (md->c2s). */
    const uint32_t to = r->tw + Q_FAST_D;
    if (E13 > md->c2s + (uint64_t)to * to + (uint64_t)(ax + ay) * (2u * Q_FAST_D)) {
        return Q_OUT;
    }
    return Q_BAND;
}

static SPVS_Q_INLINE int q_fast(const int32_t *h, const int32_t *p, const q_model_t *md,
                                q_hw_t *r)
{
    const int64_t w = q_w(md->h8c, h[6], h[7], p);
    if (w <= 0) {
        return Q_OUT;
    }
    *r = q_hw(p, md, w);
    return q_fast_hw(r, md);
}

/* The fast test and the band's Sampson test of one point of a checked
 * model (q_model_t: chk), or Q_EXACT for a point outside their ranges.
 * w is exact, so w <= 0 is the exact test's decision (out).  With
 * 0 < w < 16 (2^57 in Q53) w27 is in int32 and the sums of ex and ey are
 * exact in int64 (|u w27|, |h11 x|, |h12 y| < 2^61, |h13| 2^26 < 2^57);
 * |ex|, |ey| < 2^62, the high words in [-2^30, 2^30), is the rest of what
 * model_prep's bounds give the fast test, and q_band_sampson's bounds are
 * per point (sampson_prep's bound of w, 16, is the one tested here).  So
 * the decisions are those of the two tests, which are the exact test's. */
static SPVS_Q_NOINLINE int q_checked(const int32_t *h, const int32_t *p, q_model_t *md)
{
    const int64_t w = q_w(md->h8c, h[6], h[7], p);
    if (w <= 0) {
        return Q_OUT;
    }
    if (w >= ((int64_t)1 << 57)) {
        return Q_EXACT;
    }
    const q_hw_t r = q_hw(p, md, w);
    if ((((uint32_t)r.exh + 0x40000000u) | ((uint32_t)r.eyh + 0x40000000u)) >= 0x80000000u) {
        return Q_EXACT;
    }
    const int c = q_fast_hw(&r, md);
    return c == Q_BAND ? q_band_sampson(p, md, r.w27) : c;
}


/* hp_inlier: 1 for an inlier of H (w > 0, squared Sampson error at most
 * t2): the fast test and the band's Sampson test where the model has them
 * (fast) or has them per point (q_checked), the exact test for the points
 * they leave and for every point of a model without them. */
static SPVS_Q_INLINE int q_inlier(const int32_t *h, const int32_t *p, q_model_t *md,
                                  const spvs_qf_t *t2, const int fast)
{
    if (fast) {
        q_hw_t r;
        const int c = q_fast(h, p, md, &r);
        if (c != Q_BAND) {
            return c;
        }
        const int b = q_band_sampson(p, md, r.w27);
        if (b >= 0) {
            return b;
        }
    } else if (md->chk) {
        const int c = q_checked(h, p, md);
        if (c >= 0) {
            return c;
        }
    }
    return q_inlier_exact(h, p, *t2);
}


/* Counts the inliers among points [i, end) into *inl (points.c,
 * score_points); 0 at the first point that leaves more than max_out
 * outliers. */
static SPVS_Q_INLINE int score_range(const spvs_q_store_t *st, const int32_t *h, size_t i,
                                     size_t end, q_model_t *md, const spvs_qf_t *t2,
                                     int32_t max_out, uint8_t *mask, int32_t *inl, const int fast)
{
    int32_t count = *inl;
    int ok_all = 1;
    for (size_t r = i; r < end; r++) {
        const int ok = q_inlier(h, &st->v[4u * r], md, t2, fast);
        count += ok;
        if (mask) {
            mask[r] = (uint8_t)ok;
        }
        if ((int32_t)(r + 1) - count > max_out) {
            ok_all = 0;
            break;
        }
    }
    *inl = count;
    return ok_all;
}

/* score_range with the model's fast test, or without it (every point to
 * the exact test), chosen once per call. */
static int score_points(const spvs_q_store_t *st, const int32_t *h, size_t i, size_t end,
                        q_model_t *md, const spvs_qf_t *t2, int32_t max_out,
                        uint8_t *mask, int32_t *inl)
{
    return md->fast ? score_range(st, h, i, end, md, t2, max_out, mask, inl, 1)
                    : score_range(st, h, i, end, md, t2, max_out, mask, inl, 0);
}

/* spvs_q_pts_score for a model with the fast test and a mask, the
 * estimator's case, in one loop: q_fast's arithmetic on the model's
 * constants in locals (the byte stores to the mask may alias any object,
 * so values read through md or h would be read again after each), the
 * early stop kept as the number of outliers still allowed (an inlier
 * costs nothing more), the bail-out test after each full block, as
 * spvs_q_pts_score's blocks make them.  The same decisions, mask and
 * count.  Bound: n points. */
static SPVS_Q_NOINLINE uint16_t score_fast_mask(const spvs_q_store_t *st, const int32_t *h,
                                                size_t n, q_model_t *md, const spvs_qf_t *t2,
                                                int64_t need_b, int32_t max_out, uint8_t *mask)
{
    const int32_t h6 = h[6], h7 = h[7], nh0 = md->nh0, nh1 = md->nh1, T = md->T;
    const int64_t h8c = md->h8c, nh2c = md->nh2c;
    const uint64_t c2s = md->c2s;
    /* The model for the band's calls, read from memory there, so that no
     * register holds it through the loop. */
    q_model_t *volatile mdv = md;
    /* |e| <= far as one unsigned comparison, (uint32_t)e + fo <= 2 fo (e
     * in -fo..fo): model_prep keeps |ex|, |ey| below 2^62 in Q53, so
     * |exh|, |eyh| < 2^30 and a far of 2^30 or more bounds nothing (fo =
     * 2^30 passes every point). */
    const uint32_t fo = md->far < 0x40000000u ? md->far : 0x40000000u;
    /* bails() with its factor made once. */
    const int32_t nb = (int32_t)need_b, ni = (int32_t)n;
    const uint32_t kb = bail_k(nb, ni);
    /* Outliers still allowed: the stop comes at the first point r with
     * (r + 1) - count > max_out. */
    int32_t left = max_out;
    const int32_t *p = st->v;
    uint8_t *m = mask;
    uint8_t *const mend = mask + n;
    /* Bound: n / SPVS_SCORE_BLOCK + 1 blocks. */
    while (m != mend) {
        uint8_t *const me = (size_t)(mend - m) > SPVS_SCORE_BLOCK ? m + SPVS_SCORE_BLOCK : mend;
        /* Bound: SPVS_SCORE_BLOCK points (at least one: me > m). */
        do {
            int ok = 0;
            /* fo read here, so that 2 fo is a shifted operand of the
             * comparisons rather than a second value kept. */
            const uint32_t fl = (uint32_t)spvs_q_opaque32((int32_t)fo);
            const int64_t w = q_w(h8c, h6, h7, p);
            /* q_hw and q_fast on the locals; a residual beyond far
             * decides alone (q_far_bound), ey first, the cheaper, and
             * before w's sign: where w > 0 that is q_fast's decision
             * (which takes w27 = 0 as well), where w <= 0 the point is out
             * as in the exact test (the high words stay in range for
             * either sign, model_prep).  A point within far with w27 <= 0
             * (w below 2^-27, or behind the camera) goes to the exact
             * test, which decides w <= 0 as well. */
            const int32_t w27 = (int32_t)(w >> 26);
            const int32_t eyh = spvs_q_opaque32((int32_t)(q_ey53(p, w27) >> 32));
            if ((uint32_t)eyh + fl <= 2u * fl) {
                const int32_t exh =
                    spvs_q_opaque32((int32_t)(q_ex53(nh2c, nh0, nh1, p, w27) >> 32));
                if ((uint32_t)exh + fl > 2u * fl) {
                    ok = 0;
                } else if (w27 <= 0) {
                    ok = q_inlier_exact(h, p, *t2);
                } else {
                    const uint32_t tw = (uint32_t)(((int64_t)T * w27) >> 32);
                    /* The squares of the signed values are those of the
                     * magnitudes. */
                    const uint64_t E13 =
                        (uint64_t)((int64_t)(13 * Q_FAST_D * Q_FAST_D) + (int64_t)exh * exh +
                                   (int64_t)eyh * eyh);
                    const int32_t ti = (int32_t)tw - 3 * Q_FAST_D;
                    if (E13 <= (uint64_t)((int64_t)ti * ti)) {
                        ok = 1;
                    } else {
                        const uint32_t ax = (uint32_t)(exh < 0 ? -exh : exh);
                        const uint32_t ay = (uint32_t)(eyh < 0 ? -eyh : eyh);
                        const uint32_t to = tw + Q_FAST_D;
                        if (E13 <= c2s + (uint64_t)to * to + (uint64_t)(ax + ay) * (2u * Q_FAST_D)) {
                            ok = q_band_sampson(p, mdv, w27);
                            if (ok < 0) {
                                ok = q_inlier_exact(h, p, *t2);
                            }
                        }
                    }
                }
            }
            *m++ = (uint8_t)ok;
            if (!ok && --left < 0) {
                return (uint16_t)((size_t)(m - mask) - (size_t)(max_out + 1));
            }
            p += 4;
        } while (m != me);
        const int32_t done = (int32_t)(m - mask);
        const int32_t inl = done - (max_out - left);
        if (done % SPVS_SCORE_BLOCK == 0 && bails_k(kb, nb, ni, done, inl)) {
            return (uint16_t)inl;
        }
    }
    return (uint16_t)((int32_t)n - (max_out - left));
}

uint16_t spvs_q_pts_score(const spvs_q_store_t *st, size_t n, const int32_t Hq[9],
                          const spvs_q_thr_t *thr, uint16_t need, uint8_t *mask)
{
    const int32_t max_out = need <= n ? (int32_t)(n - need) : 0;
    /* need > n: the float test's p = 1 (points.c), as need = n here. */
    const int64_t need_b = need <= n ? (int64_t)need : (int64_t)n;
    q_model_t md = model_prep(st, Hq, thr);
    if (md.fast && mask) {
        /* It takes the model's constants into locals itself. */
        return score_fast_mask(st, Hq, n, &md, &thr->t2, need_b, max_out, mask);
    }
    /* H in a local copy for the loops below: the mask's byte stores may
     * alias any object, so values read through Hq would be read again
     * after each. */
    int32_t h[9];
    for (int k = 0; k < 9; k++) {
        h[k] = Hq[k];
    }
    int32_t inl = 0;
    size_t i = 0;
    /* Bound: n / SPVS_SCORE_BLOCK blocks, then fewer than SPVS_SCORE_BLOCK
     * points. */
    for (; i + SPVS_SCORE_BLOCK <= n; i += SPVS_SCORE_BLOCK) {
        if (!score_points(st, h, i, i + SPVS_SCORE_BLOCK, &md, &thr->t2, max_out, mask, &inl) ||
            bails((int32_t)need_b, (int32_t)n, (int32_t)(i + SPVS_SCORE_BLOCK), inl)) {
            return (uint16_t)inl;
        }
    }
    (void)score_points(st, h, i, n, &md, &thr->t2, max_out, mask, &inl);
    return (uint16_t)inl;
}

