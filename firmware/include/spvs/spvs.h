/*
 * spvs.h - the spvs controller's API: one call per frame, matches in,
 * command out.  This header, status.h, abi.h and spvs_config.h are all a
 * program needs (and all that is installed).
 *
 *   matches -> H: planar-motion RANSAC, re-selection and refit
 *           -> off-plane candidates and memory
 *           -> epipole and parallax
 *           -> step logic and control law -> (v, w)
 *
 * The stages are the core's own (firmware/src/spvs/: plane_h.h,
 * homography.h, ransac.h, offplane.h, epipole.h, control.h); tests and
 * tools include them from the source tree.
 */
#ifndef SPVS_SPVS_H
#define SPVS_SPVS_H

#include <stdint.h>

#include "spvs/abi.h"
#include "spvs/spvs_config.h"
#include "spvs/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One scalar type for the whole core, chosen by SPVS_USE_DOUBLE
 * (spvs_config.h).  SPVS_R() writes a literal in it, so a float build never
 * promotes to double (it appends the f suffix). */
#if SPVS_USE_DOUBLE
typedef double spvs_real;
#define SPVS_R(x) (x)
#else
typedef float spvs_real;
#define SPVS_R(x) (x##f)
#endif

#if defined(__GNUC__) || defined(__clang__)
#define SPVS_NODISCARD __attribute__((warn_unused_result))
#else
#define SPVS_NODISCARD
#endif

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

/* ---- the controller's parameters (docs/CONTROL.md) --------------------- */

typedef enum {
    SPVS_METHOD_I = 1,   /* calibrated, eq. (20)   */
    SPVS_METHOD_II = 2,  /* uncalibrated, eq. (21) */
    SPVS_METHOD_III = 3  /* parallax, eq. (22)     */
} spvs_method_t;

typedef enum {
    SPVS_STEP_ROTATE = 1,    /* step 1: turn to face the target             */
    SPVS_STEP_TRANSLATE = 2, /* step 2: drive straight to it                */
    SPVS_STEP_ALIGN = 3,     /* step 3: turn to the target heading          */
    SPVS_STEP_DONE = 4,      /* converged: (v, w) = (0, 0) from now on      */
    SPVS_STEP_FAILED = 5     /* a latched failure: (0, 0) until reset       */
} spvs_step_t;

