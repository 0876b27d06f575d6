/*
 * sums_q.h - what the fixed-point cost and sums share between the
 * reference (sums_q.c) and the accelerated paths (accel/sums_fast_q.c):
 * the block floating point of spvs_q_sums_t, one point's exact terms and
 * the cost's exact term (defined in points_q.c).  Private to the core.
 */
#ifndef SPVS_FIXED_SUMS_Q_H
#define SPVS_FIXED_SUMS_Q_H

#include "point_q.h"

/* The block of term k (spvs_q_sums_t) and block b's terms [*lo, *hi). */
static inline int blk_of(const spvs_q_sums_t *s, int k)
{
    return (k >= s->split) + (k >= s->split2);
}

static inline void blk_range(const spvs_q_sums_t *s, int b, int *lo, int *hi)
{
    *lo = b == 0 ? 0 : (b == 1 ? s->split : s->split2);
    *hi = b == 0 ? s->split : (b == 1 ? s->split2 : s->nt);
}

/* Sets out's blocks for kind and clears its sums: 0, or -2 for a kind
 * spvs_q_pts_sum does not make. */
int spvs_q_sums_clear(spvs_terms_t kind, spvs_q_sums_t *out);

/* Adds term t to sum k of the accumulator s (sub = 0) or subtracts it
 * (sub = 1), raising a block's exponent before a mantissa reaches 2^62. */
void spvs_q_acc_add(spvs_q_sums_t *s, int k, spvs_qf_t t, int sub);

/* One point's SPVS_T_FIT_Y or SPVS_T_FIT_X terms from its exact residuals
 * r into s. */
void spvs_q_terms_fit(int kind, const q_eps_t *r, const int32_t *p, spvs_q_sums_t *s);

/* One point's SPVS_T_LIN terms under h from its exact residuals r, added
 * to s (sub = 0) or subtracted (sub = 1). */
void spvs_q_terms_lin(const int32_t *h, const q_eps_t *r, const int32_t *p, spvs_q_sums_t *s,
                      int sub);

/* One point's squared Sampson error num / den from its exact residuals. */
spvs_qf_t spvs_q_sampson_term(const int32_t *h, const q_eps_t *r, const int32_t *p);

/* q_eps as a call. */
void spvs_q_eps_call(const int32_t *h, const int32_t *p, q_eps_t *r);

/* One point's squared Sampson error into out's term 0; 0 when w <=
 * SPVS_W_EPS (out unchanged). */
int spvs_q_sampson_exact(const int32_t *h, const int32_t *p, spvs_q_sums_t *out);

/* One point's terms of kind (SPVS_T_LIN, SPVS_T_FIT_Y or SPVS_T_FIT_X) on
 * the exact path into s; 0 when w <= SPVS_W_EPS (s unchanged). */
int spvs_q_sum_exact_point(int kind, const int32_t *h, const int32_t *p, spvs_q_sums_t *s);

/* spvs_q_lin_move on the exact path: point p's SPVS_T_LIN terms under Hw
 * from its exact residuals, added to s (sub = 0) or subtracted (sub = 1).
 * Returns 1, or 0 when w <= SPVS_W_EPS (s unchanged). */
int spvs_q_lin_move_exact(const int32_t Hw[9], const int32_t p[4], int sub, spvs_q_sums_t *s);

/* The cost's term of one point, |eps|^2 in Q52 from its exact residuals. */
uint64_t spvs_q_cost_exact(const int32_t *h, const int32_t *p, uint32_t *sat);

/* *sum + t, or the flag and UINT64_MAX on the unsigned sum's carry. */
static inline int spvs_q_cost_add(uint64_t *sum, uint64_t t, uint32_t *sat)
{
    const uint64_t s = *sum + t;
    if (s < *sum) {
        *sat |= SPVS_Q_SAT;
        *sum = UINT64_MAX;
        return 0;
    }
    *sum = s;
    return 1;
}


#endif /* SPVS_FIXED_SUMS_Q_H */
