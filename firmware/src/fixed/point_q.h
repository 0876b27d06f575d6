/*
 * point_q.h - the fixed-point arithmetic of one point of the Q store
 * (private to the core): its exact residuals (q_eps), the Jacobian's block
 * P, the Sampson error's num and den, the reference inlier test
 * (q_inlier_ref), the residuals from w's floor in Q53 that the fast paths
 * read (q_w, q_ex53, q_ey53), and the inlier count's bail-out test in
 * integers.  Included by points_q.c, by the count's translation unit
 * (score_q.c, or accel/score_fast_q.c) and by the tests; formats in
 * points_q.h and docs/FIXED.md.
 */
#ifndef SPVS_FIXED_POINT_Q_H
#define SPVS_FIXED_POINT_Q_H

#include "points_q.h"

/* Scaled coordinates are below 2^30 in Q26 (points_q.h). */
#define COORD_LIM ((int32_t)1 << 30)
/* SPVS_W_EPS (1e-6) in Q53, rounded down. */
#define W_EPS_Q53 ((int64_t)9007199254)

/* A point's residuals under H.  w = h3 . p, g = h1 . p and y_tgt are exact
 * in Q53 (|h| < 2^31, |coordinate| <= 2^30: each product < 2^61, each sum
 * < 2^62 + 2^57).  The shift s1 brings the largest of them below 2^30; w
 * is split as w1 2^s1 + wr (w1 = w rounded, |wr| <= 2^(s1 - 1) < 2^32),
 * so that in Q(79 - s1)
 *     ex = u w - g 2^26 = u w1 + (u wr) 2^-s1 - g 2^(26 - s1)
 * is formed with int64 products only (u w1 < 2^60, u wr < 2^62, the last
 * term < 2^56) and one rounding, of less than 1 unit: the residual keeps
 * its bits however far it cancels (ey likewise with v and y). */
typedef struct {
    int64_t w;  /* Q53, exact */
    int32_t w1; /* w 2^-s1 rounded, Q(53 - s1) */
    int s1;
    int64_t ex, ey; /* Q(79 - s1), |.| < 2^61 */
} q_eps_t;

/* a 2^(26 - s1) for an exact Q53 a with |a| < 2^(30 + s1): exact for
 * s1 <= 26, rounded otherwise. */
static SPVS_Q_INLINE int64_t q_to_eps_unit(int64_t a, int s1)
{
    return s1 <= 26 ? a * ((int64_t)1 << (26 - s1)) : spvs_q_rshift_rnd64(a, s1 - 26);
}

static SPVS_Q_INLINE void q_eps(const int32_t *h, const int32_t *p, q_eps_t *r)
{
    const int64_t one26 = (int64_t)1 << 26;
    const int64_t w = (int64_t)h[6] * p[0] + (int64_t)h[7] * p[1] + (int64_t)h[8] * one26;
    const int64_t g = (int64_t)h[0] * p[0] + (int64_t)h[1] * p[1] + (int64_t)h[2] * one26;
    const int64_t yy = (int64_t)p[1] * ((int64_t)1 << 27);
    const int s1 =
        spvs_q_norm_shift(spvs_q_abs64(w) | spvs_q_abs64(g) | spvs_q_abs64(yy), 30);
    const int32_t w1 = (int32_t)spvs_q_rshift_rnd64(w, s1);
    const int64_t wr = w - (int64_t)w1 * ((int64_t)1 << s1);
    r->w = w;
    r->w1 = w1;
    r->s1 = s1;
    r->ex = (int64_t)p[2] * w1 + spvs_q_rshift_rnd64((int64_t)p[2] * wr, s1) -
            q_to_eps_unit(g, s1);
    r->ey = (int64_t)p[3] * w1 + spvs_q_rshift_rnd64((int64_t)p[3] * wr, s1) -
            q_to_eps_unit(yy, s1);
}

/* Entry k (0..3, row by row) of the Jacobian's block P = [[u h31 - h11,
 * u h32 - h12], [v h31, v h32 - 1]] (h_point.inc), exact in Q53
 * (< 2^62).  Inlined with a constant k: no array of the four. */
static SPVS_Q_INLINE int64_t q_jac53(const int32_t *h, const int32_t *p, int k)
{
    const int64_t one26 = (int64_t)1 << 26;
    switch (k) {
    case 0:
        return (int64_t)p[2] * h[6] - (int64_t)h[0] * one26;
    case 1:
        return (int64_t)p[2] * h[7] - (int64_t)h[1] * one26;
    case 2:
        return (int64_t)p[3] * h[6];
    default:
        return (int64_t)p[3] * h[7] - ((int64_t)1 << 53);
    }
}

