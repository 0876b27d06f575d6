/*
 * epipole_cone_q.h - the epipole's support test in fixed point (private to
 * the core).  Direction i (a Q30 unit vector) supports direction j within
 * the cone of squared sine tol (Q62, below 2^63) when their dot product is
 * positive and floor(|cross| 2^-29)^2 <= tol: cross to Q31 (below 2^32),
 * squared in Q62, exact up to 2^-31 on the sine (1e-8 of the default
 * 0.01).  The reference (epipole_cone_q.c) tests each pair so, counts
 * every supporter and takes square roots bit by bit; the accelerator
 * (accel/epipole_cone_fast_q.c) decides most pairs on the cross product's
 * high word, stops a count that can no longer reach `need` and corrects a
 * root estimate to the floor.  The same supporters, the same consensus,
 * the same roots (test_fixed_accel).
 */
#ifndef SPVS_FIXED_EPIPOLE_CONE_Q_H
#define SPVS_FIXED_EPIPOLE_CONE_Q_H

#include <stdint.h>

/* The cone: tol, and the bound it puts on |cross| (|cross| <= lim inside:
 * floor(|cross| 2^-29) <= floor(sqrt(tol))), with lim's high word. */
typedef struct {
    uint64_t tol; /* sin^2 of the half angle, Q62, below 2^63     */
    uint64_t lim; /* (floor(sqrt(tol)) + 1) 2^29 - 1, below 2^61  */
    uint32_t lh;  /* lim's high word, below 2^29                  */
} spvs_q_cone_t;

/* The cone of tol (epipole_q.c). */
spvs_q_cone_t spvs_q_cone(uint64_t tol);

/* 1 when d supports (xj, zj) in cone k; a zero direction supports none. */
int spvs_q_cone_supports(const int32_t d[2], int32_t xj, int32_t zj, const spvs_q_cone_t *k);

/* The supporters of (xj, zj) among the directions u[0..n), where they can
 * reach need (at least 1): a count of need or more is exact; a smaller
 * one may stop early and stays below need.  u[n] is read for an odd n and
 * must be zero (the estimator's work holds the spare entry).  Bound: n
 * directions. */
uint16_t spvs_q_cone_count(const int32_t (*u)[2], uint16_t n, int32_t xj, int32_t zj,
                           const spvs_q_cone_t *k, uint32_t need);

/* floor(sqrt(x)), exact, for any uint64 x. */
uint32_t spvs_q_sqrt_floor(uint64_t x);

#endif /* SPVS_FIXED_EPIPOLE_CONE_Q_H */
