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
