/*
 * control_q.h - Shortest Path Control in fixed point: the twin of control.h
 * (Methods I, II and III, three steps each, paper section 3, eqs. (11),
 * (20), (21), (22); docs/CONTROL.md derives every rule).  Private: not
 * installed, not part of the API; docs/FIXED.md gives the formats.
 *
 * The steps, the step-ending rules, the sign choices, the start's plane
 * check, step 2's least-squares line, Method III's switch to eq. (11), the
 * arrival check after step 3 and its re-entries are written once, in
 * control_steps.inc, for this core and the float one; control_q.c gives
 * them the signals in Q.  Nothing here
 * reads a float or double except through its bits (q.h), so the object
 * links no floating-point helper.
 *
 * Formats of the input (value = integer 2^-f):
 *   H          H_cur_tgt in scaled units (pixels / SPVS_COORD_SCALE), int32
 *              Q27 (SPVS_QH), h22 = 1: what plane_h_q.h estimates.  The
 *              float controller takes H in pixels (spvs.c rescales with
 *              spvs_h_rescale first); here the pixel entries are the same
 *              integers read in another format, since the scale is a power
 *              of two: h13 in pixels is Q(27 - 9) = Q18, h31 and h32 per
 *              pixel are Q(27 + 9) = Q36, the rest Q27.  No rescale costs.
 *   e_x        x of the epipole, pixels, int32 Q16: |e_x| < 32768 px (an
 *              epipole further out is clamped there by the conversion,
 *              which changes no command: k_w |e_x| is then far past w_max
 *              for any k_w above 2^-15 w_max rad/s per px, and no
 *              comparison of control.c sits beyond 4 lock_ex_px).
 *   e_side     the sign of the epipole direction's z (control.h's e_dir_z,
 *              of which only the sign is used): +1 target ahead, -1 behind,
 *              0 unknown.
 *   parallax   median off-plane parallax, pixels, int32 Q16; negative:
 *              unknown.
 *   t          frame time, seconds, int32 Q16: 15 us resolution over
 *              +-32768 s (9.1 h).  Integer milliseconds would hold longer
 *              runs but round each frame interval by up to 1 ms, 1 % of a
 *              100 ms frame, and the odometry integrates v dt; Q16 keeps
 *              that error under 2^-17 s a frame.
 *   n_inliers  as control.h.
 * Output: v in int32 Q24 m/s and w in int32 Q24 rad/s, saturated at v_max
 * and w_max (a saturation there is the command limit, not an error).  Q24
 * holds 128 m/s and 128 rad/s with 6e-8 resolution; Q16's 1.5e-5 m/s would
 * be 5e-4 of a command near the end of step 2 (v = k_v D, D -> 0), and the
 * odometry of step 2's line integrates the commands.
 *
 * Internal formats (ranges proved in control_q.c):
 *   gains and coefficients  spvs_qf_t (31-bit mantissa, own exponent): each
 *              product gain x signal is one 32 x 32 -> 64-bit multiply and
 *              one shift, relative error <= 2^-31, whatever the gain;
 *   H signals  f of eq. (19), h12, h11 - h33, alpha_y h32: int32 Q27; a
 *              signal clamped at +-16 only ever meets a command already
 *              past its limit and comparisons far below 16 (flagged in sat);
 *   h13        pixels, Q18 (the input's integer);
 *   det H - 1  int64 Q54, exact;
 *   cos phi_t  int64 Q40 (running / exponential mean of h11);
 *   odometry   int64 Q40 metres; the step-2 distance s in int32 Q24 m;
 *   step 2's least-squares sums  n, sum s (Q24) and sum D, sum h33 (Q27)
 *              exact in int64; sum s^2, sum s D, sum s h33 in spvs_qf_t
 *              (s^2 alone needs 62 bits);
 *   the arrival sums  H - I exact in int64 Q27, sum 1 / n_inliers in int64
 *              Q32, the parallax in int64 Q16; the averages, the corner
 *              transfers and the bound with its square root in spvs_qf_t;
 *              the figures kept for the telemetry in int32 Q16 pixels.
 *
 * Bounds: no loop here depends on the input (four corners, six sums, three
 * normal components).
 */
