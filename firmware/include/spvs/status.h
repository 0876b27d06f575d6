/*
 * status.h - the statuses of every spvs call: 0 is success, negative values
 * are errors, each with one meaning (installed; spvs.h includes it).
 */
#ifndef SPVS_STATUS_H
#define SPVS_STATUS_H

#ifdef __cplusplus
extern "C" {
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

/* Short, constant name of a status ("ok", "too_few_matches", ...);
 * "unknown" for a value that is no spvs_status_t. */
const char *spvs_status_str(int status);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_STATUS_H */
