/*
 * v4.h - four scalars in one SIMD register, GNU C vector extensions that
 * GCC and Clang lower to SSE2 or NEON (private to the core;
 * accel/points_columns.c includes it for its column layout only).
 */
#ifndef SPVS_V4_H
#define SPVS_V4_H

#include "spvs/common.h"

#if SPVS_USE_DOUBLE && defined(__GNUC__) && !defined(__clang__)
/* Four doubles make a 32-byte vector, which GCC passes differently with and
 * without AVX and says so (-Wpsabi).  Every function here that takes or
 * returns one is static, so no such value crosses a translation unit. */
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
/* SPVS_VLANES scalars in one SIMD register (GNU C vector extensions, which
 * GCC and Clang lower to SSE2 or NEON), the integers of the same width that
 * a comparison of two such vectors gives (-1 true, 0 false), and the load of
 * SPVS_VLANES consecutive scalars from any scalar-aligned address. */
#define SPVS_VLANES 4
/* 1 where the float lanes are SSE2 registers (x86-64 with GCC or Clang):
 * the helpers below then use SSE instructions the vector extensions do not
 * name; elsewhere they are written in the extensions alone. */
#if defined(__SSE2__) && !SPVS_USE_DOUBLE && (defined(__GNUC__) || defined(__clang__))
#define SPVS_V4_SSE 1
#else
#define SPVS_V4_SSE 0
#endif
#if SPVS_USE_DOUBLE
typedef int64_t spvs_lane_int;
#else
typedef int32_t spvs_lane_int;
#endif
typedef spvs_real spvs_v4 __attribute__((vector_size(SPVS_VLANES * sizeof(spvs_real))));
typedef spvs_lane_int spvs_v4i __attribute__((vector_size(SPVS_VLANES * sizeof(spvs_real))));
typedef spvs_real spvs_v4u
    __attribute__((vector_size(SPVS_VLANES * sizeof(spvs_real)), aligned(sizeof(spvs_real)),
                   may_alias));

static inline spvs_v4 spvs_v4_load(const spvs_real *p)
{
    return *(const spvs_v4u *)p;
}

/* |v| lane by lane (the sign bits cleared). */
static inline spvs_v4 spvs_v4_abs(spvs_v4 v)
{
    const spvs_v4 neg0 = -(spvs_v4){0};
    return (spvs_v4)((spvs_v4i)v & ~(spvs_v4i)neg0);
}

/* The larger of a and b lane by lane, for lanes where neither is NaN (where
 * one is, either may come out): one maxps with SSE. */
static inline spvs_v4 spvs_v4_max(spvs_v4 a, spvs_v4 b)
{
#if SPVS_V4_SSE
    return __builtin_ia32_maxps(a, b);
#else
    const spvs_v4i gt = a > b;
    return (spvs_v4)(((spvs_v4i)a & gt) | ((spvs_v4i)b & ~gt));
#endif
}

/* The flags use[0..SPVS_VLANES) as lanes: -1 where a flag is nonzero (one
 * load of the four bytes, each lane keeping its own byte). */
#if SPVS_USE_DOUBLE
typedef uint64_t spvs_lane_uint;
#else
typedef uint32_t spvs_lane_uint;
#endif
typedef spvs_lane_uint spvs_v4n __attribute__((vector_size(SPVS_VLANES * sizeof(spvs_real))));
static inline spvs_v4i spvs_v4_flags(const uint8_t *use)
{
    uint32_t b;
    __builtin_memcpy(&b, use, sizeof b);
#if defined(__BYTE_ORDER__) && (__BYTE_ORDER__ == __ORDER_BIG_ENDIAN__)
    const spvs_v4n byte = {0xff000000u, 0xff0000u, 0xff00u, 0xffu};
#else
    const spvs_v4n byte = {0xffu, 0xff00u, 0xff0000u, 0xff000000u};
#endif
    return (((spvs_v4n){0} + b) & byte) != 0;
}