/* The four entries of P (q_jac53) as spvs_qf_t. */
static SPVS_Q_INLINE void q_jac(const int32_t *h, const int32_t *p, spvs_qf_t P[4])
{
    P[0] = spvs_qf_from_i64(q_jac53(h, p, 0), -53);
    P[1] = spvs_qf_from_i64(q_jac53(h, p, 1), -53);
    P[2] = spvs_qf_from_i64(q_jac53(h, p, 2), -53);
    P[3] = spvs_qf_from_i64(q_jac53(h, p, 3), -53);
}

static SPVS_Q_INLINE spvs_qf_t qf_sq(spvs_qf_t a)
{
    return spvs_qf_mul(a, a);
}

/* The squared Sampson error as num / den without cancellation: with
 * J J^T = w^2 I + P P^T,
 *   num = eps^T adj(J J^T) eps = w^2 |eps|^2 + |adj(P) eps|^2,
 *   den = det(J J^T) = w^4 + w^2 |P|_F^2 + det(P)^2,
 * sums of squares, the same quantities as h_point.inc's hp_sampson. */
static SPVS_Q_INLINE void q_sampson(const spvs_qf_t P[4], spvs_qf_t ww, spvs_qf_t ee,
                                    spvs_qf_t ex, spvs_qf_t ey, spvs_qf_t *num, spvs_qf_t *den)
{
    const spvs_qf_t a0 = spvs_qf_sub(spvs_qf_mul(P[3], ex), spvs_qf_mul(P[1], ey));
    const spvs_qf_t a1 = spvs_qf_sub(spvs_qf_mul(P[0], ey), spvs_qf_mul(P[2], ex));
    *num = spvs_qf_add(spvs_qf_mul(ww, ee), spvs_qf_add(qf_sq(a0), qf_sq(a1)));
    const spvs_qf_t pp =
        spvs_qf_add(spvs_qf_add(qf_sq(P[0]), qf_sq(P[1])), spvs_qf_add(qf_sq(P[2]), qf_sq(P[3])));
    const spvs_qf_t dp = spvs_qf_sub(spvs_qf_mul(P[0], P[3]), spvs_qf_mul(P[1], P[2]));
    *den = spvs_qf_add(spvs_qf_mul(ww, spvs_qf_add(ww, pp)), qf_sq(dp));
}


/* |x| for the bounds over a frame, as uint32 (at most 2^31, for
 * INT32_MIN) then widened: its products with the frame's bounds (below
 * 2^31) are one 32 x 32 -> 64-bit multiply each. */
static SPVS_Q_INLINE uint64_t h_mag(int32_t x)
{
    const uint32_t u = (uint32_t)x;
    /* Opaque: GCC otherwise widens the negation to 64 bits. */
    return (uint32_t)spvs_q_opaque32((int32_t)(x < 0 ? 0u - u : u));
}


/* w = h3 . p of point p, exact in Q53 (as q_eps), from h33 2^26 (h8c)
 * and h31, h32 (Q27).  The constant first: the sum is one 64-bit load and
 * two multiply-accumulates. */
static SPVS_Q_INLINE int64_t q_w(int64_t h8c, int32_t h6, int32_t h7, const int32_t *p)
{
    return h8c + (int64_t)h6 * p[0] + (int64_t)h7 * p[1];
}

/* The residuals of point p in Q53 from w27 = floor(w 2^-26) (Q27): ex =
 * u w27 - h1 . p 2^26 as one chain of multiply-accumulates on the negated
 * row (-h11, -h12 and -h13 2^26, model_rows), and ey = v w27 - y 2^27
 * with y 2^27 as a product, so that its sum is one multiply-accumulate.
 * Exact for w27 in int32: every partial sum is below 2^63. */
static SPVS_Q_INLINE int64_t q_ex53(int64_t nh2c, int32_t nh0, int32_t nh1, const int32_t *p,
                                    int32_t w27)
{
    return nh2c + (int64_t)p[2] * w27 + (int64_t)nh0 * p[0] + (int64_t)nh1 * p[1];
}

static SPVS_Q_INLINE int64_t q_ey53(const int32_t *p, int32_t w27)
{
    return (int64_t)p[3] * w27 + (int64_t)p[1] * (int32_t)-(1 << 27);
}


/* The squares of a point's residuals r (q_eps): |eps|^2 and w^2, and eps
 * itself, as spvs_qf_t, with eps rounded to 31 bits together (its square
 * sums in int64, < 2^61). */
