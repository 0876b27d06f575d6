/*
 * control.c - Shortest Path Control, Methods I, II and III (paper, section 3).
 *
 * The derivations behind every sign and step-ending rule are in
 * docs/CONTROL.md; the comments here name the result and the equation.
 */
#include <math.h>

#include "spvs/control.h"
#include "spvs/homography.h"

static int8_t sgn(spvs_real x)
{
    return (int8_t)((x > SPVS_R(0.0)) - (x < SPVS_R(0.0)));
}

static spvs_real clamp(spvs_real x, spvs_real lim)
{
    if (x > lim) {
        return lim;
    }
    if (x < -lim) {
        return -lim;
    }
    return x;
}

int spvs_control_params_check(const spvs_control_params_t *p)
{
    if (p == 0) {
        return SPVS_E_ARG;
    }
    if (p->method != SPVS_METHOD_I && p->method != SPVS_METHOD_II &&
        p->method != SPVS_METHOD_III) {
        return SPVS_E_CONFIG;
    }
    const spvs_real pos[] = {p->alpha_x, p->alpha_y, p->k_w, p->k_v, p->k_w3,
                             p->k_w11, p->v_max, p->w_max, p->tol_align,
                             p->tol_translate, p->tol_h13_px, p->lock_ex_px, p->tol_det,
                             p->step_timeout_s, p->arrival_sigma_px, p->arrival_k,
                             p->arrival_leverage, p->arrival_corner_x_px,
                             p->arrival_corner_y_px, p->arrival_resolution_px};
    for (unsigned i = 0; i < sizeof pos / sizeof pos[0]; i++) {
        /* Written so that NaN fails too. */
        if (!(pos[i] > SPVS_R(0.0) && pos[i] < SPVS_REAL_MAX)) {
            return SPVS_E_CONFIG;
        }
    }
    if (!(p->w_min_escape >= SPVS_R(0.0) && p->w_min_escape <= p->w_max) ||
        !(p->switch_parallax_px >= SPVS_R(0.0)) ||
        !(p->hold_heading_ratio >= SPVS_R(0.0) && p->hold_heading_ratio < SPVS_R(1.0)) ||
        !(p->min_signal_ratio >= SPVS_R(0.0) && p->min_signal_ratio < SPVS_R(1.0)) ||
        p->hold_frames < 1u || p->fit_min_frames < 2u ||
        !(p->fit_min_span_m > SPVS_R(0.0)) || p->arrival_frames < 1u ||
        p->arrival_max_frames < p->arrival_frames ||
        p->arrival_max_frames > SPVS_CTL_ARRIVAL_MAX_FRAMES) {
        return SPVS_E_CONFIG;
    }
    return SPVS_OK;
}

static void fit_clear(spvs_control_t *c)
{
    c->fit_n = c->fit_s = c->fit_ss = c->fit_d = c->fit_sd = SPVS_R(0.0);
    c->fit_ax = c->fit_sax = SPVS_R(0.0);
}

void spvs_control_reset(spvs_control_t *c)
{
    SPVS_ASSERT(c != 0);
    c->step = SPVS_STEP_ROTATE;
    c->status = SPVS_OK;
    c->sign_w = 0;
    c->sign_v = 0;
    c->ahead = 0;
    c->sign_sin_phit = 0;
    c->trans_sign0 = 0;
    c->trans_d0 = SPVS_R(0.0);
    c->run_sign = 0;
    c->held_sign = 0;
    c->run_len = 0;
    c->low_parallax = 0;
    c->use_eq11 = 0;
    c->checked_plane = 0;
    c->hold = 0;
    c->step_t0 = SPVS_R(-1.0);
    c->cos_phit = SPVS_R(1.0);
    c->n_phit = 0;
    for (int k = 0; k < 4; k++) {
        c->t_step_end[k] = SPVS_R(-1.0);
    }
    for (int k = 0; k < 3; k++) {
        c->normal_est[k] = SPVS_R(0.0);
    }
    c->h32_sum = SPVS_R(0.0);
    c->ahead_votes = 0;
    c->n_start = 0;
    c->at_target = 0;
    c->odo_s = SPVS_R(0.0);
    c->last_v = SPVS_R(0.0);
    c->last_t = SPVS_R(-1.0);
    fit_clear(c);
    c->arriving = 0;
    c->reentries = 0;
    c->reentered = 0;
    c->backing = 0;
    c->arrival_next = 0;
    c->arrive_n = 0;
    for (int k = 0; k < 6; k++) {
        c->arrive_sum[k] = SPVS_R(0.0);
    }
    c->arrive_inv_n = SPVS_R(0.0);
    c->arrival_corner_px = SPVS_R(0.0);
    c->arrival_bound_px = SPVS_R(0.0);
    c->arrival_lateral_px = SPVS_R(0.0);
    c->arrival_depth_px = SPVS_R(0.0);
    c->arrival_h13_px = SPVS_R(0.0);
    c->arrival_parallax_px = SPVS_R(0.0);
    c->arrive_par_sum = SPVS_R(0.0);
    c->arrive_par_n = 0;
    c->slope_sig = SPVS_R(0.0);
    c->slope_ax = SPVS_R(0.0);
    c->reentry_d0 = SPVS_R(0.0);
}