#ifndef SPVS_FIXED_CONTROL_Q_H
#define SPVS_FIXED_CONTROL_Q_H

#include <stdint.h>

#include "points_q.h"
#include "q.h"
#include "spvs/control.h"

#define SPVS_QCTL_T 16  /* time, seconds            */
#define SPVS_QCTL_PX 16 /* e_x, parallax, pixels    */
#define SPVS_QCTL_CMD 24 /* v (m/s), w (rad/s)       */
#define SPVS_QCTL_S 24  /* step-2 distance, metres  */
#define SPVS_QCTL_ODO 40 /* odometry, metres (int64) */

/* control.h's parameters, converted once by spvs_q_ctl_params_from_real. */
typedef struct {
    spvs_method_t method;
    /* Coefficients of H's scaled entries: 512 / alpha_x (h13 to h13 /
     * alpha_x), alpha_x / 512 (h31 to alpha_x h31), alpha_y / 512 (h32 to
     * alpha_y h32), alpha_y / alpha_x (h12 to alpha_y h12 / alpha_x). */
    spvs_qf_t c13, c31, c32, c12;
    int32_t alpha_x;          /* pixels, Q16 */
    spvs_qf_t k_w, k_v, k_w3, k_w11;
    int32_t v_max, w_max, w_min_escape; /* Q24 */
    int32_t tol_align;        /* in the step-1 signal's format: Q27, III Q16 */
    int32_t tol_translate;    /* Q27 */
    int32_t tol_h13;          /* pixels, Q18 */
    int32_t lock_ex;          /* pixels, Q16 */
    int32_t switch_parallax;  /* pixels, Q16 */
    spvs_qf_t hold_heading_ratio;
    int64_t tol_det;          /* Q54 */
    spvs_qf_t min_signal_ratio2; /* its square */
    int32_t step_timeout;     /* seconds, Q16 */
    uint16_t hold_frames;
    uint16_t fit_min_frames;
    int32_t fit_min_span;     /* metres, Q24 */
    spvs_qf_t fit_min_den;    /* (SPVS_CTL_FIT_MIN_SPREAD_UM um)^2 in Q48 m^2 */
    /* The arrival check (control.h). */
    spvs_qf_t arrival_k;
    spvs_qf_t res_scale[6];   /* pixels per scaled-unit entry of H - I */
    spvs_qf_t corner_x, corner_y; /* pixels */
    spvs_qf_t resolution;     /* pixels */
    int32_t arrival_par_max;  /* pixels, Q16: 1.75 x 1.665 sigma */
    uint16_t arrival_frames;
} spvs_q_ctl_params_t;

/* What the estimation stages hand to the controller for one frame. */
typedef struct {
    int32_t H[9];       /* H_cur_tgt, scaled units, Q27, h22 = 1 */
    int32_t e_x;        /* pixels, Q16 (when e_valid)             */
    int8_t e_side;      /* sign of the epipole's z: +1, -1, 0     */
    int32_t parallax;   /* pixels, Q16; negative: unknown          */
    int32_t parallax_x; /* horizontal parallax, signed, pixels, Q16 */
    int32_t parallax_r; /* radial parallax, signed, pixels, Q16     */
    int32_t t;          /* seconds, Q16                            */
    uint8_t e_valid;
    uint16_t n_inliers;
} spvs_q_ctl_input_t;

