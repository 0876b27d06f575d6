/*
 * core_util.h - small helpers shared by the core's sources (private: not
 * installed, not part of the API).
 */
#ifndef SPVS_CORE_UTIL_H
#define SPVS_CORE_UTIL_H

#include <stddef.h>

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

/* Asks the data cache for the `bytes` bytes at p, a line (64 bytes) at a
 * time, ahead of reads in an order the hardware cannot guess (SPVS_PREFETCH;
 * nothing where it is 0).  Bound: bytes / 64 + 1 hints. */
static inline void spvs_prefetch(const void *p, size_t bytes)
{
#if SPVS_PREFETCH && (defined(__GNUC__) || defined(__clang__))
    const char *c = (const char *)p;
    for (size_t b = 0; b < bytes; b += 64u) {
        __builtin_prefetch(c + b);
    }
#else
    (void)p;
    (void)bytes;
#endif
}

#if SPVS_SIMD_COLUMNS
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

#endif /* SPVS_CORE_UTIL_H */