static int fail(spvs_control_t *c, int status)
{
    c->step = SPVS_STEP_FAILED;
    c->status = status;
    return status;
}

static void next_step(spvs_control_t *c, spvs_step_t step, spvs_real t_s)
{
    c->t_step_end[c->step] = t_s;
    c->step = step;
    c->step_t0 = t_s;
    c->hold = 0;
    c->run_sign = 0;
    c->held_sign = 0;
    c->run_len = 0;
}

/* A step ends when its signal changes sign and the new sign holds for
 * hold_frames frames after the old one had held as long (with noise the
 * first lasting change happens where the true signal meets the noise floor;
 * a single wild frame cannot end a step), or when |signal| stays under tol
 * for hold_frames frames (noise-free exponential approach). */
static int step_done(spvs_control_t *c, const spvs_control_params_t *p,
                     spvs_real signal, spvs_real tol)
{
    int8_t s = sgn(signal);
    if (s != 0 && s == c->run_sign) {
        if (c->run_len < UINT16_MAX) {
            c->run_len++;
        }
    } else {
        c->run_sign = s;
        c->run_len = 1;
    }
    int crossed = 0;
    if (s != 0 && c->run_len >= p->hold_frames) {
        if (c->held_sign == 0) {
            c->held_sign = s;
        } else if (c->held_sign != s) {
            crossed = 1;
        }
    }
    if (SPVS_FABS(signal) < tol) {
        c->hold++;
    } else {
        c->hold = 0;
    }
    return crossed || c->hold >= p->hold_frames;
}

/* The plane check at the start (beyond the paper, which only reports the
 * failure): with the epipole direction e^ = (e1, e3)/|e| known from the
 * parallax, H gives (r/d) n without decomposing it:
 *   (r/d) n_x = -e1 P - e3 Q,  (r/d) n_z = e3 P - e1 Q,
 *   (r/d) n_y = -(e3 alpha_y h32 + e1 alpha_y h12 / alpha_x),
 * with P = h11 - h33 and Q = h13 / alpha_x + alpha_x h31 (from eq. 5). */
static void plane_accumulate(spvs_control_t *c, const spvs_control_params_t *p,
                             const spvs_control_input_t *in)
{
    const spvs_real *H = in->H;
    spvs_real e1 = in->e_x_px / p->alpha_x;
    spvs_real e3 = SPVS_R(1.0);
    spvs_real en = SPVS_SQRT(e1 * e1 + e3 * e3);
    spvs_real side = in->e_dir_z > SPVS_R(0.0) ? SPVS_R(1.0) : SPVS_R(-1.0);
    e1 = side * e1 / en;
    e3 = side * e3 / en;
    spvs_real P = H[SPVS_H11] - H[SPVS_H33];
    spvs_real Q = H[SPVS_H13] / p->alpha_x + p->alpha_x * H[SPVS_H31];
    c->normal_est[0] += -e1 * P - e3 * Q;
    c->normal_est[2] += e3 * P - e1 * Q;
    c->normal_est[1] += -(e3 * p->alpha_y * H[SPVS_H32] +
                          e1 * p->alpha_y * H[SPVS_H12] / p->alpha_x);
}

/* Decide on the sums of hold_frames start frames, so that one frame with few
 * matches cannot latch a failure. */
static int plane_check(spvs_control_t *c, const spvs_control_params_t *p)
{
    const spvs_real nx = c->normal_est[0], ny = c->normal_est[1], nz = c->normal_est[2];
    spvs_real norm = SPVS_SQRT(nx * nx + ny * ny + nz * nz);
    if (!(norm > SPVS_R(0.0))) {
        return fail(c, p->method == SPVS_METHOD_II ? SPVS_E_PLANE_NY : SPVS_E_PLANE_NZ);
    }
    if (p->method == SPVS_METHOD_II) {
        if (!(SPVS_FABS(ny) > p->min_signal_ratio * norm)) {
            return fail(c, SPVS_E_PLANE_NY);
        }
    } else if (!(SPVS_FABS(nz) > p->min_signal_ratio * norm)) {
        return fail(c, SPVS_E_PLANE_NZ);
    }
    return SPVS_OK;
}

/* Method I: the epipole says the robot is clearly not facing the target,
 * as at the false zero of eq. (19), which lies 20 deg or more off the target
 * line (docs/CONTROL.md).  In step 1 the margin is SPVS_CTL_FALSE_ZERO_LOCKS
 * times lock_ex_px: at grazing views the image noise moves the zero of f
 * and that of the epipole a few degrees apart, and a tighter test would
 * hold the two laws against each other for good.  In step 2 it stays
 * lock_ex_px, so that the epipole keeps the line. */
static int far_from_line(const spvs_control_t *c, const spvs_control_params_t *p,
                         const spvs_control_input_t *in)
{
    const spvs_real locks =
        c->step == SPVS_STEP_ROTATE ? (spvs_real)SPVS_CTL_FALSE_ZERO_LOCKS : SPVS_R(1.0);
    return in->e_valid && SPVS_FABS(in->e_x_px) > locks * p->lock_ex_px;
}

