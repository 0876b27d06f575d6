/*
 * control.c - Shortest Path Control, Methods I, II and III (paper, section 3).
 *
 * The derivations behind every sign and step-ending rule are in
 * docs/CONTROL.md; the comments here name the result and the equation.
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "core_util.h"
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

static void fit_clear(spvs_control_t *c)
{
    c->fit_n = c->fit_s = c->fit_ss = c->fit_d = c->fit_sd = SPVS_R(0.0);
    c->fit_ax = c->fit_sax = SPVS_R(0.0);
}

/* ---- the float core's side of control_steps.inc ---------------------------
 * The signals, commands and sums in spvs_real; every decision on them is in
 * control_steps.inc, included at the end of this file. */

typedef spvs_control_t ctl_t;
typedef spvs_control_params_t ctl_params_t;
typedef spvs_control_input_t ctl_input_t;
typedef spvs_real ctl_sig_t;
typedef spvs_real ctl_wide_t;
typedef spvs_real ctl_cmd_t;
typedef spvs_real ctl_time_t;
typedef spvs_real ctl_px_t;
typedef spvs_real ctl_val_t;

static int real_in(const void *x, const spvs_real *lo, int lo_incl, const spvs_real *hi,
                   int hi_incl)
{
    return spvs_real_in(x, lo, lo_incl, hi, hi_incl);
}

static spvs_real time_none(void)
{
    return SPVS_R(-1.0);
}

static spvs_real cos_one(void)
{
    return SPVS_R(1.0);
}

static spvs_real val_zero(void)
{
    return SPVS_R(0.0);
}

static int under(spvs_real x, spvs_real tol)
{
    return SPVS_FABS(x) < tol;
}

static int ex_beyond(const spvs_control_params_t *p, const spvs_control_input_t *in, int locks)
{
    return SPVS_FABS(in->e_x_px) > (spvs_real)locks * p->lock_ex_px;
}

static int val_le(spvs_real a, spvs_real b)
{
    return a <= b;
}

static int val_lt(spvs_real a, spvs_real b)
{
    return a < b;
}

static spvs_real val_abs(spvs_real a)
{
    return SPVS_FABS(a);
}

static spvs_real val_of_x10(int n)
{
    return (spvs_real)n * SPVS_R(0.1);
}

static spvs_real val_max(spvs_real a, spvs_real b)
{
    return a > b ? a : b;
}

static spvs_real val_hypot(spvs_real a, spvs_real b)
{
    return SPVS_SQRT(a * a + b * b);
}

static spvs_real val_times(spvs_real a, int k)
{
    return (spvs_real)k * a;
}

static int val_is_zero(spvs_real a)
{
    return a == SPVS_R(0.0);
}

/* dm decimetres in metres (correctly rounded). */
static spvs_real odo_from_dm(int dm)
{
    return (spvs_real)dm / SPVS_R(10.0);
}

static spvs_real in_time(const spvs_control_input_t *in)
{
    return in->t_s;
}

static int8_t in_side(const spvs_control_input_t *in)
{
    return sgn(in->e_dir_z);
}

static spvs_real in_ex(const spvs_control_input_t *in)
{
    return in->e_x_px;
}

static spvs_real in_parallax(const spvs_control_input_t *in)
{
    return in->parallax_px;
}

static spvs_real odo(const spvs_control_t *c)
{
    return c->odo_s;
}

static spvs_real fit_distance(const spvs_control_t *c)
{
    return c->odo_s;
}

static spvs_real tol_h13(const spvs_control_params_t *p)
{
    return p->tol_h13_px;
}

static spvs_real tol_ex(const spvs_control_params_t *p)
{
    return p->tol_h13_px;
}

static spvs_real switch_parallax(const spvs_control_params_t *p)
{
    return p->switch_parallax_px;
}

static spvs_real step_timeout(const spvs_control_params_t *p)
{
    return p->step_timeout_s;
}

static spvs_real fit_min_span(const spvs_control_params_t *p)
{
    return p->fit_min_span_m;
}

static spvs_real arrival_threshold(const spvs_control_params_t *p)
{
    return p->arrival_k;
}

