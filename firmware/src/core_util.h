/*
 * core_util.h - small helpers shared by the core's sources (private: not
 * installed, not part of the API).
 */
#ifndef SPVS_CORE_UTIL_H
#define SPVS_CORE_UTIL_H

#include <stddef.h>
#include <string.h>

#include "spvs/common.h"

/* Compiler steering: SPVS_ALWAYS_INLINE marks the per-point helpers and
 * SPVS_UNROLL the loops of a fixed trip count.  The reference path is plain
 * C (an inline function, a loop); where the accelerators are built,
 * accel/steer.h makes them the attribute and the pragma that let an
 * in-order core run the per-point loops without calls
 * (docs/EMBEDDED.md). */
#if SPVS_ACCEL
#include "accel/steer.h"
#else
#define SPVS_ALWAYS_INLINE inline
#define SPVS_UNROLL
#endif

/* Eight bytes p[0..8) as a word with p[k] in bits 8k..8k+7, whatever the
 * target's byte order (one load where it is little-endian). */
static inline uint64_t spvs_load_le64(const uint8_t *p)
{
    return (uint64_t)p[0] | (uint64_t)p[1] << 8 | (uint64_t)p[2] << 16 | (uint64_t)p[3] << 24 |
           (uint64_t)p[4] << 32 | (uint64_t)p[5] << 40 | (uint64_t)p[6] << 48 |
           (uint64_t)p[7] << 56;
}

/* The k of the lowest nonzero byte k of d (d != 0; spvs_load_le64's
 * numbering). */
static inline unsigned spvs_byte_of_lowest(uint64_t d)
{
#if defined(__GNUC__) || defined(__clang__)
    return (unsigned)__builtin_ctzll(d) / 8u;
#else
    unsigned k = 0;
    /* Bound: 7 bytes. */
    while (k < 7u && (d & 0xffu) == 0u) {
        d >>= 8;
        k++;
    }
    return k;
#endif
}

/* 1 when x is neither NaN nor infinite.  Written without isfinite() so no
 * libm call is needed on any target: NaN fails the first test, +-Inf the
 * second. */
static inline int spvs_is_finite(spvs_real x)
{
    return (x == x) && (x - x == SPVS_R(0.0));
}

/* lo < x < hi for the spvs_real at x (lo_incl, hi_incl: <=; hi NULL: no
 * upper bound); false for a NaN.  The parameters' rules (control_steps.inc,
 * pipeline.inc) compare through this or its fixed-point twin
 * spvs_q_real_in (fixed/q.h), which compares the same on the bits. */
static inline int spvs_real_in(const void *x, const spvs_real *lo, int lo_incl,
                               const spvs_real *hi, int hi_incl)
{
    spvs_real v;
    memcpy(&v, x, sizeof v);
    if (!(lo_incl ? v >= *lo : v > *lo)) {
        return 0;
    }
    return hi == 0 || (hi_incl ? v <= *hi : v < *hi);
}

/* 1 when a[0..3) and b[0..3) are all finite: x * 0 is +-0 for a finite x
 * and NaN otherwise, so one comparison tests the six (no branch each). */
static inline int spvs_finite3x2(const spvs_real a[3], const spvs_real b[3])
{
    const spvs_real z = ((a[0] * SPVS_R(0.0) + a[1] * SPVS_R(0.0)) + a[2] * SPVS_R(0.0)) +
                        ((b[0] * SPVS_R(0.0) + b[1] * SPVS_R(0.0)) + b[2] * SPVS_R(0.0));
    return z == SPVS_R(0.0);
}

/* Ascending insertion sort of n values; callers bound n by a config constant
 * (SPVS_MAX_OFFPLANE or SPVS_EPIPOLE_MEDIAN). */
static inline void spvs_sort_small(spvs_real *v, uint16_t n)
{
    for (uint16_t i = 1; i < n; i++) {
        spvs_real key = v[i];
        uint16_t k = i;
        while (k > 0 && v[k - 1] > key) {
            v[k] = v[k - 1];
            k--;
        }
        v[k] = key;
    }
}

/* The input index of stored slot k (spvs_pts_load, and the Q loader of
 * fixed/points_q.c): the plane matches' slots 0..n_plane take them in
 * spread order, the position among them advancing by `stride` (mod
 * n_plane) from slot to slot, through order[] when it is given; the other
 * slots take order[k]. */
static inline uint16_t spvs_slot_source(uint16_t k, uint16_t n_plane, const uint16_t *order,
                                        uint16_t stride, uint16_t *pos)
{
    if (order != 0 && k >= n_plane) {
        return order[k];
    }
    const uint16_t p = *pos;
    const uint16_t q = (uint16_t)(p + stride);
    *pos = (uint16_t)(q >= n_plane ? q - n_plane : q);
    return order != 0 ? order[p] : p;
}

#endif /* SPVS_CORE_UTIL_H */