/* Rotation command of steps 1 and 2 for each method. */
static spvs_real rotation(spvs_control_t *c, const spvs_control_params_t *p,
                          const spvs_control_input_t *in)
{
    const spvs_real *H = in->H;
    switch (p->method) {
    case SPVS_METHOD_I: {
        /* Eq. (20): w = -k_w f, f = h11^2 + h13^2 / alpha_x^2 - 1 (eq. 19).
         * f also vanishes at a false heading (DESIGN.md, docs/CONTROL.md);
         * while the epipole says the robot is clearly not facing the target,
         * the sign of k_w is taken so that the robot turns towards it, with a
         * least rate, so it passes through a false zero. */
        spvs_real h13n = H[SPVS_H13] / p->alpha_x;
        spvs_real f = H[SPVS_H11] * H[SPVS_H11] + h13n * h13n - SPVS_R(1.0);
        int misaligned = far_from_line(c, p, in);
        if (misaligned && sgn(f) != 0) {
            c->sign_w = (int8_t)(sgn(f) * sgn(in->e_x_px));
        }
        spvs_real w = -(spvs_real)c->sign_w * p->k_w * f;
        if (misaligned && SPVS_FABS(w) < p->w_min_escape) {
            w = -(spvs_real)sgn(in->e_x_px) * p->w_min_escape;
        }
        return w;
    }
    case SPVS_METHOD_II:
        /* Eq. (21): w = -k_w h12. */
        return -(spvs_real)c->sign_w * p->k_w * H[SPVS_H12];
    case SPVS_METHOD_III:
    default:
        if (c->use_eq11) {
            /* Eq. (11): w = k_w11 (h11 - cos phi_t), sign of k_w11 that of
             * sin phi_t, as h11 - cos phi_t ~ -sin phi_t (phi - phi_t). */
            return (spvs_real)c->sign_sin_phit * p->k_w11 *
                   (H[SPVS_H11] - c->cos_phit);
        }
        /* Eq. (22): w = -k_w e_x; e_x = alpha_x tan(phi - phi_t). */
        return -p->k_w * in->e_x_px;
    }
}

/* The step-1 alignment signal of each method. */
static spvs_real align_signal(const spvs_control_params_t *p,
                              const spvs_control_input_t *in)
{
    const spvs_real *H = in->H;
    if (p->method == SPVS_METHOD_I) {
        spvs_real h13n = H[SPVS_H13] / p->alpha_x;
        return H[SPVS_H11] * H[SPVS_H11] + h13n * h13n - SPVS_R(1.0);
    }
    if (p->method == SPVS_METHOD_II) {
        return H[SPVS_H12];
    }
    return in->e_x_px;
}

/* The step-2 translation signal: h11 - h33 (eqs. 20, 22) or alpha_y h32
 * (eq. 21; alpha_y only scales the gain). */
static spvs_real translate_signal(const spvs_control_params_t *p,
                                  const spvs_control_input_t *in)
{
    if (p->method == SPVS_METHOD_II) {
        return p->alpha_y * in->H[SPVS_H32];
    }
    return in->H[SPVS_H11] - in->H[SPVS_H33];
}

/* Method III learns phi_t from eq. (8): on the line h11 = cos phi_t and
 * h13 = alpha_x sin phi_t, whatever the distance. */
static void learn_phit(spvs_control_t *c, const spvs_control_params_t *p,
                       const spvs_control_input_t *in)
{
    if (p->method != SPVS_METHOD_III || c->use_eq11 || c->reentered || !in->e_valid ||
        SPVS_FABS(in->e_x_px) > p->lock_ex_px) {
        return;
    }
    /* A running mean at first, then an exponential one of the same length:
     * the learnt value can still follow odometry drift along the line. */
    if (c->n_phit < (uint32_t)SPVS_CTL_PHIT_FRAMES) {
        c->n_phit++;
    }
    spvs_real a = SPVS_R(1.0) / (spvs_real)c->n_phit;
    c->cos_phit += a * (in->H[SPVS_H11] - c->cos_phit);
    int8_t s = sgn(in->H[SPVS_H13]);
    if (s != 0) {
        c->sign_sin_phit = s;
    }
}

/* Step 2 under noise (beyond the paper).  On the straight line the signal is
 * linear in the distance to the target (eq. 8: row 3 of H moves by
 * (s / d)(n_x / alpha_x, n_y / alpha_y, n_z)), so a least-squares line of D
 * against the distance driven averages the per-frame noise of H away; its
 * value at the current distance replaces the raw D in v = -k_v D and in the
 * step-end test.  Until the fit has fit_min_frames frames over at least
 * fit_min_span_m metres the raw signal is used, and so it is while the
 * distances driven are too close together to fix a slope.
 *
 * The same line's slope of ax = h33 - h11 goes to slope_ax for a later
 * re-entry (reentry_signal): along the optical axis it moves by n_z / d per
 * metre like h33, but without h33's cos phi, which h11 carries too (eq. 5),
 * so the heading corrections of the line do not enter it.  From the grazing
 * start the line is driven about 72 deg off the target heading, where one
 * degree of heading moves h33 as much as a metre of the line. */
