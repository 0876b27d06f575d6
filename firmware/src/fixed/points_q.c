/*
 * points_q.c - the estimator's per-point kernels in fixed point
 * (points_q.h; formats, ranges and error bounds in docs/FIXED.md).
 *
 * The per-point arithmetic is that of h_point.inc, rewritten for integers:
 * the stages whose range a Q format holds are exact (w and h1 . p in int64
 * Q53), the residuals are formed exactly from those rounded to 31 bits,
 * and the stages whose range grows without bound (the Sampson error's
 * terms, the fits' weights 1 / w and (J J^T)^-1) are in spvs_qf_t.
 */
#include <string.h>

#include "../core_util.h"
#include "point_q.h"
#include "sums_q.h"

/* Scaled coordinates are below 2^30 in Q26 (points_q.h). */

/* ---- conversions --------------------------------------------------------- */


uint32_t spvs_q_h_from_real(const spvs_real H[9], int32_t Hq[9])
{
    uint32_t sat = 0;
    for (int k = 0; k < 9; k++) {
        Hq[k] = spvs_q_from_ieee(spvs_q_real_parts(H[k]), SPVS_QH, &sat, 0);
        /* +-16 itself is outside (-16, 16): it would clamp to 2^31 - 1. */
        sat |= (Hq[k] == SPVS_Q_I32_MAX || Hq[k] == SPVS_Q_I32_MIN) ? SPVS_Q_SAT : 0u;
    }
    return sat;
}

spvs_qf_t spvs_q_t2_from_real(spvs_real t2, uint32_t *sat)
{
    return spvs_qf_from_ieee(spvs_q_real_parts(t2), sat);
}

void spvs_q_pts_row(const spvs_q_store_t *st, uint16_t i, int32_t row[4])
{
    const int32_t *const v = &st->v[4u * i];
    row[0] = v[0];
    row[1] = v[1];
    row[2] = v[2];
    row[3] = v[3];
}

/* |eps|^2 of one point, from the exact residuals (q_eps): the cost's term,
 * as a spvs_qf_t (relative error <= 2^-30). */
static spvs_qf_t q_e2(const int32_t *h, const int32_t *p)
{
    q_eps_t r;
    q_eps(h, p, &r);
    const int s2 = spvs_q_norm_shift(spvs_q_abs64(r.ex) | spvs_q_abs64(r.ey), 30);
    const int32_t ex2 = (int32_t)spvs_q_rshift_rnd64(r.ex, s2);
    const int32_t ey2 = (int32_t)spvs_q_rshift_rnd64(r.ey, s2);
    return spvs_qf_from_i64((int64_t)ex2 * ex2 + (int64_t)ey2 * ey2, -2 * (79 - r.s1 - s2));
}



/* The term of a point beyond cost's fast path, in Q52. */
uint64_t spvs_q_cost_exact(const int32_t *h, const int32_t *p, uint32_t *sat)
{
    return (uint64_t)spvs_qf_to_q64(q_e2(h, p), SPVS_QCOST, sat);
}


/* ---- the sums of the linear fits ------------------------------------------ */

spvs_qf_t spvs_q_sums_term(const spvs_q_sums_t *s, int k)
{
    if (k < 0 || k >= s->nt) {
        return spvs_qf_from_i64(0, 0);
    }
    return spvs_qf_from_i64(s->m[k], s->e[blk_of(s, k)]);
}

/* Adds term t to sum k of a block-floating-point accumulator (sub = 0) or
 * subtracts it (sub = 1).  Invariant: every |m| < 2^62.  A term more than
 * 2^30 above the block's unit first shifts the block right (raising its
 * exponent), so the term's share is below 2^61 and the result below 2^63
 * in magnitude either way; a result that reaches 2^62 shifts the block by
 * one.  Terms below the unit are rounded to it (the block keeps 62 bits
 * of its largest sum).  The share is rounded before its sign is applied,
 * so subtracting a term added before at the same exponent undoes the add
 * exactly (round to nearest with ties up is not odd: rnd(-x) can differ
 * from -rnd(x)). */