typedef struct {
    spvs_method_t method;
    spvs_real alpha_x;        /* assumed focal length in x, pixels (Method I) */
    spvs_real alpha_y;        /* assumed focal length in y, pixels            */
    spvs_real k_w;            /* step 1 and 2 rotation gain (method's units)  */
    spvs_real k_v;            /* step 2 translation gain                      */
    spvs_real k_w3;           /* step 3 rotation gain, rad/s per pixel of h13 */
    spvs_real k_w11;          /* Method III eq. (11) gain, rad/s              */
    spvs_real v_max;          /* |v| saturation, m/s                          */
    spvs_real w_max;          /* |w| saturation, rad/s                        */
    spvs_real w_min_escape;   /* Method I: least |w| while the epipole says
                                 the robot is not yet facing the target      */
    spvs_real tol_align;      /* step 1 ends: |signal| under this ...         */
    spvs_real tol_translate;  /* step 2 ends: |signal| under this, or a sign
                                 change of the signal                        */
    spvs_real tol_h13_px;     /* step 3 ends: |h13| under this (pixels)       */
    spvs_real lock_ex_px;     /* |e_x| under this counts as facing the target */
    spvs_real switch_parallax_px; /* Method III switches to eq. (11) below   */
    spvs_real hold_heading_ratio; /* step 2: once the fitted signal is under
                                 this fraction of its start value, the
                                 heading is held (w = 0), except on eq. (11) */
    spvs_real tol_det;        /* step 2 may end only with |det H - 1| under
                                 this (det H = 1 + n^T c / d, eq. 2)         */
    spvs_real min_signal_ratio;   /* plane check: the normal component the
                                     method relies on, relative, must exceed */
    spvs_real step_timeout_s; /* a step longer than this fails                */
    uint16_t hold_frames;     /* consecutive frames a step-end test must hold */
    uint16_t fit_min_frames;  /* step 2: frames before the fitted signal is used */
    spvs_real fit_min_span_m; /* step 2: distance driven before it is used, m */
    /* The arrival check after step 3 (beyond the paper; docs/CONTROL.md,
     * "A verified arrival"): the robot stands still for arrival_frames
     * frames and tests H = I (eq. 10; eq. 2 at the target whatever the
     * calibration) and a zero parallax of the remembered off-plane points.
     * Each of eight residuals (the six free entries of H - I at the image
     * corner +-arrival_corner_x_px, +-arrival_corner_y_px, the horizontal
     * and the radial parallax) is averaged over the hold; its standard
     * deviation is measured from the hold's own frames, with the goal
     * image's share, which does not average, counted once:
     *   sd = sqrt(s^2 (1 + 1/frames) + (SPVS_CTL_ARRIVAL_SD_MIN_MPX / 1000)^2)
     * (s^2 the residual's variance from frame to frame).  Converged when
     * no mean lies more than arrival_k sd beyond its dead zone
     * (arrival_resolution_px; tol_h13_px for h13; for the horizontal
     * parallax SPVS_CTL_ARRIVAL_LATERAL_ZONE_X10 / 10 times it) and the
     * mean median parallax is under SPVS_CTL_ARRIVAL_PARALLAX_X100 / 100
     * of what noise of arrival_sigma_px gives. */
    spvs_real arrival_sigma_px;   /* image noise sigma assumed, pixels      */
    spvs_real arrival_k;          /* threshold, standard deviations         */
    spvs_real arrival_corner_x_px; /* image half width, pixels              */
    spvs_real arrival_corner_y_px; /* image half height, pixels             */
    uint16_t arrival_frames;      /* frames averaged standing still, 2 to
                                     SPVS_CTL_ARRIVAL_MAX_FRAMES             */
    spvs_real arrival_resolution_px; /* the dead zone: residuals the check
                                        ignores, pixels                     */
} spvs_control_params_t;

typedef struct {
    spvs_control_params_t ctl; /* control law, see above                     */
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
    spvs_real arrival_stat;       /* the most sd a mean lies beyond its dead
                                     zone: converged only if <=
                                     arrival_threshold                     */
    spvs_real arrival_threshold;  /* arrival_k, standard deviations         */
    spvs_real arrival_lateral_px; /* sideways: the off-plane points'
                                     horizontal parallax (without them, row 1
                                     of H - I at the image corner)          */
    spvs_real arrival_lateral_sd_px;
    spvs_real arrival_depth_px;   /* along the optical axis: the radial
                                     parallax (without off-plane points,
                                     (h33 - 1) times the corner's radius)   */
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

/* The instance: caller-owned storage (usually static), passed by pointer;
 * spvs_init() sets it up, spvs_reset() clears its state.  No heap.
 *
 * Its contents are the core's own (firmware/src/spvs/instance.h: the stage
 * states of the float core, or the Q pipeline's in the fixed-point build),
 * so this header declares only storage of the right size and alignment:
 * SPVS_INSTANCE_BYTES (spvs_config.h, a formula in the SPVS_MAX_* settings
 * and the scalar type), which the core checks at compile time to hold its
 * state in every build.  Storage rather than the state's type keeps this
 * header whole on its own: the state is built of every stage's types, and
 * spelling them here would install every stage header with it.  abi.h
 * makes a caller built with other settings fail to link. */
typedef union {
    unsigned char bytes[SPVS_INSTANCE_BYTES];
    uint64_t align_u64;
    double align_f64;
    void *align_ptr;
} spvs_t;

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
 *   and the controller's: SPVS_E_NO_PARALLAX, SPVS_E_PLANE_NZ,
 *   SPVS_E_PLANE_NY, SPVS_E_STEP_TIMEOUT, SPVS_E_NOT_AT_TARGET (status.h).
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

/* The controller's step now (SPVS_STEP_ROTATE .. SPVS_STEP_FAILED), as
 * out->step after the last update; SPVS_STEP_ROTATE after spvs_init() or
 * spvs_reset().  s must be an initialised instance (not checked). */
spvs_step_t spvs_step(const spvs_t *s);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_SPVS_H */