static spvs_real fitted_signal(spvs_control_t *c, const spvs_control_params_t *p,
                               spvs_real D, spvs_real ax)
{
    spvs_real s = c->odo_s;
    c->fit_ax += ax;
    c->fit_sax += s * ax;
    c->fit_n += SPVS_R(1.0);
    c->fit_s += s;
    c->fit_ss += s * s;
    c->fit_d += D;
    c->fit_sd += s * D;
    if (c->fit_n < (spvs_real)p->fit_min_frames || s < p->fit_min_span_m) {
        return D;
    }
    /* den = n^2 var(s). */
    const spvs_real min_spread_m = (spvs_real)SPVS_CTL_FIT_MIN_SPREAD_UM * SPVS_R(1.0e-6);
    spvs_real den = c->fit_n * c->fit_ss - c->fit_s * c->fit_s;
    if (!(den > min_spread_m * min_spread_m * c->fit_n * c->fit_n)) {
        return D;
    }
    spvs_real b = (c->fit_n * c->fit_sd - c->fit_s * c->fit_d) / den;
    spvs_real a = (c->fit_d - b * c->fit_s) / c->fit_n;
    c->slope_sig = b;
    c->slope_ax = (c->fit_n * c->fit_sax - c->fit_s * c->fit_ax) / den;
    return a + b * s;
}

/* Odometry from the commands: the last command held since the last frame (a
 * stop wherever spvs_control_step returns early, so last_v is cleared here
 * and set again only when a command goes out). */
static void odometry(spvs_control_t *c, spvs_real t_s)
{
    if (c->last_t >= SPVS_R(0.0) && t_s > c->last_t) {
        c->odo_s += SPVS_FABS(c->last_v) * (t_s - c->last_t);
    }
    c->last_v = SPVS_R(0.0);
    c->last_t = t_s;
}

/* No parallax at the start.  If H shows no translation either (both kinds of
 * step-2 signal and det H - 1 under their tolerances, for hold_frames
 * frames) the robot is at the target up to a rotation, eq. (9): only step 3
 * is left.  Otherwise the signs cannot be chosen: stop. */
static int start_without_parallax(spvs_control_t *c, const spvs_control_params_t *p,
                                  const spvs_control_input_t *in)
{
    const spvs_real *H = in->H;
    spvs_real D = H[SPVS_H11] - H[SPVS_H33];
    spvs_real Dy = p->alpha_y * H[SPVS_H32];
    spvs_real det = H[SPVS_H11] * H[SPVS_H33] - H[SPVS_H13] * H[SPVS_H31];
    int still = SPVS_FABS(D) < p->tol_translate && SPVS_FABS(Dy) < p->tol_translate &&
                SPVS_FABS(det - SPVS_R(1.0)) < p->tol_det;
    c->at_target = still ? (uint16_t)(c->at_target + 1u) : 0u;
    if (c->at_target < p->hold_frames) {
        return still ? SPVS_OK : SPVS_E_NO_PARALLAX;
    }
    next_step(c, SPVS_STEP_TRANSLATE, in->t_s);
    next_step(c, SPVS_STEP_ALIGN, in->t_s);
    c->checked_plane = 1;
    return SPVS_OK;
}

/* The signs of the rotation gain, from the start frames' sums (paper, end of
 * section 3.3; docs/CONTROL.md derives each).  sign(k_v) is chosen when step 2
 * starts. */
static void choose_rotation_sign(spvs_control_t *c, const spvs_control_params_t *p,
                                 const spvs_control_input_t *in)
{
    switch (p->method) {
    case SPVS_METHOD_I: {
        /* Turn towards the target: sign(f) sign(e_x). */
        spvs_real f = align_signal(p, in);
        c->sign_w = (int8_t)(sgn(f) * sgn(in->e_x_px));
        if (c->sign_w == 0) {
            c->sign_w = 1;
        }
        break;
    }
    case SPVS_METHOD_II:
        /* sign(k_w) = -sign(n_y) sign(e_z) = sign(h32). */
        c->sign_w = sgn(c->h32_sum);
        break;
    case SPVS_METHOD_III:
    default:
        /* e_x = alpha_x tan(phi - phi_t): always positive. */
        c->sign_w = 1;
        break;
    }
}

/* The start takes hold_frames frames with an epipole, standing still: their
 * sums decide the plane check and the signs, so that one frame with few
 * matches cannot latch a failure or a wrong sign. */
static int start_with_parallax(spvs_control_t *c, const spvs_control_params_t *p,
                               const spvs_control_input_t *in)
{
    c->at_target = 0;
    plane_accumulate(c, p, in);
    c->h32_sum += in->H[SPVS_H32];
    c->ahead_votes = (int16_t)(c->ahead_votes + sgn(in->e_dir_z));
    c->n_start++;
    if (c->n_start < p->hold_frames) {
        return SPVS_OK;
    }
    c->ahead = c->ahead_votes >= 0 ? 1 : -1;
    int rc = plane_check(c, p);
    if (rc != SPVS_OK) {
        return rc;
    }
    choose_rotation_sign(c, p, in);
    c->checked_plane = 1;
    return SPVS_OK;
}

