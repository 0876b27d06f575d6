/*
 * instance.h - what an spvs_t holds (private to the core; tests and tools
 * that look into an instance include it from the source tree).
 *
 * spvs.h gives the caller storage of SPVS_INSTANCE_BYTES; the core's state
 * lives in it as spvs_state_t: the float core's stage states below, or in
 * the fixed-point build (SPVS_FIXED=ON) the Q pipeline's state, spvs_q_t
 * of fixed/spvs_q.h.  spvs_state() views an instance as its state; the
 * core reads and writes an instance only through that view, and the caller
 * never through its bytes, so the storage is only ever accessed as one
 * type.  The checks below make a state that outgrows the storage, or needs
 * a stricter alignment, a compile error in every build and configuration.
 */
#ifndef SPVS_INSTANCE_H
#define SPVS_INSTANCE_H

#include "spvs/common.h"
#include "spvs/control.h"
#include "spvs/epipole.h"
#include "spvs/homography.h"
#include "spvs/offplane.h"
#include "spvs/plane_h.h"
#include "spvs/ransac.h"
#include "spvs/spvs.h"

#if SPVS_USE_FIXED
#include "fixed/spvs_q.h"

typedef spvs_q_t spvs_state_t;
#else
typedef struct {
    spvs_params_t p;
    spvs_control_t ctl;
    spvs_rng_t rng;
    spvs_real last_t_s;       /* time of the last update                      */
    spvs_real last_good_t_s;  /* time of the last frame with a valid H        */
    uint8_t has_last;
    uint8_t has_good;
    spvs_plane_h_t est;       /* the frame's points and H (plane_h.h)         */
    spvs_offplane_t off;      /* off-plane memory and candidates (offplane.h) */
    spvs_epipole_work_t ework;
    /* The last SPVS_EPIPOLE_MEDIAN epipole estimates (x in pixels, side). */
    spvs_real ehist_x[SPVS_EPIPOLE_MEDIAN];
    int8_t ehist_z[SPVS_EPIPOLE_MEDIAN];
    uint8_t n_ehist;
    uint8_t i_ehist;
    spvs_real lateral_px;     /* the frame's horizontal and radial parallax */
    spvs_real radial_px;      /*   (offplane.h), while arriving            */
} spvs_state_t;
#endif

#ifdef __cplusplus
#define SPVS_ALIGNOF(t) alignof(t)
#else
#define SPVS_ALIGNOF(t) _Alignof(t)
#endif
SPVS_STATIC_ASSERT(sizeof(spvs_state_t) <= sizeof(spvs_t),
                   "the core's state outgrows spvs_t: raise SPVS_INSTANCE_FIXED_BYTES "
                   "or the per-setting terms of SPVS_INSTANCE_BYTES (spvs_config.h)");
SPVS_STATIC_ASSERT(SPVS_ALIGNOF(spvs_state_t) <= SPVS_ALIGNOF(spvs_t),
                   "the core's state needs a stricter alignment than spvs_t gives");

/* The state an instance holds (the caller's storage, spvs.h). */
static inline spvs_state_t *spvs_state(spvs_t *s)
{
    return (spvs_state_t *)(void *)s;
}

static inline const spvs_state_t *spvs_state_c(const spvs_t *s)
{
    return (const spvs_state_t *)(const void *)s;
}

#endif /* SPVS_INSTANCE_H */
