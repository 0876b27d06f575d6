/*
 * control.h - Shortest Path Control: Methods I, II and III, three steps each
 * (paper, section 3, eqs. (11), (20), (21), (22)).
 *
 *   Method I   (calibrated, eq. 20), f = h11^2 + h13^2 / alpha_x^2 - 1 (eq. 19)
 *     step 1: v = 0,                   w = -k_w f
 *     step 2: v = -k_v (h11 - h33),    w = -k_w f
 *     step 3: v = 0,                   w = -k_w3 h13
 *   Method II  (uncalibrated, eq. 21)
 *     step 1: v = 0,                   w = -k_w h12
 *     step 2: v = -k_v h32,            w = -k_w h12
 *     step 3: v = 0,                   w = -k_w3 h13
 *   Method III (parallax, eq. 22), e_x = x of the epipole in pixels
 *     step 1: v = 0,                   w = -k_w e_x
 *     step 2: v = -k_v (h11 - h33),    w = -k_w e_x, and once the parallax
 *             falls under switch_parallax_px: w = k_w11 (h11 - cos phi_t)
 *             (eq. 11), with cos phi_t learnt from h11 while aligned (eq. 8)
 *     step 3: v = 0,                   w = -k_w3 h13
 *
 * Gains here are magnitudes; their signs are chosen once, from the parallax
 * (the signed epipole) and H at the start of the step that needs them, as the
 * paper suggests.  docs/CONTROL.md derives each rule.  Step-ending rules,
 * saturation and the Method I false-zero escape are documented there too.
 *
 * Beyond the paper, the end of step 3 is checked: standing still, H averaged
 * over arrival_frames frames must be the identity (eq. 10) within the spread
 * image noise gives it.  Otherwise the residual says which step to run again
 * from where the robot stands: row 3 of H - I (an offset along the optical
 * axis) step 2, h13 alone step 3, row 1 (a sideways offset) step 1; at most
 * SPVS_CTL_ARRIVAL_MAX_REENTRIES times, then SPVS_E_NOT_AT_TARGET.
 */
#ifndef SPVS_CONTROL_H
#define SPVS_CONTROL_H

#include "spvs/common.h"