/* Method III needs the epipole until it has switched to eq. (11), which it
 * does once the parallax has stayed under switch_parallax_px for hold_frames
 * frames of step 2 (one frame with few off-plane points in view must not
 * latch the switch). */
static int eq11_switch(spvs_control_t *c, const spvs_control_params_t *p,
                       const spvs_control_input_t *in)
{
    if (p->method != SPVS_METHOD_III || c->step == SPVS_STEP_ALIGN) {
        return SPVS_OK;
    }
    /* A re-entered step 2 holds the heading: it needs no epipole. */
    if (c->reentered) {
        return SPVS_OK;
    }
    if (c->use_eq11) {
        return SPVS_OK;
    }
    int low = c->step == SPVS_STEP_TRANSLATE && in->parallax_px >= SPVS_R(0.0) &&
              in->parallax_px < p->switch_parallax_px;
    c->low_parallax = low ? (uint16_t)(c->low_parallax + 1u) : 0u;
    if (c->low_parallax >= p->hold_frames) {
        c->use_eq11 = 1;
        if (c->n_phit == 0u) {
            c->cos_phit = in->H[SPVS_H11];
            c->sign_sin_phit = sgn(in->H[SPVS_H13]);
        }
    } else if (!in->e_valid) {
        return SPVS_E_NO_PARALLAX;
    }
    return SPVS_OK;
}

/* Step 1: turn to face the target, v = 0. */
static void step_rotate(spvs_control_t *c, const spvs_control_params_t *p,
                        const spvs_control_input_t *in, spvs_real *vc, spvs_real *wc)
{
    learn_phit(c, p, in);
    *vc = SPVS_R(0.0);
    *wc = rotation(c, p, in);
    spvs_real a = align_signal(p, in);
    int done = step_done(c, p, a, p->tol_align);
    /* Method I: a zero of eq. (19) away from the target line is false. */
    if (p->method == SPVS_METHOD_I && far_from_line(c, p, in)) {
        done = 0;
        /* The sign change at a false zero is spent here: only a change
         * after it counts. */
        c->held_sign = sgn(a);
        c->hold = 0;
    }
    if (done) {
        next_step(c, SPVS_STEP_TRANSLATE, in->t_s);
        c->trans_sign0 = 0;
        c->odo_s = SPVS_R(0.0);
        fit_clear(c);
    }
}

/* The first frame of step 2: the sign of k_v, with the side read again facing
 * the line, where e_z is largest (at the start it can be near zero when the
 * target is side-on). */
static void translate_begin(spvs_control_t *c, const spvs_control_params_t *p,
                            const spvs_control_input_t *in, spvs_real D)
{
    c->trans_sign0 = sgn(D);
    c->trans_d0 = SPVS_FABS(D);
    if (in->e_valid && sgn(in->e_dir_z) != 0) {
        c->ahead = sgn(in->e_dir_z);
    }
    /* sign(k_v) below comes out as -sign(n_z) (Methods I, III) or sign(n_y)
     * (Method II), whatever the line: a re-entered step 2 keeps it. */
    if (c->reentered) {
        return;
    }
    if (p->method == SPVS_METHOD_II) {
        /* sign(k_v) = sign(n_y) = -sign(h32) sign(e_z), with the sign of h32
         * at the start (sign_w). */
        c->sign_v = (int8_t)(-c->sign_w * c->ahead);
    } else {
        /* Eqs. (20), (22): v = -k_v (h11 - h33) = k_v z n_z / (d cos phi_t)
         * on the line, so sign(k_v) = -sign(D) sign(e_z) makes v drive
         * towards the target. */
        c->sign_v = (int8_t)(-c->trans_sign0 * c->ahead);
    }
}

/* Backing off for a new start (reenter, below): straight back at v_max,
 * then the controller starts over as if reset, keeping only the count of
 * re-entries, the last check's figures and the odometry's clock. */
static void back_off(spvs_control_t *c, const spvs_control_params_t *p, spvs_real *vc)
{
    const spvs_real dist_m = (spvs_real)SPVS_CTL_ARRIVAL_BACKOFF_DM * SPVS_R(0.1);
    if (c->odo_s < dist_m) {
        *vc = -p->v_max;
        return;
    }
    const spvs_control_t keep = *c;
    spvs_control_reset(c);
    c->last_t = keep.last_t;
    c->reentries = keep.reentries;
    c->arrival_next = keep.arrival_next;
    c->arrival_corner_px = keep.arrival_corner_px;
    c->arrival_bound_px = keep.arrival_bound_px;
    c->arrival_lateral_px = keep.arrival_lateral_px;
    c->arrival_depth_px = keep.arrival_depth_px;
    c->arrival_h13_px = keep.arrival_h13_px;
    c->arrival_parallax_px = keep.arrival_parallax_px;
    c->arrive_n = keep.arrive_n;
}

/* Step 2: drive straight to the target on the fitted signal. */
/* A step 2 re-entered by the arrival check, where the first line's fit gave
 * the slope of the signal per metre driven: its size, n_z / d (Methods I,
 * III) or n_y / d (Method II), is the same on every line, so the averaged
 * row-3 residual of the check says how far to drive, and the robot drives
 * that far by odometry on the heading it has (the per-frame signal there is
 * mostly noise). */
