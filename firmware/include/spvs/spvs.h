/*
 * spvs.h - the update pipeline: one call per frame, matches in, command out.
 *
 *   matches -> H: planar-motion RANSAC, re-selection and refit (plane_h.h,
 *              on homography.h and ransac.h)
 *           -> off-plane candidates and memory (offplane.h)
 *           -> epipole and parallax (epipole.h)
 *           -> step logic and control law (control.h) -> (v, w)
 *
 * The instance is a plain struct the caller owns (usually static): no heap.
 * Its size is sizeof(spvs_t), about
 *   SPVS_MAX_MATCHES * (4 * sizeof(spvs_real) + 6) + SPVS_MAX_FEATURES
 *   + SPVS_MAX_OFFPLANE * (10 * sizeof(spvs_real) + 5) + a few hundred bytes
 * (spvs_config.h), the same whatever the point layout.
 */
#ifndef SPVS_SPVS_H
#define SPVS_SPVS_H

#include "spvs/abi.h"
#include "spvs/common.h"
#include "spvs/control.h"
#include "spvs/epipole.h"
#include "spvs/homography.h"
#include "spvs/offplane.h"
#include "spvs/plane_h.h"
#include "spvs/ransac.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    spvs_control_params_t ctl; /* control law, see control.h                 */
    spvs_real noise_px;        /* image noise sigma, pixels, in both images:
                                  inliers have a Sampson error within
                                  sqrt(SPVS_INLIER_CHI2_X100 / 100) of it  */
    spvs_real confidence;      /* RANSAC confidence, (0, 1)                  */
    uint32_t max_iters;        /* RANSAC cap, <= SPVS_RANSAC_MAX_ITERS       */
    spvs_real offplane_px;     /* a rejected match is an off-plane candidate
                                  when its transfer error exceeds this       */
    spvs_real epipole_sin_tol; /* angle tolerance of epipole support (sine)  */
    uint16_t min_support;      /* off-plane supporters needed for an epipole */
    spvs_real max_frame_gap_s; /* a frame later than this after the last good
                                  one is stale: stop and re-acquire          */
    uint32_t seed;             /* PRNG seed: same seed, same result          */
} spvs_params_t;

/* Telemetry and command of one update. */
typedef struct {
    spvs_real v;            /* command, m/s                                   */
    spvs_real w;            /* command, rad/s                                 */
    spvs_real H[9];         /* H_cur_tgt, centred pixels, h22 = 1             */
    spvs_real e_x_px;       /* x of the epipole, pixels (when e_valid)        */
    spvs_real parallax_px;  /* median off-plane parallax, pixels              */
    uint16_t n_matches;     /* matches given                                  */
    uint16_t n_inliers;     /* plane inliers of H                             */
    uint16_t n_offplane;    /* off-plane supporters of the epipole            */
    uint16_t ransac_iters;  /* hypotheses tried                               */
    int16_t status;         /* spvs_status_t of this update                   */
    uint8_t step;           /* spvs_step_t after this update                  */
    uint8_t h_valid;        /* H is this frame's estimate                     */
    uint8_t e_valid;        /* e_x_px is this frame's estimate                */
    uint8_t eq11;           /* Method III runs on eq. (11)                    */
    /* The arrival check after step 3 (control.h; docs/CONTROL.md): the
     * figures of the last check made (0 before the first), over the
     * arrival_frames frames standing still.  Each residual is the mean over
     * the hold, in pixels, with its standard deviation (_sd_px) measured
     * from the hold's own frames, the goal image's share not averaged: */
    spvs_real arrival_stat;       /* the largest |residual| / sd: converged
                                     only if <= arrival_threshold          */
    spvs_real arrival_threshold;  /* arrival_k, standard deviations         */
    spvs_real arrival_lateral_px; /* sideways: the off-plane points'
                                     horizontal parallax (without them, row 1
                                     of H - I at the image corner)          */
    spvs_real arrival_lateral_sd_px;
    spvs_real arrival_depth_px;   /* along the optical axis: (h33 - 1) times
                                     the corner's distance from the centre  */
    spvs_real arrival_depth_sd_px;
    spvs_real arrival_h13_px;     /* heading: h13                           */
    spvs_real arrival_h13_sd_px;
    spvs_real arrival_corner_px;  /* mean corner transfer of the mean H - I */
    spvs_real arrival_parallax_px; /* mean median parallax of the remembered
                                      off-plane points, pixels; -1: none seen */
    uint16_t arrival_frames;      /* frames averaged (so far, while holding) */
    uint8_t arrival_reentries;    /* failed checks that re-entered a step   */
    uint8_t arrival_next;         /* the step the last failed check chose   */
    uint8_t arriving;             /* standing still for the check now       */
} spvs_output_t;