#ifdef __cplusplus
extern "C" {
#endif

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
     * Each of seven residuals (the six free entries of H - I at the image
     * corner +-arrival_corner_x_px, +-arrival_corner_y_px, and the
     * horizontal parallax) is averaged over the hold; its standard
     * deviation is measured from the hold's own frames, with the goal
     * image's share, which does not average, counted once:
     *   sd = sqrt(s^2 (1 + 1/frames) + arrival_resolution_px^2)
     * (s^2 the residual's variance from frame to frame).  Converged when
     * every |mean| / sd is at most arrival_k and the mean median parallax
     * is under SPVS_CTL_ARRIVAL_PARALLAX_X100 / 100 of what noise of
     * arrival_sigma_px gives. */
    spvs_real arrival_sigma_px;   /* image noise sigma assumed, pixels      */
    spvs_real arrival_k;          /* threshold, standard deviations         */
    spvs_real arrival_corner_x_px; /* image half width, pixels              */
    spvs_real arrival_corner_y_px; /* image half height, pixels             */
    uint16_t arrival_frames;      /* frames averaged standing still, 2 to
                                     SPVS_CTL_ARRIVAL_MAX_FRAMES             */
    spvs_real arrival_resolution_px; /* the least sd: smaller residuals are
                                        not resolved, pixels                */
} spvs_control_params_t;

/* What the estimation stages hand to the controller for one frame. */
typedef struct {
    spvs_real H[9];      /* H_cur_tgt, centred pixels, h22 = 1              */
    spvs_real e_x_px;    /* x of the epipole, pixels (when e_valid)         */
    spvs_real e_dir_x;   /* signed epipole direction (see epipole.h); only  */
    spvs_real e_dir_z;   /*   the sign of e_dir_z is used: target ahead     */
    spvs_real parallax_px; /* median off-plane parallax, negative: unknown  */
    spvs_real parallax_x_px; /* median horizontal and radial parallax of the */
    spvs_real parallax_r_px; /*   remembered off-plane points, signed, while
                                  arriving (parallax_px >= 0)             */
    spvs_real t_s;       /* frame time, seconds                             */
    uint8_t e_valid;     /* the epipole estimate is usable this frame       */
    uint16_t n_inliers;  /* plane inliers behind H (the arrival check's
                            noise model; under 4 counts as 4)              */
} spvs_control_input_t;

/* Controller state: caller-owned, cleared by spvs_control_reset(). */
typedef struct {
    spvs_step_t step;
    int status;              /* latched status once step is FAILED          */
    int8_t sign_w;           /* chosen sign of k_w (0: not chosen yet)      */
    int8_t sign_v;           /* chosen sign of k_v (0: not chosen yet)      */
    int8_t ahead;            /* +1 target in front, -1 behind, 0 unknown    */
    int8_t sign_sin_phit;    /* Method III: sign of sin(phi_t)              */
    int8_t trans_sign0;      /* sign of the step-2 signal at its start      */
    spvs_real trans_d0;      /* |step-2 signal| at its start                */
    int8_t run_sign;         /* sign of the step's signal, current run      */
    int8_t held_sign;        /* the sign that has held hold_frames frames   */
    uint16_t run_len;        /* frames in the current run of run_sign       */
    uint16_t low_parallax;   /* Method III: consecutive frames under 5 px   */
    uint8_t use_eq11;        /* Method III: parallax gone, eq. (11) in use  */
    uint8_t checked_plane;   /* the plane check has been made               */
    uint16_t hold;           /* consecutive frames the step-end test held   */
    spvs_real step_t0;       /* time the current step started, s            */
    spvs_real cos_phit;      /* Method III: learnt cos(phi_t)               */
    uint32_t n_phit;         /* frames averaged into cos_phit               */
    spvs_real t_step_end[4]; /* time each step ended (index 1..3), s        */
    spvs_real normal_est[3]; /* sum of (r/d) n over the start frames        */
    spvs_real h32_sum;       /* sum of h32 over the start frames            */
    int16_t ahead_votes;     /* sum of sign(e_z) over the start frames      */
    uint16_t n_start;        /* start frames seen (decision at hold_frames) */
    uint16_t at_target;      /* consecutive start frames showing no motion  */
    /* Step 2: the translation signal D against the distance driven s (from
     * the commanded v), fitted by least squares D ~ a + b s (docs/CONTROL.md). */
    spvs_real odo_s;         /* distance commanded since step 2 began, m    */
    spvs_real last_v;        /* last commanded v, m/s                       */
    spvs_real last_t;        /* time of the last frame, s                   */
    spvs_real fit_n, fit_s, fit_ss, fit_d, fit_sd; /* LS sums               */
    /* The arrival check (after step 3).  The figures of the last check stay
     * for the telemetry; all corner figures are mean corner transfers of the
     * averaged H in pixels. */
    uint8_t arriving;        /* step 3 has ended: holding still, averaging  */
    uint8_t reentries;       /* checks failed so far (each re-entered a step) */
    uint8_t reentered;       /* the steps now running are a re-entry        */
    uint8_t backing;         /* re-entry: backing off for a new start       */
    uint8_t depth_fixed;     /* the depth correction before the verdict is done */
    uint8_t ex_steer;        /* after backing off: steps 1 and 2 steer on
                                the epipole (Methods I, II)                */
    uint8_t arrival_next;    /* step the last failed check pointed to, 0    */
    uint16_t arrive_n;       /* frames averaged so far                      */
    spvs_real arrive_sum[6]; /* sums of h11 - 1, h12, h13, h31, h32, h33 - 1 */
    /* Sums and sums of squares of the residuals, pixels: those six at the
     * corner, and the horizontal and radial parallax (over arrive_par_n
     * frames). */
    spvs_real arrive_res[SPVS_CTL_ARRIVAL_RESIDUALS];
    spvs_real arrive_sq[SPVS_CTL_ARRIVAL_RESIDUALS];
    spvs_real arrival_stat;       /* largest |mean| / sd                    */
    spvs_real arrival_corner_px;  /* mean corner transfer of the mean H - I */
    spvs_real arrival_lateral_px, arrival_lateral_sd_px; /* sideways        */
    spvs_real arrival_depth_px, arrival_depth_sd_px; /* optical axis        */
    spvs_real arrival_h13_px, arrival_h13_sd_px;     /* heading             */
    spvs_real arrival_parallax_px; /* mean parallax of the remembered
                                     off-plane points, -1: none seen       */
    spvs_real arrive_par_sum;     /* sum of the frames' parallax            */
    uint16_t arrive_par_n;        /* frames with a parallax                 */
    spvs_real fit_ax, fit_sax; /* step 2: sums of h33 - h11 and s (h33 - h11) */
    spvs_real slope_sig;     /* d signal / d metre, the first step 2's fit  */
    spvs_real slope_ax;      /* d (h33 - h11) / d metre, the same line      */
    spvs_real reentry_d0;    /* row-3 part of the step-2 signal at the check */
} spvs_control_t;

/* Defaults for a method: the gains and tolerances of docs/CONTROL.md for the
 * nominal 640x480, alpha = 800 px camera. */
void spvs_control_params_default(spvs_control_params_t *p, spvs_method_t m);

/* Check parameters; returns SPVS_OK or SPVS_E_CONFIG. */
SPVS_NODISCARD int spvs_control_params_check(const spvs_control_params_t *p);

void spvs_control_reset(spvs_control_t *c);

/* One control step.  in may be NULL: no valid estimate this frame.
 * Writes the command to *v (m/s) and *w (rad/s); (0, 0) on every error.
 * Returns SPVS_OK, or SPVS_E_NO_PARALLAX (signs not yet chosen, or Method III
 * without an epipole), SPVS_E_PLANE_NZ / SPVS_E_PLANE_NY (latched: the plane
 * gives this method no signal), SPVS_E_STEP_TIMEOUT (latched),
 * SPVS_E_NOT_AT_TARGET (latched: the arrival check failed
 * SPVS_CTL_ARRIVAL_MAX_REENTRIES + 1 times, or pointed to a step 1 that
 * Method III cannot run without an epipole). */
SPVS_NODISCARD int spvs_control_step(spvs_control_t *c,
                                     const spvs_control_params_t *p,
                                     const spvs_control_input_t *in,
                                     spvs_real *v, spvs_real *w);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_CONTROL_H */