static void step_translate_again(spvs_control_t *c, const spvs_control_params_t *p,
                                 const spvs_control_input_t *in, spvs_real *vc,
                                 spvs_real *wc)
{
    const spvs_real d0 = c->reentry_d0;
    const spvs_real D = d0 - (spvs_real)sgn(d0) * SPVS_FABS(c->slope_sig) * c->odo_s;
    *vc = -(spvs_real)c->sign_v * p->k_v * D;
    *wc = SPVS_R(0.0);
    if (sgn(D) != sgn(d0) || SPVS_FABS(D) < p->tol_translate) {
        next_step(c, SPVS_STEP_ALIGN, in->t_s);
        *vc = SPVS_R(0.0);
    }
}

static void step_translate(spvs_control_t *c, const spvs_control_params_t *p,
                           const spvs_control_input_t *in, spvs_real *vc, spvs_real *wc)
{
    if (c->backing) {
        back_off(c, p, vc);
        return;
    }
    if (c->reentered && c->slope_sig != SPVS_R(0.0) && c->reentry_d0 != SPVS_R(0.0)) {
        step_translate_again(c, p, in, vc, wc);
        return;
    }
    learn_phit(c, p, in);
    spvs_real D = translate_signal(p, in);
    if (c->trans_sign0 == 0) {
        translate_begin(c, p, in, D);
    }
    spvs_real Df = fitted_signal(c, p, D, in->H[SPVS_H33] - in->H[SPVS_H11]);
    /* det H = 1 + n^T c / d whatever the heading and the calibration
     * (eq. 2): a step-2 signal that crossed zero while det H says the robot
     * is still away from the target crossed through a turn. */
    spvs_real det = in->H[SPVS_H11] * in->H[SPVS_H33] - in->H[SPVS_H13] * in->H[SPVS_H31];
    int det_ok = SPVS_FABS(det - SPVS_R(1.0)) < p->tol_det;
    *vc = -(spvs_real)c->sign_v * p->k_v * Df;
    *wc = rotation(c, p, in);
    /* Near the target the rotation signals of eqs. (20)-(22) vanish with the
     * distance while their noise does not: in the last part of the line the
     * heading is held (beyond the paper; Method III's eq. (11) does not
     * vanish and stays on). */
    if (SPVS_FABS(Df) < p->hold_heading_ratio * c->trans_d0 &&
        !(p->method == SPVS_METHOD_III && c->use_eq11)) {
        *wc = SPVS_R(0.0);
    }
    /* A re-entered step 2 is short and near the target, where every rotation
     * signal is noise: it drives on the heading it starts with. */
    if (c->reentered) {
        *wc = SPVS_R(0.0);
    }
    if (step_done(c, p, Df, p->tol_translate) && det_ok) {
        next_step(c, SPVS_STEP_ALIGN, in->t_s);
        *vc = SPVS_R(0.0);
        *wc = SPVS_R(0.0);
    }
}

/* ---- the arrival check (beyond the paper) ------------------------------
 * At the target H = I whatever the calibration (eq. 2 with R = I, c = 0).
 * Near it, to first order (eq. 5), an offset along the optical axis moves
 * only row 3 of H, a sideways offset row 1 (h13 with it), a turn h13 and
 * h31.  docs/CONTROL.md derives the bound. */

/* Mean over the four image corners of the transfer |H p - p| (pixels), of H
 * = I + the residual r (h11 - 1, h12, h13, h31, h32, h33 - 1), and of its
 * row-1 (without h13) and row-3 parts. */
static void corner_figures(const spvs_control_params_t *p, const spvs_real r[6],
                           spvs_real *all, spvs_real *lateral, spvs_real *depth)
{
    *all = *lateral = *depth = SPVS_R(0.0);
    for (int k = 0; k < 4; k++) {
        const spvs_real u = (k & 1) ? p->arrival_corner_x_px : -p->arrival_corner_x_px;
        const spvs_real v = (k & 2) ? p->arrival_corner_y_px : -p->arrival_corner_y_px;
        const spvs_real w = r[3] * u + r[4] * v + SPVS_R(1.0) + r[5];
        const spvs_real x1 = (SPVS_R(1.0) + r[0]) * u + r[1] * v;
        if (!(w > SPVS_R(0.0))) {
            /* A corner behind the camera: as far from the identity as can be. */
            *all = *depth = SPVS_REAL_MAX;
            return;
        }
        const spvs_real dx = (x1 + r[2]) / w - u;
        const spvs_real dy = v / w - v;
        const spvs_real gw = SPVS_R(1.0) / w - SPVS_R(1.0);
        *all += SPVS_R(0.25) * SPVS_SQRT(dx * dx + dy * dy);
        *lateral += SPVS_R(0.25) * SPVS_FABS(x1 - u);
        *depth += SPVS_R(0.25) * SPVS_FABS(gw) * SPVS_SQRT(u * u + v * v);
    }
}