/* The state: control.h's spvs_control_t field for field, in Q. */
typedef struct {
    spvs_step_t step;
    int status;
    int8_t sign_w, sign_v, ahead, sign_sin_phit, trans_sign0;
    int32_t trans_d0;         /* Q27 */
    int8_t run_sign, held_sign;
    uint16_t run_len, low_parallax;
    uint8_t use_eq11, checked_plane;
    uint16_t hold;
    int32_t step_t0;          /* s, Q16; negative: not started */
    int64_t cos_phit;         /* Q40 */
    uint32_t n_phit;
    int32_t t_step_end[4];    /* s, Q16 */
    int64_t normal_est[3];    /* Q27 */
    int64_t h32_sum;          /* Q27 */
    int16_t ahead_votes;
    uint16_t n_start, at_target;
    int64_t odo;              /* m, Q40 */
    int32_t last_v;           /* m/s, Q24 */
    int32_t last_t;           /* s, Q16; negative: none */
    uint32_t fit_n;
    int64_t fit_s, fit_d, fit_ax; /* Q24, Q27, Q27 (ax = h33 - h11) */
    spvs_qf_t fit_ss, fit_sd, fit_sax;
    uint8_t arriving, reentries, reentered, backing, arrival_next, ex_steer, depth_fixed;
    uint16_t arrive_n;
    int64_t arrive_sum[6];    /* Q27: h11 - 1, h12, h13 (scaled), h31, h32 (scaled), h33 - 1 */
    int64_t arrive_res[SPVS_CTL_ARRIVAL_RESIDUALS]; /* Q16 px (control.h) */
    int64_t arrive_sq[SPVS_CTL_ARRIVAL_RESIDUALS];  /* Q32 px^2 */
    int32_t arrival_stat;     /* Q16 */
    int32_t arrival_corner_px, arrival_lateral_px, arrival_lateral_sd_px, arrival_depth_px,
        arrival_depth_sd_px, arrival_h13_px, arrival_h13_sd_px, arrival_parallax_px; /* Q16 px */
    int64_t arrive_par_sum;   /* Q16 px */
    uint16_t arrive_par_n;
    spvs_qf_t slope_sig;      /* Q27 signal units per metre, as a value */
    spvs_qf_t slope_ax;       /* d (h33 - h11) / d metre, the same line */
    int32_t reentry_d0;       /* Q27 */
    uint32_t sat;             /* sticky q.h flags: a signal was clamped */
} spvs_q_ctl_t;

/* spvs_control_params_check's rules (control_steps.inc's params_rules,
 * written once: the method, the positive finite fields under
 * SPVS_REAL_MAX, w_min_escape in [0, w_max], the ratios in [0, 1), the
 * frame counts), each compared exactly on the parameters' bits
 * (spvs_q_real_in), so it returns SPVS_OK or SPVS_E_CONFIG wherever the
 * float check does (NaN and infinities included) without a float
 * operation; SPVS_E_ARG for NULL. */
SPVS_NODISCARD int spvs_q_ctl_params_check(const spvs_control_params_t *p);

/* control.h's parameters in Q, checked first by spvs_q_ctl_params_check.
 * Returns SPVS_OK, SPVS_E_ARG (NULL) or SPVS_E_CONFIG: a parameter the
 * check refuses, or a value outside its Q format (alpha_x, alpha_y and
 * the pixel tolerances under 32768, v_max and w_max under 128, the
 * timeout under 32768 s, a tolerance that rounds to 0). */
SPVS_NODISCARD int spvs_q_ctl_params_from_real(spvs_q_ctl_params_t *q,
                                               const spvs_control_params_t *p);

/* control.h's frame input in Q (H in pixels to scaled Q27, the rest as
 * above).  A nonzero value that would round to 0 keeps its sign as one
 * ulp, since the controller takes signs of H, e_x and the parallax.
 * Returns SPVS_OK, SPVS_E_ARG, SPVS_E_NONFINITE (a NaN or infinity in H,
 * t_s, a valid e_x or the parallax) or SPVS_E_RANGE (an H entry outside
 * Q27's (-16, 16) in scaled units, |t_s| >= 32768 s); e_x and the parallax
 * are clamped at 32768 px. */
SPVS_NODISCARD int spvs_q_ctl_input_from_real(spvs_q_ctl_input_t *q,
                                              const spvs_control_input_t *in);

void spvs_q_ctl_reset(spvs_q_ctl_t *c);

/* One control step, spvs_control_step's twin: in may be NULL (no valid
 * estimate: SPVS_E_ARG, as float).  Writes v (m/s, Q24) and w (rad/s,
 * Q24); (0, 0) on every error.  Returns control.h's statuses. */
SPVS_NODISCARD int spvs_q_ctl_step(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                                   const spvs_q_ctl_input_t *in, int32_t *v, int32_t *w);

#endif /* SPVS_FIXED_CONTROL_Q_H */
