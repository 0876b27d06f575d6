/*
 * accel/steer.h - the compiler steering of the float core (private to the
 * core; core_util.h includes it where SPVS_ACCEL is 1, and defines the
 * same names as plain C where it is 0).
 *
 * The per-point arithmetic (h_point.inc) and the loops over a frame's
 * points (points.inc) are small helpers called with constant selectors (the
 * kind of terms, the number of terms).  Inlined at every call, each call
 * compiles to the branch-free loop it names; unrolled, a loop of a fixed
 * trip count becomes a plain sequence that keeps its sums in registers or
 * runs on SIMD lanes.  A compiler that sizes its inlining for flash (-Os,
 * the Cortex-M images) does neither on its own.  Neither changes an
 * operation or its order: the results are the reference path's bit for bit
 * (tests/compare_layouts.sh).
 */
#ifndef SPVS_ACCEL_STEER_H
#define SPVS_ACCEL_STEER_H

#if defined(__GNUC__) || defined(__clang__)
/* Inlined at every call. */
#define SPVS_ALWAYS_INLINE inline __attribute__((always_inline))
/* Unroll the next loop completely (a fixed trip count of at most 32). */
#define SPVS_UNROLL _Pragma("GCC unroll 32")
#else
#define SPVS_ALWAYS_INLINE inline
#define SPVS_UNROLL
#endif

#endif
