/*
 * common.h - the scalar type, literal macro, status codes and the match record
 * shared by every module of the core.
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

#include "spvs/spvs_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One scalar type for the whole core.  SPVS_R() writes a literal in it, so a
 * float build never promotes to double (it appends the f suffix). */
#if SPVS_USE_DOUBLE
typedef double spvs_real;
#define SPVS_R(x) (x)
#define SPVS_SQRT(x) sqrt(x)
#define SPVS_FABS(x) fabs(x)
#define SPVS_LOG(x) log(x)
#define SPVS_REAL_EPS 2.220446049250313e-16
#define SPVS_REAL_MAX 1.0e300
#else
typedef float spvs_real;
#define SPVS_R(x) (x##f)
#define SPVS_SQRT(x) sqrtf(x)
#define SPVS_FABS(x) fabsf(x)
#define SPVS_LOG(x) logf(x)
#define SPVS_REAL_EPS 1.1920929e-07f
#define SPVS_REAL_MAX 1.0e30f
#endif

#if defined(__GNUC__) || defined(__clang__)
#define SPVS_NODISCARD __attribute__((warn_unused_result))
#else
#define SPVS_NODISCARD
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

/* Status of every core call: 0 is success, negative values are errors.  Every
 * error returned by spvs_update() comes with the command (v, w) = (0, 0). */
typedef enum {
    SPVS_OK = 0,
    SPVS_E_ARG = -1,            /* NULL pointer or impossible argument          */
    SPVS_E_TOO_FEW = -2,        /* fewer matches than the estimator needs       */
    SPVS_E_NONFINITE = -3,      /* a NaN or infinite coordinate in the input    */
    SPVS_E_RANGE = -4,          /* a coordinate or feature index out of range   */
    SPVS_E_CAPACITY = -5,       /* more matches than SPVS_MAX_MATCHES           */
    SPVS_E_DEGENERATE = -6,     /* the sample or inlier set fixes no unique H   */
    SPVS_E_NO_CONSENSUS = -7,   /* no homography explains enough matches        */
    SPVS_E_STALE = -8,          /* frame time not after the last, or too late   */
    SPVS_E_NO_PARALLAX = -9,    /* no off-plane points: epipole unknown         */
    SPVS_E_PLANE_NZ = -10,      /* Methods I, III: plane has n_z ~ 0, no signal */
    SPVS_E_PLANE_NY = -11,      /* Method II: plane has n_y ~ 0, no signal      */
    SPVS_E_STEP_TIMEOUT = -12,  /* a step ran past its time bound               */
    SPVS_E_CONFIG = -13,        /* parameters out of their documented range    */
    SPVS_E_NOT_AT_TARGET = -14  /* step 3 ended but H is not the identity      */
} spvs_status_t;

/* Number of distinct status values (for tables and tests). */
#define SPVS_STATUS_COUNT 15

/* One match: a target-image feature and where it is seen in the current image.
 * Pixels, centred on the assumed principal point.  `feature` is the index of
 * the feature in the target image, stable from frame to frame, and must be
 * below SPVS_MAX_FEATURES. */
typedef struct {
    spvs_real x_tgt;
    spvs_real y_tgt;
    spvs_real x_cur;
    spvs_real y_cur;
    uint16_t feature;
} spvs_match_t;

/* Short, constant name of a status ("ok", "too_few_matches", ...). */
const char *spvs_status_str(int status);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_COMMON_H */
