/*
 * common.h - what every module of the core shares beyond spvs.h (the
 * scalar type, the statuses and the match record): the scalar's functions
 * and limits, the compile-time check, the assert hook and the match list's
 * checks (private to the core, not installed).
 *
 * Units and frames used throughout the core (see DESIGN.md section 1):
 *   - image points are pixels centred on the principal point the controller
 *     assumes (u - 320, v - 240 for a 640x480 image), x right, y down;
 *   - H_cur_tgt maps target-image points to current-image points,
 *     p_cur ~ H p_tgt, normalised so that h22 = 1;
 *   - velocities: v in m/s along the optical axis, w in rad/s (eq. 7).
 */
#ifndef SPVS_COMMON_H
#define SPVS_COMMON_H

#include <stdint.h>

#include "spvs/spvs.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The scalar's functions and limits (the type itself, spvs_real, and
 * SPVS_R() are spvs.h's). */
#if SPVS_USE_DOUBLE
#define SPVS_SQRT(x) sqrt(x)
#define SPVS_FABS(x) fabs(x)
#define SPVS_LOG(x) log(x)
#define SPVS_REAL_EPS 2.220446049250313e-16
#define SPVS_REAL_MAX 1.0e300
#else
#define SPVS_SQRT(x) sqrtf(x)
#define SPVS_FABS(x) fabsf(x)
#define SPVS_LOG(x) logf(x)
#define SPVS_REAL_EPS 1.1920929e-07f
#define SPVS_REAL_MAX 1.0e30f
#endif

/* A compile-time check in a header that C++ code may include too. */
#ifdef __cplusplus
#define SPVS_STATIC_ASSERT(cond, msg) static_assert(cond, msg)
#else
#define SPVS_STATIC_ASSERT(cond, msg) _Static_assert(cond, msg)
#endif

/* Programmer errors (a NULL instance, a broken invariant) go to this hook;
 * bad input never does: it returns a status.  Override SPVS_ASSERT to route it
 * to a platform fault handler. */
#ifndef SPVS_ASSERT
#include <assert.h>
#define SPVS_ASSERT(c) assert(c)
#endif

/* The checks of a frame's match list that read no values (common.c), as
 * every core's loader makes them first: SPVS_OK, SPVS_E_CAPACITY
 * (n > SPVS_MAX_MATCHES), SPVS_E_ARG (m NULL with n > 0) or
 * SPVS_E_TOO_FEW (n < 3). */
int spvs_match_list_check(const spvs_match_t *m, uint16_t n);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_COMMON_H */