static SPVS_Q_INLINE void q_eps_sq(const q_eps_t *r, spvs_qf_t *ee, spvs_qf_t *ww, spvs_qf_t *ex,
                                   spvs_qf_t *ey)
{
    const int s2 = spvs_q_norm_shift(spvs_q_abs64(r->ex) | spvs_q_abs64(r->ey), 30);
    const int32_t ex2 = (int32_t)spvs_q_rshift_rnd64(r->ex, s2);
    const int32_t ey2 = (int32_t)spvs_q_rshift_rnd64(r->ey, s2);
    const int32_t fe = 79 - r->s1 - s2;
    *ee = spvs_qf_from_i64((int64_t)ex2 * ex2 + (int64_t)ey2 * ey2, -2 * fe);
    *ww = spvs_qf_from_i64((int64_t)r->w1 * r->w1, -2 * (53 - r->s1));
    *ex = spvs_qf_from_i64(ex2, -fe);
    *ey = spvs_qf_from_i64(ey2, -fe);
}

/* The Sampson error's num and den (q_sampson) of point p under h from its
 * residuals r (q_eps, w > 0). */
static SPVS_Q_INLINE void q_sampson_nd(const int32_t *h, const int32_t *p, const q_eps_t *r,
                                       spvs_qf_t *num, spvs_qf_t *den)
{
    spvs_qf_t ee, ww, ex, ey, P[4];
    q_eps_sq(r, &ee, &ww, &ex, &ey);
    q_jac(h, p, P);
    q_sampson(P, ww, ee, ex, ey, num, den);
}

/* The Sampson inlier test in spvs_qf_t, for a point with w > 0 and its
 * residuals r (q_eps): 1 for an inlier.  Where |eps|^2 <= t2 w^2 the
 * point is in without the rest (the Sampson error is at most the transfer
 * error |eps|^2 / w^2). */
static inline int q_inlier_qf(const int32_t *h, const int32_t *p, const q_eps_t *r,
                              spvs_qf_t t2)
{
    spvs_qf_t ee, ww, ex, ey;
    q_eps_sq(r, &ee, &ww, &ex, &ey);
    if (spvs_qf_le(ee, spvs_qf_mul(t2, ww))) {
        return 1;
    }
    spvs_qf_t P[4], num, den;
    q_jac(h, p, P);
    q_sampson(P, ww, ee, ex, ey, &num, &den);
    return spvs_qf_le(num, spvs_qf_mul(t2, den));
}

/* The reference inlier test of one point of the Q store: w > 0 and the
 * squared Sampson error at most t2 (h_point.inc's hp_inlier in fixed
 * point), decided on the exact residuals (q_eps) in spvs_qf_t.  Every
 * faster test (fixed/accel/score_fast_q.c) decides as this one. */
static inline int q_inlier_ref(const int32_t *h, const int32_t *p, spvs_qf_t t2)
{
    q_eps_t r;
    q_eps(h, p, &r);
    if (r.w <= 0) {
        return 0;
    }
    return q_inlier_qf(h, p, &r, t2);
}

/* ---- the inlier count's stopping rule -------------------------------------- */

/* The bail-out test after m points with inl inliers (points.c, bails), in
 * integers: with p = need / n the float test d = p m - inl > 0 and
 * d^2 > SPVS_BAIL_SIGMAS^2 p (1 - p) m becomes, times n^2,
 * D = need m - inl n > 0 and D^2 > kb m with kb = SPVS_BAIL_SIGMAS^2
 * need (n - need).  need, n, m and inl are at most SPVS_MAX_MATCHES <=
 * 4096 (spvs_config.h), so D is within +-2^24 in int32, kb below 2^27
 * (bail_k) and kb m below 2^39. */
static SPVS_Q_INLINE uint32_t bail_k(int32_t need, int32_t n)
{
    return (uint32_t)(SPVS_BAIL_SIGMAS * SPVS_BAIL_SIGMAS) * (uint32_t)need * (uint32_t)(n - need);
}

static SPVS_Q_INLINE int bails_k(uint32_t kb, int32_t need, int32_t n, int32_t m, int32_t inl)
{
    const int32_t d = need * m - inl * n;
    return d > 0 && (uint64_t)((int64_t)d * d) > (uint64_t)kb * (uint32_t)m;
}

static inline int bails(int32_t need, int32_t n, int32_t m, int32_t inl)
{
    return bails_k(bail_k(need, n), need, n, m, inl);
}


#endif /* SPVS_FIXED_POINT_Q_H */