/* The lanes' flags (-1 or 0) as bytes 1 or 0 in mask[0..SPVS_VLANES): one
 * 4-byte store of the lanes' bytes gathered by two swaps. */
#if defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 12)
#define SPVS_V4_SHUFFLE(v, a, b, c, d) __builtin_shufflevector(v, v, a, b, c, d)
#define SPVS_V4_SHUFFLE2(v, w, a, b, c, d) __builtin_shufflevector(v, w, a, b, c, d)
#else
#define SPVS_V4_SHUFFLE(v, a, b, c, d) __builtin_shuffle(v, (spvs_v4i){a, b, c, d})
#define SPVS_V4_SHUFFLE2(v, w, a, b, c, d) __builtin_shuffle(v, w, (spvs_v4i){a, b, c, d})
#endif
static inline void spvs_v4_store_flags(spvs_v4i f, uint8_t *mask)
{
#if defined(__BYTE_ORDER__) && (__BYTE_ORDER__ == __ORDER_BIG_ENDIAN__)
    const spvs_v4i byte = {0x1000000, 0x10000, 0x100, 0x1};
#else
    const spvs_v4i byte = {0x1, 0x100, 0x10000, 0x1000000};
#endif
    spvs_v4i b = f & byte;
    b |= SPVS_V4_SHUFFLE(b, 2, 3, 0, 1);
    b |= SPVS_V4_SHUFFLE(b, 1, 0, 3, 2);
    const uint32_t word = (uint32_t)b[0];
    __builtin_memcpy(mask, &word, sizeof word);
}

/* The flags of four rows of lanes, f[r] for points 4 r .. 4 r + 3, as
 * bytes 1 or 0 in mask[0..4 SPVS_VLANES).  With SSE2 the sixteen flags are
 * narrowed by two saturating packs (-1 stays -1, 0 stays 0) and stored at
 * once; elsewhere row by row. */
#if SPVS_V4_SSE
typedef short spvs_v8s __attribute__((vector_size(16)));
typedef char spvs_v16c __attribute__((vector_size(16)));
static inline void spvs_v4_store_flags4(spvs_v4i f0, spvs_v4i f1, spvs_v4i f2, spvs_v4i f3,
                                        uint8_t *mask)
{
    const spvs_v8s lo = __builtin_ia32_packssdw128(f0, f1);
    const spvs_v8s hi = __builtin_ia32_packssdw128(f2, f3);
    const spvs_v16c bytes = __builtin_ia32_packsswb128(lo, hi) & ((spvs_v16c){0} + 1);
    __builtin_memcpy(mask, &bytes, sizeof bytes);
}
#else
static inline void spvs_v4_store_flags4(spvs_v4i f0, spvs_v4i f1, spvs_v4i f2, spvs_v4i f3,
                                        uint8_t *mask)
{
    spvs_v4_store_flags(f0, mask);
    spvs_v4_store_flags(f1, mask + SPVS_VLANES);
    spvs_v4_store_flags(f2, mask + 2 * SPVS_VLANES);
    spvs_v4_store_flags(f3, mask + 3 * SPVS_VLANES);
}
#endif

/* Nonzero when any lane of the comparison m is true.  With SSE the lanes'
 * sign bits are gathered by one instruction (movmskps) instead of four lane
 * extractions; a comparison's lanes are all ones or all zeros, so the sign
 * bit says the same. */
static inline int spvs_v4_any(spvs_v4i m)
{
#if SPVS_V4_SSE
    return __builtin_ia32_movmskps((spvs_v4)m) != 0;
#else
    return ((m[0] | m[1]) | (m[2] | m[3])) != 0;
#endif
}

/* The sum of the four lanes, added by two swaps (no lane extractions). */
static inline spvs_lane_int spvs_v4i_sum(spvs_v4i v)
{
    v += SPVS_V4_SHUFFLE(v, 2, 3, 0, 1);
    v += SPVS_V4_SHUFFLE(v, 1, 0, 3, 2);
    return v[0];
}

#endif /* SPVS_V4_H */