void spvs_q_acc_add(spvs_q_sums_t *s, int k, spvs_qf_t t, int sub)
{
    if (t.m == 0) {
        return;
    }
    const int b = blk_of(s, k);
    int lo, hi;
    blk_range(s, b, &lo, &hi);
    int32_t d = t.e - s->e[b];
    if (d > 30) {
        const int32_t sh = d - 30;
        for (int j = lo; j < hi; j++) {
            s->m[j] = spvs_q_rshift_rnd64(s->m[j], sh > 63 ? 63 : (int)sh);
        }
        s->e[b] += sh;
        d = 30;
    }
    const int64_t add = d >= 0 ? (int64_t)t.m * ((int64_t)1 << d)
                               : spvs_q_rshift_rnd64(t.m, d < -63 ? 63 : (int)-d);
    const int64_t r = sub ? s->m[k] - add : s->m[k] + add;
    s->m[k] = r;
    if (spvs_q_abs64(r) >= ((uint64_t)1 << 62)) {
        for (int j = lo; j < hi; j++) {
            s->m[j] = spvs_q_rshift_rnd64(s->m[j], 1);
        }
        s->e[b] += 1;
    }
}

static spvs_qf_t qf_c(int32_t q) /* a Q26 coordinate */
{
    return spvs_qf_from_i64(q, -SPVS_QC);
}

/* SPVS_T_FIT_Y and SPVS_T_FIT_X terms of one point (h_point.inc):
 * q = sc (x, y, 1), sc = v / w or 1 / w, r = y / w or u.  A call from
 * the sums' translation unit: its spvs_qf_t temporaries stay out of
 * spvs_q_pts_sum's frame. */
void spvs_q_terms_fit(int kind, const q_eps_t *r, const int32_t *p, spvs_q_sums_t *s)
{
    uint32_t z = 0;
    const spvs_qf_t iw = spvs_qf_recip(spvs_qf_from_i64(r->w, -53), &z);
    const spvs_qf_t x = qf_c(p[0]), y = qf_c(p[1]);
    const spvs_qf_t sc = kind == SPVS_T_FIT_Y ? spvs_qf_mul(qf_c(p[3]), iw) : iw;
    const spvs_qf_t rr = kind == SPVS_T_FIT_Y ? spvs_qf_mul(y, iw) : qf_c(p[2]);
    const spvs_qf_t q0 = spvs_qf_mul(sc, x), q1 = spvs_qf_mul(sc, y), q2 = sc;
    spvs_q_acc_add(s, 0, qf_sq(q0), 0);
    spvs_q_acc_add(s, 1, spvs_qf_mul(q0, q1), 0);
    spvs_q_acc_add(s, 2, spvs_qf_mul(q0, q2), 0);
    spvs_q_acc_add(s, 3, qf_sq(q1), 0);
    spvs_q_acc_add(s, 4, spvs_qf_mul(q1, q2), 0);
    spvs_q_acc_add(s, 5, qf_sq(q2), 0);
    spvs_q_acc_add(s, 6, spvs_qf_mul(q0, rr), 0);
    spvs_q_acc_add(s, 7, spvs_qf_mul(q1, rr), 0);
    spvs_q_acc_add(s, 8, spvs_qf_mul(q2, rr), 0);
}

/* SPVS_T_LIN terms of one point (h_point.inc): the joint fit of rows 1
 * and 3 at the Sampson weights W = (J J^T)^-1 = adj(J J^T) / det of H,
 * added to s (sub = 0) or subtracted (sub = 1, spvs_q_lin_move). */
/* A call from the sums' translation unit: its spvs_qf_t temporaries stay
 * out of spvs_q_pts_sum's frame, which the fast path uses alone. */