/* SPVS_CTL_ARRIVAL_PARALLAX_X100 / 100 of the median parallax that image
 * noise alone gives, SPVS_CTL_NOISE_PARALLAX_X1000 / 1000 arrival_sigma_px. */
static spvs_real parallax_gate(const spvs_control_params_t *p)
{
    const spvs_real median = (spvs_real)SPVS_CTL_NOISE_PARALLAX_X1000 / SPVS_R(1000.0);
    return (spvs_real)SPVS_CTL_ARRIVAL_PARALLAX_X100 * SPVS_R(0.01) * median *
           p->arrival_sigma_px;
}

static spvs_real parallax_none(void)
{
    return SPVS_R(-1.0);
}

/* Eq. (19): f = h11^2 + h13^2 / alpha_x^2 - 1. */
static spvs_real f_signal(spvs_control_t *c, const spvs_control_params_t *p,
                          const spvs_control_input_t *in)
{
    (void)c;
    const spvs_real *H = in->H;
    spvs_real h13n = H[SPVS_H13] / p->alpha_x;
    return H[SPVS_H11] * H[SPVS_H11] + h13n * h13n - SPVS_R(1.0);
}

/* The step-2 translation signal: h11 - h33 (eqs. 20, 22) or alpha_y h32
 * (eq. 21; alpha_y only scales the gain). */
static spvs_real translate_signal(spvs_control_t *c, const spvs_control_params_t *p,
                                  const spvs_control_input_t *in)
{
    (void)c;
    if (p->method == SPVS_METHOD_II) {
        return p->alpha_y * in->H[SPVS_H32];
    }
    return in->H[SPVS_H11] - in->H[SPVS_H33];
}

static spvs_real axial_signal(spvs_control_t *c, const spvs_control_input_t *in)
{
    (void)c;
    return in->H[SPVS_H33] - in->H[SPVS_H11];
}

/* Both kinds of step-2 signal, for the start without parallax. */
static void start_signals(spvs_control_t *c, const spvs_control_params_t *p,
                          const spvs_control_input_t *in, spvs_real *D, spvs_real *Dy)
{
    (void)c;
    *D = in->H[SPVS_H11] - in->H[SPVS_H33];
    *Dy = p->alpha_y * in->H[SPVS_H32];
}

/* det H - 1 (det H = h11 h33 - h13 h31 for the planar-motion form). */
static spvs_real det_minus_1(spvs_control_t *c, const spvs_control_input_t *in)
{
    (void)c;
    const spvs_real *H = in->H;
    spvs_real det = H[SPVS_H11] * H[SPVS_H33] - H[SPVS_H13] * H[SPVS_H31];
    return det - SPVS_R(1.0);
}

static spvs_real start_size(spvs_control_t *c, spvs_real D)
{
    (void)c;
    return SPVS_FABS(D);
}

