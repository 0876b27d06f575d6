/*
 * fixed/accel/steer_q.h - the compiler steering of the fixed-point core
 * (private to the core; q.h includes it where SPVS_ACCEL is 1, and defines
 * the same names as plain C where it is 0).
 *
 * A Cortex-M3 has 13 general registers and multiplies 32 x 32 -> 64 bits in
 * one instruction (SMULL), 64 x 64 in three.  Built for size (-Os), GCC
 * calls the kernels' per-point helpers instead of inlining them, inlines
 * large helpers whose frames then spill their callers' loop variables, and
 * folds a 32-bit value taken from a 64-bit shift back into a 64-bit
 * product.  These three marks undo that.  None changes an integer result:
 * the outputs are the reference path's bit for bit.
 */
#ifndef SPVS_FIXED_ACCEL_STEER_Q_H
#define SPVS_FIXED_ACCEL_STEER_Q_H

#include <stdint.h>

#if defined(__GNUC__) || defined(__clang__)
/* Inlined at every call: the kernels' per-point helpers. */
#define SPVS_Q_INLINE inline __attribute__((always_inline))
/* Never inlined: a helper whose frame (or register pressure) should stay
 * out of its caller's. */
#define SPVS_Q_NOINLINE __attribute__((noinline))
#else
#define SPVS_Q_INLINE inline
#define SPVS_Q_NOINLINE
#endif

/* x, opaque to the optimiser, at no cost: a 32-bit value taken from a
 * 64-bit shift stays a 32-bit value, so that a product with it is one
 * 32 x 32 -> 64-bit multiply (SMULL).  GCC otherwise folds the sign
 * extension back into the shift and multiplies in 64 bits (UMULL and two
 * MLA on the Cortex-M3). */
static inline int32_t spvs_q_opaque32(int32_t x)
{
#if defined(__GNUC__) || defined(__clang__)
    __asm__("" : "+r"(x));
#endif
    return x;
}

#endif