void spvs_q_terms_lin(const int32_t *h, const q_eps_t *r, const int32_t *p, spvs_q_sums_t *s,
                      int sub)
{
    uint32_t z = 0;
    const spvs_qf_t x = qf_c(p[0]), y = qf_c(p[1]), u = qf_c(p[2]), v = qf_c(p[3]);
    const spvs_qf_t w = spvs_qf_from_i64(r->w, -53);
    const spvs_qf_t ex = spvs_qf_from_i64(r->ex, -(79 - r->s1));
    const spvs_qf_t ey = spvs_qf_from_i64(r->ey, -(79 - r->s1));
    spvs_qf_t P[4];
    q_jac(h, p, P);
    const spvs_qf_t ww = qf_sq(w);
    const spvs_qf_t pq = spvs_qf_add(qf_sq(P[0]), qf_sq(P[1]));
    const spvs_qf_t rs = spvs_qf_add(qf_sq(P[2]), qf_sq(P[3]));
    const spvs_qf_t ja = spvs_qf_add(pq, ww), jb = spvs_qf_add(rs, ww);
    const spvs_qf_t jc = spvs_qf_add(spvs_qf_mul(P[0], P[2]), spvs_qf_mul(P[1], P[3]));
    /* det(J J^T) without cancellation (q_sampson). */
    const spvs_qf_t dp = spvs_qf_sub(spvs_qf_mul(P[0], P[3]), spvs_qf_mul(P[1], P[2]));
    const spvs_qf_t den = spvs_qf_add(spvs_qf_mul(ww, spvs_qf_add(ww, spvs_qf_add(pq, rs))),
                                      qf_sq(dp));
    const spvs_qf_t id = spvs_qf_recip(den, &z);
    const spvs_qf_t w11 = spvs_qf_mul(jb, id), w12 = spvs_qf_neg(spvs_qf_mul(jc, id));
    const spvs_qf_t w22 = spvs_qf_mul(ja, id);
    const spvs_qf_t uw = spvs_qf_add(spvs_qf_mul(u, w11), spvs_qf_mul(v, w12));
    const spvs_qf_t vw = spvs_qf_add(spvs_qf_mul(u, w12), spvs_qf_mul(v, w22));
    const spvs_qf_t a[3] = {w11, spvs_qf_neg(uw),
                            spvs_qf_add(spvs_qf_mul(u, uw), spvs_qf_mul(v, vw))};
    const spvs_qf_t q[5] = {qf_sq(x), spvs_qf_mul(x, y), x, qf_sq(y), y};
    for (int m = 0; m < 3; m++) {
        for (int k = 0; k < 5; k++) {
            spvs_q_acc_add(s, 6 * m + k, spvs_qf_mul(a[m], q[k]), sub);
        }
        spvs_q_acc_add(s, 6 * m + 5, a[m], sub);
    }
    const spvs_qf_t b1 = spvs_qf_add(spvs_qf_mul(w11, ex), spvs_qf_mul(w12, ey));
    const spvs_qf_t c1 = spvs_qf_add(spvs_qf_mul(w12, ex), spvs_qf_mul(w22, ey));
    const spvs_qf_t b3 = spvs_qf_neg(spvs_qf_add(spvs_qf_mul(u, b1), spvs_qf_mul(v, c1)));
    spvs_q_acc_add(s, 18, spvs_qf_mul(b1, x), sub);
    spvs_q_acc_add(s, 19, spvs_qf_mul(b1, y), sub);
    spvs_q_acc_add(s, 20, b1, sub);
    spvs_q_acc_add(s, 21, spvs_qf_mul(b3, x), sub);
    spvs_q_acc_add(s, 22, spvs_qf_mul(b3, y), sub);
    spvs_q_acc_add(s, 23, b3, sub);
    /* eps^T W eps as h_point.inc forms it (ex b1 + ey b2).  W is positive
     * definite, so the two products cancel only as far as its condition
     * number allows (that of J J^T = w^2 I + P P^T, at most
     * 1 + |P|^2 / w^2). */
    spvs_q_acc_add(s, 24, spvs_qf_add(spvs_qf_mul(ex, b1), spvs_qf_mul(ey, c1)), sub);
}