static spvs_real hold_below(spvs_control_t *c, const spvs_control_params_t *p)
{
    return p->hold_heading_ratio * c->trans_d0;
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

/* |n_k| over min_signal_ratio |n| of the summed normal (false for n = 0). */
static int normal_has_signal(const spvs_control_t *c, const spvs_control_params_t *p, int k)
{
    const spvs_real nx = c->normal_est[0], ny = c->normal_est[1], nz = c->normal_est[2];
    spvs_real norm = SPVS_SQRT(nx * nx + ny * ny + nz * nz);
    return norm > SPVS_R(0.0) && SPVS_FABS(c->normal_est[k]) > p->min_signal_ratio * norm;
}

static void phit_mean(spvs_control_t *c, const spvs_control_input_t *in)
{
    spvs_real a = SPVS_R(1.0) / (spvs_real)c->n_phit;
    c->cos_phit += a * (in->H[SPVS_H11] - c->cos_phit);
}

static void phit_first(spvs_control_t *c, const spvs_control_input_t *in)
{
    c->cos_phit = in->H[SPVS_H11];
}

/* Eq. (20): w = -k_w f. */
static spvs_real w_eq20(const spvs_control_t *c, const spvs_control_params_t *p, spvs_real f)
{
    return -(spvs_real)c->sign_w * p->k_w * f;
}

static spvs_real w_escape(const spvs_control_params_t *p, int8_t s)
{
    return -(spvs_real)s * p->w_min_escape;
}

/* Eq. (21): w = -k_w h12. */
static spvs_real w_eq21(const spvs_control_t *c, const spvs_control_params_t *p,
                        const spvs_control_input_t *in)
{
    return -(spvs_real)c->sign_w * p->k_w * in->H[SPVS_H12];
}

/* Eq. (11): w = k_w11 (h11 - cos phi_t), sign of k_w11 that of sin phi_t,
 * as h11 - cos phi_t ~ -sin phi_t (phi - phi_t). */
static spvs_real w_eq11(const spvs_control_t *c, const spvs_control_params_t *p,
                        const spvs_control_input_t *in)
{
    return (spvs_real)c->sign_sin_phit * p->k_w11 * (in->H[SPVS_H11] - c->cos_phit);
}

/* Eq. (22): w = -k_w e_x; e_x = alpha_x tan(phi - phi_t). */
static spvs_real w_eq22(const spvs_control_t *c, const spvs_control_params_t *p,
                        const spvs_control_input_t *in)
{
    (void)c;
    return -p->k_w * in->e_x_px;
}

/* Eq. (22) with step 3's gain: w = -k_w3 e_x (e_x and h13 are both
 * alpha_x times the heading's error near the line). */
static spvs_real w_ex(const spvs_control_t *c, const spvs_control_params_t *p,
                      const spvs_control_input_t *in)
{
    (void)c;
    return -p->k_w3 * in->e_x_px;
}

/* Eq. (17): w = -k_w3 h13. */
static spvs_real w_eq17(const spvs_control_t *c, const spvs_control_params_t *p,
                        const spvs_control_input_t *in)
{
    (void)c;
    return -p->k_w3 * in->H[SPVS_H13];
}

/* Eqs. (20), (22): v = -k_v D (eq. 21 with D = alpha_y h32). */
static spvs_real v_eq20(const spvs_control_t *c, const spvs_control_params_t *p, spvs_real D)
{
    return -(spvs_real)c->sign_v * p->k_v * D;
}

static void odo_add(spvs_control_t *c, spvs_real t_s)
{
    c->odo_s += SPVS_FABS(c->last_v) * (t_s - c->last_t);
}

static void line_clear(spvs_control_t *c)
{
    c->odo_s = SPVS_R(0.0);
    fit_clear(c);
}

/* Step 2's least-squares sums of D and ax = h33 - h11 against s. */
static void fit_add(spvs_control_t *c, spvs_real s, spvs_real D, spvs_real ax)
{
    c->fit_ax += ax;
    c->fit_sax += s * ax;
    c->fit_n += SPVS_R(1.0);
    c->fit_s += s;
    c->fit_ss += s * s;
    c->fit_d += D;
    c->fit_sd += s * D;
}

/* The line D ~ a + b s at s (and its slope, and that of ax, kept for a
 * re-entry); D while the distances spread under
 * SPVS_CTL_FIT_MIN_SPREAD_UM. */
static spvs_real fit_line(spvs_control_t *c, const spvs_control_params_t *p, spvs_real s,
                          spvs_real D)
{
    (void)p;
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

/* A re-entered step 2's signal: d0 less the first line's slope times the
 * distance driven. */
static spvs_real reentry_remaining(const spvs_control_t *c)
{
    const spvs_real d0 = c->reentry_d0;
    return d0 - (spvs_real)sgn(d0) * SPVS_FABS(c->slope_sig) * c->odo_s;
}

/* The pixels per unit of each entry of H - I: its part of the transfer of
 * the corner (cx, cy), |c| its distance from the centre. */
static void residual_scale(const spvs_control_params_t *p, spvs_real scale[6])
{
    const spvs_real cx = p->arrival_corner_x_px, cy = p->arrival_corner_y_px;
    const spvs_real rc = SPVS_SQRT(cx * cx + cy * cy);
    scale[0] = cx;
    scale[1] = cy;
    scale[2] = SPVS_R(1.0);
    scale[3] = cx * rc;
    scale[4] = cy * rc;
    scale[5] = rc;
}

/* A frame's H - I, and its residuals in pixels: the entries scaled to
 * their part of a corner's transfer, then the horizontal parallax. */
static void arrival_add(spvs_control_t *c, const spvs_control_params_t *p,
                        const spvs_control_input_t *in, int with_parallax)
{
    const spvs_real *H = in->H;
    spvs_real s[SPVS_CTL_ARRIVAL_RESIDUALS], scale[6];
    s[0] = H[SPVS_H11] - SPVS_R(1.0);
    s[1] = H[SPVS_H12];
    s[2] = H[SPVS_H13];
    s[3] = H[SPVS_H31];
    s[4] = H[SPVS_H32];
    s[5] = H[SPVS_H33] - SPVS_R(1.0);
    residual_scale(p, scale);
    for (int k = 0; k < 6; k++) {
        c->arrive_sum[k] += s[k];
        s[k] *= scale[k];
    }
    s[6] = in->parallax_x_px;
    s[7] = in->parallax_r_px;
    const int n = with_parallax ? SPVS_CTL_ARRIVAL_RESIDUALS : 6;
    for (int k = 0; k < n; k++) {
        c->arrive_res[k] += s[k];
        c->arrive_sq[k] += s[k] * s[k];
    }
}

/* Residual k's mean over n frames, pixels, and its standard deviation:
 * the frames' variance s^2 is one image's noise; the goal image's, as
 * large, is the same in every frame, so the mean's variance is s^2 / n +
 * s^2 (at least SPVS_CTL_ARRIVAL_SD_MIN_MPX). */
static spvs_real residual_mean_sd(const spvs_control_t *c, int k, spvs_real n, spvs_real *sd)
{
    const spvs_real mean = c->arrive_res[k] / n;
    spvs_real var = (c->arrive_sq[k] - mean * c->arrive_res[k]) / (n - SPVS_R(1.0));
    var = var > SPVS_R(0.0) ? var : SPVS_R(0.0);
    const spvs_real least = (spvs_real)SPVS_CTL_ARRIVAL_SD_MIN_MPX * SPVS_R(0.001);
    *sd = SPVS_SQRT(var * (SPVS_R(1.0) + SPVS_R(1.0) / n) + least * least);
    return mean;
}

/* A residual's statistic: how many sd its mean lies beyond the dead zone
 * (arrival_resolution_px; for h13 step 3's own tolerance, tol_h13_px; for
 * the horizontal parallax SPVS_CTL_ARRIVAL_LATERAL_ZONE_X10 / 10 times
 * arrival_resolution_px). */
static spvs_real residual_stat(const spvs_control_params_t *p, int k, spvs_real m, spvs_real sd)
{
    spvs_real zone = p->arrival_resolution_px;
    if (k == 2) {
        zone = p->tol_h13_px;
    } else if (k == 6) {
        zone *= (spvs_real)SPVS_CTL_ARRIVAL_LATERAL_ZONE_X10 * SPVS_R(0.1);
    }
    const spvs_real beyond = SPVS_FABS(m) - zone;
    return beyond > SPVS_R(0.0) ? beyond / sd : SPVS_R(0.0);
}

/* Mean over the four image corners of the transfer |H p - p| (pixels), of H
 * = I + the residual r (h11 - 1, h12, h13, h31, h32, h33 - 1); for the
 * telemetry. */
static spvs_real corner_transfer(const spvs_control_params_t *p, const spvs_real r[6])
{
    spvs_real all = SPVS_R(0.0);
    for (int k = 0; k < 4; k++) {
        const spvs_real u = (k & 1) ? p->arrival_corner_x_px : -p->arrival_corner_x_px;
        const spvs_real v = (k & 2) ? p->arrival_corner_y_px : -p->arrival_corner_y_px;
        const spvs_real w = r[3] * u + r[4] * v + SPVS_R(1.0) + r[5];
        if (!(w > SPVS_R(0.0))) {
            /* A corner behind the camera: as far from the identity as can be. */
            return SPVS_REAL_MAX;
        }
        const spvs_real dx = ((SPVS_R(1.0) + r[0]) * u + r[1] * v + r[2]) / w - u;
        const spvs_real dy = v / w - v;
        all += SPVS_R(0.25) * SPVS_SQRT(dx * dx + dy * dy);
    }
    return all;
}

/* The averaged residual r (entries of H - I), each residual's statistic
 * z (control_steps.inc's arrival_combine reads them) and the telemetry's
 * means and sds. */
static void arrival_figures(spvs_control_t *c, const spvs_control_params_t *p, spvs_real r[6],
                            spvs_real z[SPVS_CTL_ARRIVAL_RESIDUALS])
{
    const spvs_real nf = (spvs_real)c->arrive_n;
    spvs_real m[SPVS_CTL_ARRIVAL_RESIDUALS], sd[SPVS_CTL_ARRIVAL_RESIDUALS];
    for (int k = 0; k < 6; k++) {
        m[k] = residual_mean_sd(c, k, nf, &sd[k]);
        r[k] = c->arrive_sum[k] / nf;
        z[k] = residual_stat(p, k, m[k], sd[k]);
    }
    /* The parallax needs two frames for its spread; without, row 1 of H
     * speaks for the sideways offset alone. */
    const int par = c->arrive_par_n >= 2u;
    for (int k = 6; k < SPVS_CTL_ARRIVAL_RESIDUALS; k++) {
        m[k] = sd[k] = z[k] = SPVS_R(0.0);
        if (par) {
            m[k] = residual_mean_sd(c, k, (spvs_real)c->arrive_par_n, &sd[k]);
            z[k] = residual_stat(p, k, m[k], sd[k]);
        }
    }
    c->arrival_corner_px = corner_transfer(p, r);
    c->arrival_lateral_px = par ? m[6] : m[0];
    c->arrival_lateral_sd_px = par ? sd[6] : sd[0];
    c->arrival_depth_px = par ? m[7] : m[5];
    c->arrival_depth_sd_px = par ? sd[7] : sd[5];
    c->arrival_h13_px = m[2];
    c->arrival_h13_sd_px = sd[2];
}

static void arrival_stat_keep(spvs_control_t *c, spvs_real stat)
{
    c->arrival_stat = stat;
}

static spvs_real parallax_mean(const spvs_control_t *c)
{
    return c->arrive_par_sum / (spvs_real)c->arrive_par_n;
}

static spvs_real reentry_h33(const spvs_real r[6])
{
    return -r[5];
}

static spvs_real reentry_h33_scaled(const spvs_control_t *c, const spvs_real r[6])
{
    return r[5] * (c->slope_sig / c->slope_ax);
}

static spvs_real reentry_h32(const spvs_control_params_t *p, const spvs_real r[6])
{
    return p->alpha_y * r[4];
}

static spvs_real sig_from_val(const spvs_control_t *c, spvs_real v)
{
    (void)c;
    return v;
}

static void reset_for_new_start(spvs_control_t *c)
{
    spvs_control_reset(c);
}

#include "control_steps.inc"

int spvs_control_params_check(const spvs_control_params_t *p)
{
    return params_rules(p);
}

void spvs_control_reset(spvs_control_t *c)
{
    SPVS_ASSERT(c != 0);
    reset_state(c);
}

int spvs_control_step(spvs_control_t *c, const spvs_control_params_t *p,
                      const spvs_control_input_t *in, spvs_real *v, spvs_real *w)
{
    if (c == 0 || p == 0 || in == 0 || v == 0 || w == 0) {
        return SPVS_E_ARG;
    }
    *v = SPVS_R(0.0);
    *w = SPVS_R(0.0);
    spvs_real vc = SPVS_R(0.0);
    spvs_real wc = SPVS_R(0.0);
    const int rc = control_update(c, p, in, &vc, &wc);
    if (rc != SPVS_OK) {
        return rc;
    }
    *v = clamp(vc, p->v_max);
    *w = clamp(wc, p->w_max);
    c->last_v = *v;
    return SPVS_OK;
}