static void arrival_begin(spvs_control_t *c)
{
    c->arriving = 1;
    c->arrive_n = 0;
    for (int k = 0; k < 6; k++) {
        c->arrive_sum[k] = SPVS_R(0.0);
    }
    c->arrive_inv_n = SPVS_R(0.0);
    c->arrive_par_sum = SPVS_R(0.0);
    c->arrive_par_n = 0;
}

/* A failed check sends the robot back to a step from where it stands; the
 * signs of the gains stay as chosen at the start.  A sideways offset is the
 * exception (step 1 in the check's verdict): beside the target the robot
 * would have to turn about 90 deg to face it, with the scene out of view,
 * and every step-1 signal is noise there.  It backs off instead, straight
 * back SPVS_CTL_ARRIVAL_BACKOFF_DM decimetres by odometry, and homes again
 * from there (back_off, above): from a few metres away the same offset is a
 * bearing of several degrees, which steps 1 and 2 resolve. */
static int reenter(spvs_control_t *c, const spvs_control_input_t *in, spvs_step_t step)
{
    if (c->reentries >= (uint8_t)SPVS_CTL_ARRIVAL_MAX_REENTRIES) {
        return fail(c, SPVS_E_NOT_AT_TARGET);
    }
    c->reentries++;
    c->reentered = 1;
    c->arriving = 0;
    c->backing = (uint8_t)(step == SPVS_STEP_ROTATE);
    next_step(c, c->backing ? SPVS_STEP_TRANSLATE : step, in->t_s);
    c->trans_sign0 = 0;
    c->odo_s = SPVS_R(0.0);
    fit_clear(c);
    return SPVS_OK;
}

/* The row-3 part of the method's step-2 signal in the averaged residual r:
 * along the optical axis h11 - h33 moves by -h33 (Methods I, III).  Method
 * II's alpha_y h32 scatters about SPVS_CTL_H32_NOISE_RATIO times as much as
 * h33 from frame to frame, so where the first line's fits say h33 - h11
 * moved at least a third as much it is read from h33, scaled by the ratio
 * of the two slopes (both lines of the same motion; facing the target
 * after step 3, h11 is 1 but for a sideways offset). */
static spvs_real reentry_signal(const spvs_control_t *c, const spvs_control_params_t *p,
                                const spvs_real r[6])
{
    if (p->method != SPVS_METHOD_II) {
        return -r[5];
    }
    if ((spvs_real)SPVS_CTL_H32_NOISE_RATIO * SPVS_FABS(c->slope_ax) > SPVS_FABS(c->slope_sig)) {
        return r[5] * (c->slope_sig / c->slope_ax);
    }
    return p->alpha_y * r[4];
}

/* arrival_k standard deviations of the mean corner transfer that image
 * noise alone gives the average of the frames so far at the target: one
 * frame's H from n inliers moves a corner by 2 sigma^2 L / n in variance
 * (noise in both images; L the corners' leverage), N frames average it. */
static spvs_real arrival_bound(const spvs_control_t *c, const spvs_control_params_t *p)
{
    const spvs_real nf = (spvs_real)c->arrive_n;
    const spvs_real var1 = SPVS_R(2.0) * p->arrival_sigma_px * p->arrival_sigma_px *
                           p->arrival_leverage * (c->arrive_inv_n / nf);
    return p->arrival_k * SPVS_SQRT(var1 / nf);
}

/* The check, on the average of arrival_frames frames standing still: the
 * mean corner transfer of the averaged H against arrival_k standard
 * deviations of what image noise alone gives it at the target. */
static int arrival_decide(spvs_control_t *c, const spvs_control_params_t *p,
                          const spvs_control_input_t *in)
{
    const spvs_real nf = (spvs_real)c->arrive_n;
    spvs_real r[6];
    for (int k = 0; k < 6; k++) {
        r[k] = c->arrive_sum[k] / nf;
    }
    c->arrival_bound_px = arrival_bound(c, p);
    corner_figures(p, r, &c->arrival_corner_px, &c->arrival_lateral_px, &c->arrival_depth_px);
    c->arrival_h13_px = r[2];
    c->arriving = 0;
    /* The remembered off-plane points' parallax: 0 at the target up to the
     * noise of both images, and several pixels beside it, where H barely
     * moves (docs/CONTROL.md). */
    c->arrival_parallax_px = c->arrive_par_n > 0u
                                 ? c->arrive_par_sum / (spvs_real)c->arrive_par_n
                                 : SPVS_R(-1.0);
    const int par_ok = c->arrival_parallax_px <=
                       (spvs_real)SPVS_CTL_ARRIVAL_PARALLAX_X100 * SPVS_R(0.01) *
                           SPVS_R(1.665) * p->arrival_sigma_px;
    if (c->arrival_corner_px <= c->arrival_bound_px && par_ok) {
        c->arrival_next = 0;
        next_step(c, SPVS_STEP_DONE, in->t_s);
        return SPVS_OK;
    }
    const spvs_real lat = c->arrival_lateral_px, dep = c->arrival_depth_px;
    const spvs_real rot = SPVS_FABS(r[2]);
    spvs_step_t step = SPVS_STEP_ROTATE; /* sideways: back off (reenter) */
    if (par_ok && dep >= lat && dep >= rot) {
        step = SPVS_STEP_TRANSLATE;
    } else if (par_ok && rot >= lat) {
        step = SPVS_STEP_ALIGN;
    }
    c->arrival_next = (uint8_t)step;
    c->reentry_d0 = reentry_signal(c, p, r);
    return reenter(c, in, step);
}