/* The squared Sampson error of one point num / den (q_sampson, from the
 * exact residuals r): num and den rounded to 31 bits after sums of
 * squares (no cancellation, relative 2^-29 each), one reciprocal (2^-28)
 * and one product (2^-31): relative error below 2^-26. */
/* A call from the sums' translation unit: its temporaries stay out of
 * spvs_q_pts_sum's frame. */
spvs_qf_t spvs_q_sampson_term(const int32_t *h, const q_eps_t *r, const int32_t *p)
{
    spvs_qf_t num, den;
    q_sampson_nd(h, p, r, &num, &den);
    /* den >= w^4 > 0 for a point in front: no division by zero. */
    uint32_t z = 0;
    return spvs_qf_mul(num, spvs_qf_recip(den, &z));
}

/* q_eps as a call, for the per-point paths where its size matters more
 * than a call's few instructions (the Sampson sum, the moved point). */
void spvs_q_eps_call(const int32_t *h, const int32_t *p, q_eps_t *r)
{
    q_eps(h, p, r);
}


/* One point's squared Sampson error from its exact residuals
 * (spvs_q_sampson_term) into out's term 0; 0 when w <= SPVS_W_EPS (out
 * unchanged). */
int spvs_q_sampson_exact(const int32_t *h, const int32_t *p, spvs_q_sums_t *out)
{
    q_eps_t r;
    spvs_q_eps_call(h, p, &r);
    if (r.w <= W_EPS_Q53) {
        return 0;
    }
    spvs_q_acc_add(out, 0, spvs_q_sampson_term(h, &r, p), 0);
    return 1;
}


/* One point's terms on the exact path (spvs_q_terms_lin or spvs_q_terms_fit) into s;
 * 0 when w <= SPVS_W_EPS (s unchanged).  A call from the sums'
 * translation unit, so that spvs_q_pts_sum's loop over the points keeps
 * its own values in registers. */
int spvs_q_sum_exact_point(int kind, const int32_t *h, const int32_t *p, spvs_q_sums_t *s)
{
    q_eps_t r;
    spvs_q_eps_call(h, p, &r);
    if (r.w <= W_EPS_Q53) {
        return 0;
    }
    if (kind == SPVS_T_LIN) {
        spvs_q_terms_lin(h, &r, p, s, 0);
    } else {
        spvs_q_terms_fit(kind, &r, p, s);
    }
    return 1;
}


int spvs_q_sums_clear(spvs_terms_t kind, spvs_q_sums_t *out)
{
    const int lin = kind == SPVS_T_LIN, samp = kind == SPVS_T_SAMPSON;
    if (kind != SPVS_T_FIT_Y && kind != SPVS_T_FIT_X && !lin && !samp) {
        return -2;
    }
    /* The blocks of spvs_q_sums_t. */
    out->nt = (uint8_t)(lin ? SPVS_H_LIN_SUMS : (samp ? 1 : SPVS_NT_FIT));
    out->split = (uint8_t)(lin ? 18 : (samp ? 1 : 6));
    out->split2 = (uint8_t)(lin ? SPVS_H_LIN_COST : out->nt);
    /* A block starts far below any term, so the first term sets its unit. */
    out->e[0] = out->e[1] = out->e[2] = -4000;
    for (int k = 0; k < SPVS_H_LIN_SUMS; k++) {
        out->m[k] = 0;
    }
    return 0;
}

int spvs_q_lin_move_exact(const int32_t Hw[9], const int32_t p[4], int sub, spvs_q_sums_t *s)
{
    q_eps_t r;
    spvs_q_eps_call(Hw, p, &r);
    if (r.w <= W_EPS_Q53) {
        return 0;
    }
    spvs_q_terms_lin(Hw, &r, p, s, sub);
    return 1;
}
