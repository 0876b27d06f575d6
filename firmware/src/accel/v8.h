/*
 * v8.h - eight float32 lanes in one AVX register, GNU C vector extensions
 * (private to the core; accel/points_columns.c includes it where SPVS_AVX2 is set).
 *
 * Nothing here names an AVX instruction: the helpers are generic vector
 * code, which the compiler lowers to AVX where they are inlined into a
 * function built for AVX2 (SPVS_TARGET_AVX2) and nowhere else.  Lanes 0-3
 * hold one row of four points and lanes 4-7 the next (v4.h's rows).
 */
#ifndef SPVS_V8_H
#define SPVS_V8_H

#include "v4.h"

/* An eight-lane value is 32 bytes, which GCC and Clang pass differently
 * with and without AVX and say so (-Wpsabi).  Every function that takes or
 * returns one is static and inlined into a function built for AVX2, so no
 * such value is ever passed. */
#if defined(__clang__)
#pragma clang diagnostic ignored "-Wpsabi"
#else
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

/* A function built for AVX2, whatever the translation unit's flags, and
 * never inlined into one that is not; it may run only where
 * spvs_have_avx2() is true. */
#define SPVS_TARGET_AVX2 __attribute__((target("avx2"), noinline))

typedef float spvs_v8 __attribute__((vector_size(32)));
typedef int32_t spvs_v8i __attribute__((vector_size(32)));
typedef float spvs_v8u __attribute__((vector_size(32), aligned(4), may_alias));

/* Nonzero when this processor and its operating system run AVX2 code (the
 * compiler's run-time library has asked the processor before main). */
static inline int spvs_have_avx2(void)
{
    return __builtin_cpu_supports("avx2");
}

static SPVS_ALWAYS_INLINE spvs_v8 spvs_v8_load(const float *p)
{
    return *(const spvs_v8u *)p;
}

/* Lanes 0-3 (the first row) and lanes 4-7 (the second) as four-lane
 * values. */
static SPVS_ALWAYS_INLINE spvs_v4 spvs_v8_lo(spvs_v8 v)
{
    return __builtin_shufflevector(v, v, 0, 1, 2, 3);
}

static SPVS_ALWAYS_INLINE spvs_v4 spvs_v8_hi(spvs_v8 v)
{
    return __builtin_shufflevector(v, v, 4, 5, 6, 7);
}

static SPVS_ALWAYS_INLINE spvs_v4i spvs_v8i_lo(spvs_v8i v)
{
    return __builtin_shufflevector(v, v, 0, 1, 2, 3);
}

static SPVS_ALWAYS_INLINE spvs_v4i spvs_v8i_hi(spvs_v8i v)
{
    return __builtin_shufflevector(v, v, 4, 5, 6, 7);
}

/* The flags use[0..8) as lanes: -1 where a flag is nonzero (spvs_v4_flags
 * of each row). */
static SPVS_ALWAYS_INLINE spvs_v8i spvs_v8_flags(const uint8_t *use)
{
    const spvs_v4i lo = spvs_v4_flags(use);
    const spvs_v4i hi = spvs_v4_flags(use + 4);
    return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
}

/* Nonzero when any lane of the comparison m is true. */
static SPVS_ALWAYS_INLINE int spvs_v8_any(spvs_v8i m)
{
    return spvs_v4_any(spvs_v8i_lo(m) | spvs_v8i_hi(m));
}

#endif /* SPVS_V8_H */