/* Standing still after step 3: sum this frame's H - I and 1 / n_inliers. */
static int arrival_frame(spvs_control_t *c, const spvs_control_params_t *p,
                         const spvs_control_input_t *in)
{
    const spvs_real *H = in->H;
    c->arrive_sum[0] += H[SPVS_H11] - SPVS_R(1.0);
    c->arrive_sum[1] += H[SPVS_H12];
    c->arrive_sum[2] += H[SPVS_H13];
    c->arrive_sum[3] += H[SPVS_H31];
    c->arrive_sum[4] += H[SPVS_H32];
    c->arrive_sum[5] += H[SPVS_H33] - SPVS_R(1.0);
    c->arrive_inv_n += SPVS_R(1.0) / (spvs_real)(in->n_inliers > 4u ? in->n_inliers : 4u);
    if (in->parallax_px >= SPVS_R(0.0)) {
        c->arrive_par_sum += in->parallax_px;
        c->arrive_par_n++;
    }
    c->arrive_n++;
    if (c->arrive_n < p->arrival_frames) {
        return SPVS_OK;
    }
    /* With few inliers the bound is wide: hold on, up to arrival_max_frames,
     * until it resolves arrival_resolution_px. */
    if (c->arrive_n < p->arrival_max_frames &&
        arrival_bound(c, p) > p->arrival_resolution_px) {
        return SPVS_OK;
    }
    return arrival_decide(c, p, in);
}

/* Step 3: turn to the target heading, eq. (17)/(18) as chosen by the paper:
 * w = -k_w3 h13; then stand still for the arrival check. */
static int step_align(spvs_control_t *c, const spvs_control_params_t *p,
                      const spvs_control_input_t *in, spvs_real *vc, spvs_real *wc)
{
    *vc = SPVS_R(0.0);
    *wc = SPVS_R(0.0);
    if (c->arriving) {
        return arrival_frame(c, p, in);
    }
    *wc = -p->k_w3 * in->H[SPVS_H13];
    if (step_done(c, p, in->H[SPVS_H13], p->tol_h13_px)) {
        arrival_begin(c);
        *wc = SPVS_R(0.0);
    }
    return SPVS_OK;
}

int spvs_control_step(spvs_control_t *c, const spvs_control_params_t *p,
                      const spvs_control_input_t *in, spvs_real *v, spvs_real *w)
{
    if (c == 0 || p == 0 || in == 0 || v == 0 || w == 0) {
        return SPVS_E_ARG;
    }
    *v = SPVS_R(0.0);
    *w = SPVS_R(0.0);
    odometry(c, in->t_s);
    if (c->step == SPVS_STEP_DONE) {
        return SPVS_OK;
    }
    if (c->step == SPVS_STEP_FAILED) {
        return c->status;
    }
    if (c->step_t0 < SPVS_R(0.0)) {
        c->step_t0 = in->t_s;
    }
    if (in->t_s - c->step_t0 > p->step_timeout_s) {
        return fail(c, SPVS_E_STEP_TIMEOUT);
    }
    /* The start: the signs of the gains come from the parallax (paper, end of
     * section 3.3), and the plane must give this method a signal. */
    if (!c->checked_plane) {
        int rc = (!in->e_valid || sgn(in->e_dir_z) == 0) ? start_without_parallax(c, p, in)
                                                         : start_with_parallax(c, p, in);
        if (rc != SPVS_OK || !c->checked_plane) {
            return rc;
        }
    }
    /* A step 2 after a re-entry, from where the check was made or from
     * where the robot backed off to, is at most about as long as that
     * back-off: one that drives on is going the wrong way. */
    if (c->step == SPVS_STEP_TRANSLATE && c->reentries > 0u &&
        c->odo_s > SPVS_R(0.2) * (spvs_real)SPVS_CTL_ARRIVAL_BACKOFF_DM) {
        return fail(c, SPVS_E_NOT_AT_TARGET);
    }
    int rc = eq11_switch(c, p, in);
    if (rc != SPVS_OK) {
        return rc;
    }
    spvs_real vc = SPVS_R(0.0);
    spvs_real wc = SPVS_R(0.0);
    switch (c->step) {
    case SPVS_STEP_ROTATE:
        step_rotate(c, p, in, &vc, &wc);
        break;
    case SPVS_STEP_TRANSLATE:
        step_translate(c, p, in, &vc, &wc);
        break;
    case SPVS_STEP_ALIGN:
        rc = step_align(c, p, in, &vc, &wc);
        break;
    default:
        break;
    }
    if (rc != SPVS_OK) {
        return rc;
    }
    *v = clamp(vc, p->v_max);
    *w = clamp(wc, p->w_max);
    c->last_v = *v;
    return SPVS_OK;
}