#if SPVS_USE_FIXED
/* The fixed-point build (SPVS_FIXED=ON, docs/FIXED.md): the instance is
 * the Q pipeline's state, spvs_q_t of firmware/src/fixed/spvs_q.h (included
 * at the end of this header), and the functions below run the Q stages. */
typedef struct spvs_q_s spvs_t;
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
} spvs_t;
#endif

/* Parameters for a method: the defaults of docs/CONTROL.md. */
void spvs_params_default(spvs_params_t *p, spvs_method_t method);

/* The inlier threshold, pixels, on the Sampson error: noise_px times
 * sqrt(SPVS_INLIER_CHI2_X100 / 100) (3.03 noise_px by default).
 * p: parameters (only noise_px, pixels, is read; not checked).  The
 * fixed-point build computes it in integers (in float32 the float
 * build's value bit for bit; in double within 2^-28) and itself applies
 * noise_px rounded to 2^-16 px. */
spvs_real spvs_inlier_px(const spvs_params_t *p);

/* Set up an instance (copies p) and reset it.
 * Returns SPVS_OK, SPVS_E_ARG (NULL) or SPVS_E_CONFIG (p out of range). */
SPVS_NODISCARD int spvs_init(spvs_t *s, const spvs_params_t *p);

/* Forget all state (step, signs, off-plane memory, PRNG back to the seed). */
void spvs_reset(spvs_t *s);

/* Process one frame.
 * m: n matches (n <= SPVS_MAX_MATCHES), centred pixels; t_s: frame time, s.
 * out: command and telemetry; out->v = out->w = 0 whenever the return is an
 * error.  Returns the status (also in out->status):
 *   SPVS_OK, SPVS_E_ARG, SPVS_E_CAPACITY, SPVS_E_TOO_FEW, SPVS_E_NONFINITE,
 *   SPVS_E_RANGE, SPVS_E_STALE, SPVS_E_DEGENERATE, SPVS_E_NO_CONSENSUS,
 *   and those of spvs_control_step().
 * The robot has converged when out->step == SPVS_STEP_DONE. */
SPVS_NODISCARD int spvs_update(spvs_t *s, const spvs_match_t *m, uint16_t n,
                               spvs_real t_s, spvs_output_t *out);

/* spvs_update with H given by the caller instead of estimated: H_px is
 * H_cur_tgt in centred pixels (planar form, h22 = 1; its middle row is
 * taken as (0, 1, 0)).  The frame is checked and loaded as in spvs_update,
 * the plane candidates within inlier_px of H are its inliers, and the rest
 * of the pipeline (off-plane memory, epipole, controller) runs unchanged.
 * For comparing estimators on the same pipeline (tools/bench/homing.cpp).
 * m, n, t_s: as spvs_update; out: as spvs_update (out->H is H_px with its
 * middle row (0, 1, 0); the fixed-point build rounds h13 to 2^-18 px,
 * h31 and h32 to 2^-36 per pixel and the rest to 2^-27, its Q27 format).
 * Returns what spvs_update returns (SPVS_E_NO_CONSENSUS when fewer than
 * SPVS_MIN_INLIERS candidates are inliers of H_px), SPVS_E_ARG for H_px
 * NULL, and SPVS_E_DEGENERATE for a non-finite entry of rows 1 and 3; the
 * fixed-point build also SPVS_E_RANGE for an entry beyond its Q27 range
 * (|h11|, |h12|, |h33| >= 16, |h13| >= 8192 px, |h31|, |h32| >= 1/32 per
 * pixel), which no estimate of a planar motion reaches.  On every error
 * (v, w) = (0, 0). */
SPVS_NODISCARD int spvs_update_with_h(spvs_t *s, const spvs_match_t *m, uint16_t n,
                                      spvs_real t_s, const spvs_real H_px[9],
                                      spvs_output_t *out);

/* The estimation stage alone: validate the matches, run the planar RANSAC and
 * the refit, and fill out->H (pixels), n_matches, n_inliers, ransac_iters,
 * h_valid and status; the command is (0, 0).  Matches whose feature the
 * off-plane memory holds are left out, as in spvs_update(); the memory itself
 * and the controller are not touched.  This is what benchmarks time.
 * Returns the same input and estimation statuses as spvs_update(). */
SPVS_NODISCARD int spvs_estimate_h(spvs_t *s, const spvs_match_t *m, uint16_t n,
                                   spvs_output_t *out);

#ifdef __cplusplus
}
#endif

#if SPVS_USE_FIXED
#ifdef __cplusplus
extern "C" {
#endif
#include "spvs_q.h"
#ifdef __cplusplus
}
#endif
#endif

#endif /* SPVS_SPVS_H */
