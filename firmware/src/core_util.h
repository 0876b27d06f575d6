/*
 * core_util.h - small helpers shared by the core's sources (private: not
 * installed, not part of the API).
 */
#ifndef SPVS_CORE_UTIL_H
#define SPVS_CORE_UTIL_H

#include "spvs/common.h"

/* Inlined at every call, so that a helper called with a constant selector
 * (homography.c's point terms) compiles to the branch-free loop it names. */
#if defined(__GNUC__) || defined(__clang__)
#define SPVS_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define SPVS_ALWAYS_INLINE inline
#endif

/* Unroll the next loop completely (a fixed trip count of at most 32), so that
 * the loop around it is a plain sequence a compiler can run on SIMD lanes. */
#if defined(__GNUC__) || defined(__clang__)
#define SPVS_UNROLL _Pragma("GCC unroll 32")
#else
#define SPVS_UNROLL
#endif

/* 1 when x is neither NaN nor infinite.  Written without isfinite() so no
 * libm call is needed on any target: NaN fails the first test, +-Inf the
 * second. */
static inline int spvs_is_finite(spvs_real x)
{
    return (x == x) && (x - x == SPVS_R(0.0));
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

#endif /* SPVS_CORE_UTIL_H */
