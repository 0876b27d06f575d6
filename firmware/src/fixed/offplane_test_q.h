/*
 * offplane_test_q.h - the off-plane stage's transfer test in fixed point
 * (private to the core): whether a row's squared transfer error under H
 * exceeds the off-plane threshold.  The reference (offplane_test_q.c)
 * computes the error with spvs_q_transfer_err2 and compares it; the
 * accelerated filter (accel/offplane_fast_q.c) decides most rows from a
 * bound on the transfer's ratio, without its reciprocal, and computes the
 * error only near the threshold.  Both give the same answer for every row
 * (test_fixed_epipole compares them with the float core's test).
 */
#ifndef SPVS_FIXED_OFFPLANE_TEST_Q_H
#define SPVS_FIXED_OFFPLANE_TEST_Q_H

#include <stdint.h>

/* The threshold as the test takes it: off2 = o^2 with o = 2 offplane_q16,
 * offplane_px in Q26 scaled units (Q16 pixels are Q25 scaled units),
 * below 2^32, so off2 is in Q52 scaled units^2, below 2^64; a negative
 * threshold is 0.  o_fast: what the accelerated filter precomputes (o
 * where its bound decides, else 0; 0 in the reference). */
typedef struct {
    uint64_t off2;
    uint32_t o_fast;
} spvs_q_off_thr_t;

spvs_q_off_thr_t spvs_q_off_thr(int32_t offplane_q16);

/* -1 when row p (target x, y, current x, y; Q26) is behind the camera
 * under H (Q27; w <= SPVS_W_EPS, where float's error is -1, above no
 * threshold), else 1 when spvs_q_transfer_err2(H, p) > t->off2 and 0 when
 * not. */
int spvs_q_off_above(const int32_t H[9], const int32_t p[4], const spvs_q_off_thr_t *t);

#endif /* SPVS_FIXED_OFFPLANE_TEST_Q_H */
