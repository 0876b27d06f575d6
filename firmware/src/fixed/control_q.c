/*
 * control_q.c - Shortest Path Control in fixed point (control_q.h): the
 * signals, commands and sums in Q under the decisions of control_steps.inc
 * (written once for both cores).  docs/CONTROL.md derives every rule; the
 * comments here give the formats and why each stays in range.
 *
 * Ranges used below (control_q.h):  H entries |h| < 2^31 in Q27 (below 16);
 * every signal int32; a gain's mantissa |m| < 2^31, so gain x signal is
 * below 2^62 in int64 before its one shift; commands int64 until they are
 * clamped at v_max, w_max < 128 (Q24).
 */
#include <stddef.h>
#include <string.h>

#include "control_q.h"
#include "spvs/homography.h"

#define ONE27 ((int32_t)1 << 27)
#define ONE54 ((int64_t)1 << 54)
/* h13 in pixels is h13 in scaled units (Q27) read in Q(27 - 9). */
#define QH13_PX (SPVS_QH - 9)

_Static_assert(SPVS_COORD_SCALE == 512, "the pixel formats of H assume SPVS_COORD_SCALE 512");

/* ---- small helpers -------------------------------------------------------- */

static int8_t sgn(int64_t x)
{
    return (int8_t)((x > 0) - (x < 0));
}

static uint64_t abs64(int64_t x)
{
    return spvs_q_abs64(x);
}

/* k x for a gain k (a value) and x in Qfx, as an int64 in Qfout: one
 * 32 x 32 -> 64-bit product (|k.m x| < 2^62) and one rounding shift,
 * relative error <= 2^-31 of k plus 1/2 ulp; saturated (flagged). */
static int64_t kx(spvs_qf_t k, int32_t x, int fx, int fout, uint32_t *sat)
{
    if (k.m == 0 || x == 0) {
        return 0;
    }
    const int64_t p = (int64_t)k.m * x;
    const int32_t s = k.e - fx + fout;
    if (s >= 0) {
        return spvs_q_lshift_sat64(p, s > 62 ? 63 : (int)s, sat);
    }
    return spvs_q_rshift_rnd64(p, s < -63 ? 63 : (int)-s);
}

static spvs_qf_t qf_of(int64_t v, int f)
{
    return spvs_qf_from_i64(v, -f);
}

static spvs_qf_t qf_abs(spvs_qf_t a)
{
    a.m = a.m < 0 ? -a.m : a.m;
    return a;
}

static spvs_qf_t qf_scale2(spvs_qf_t a, int32_t e)
{
    if (a.m != 0) {
        a.e += e;
    }
    return a;
}

static spvs_qf_t qf_div(spvs_qf_t a, spvs_qf_t b, uint32_t *sat)
{
    return spvs_qf_mul(a, spvs_qf_recip(b, sat));
}

/* sqrt(a) for a >= 0 (a negative a gives 0): the mantissa widened to 62 or
 * 63 bits with an even exponent, its exact integer root (31 bits),
 * relative error <= 2^-30. */
static spvs_qf_t qf_sqrt(spvs_qf_t a)
{
    if (a.m <= 0) {
        return qf_of(0, 0);
    }
    int32_t e = a.e - 32;
    uint64_t m = (uint64_t)a.m << 32;
    if (e & 1) {
        m >>= 1;
        e += 1;
    }
    return spvs_qf_from_i64((int64_t)spvs_q_isqrt64(m), e / 2);
}

/* n / d rounded to nearest (ties away), d > 0, for the per-frame means. */
static int64_t div_rnd(int64_t n, uint32_t d)
{
    const uint64_t an = abs64(n);
    const uint64_t q = (an + d / 2u) / d;
    return n < 0 ? -(int64_t)q : (int64_t)q;
}

static int32_t clamp_cmd(int64_t x, int32_t lim)
{
    return x > lim ? lim : (x < -(int64_t)lim ? -lim : (int32_t)x);
}

/* |x| < tol for an int32 signal and its tolerance in the same format. */
static int under(int64_t x, int64_t tol)
{
    return abs64(x) < (uint64_t)tol;
}

/* ---- conversions (float bits, integer operations only) -------------------- */


/* x in Qf; a nonzero x that rounds to 0 keeps its sign as one ulp, and
 * the clamp of q.h is flagged, also at exactly +-2^31 ulp. */
static int32_t q_real(spvs_real x, int f, uint32_t *sat)
{
    const spvs_q_ieee_t v = spvs_q_real_parts(x);
    int32_t q = spvs_q_from_ieee(v, f, sat, 0);
    if (q == 0 && v.mant != 0u && !v.nonfinite) {
        q = v.neg ? -1 : 1;
    }
    if (q == SPVS_Q_I32_MAX || q == SPVS_Q_I32_MIN) {
        *sat |= SPVS_Q_SAT;
    }
    return q;
}

static spvs_qf_t qf_real(spvs_real x, uint32_t *sat)
{
    return spvs_qf_from_ieee(spvs_q_real_parts(x), sat);
}

/* A positive tolerance in Qf: 0 (rounded away) or a clamp is a config
 * error, as it would change which frames pass. */
static int32_t tol_real(spvs_real x, int f, uint32_t *bad)
{
    uint32_t sat = 0;
    const int32_t q = spvs_q_from_ieee(spvs_q_real_parts(x), f, &sat, 0);
    if (sat != 0u || q == SPVS_Q_I32_MAX || q <= 0) {
        *bad = 1u;
    }
    return q;
}

static void params_coeffs(spvs_q_ctl_params_t *q, const spvs_control_params_t *p,
                          uint32_t *bad)
{
    uint32_t sat = 0;
    const spvs_qf_t ax = qf_real(p->alpha_x, &sat), ay = qf_real(p->alpha_y, &sat);
    q->c13 = qf_scale2(spvs_qf_recip(ax, &sat), 9);
    q->c31 = qf_scale2(ax, -9);
    q->c32 = qf_scale2(ay, -9);
    q->c12 = qf_div(ay, ax, &sat);
    q->alpha_x = tol_real(p->alpha_x, SPVS_QCTL_PX, bad);
    (void)tol_real(p->alpha_y, SPVS_QCTL_PX, bad);
    q->k_w = qf_real(p->k_w, &sat);
    q->k_v = qf_real(p->k_v, &sat);
    q->k_w3 = qf_real(p->k_w3, &sat);
    q->k_w11 = qf_real(p->k_w11, &sat);
    q->hold_heading_ratio = qf_real(p->hold_heading_ratio, &sat);
    const spvs_qf_t r = qf_real(p->min_signal_ratio, &sat);
    q->min_signal_ratio2 = spvs_qf_mul(r, r);
    /* (SPVS_CTL_FIT_MIN_SPREAD_UM 1e-6 m)^2, m^2. */
    const spvs_qf_t spread = qf_div(qf_of(SPVS_CTL_FIT_MIN_SPREAD_UM, 0),
                                    qf_of(1000000, 0), &sat);
    q->fit_min_den = spvs_qf_mul(spread, spread);
    *bad |= sat;
}

static void params_arrival(spvs_q_ctl_params_t *q, const spvs_control_params_t *p,
                           uint32_t *bad)
{
    uint32_t sat = 0;
    q->arrival_k = qf_real(p->arrival_k, &sat);
    q->corner_x = qf_real(p->arrival_corner_x_px, &sat);
    q->corner_y = qf_real(p->arrival_corner_y_px, &sat);
    const spvs_qf_t corner_r = qf_sqrt(spvs_qf_add(spvs_qf_mul(q->corner_x, q->corner_x),
                                                   spvs_qf_mul(q->corner_y, q->corner_y)));
    /* control.c's residual_scale on the scaled units (h13 2^9 px, h31 and
     * h32 2^-9 per px). */
    q->res_scale[0] = q->corner_x;
    q->res_scale[1] = q->corner_y;
    q->res_scale[2] = qf_of(1, -9);
    q->res_scale[3] = qf_scale2(spvs_qf_mul(q->corner_x, corner_r), -9);
    q->res_scale[4] = qf_scale2(spvs_qf_mul(q->corner_y, corner_r), -9);
    q->res_scale[5] = corner_r;
    q->resolution = qf_real(p->arrival_resolution_px, &sat);
    /* SPVS_CTL_ARRIVAL_PARALLAX_X100 / 100 x SPVS_CTL_NOISE_PARALLAX_X1000 /
     * 1000 sigma. */
    const spvs_qf_t par = qf_div(
        qf_of((int64_t)SPVS_CTL_ARRIVAL_PARALLAX_X100 * SPVS_CTL_NOISE_PARALLAX_X1000, 0),
        qf_of(100 * 1000, 0), &sat);
    q->arrival_par_max =
        spvs_qf_to_q32(spvs_qf_mul(par, qf_real(p->arrival_sigma_px, &sat)), SPVS_QCTL_PX, &sat);
    q->arrival_frames = p->arrival_frames;
    *bad |= sat;
}

/* ---- the parameters' bits (control_steps.inc's params_rules compares on them) ---- */

static int real_in(const void *x, const spvs_real *lo, int lo_incl, const spvs_real *hi,
                   int hi_incl)
{
    return spvs_q_real_in(x, lo, lo_incl, hi, hi_incl);
}

int spvs_q_ctl_params_from_real(spvs_q_ctl_params_t *q, const spvs_control_params_t *p)
{
    if (q == 0 || p == 0) {
        return SPVS_E_ARG;
    }
    /* The rules first (params_rules): the conversions below assume their ranges. */
    const int rc = spvs_q_ctl_params_check(p);
    if (rc != SPVS_OK) {
        return rc;
    }
    uint32_t bad = 0;
    q->method = p->method;
    params_coeffs(q, p, &bad);
    q->v_max = tol_real(p->v_max, SPVS_QCTL_CMD, &bad);
    q->w_max = tol_real(p->w_max, SPVS_QCTL_CMD, &bad);
    uint32_t sat = 0;
    q->w_min_escape = q_real(p->w_min_escape, SPVS_QCTL_CMD, &sat);
    q->tol_align = tol_real(p->tol_align,
                            p->method == SPVS_METHOD_III ? SPVS_QCTL_PX : SPVS_QH, &bad);
    q->tol_translate = tol_real(p->tol_translate, SPVS_QH, &bad);
    q->tol_h13 = tol_real(p->tol_h13_px, QH13_PX, &bad);
    q->lock_ex = tol_real(p->lock_ex_px, SPVS_QCTL_PX, &bad);
    q->switch_parallax = q_real(p->switch_parallax_px, SPVS_QCTL_PX, &sat);
    q->tol_det = spvs_qf_to_q64(qf_real(p->tol_det, &sat), 54, &sat);
    q->step_timeout = tol_real(p->step_timeout_s, SPVS_QCTL_T, &bad);
    q->hold_frames = p->hold_frames;
    q->fit_min_frames = p->fit_min_frames;
    q->fit_min_span = tol_real(p->fit_min_span_m, SPVS_QCTL_S, &bad);
    params_arrival(q, p, &bad);
    if (q->tol_det <= 0) {
        bad = 1u;
    }
    return (bad | sat) != 0u ? SPVS_E_CONFIG : SPVS_OK;
}

int spvs_q_ctl_input_from_real(spvs_q_ctl_input_t *q, const spvs_control_input_t *in)
{
    if (q == 0 || in == 0) {
        return SPVS_E_ARG;
    }
    uint32_t sat = 0, clamp = 0;
    /* Scaled units: h13 / 512, h31 and h32 x 512, exact powers of two. */
    for (int k = 0; k < 9; k++) {
        const int f = k == SPVS_H13 ? QH13_PX : (k == SPVS_H31 || k == SPVS_H32) ? SPVS_QH + 9
                                                                                  : SPVS_QH;
        q->H[k] = q_real(in->H[k], f, &sat);
    }
    q->t = q_real(in->t_s, SPVS_QCTL_T, &sat);
    q->e_valid = in->e_valid;
    q->e_x = in->e_valid ? q_real(in->e_x_px, SPVS_QCTL_PX, &clamp) : 0;
    const spvs_q_ieee_t ez = spvs_q_real_parts(in->e_dir_z);
    q->e_side = (int8_t)(ez.mant == 0u ? 0 : (ez.neg ? -1 : 1));
    const spvs_q_ieee_t par = spvs_q_real_parts(in->parallax_px);
    /* Any negative parallax is "unknown", however small. */
    q->parallax = (par.neg && par.mant != 0u) ? -((int32_t)1 << SPVS_QCTL_PX)
                                              : q_real(in->parallax_px, SPVS_QCTL_PX, &clamp);
    q->parallax_x = q_real(in->parallax_x_px, SPVS_QCTL_PX, &clamp);
    q->parallax_r = q_real(in->parallax_r_px, SPVS_QCTL_PX, &clamp);
    q->n_inliers = in->n_inliers;
    if (((sat | clamp) & SPVS_Q_NONFINITE) != 0u || ez.nonfinite) {
        return SPVS_E_NONFINITE;
    }
    return sat != 0u ? SPVS_E_RANGE : SPVS_OK;
}

/* ---- state ---------------------------------------------------------------- */

static void fit_clear(spvs_q_ctl_t *c)
{
    c->fit_n = 0u;
    c->fit_s = c->fit_d = c->fit_ax = 0;
    c->fit_ss = c->fit_sd = c->fit_sax = qf_of(0, 0);
}

/* ---- the fixed-point core's side of control_steps.inc ---------------------
 * The signals, commands and sums in Q (control_q.h gives the formats);
 * every decision on them is in control_steps.inc, included below. */

typedef spvs_q_ctl_t ctl_t;
typedef spvs_q_ctl_params_t ctl_params_t;
typedef spvs_q_ctl_input_t ctl_input_t;
typedef int32_t ctl_sig_t;
typedef int64_t ctl_wide_t;
typedef int64_t ctl_cmd_t;
typedef int32_t ctl_time_t;
typedef int32_t ctl_px_t;
typedef spvs_qf_t ctl_val_t;

static int32_t time_none(void)
{
    return -((int32_t)1 << SPVS_QCTL_T);
}

static int64_t cos_one(void)
{
    return (int64_t)1 << SPVS_QCTL_ODO;
}

static spvs_qf_t val_zero(void)
{
    return qf_of(0, 0);
}

static int ex_beyond(const spvs_q_ctl_params_t *p, const spvs_q_ctl_input_t *in, int locks)
{
    return abs64(in->e_x) > (uint64_t)((int64_t)locks * p->lock_ex);
}

static int val_le(spvs_qf_t a, spvs_qf_t b)
{
    return spvs_qf_le(a, b);
}

static int val_lt(spvs_qf_t a, spvs_qf_t b)
{
    return !spvs_qf_le(b, a);
}

static spvs_qf_t val_abs(spvs_qf_t a)
{
    return qf_abs(a);
}

static spvs_qf_t val_of_x10(int n)
{
    uint32_t sat = 0;
    return spvs_qf_mul(qf_of(n, 0), spvs_qf_recip(qf_of(10, 0), &sat));
}

static spvs_qf_t val_times(spvs_qf_t a, int k)
{
    return spvs_qf_mul(qf_of(k, 0), a);
}

static int val_is_zero(spvs_qf_t a)
{
    return a.m == 0;
}

/* dm decimetres of odometry, Q40 metres. */
static int64_t odo_from_dm(int dm)
{
    return ((int64_t)dm << SPVS_QCTL_ODO) / 10;
}

static int32_t in_time(const spvs_q_ctl_input_t *in)
{
    return in->t;
}

static int8_t in_side(const spvs_q_ctl_input_t *in)
{
    return in->e_side;
}

static int32_t in_ex(const spvs_q_ctl_input_t *in)
{
    return in->e_x;
}

static int32_t in_parallax(const spvs_q_ctl_input_t *in)
{
    return in->parallax;
}

static int64_t odo(const spvs_q_ctl_t *c)
{
    return c->odo;
}

/* The distance driven in step 2, Q24 metres. */
static int32_t fit_distance(spvs_q_ctl_t *c)
{
    return spvs_q_sat32(spvs_q_rshift_rnd64(c->odo, SPVS_QCTL_ODO - SPVS_QCTL_S), &c->sat);
}

static int32_t tol_h13(const spvs_q_ctl_params_t *p)
{
    return p->tol_h13;
}

/* tol_h13_px in e_x's Q16. */
static int32_t tol_ex(const spvs_q_ctl_params_t *p)
{
    return (int32_t)spvs_q_rshift_rnd64(p->tol_h13, QH13_PX - SPVS_QCTL_PX);
}

static int32_t switch_parallax(const spvs_q_ctl_params_t *p)
{
    return p->switch_parallax;
}

static int32_t step_timeout(const spvs_q_ctl_params_t *p)
{
    return p->step_timeout;
}

static int32_t fit_min_span(const spvs_q_ctl_params_t *p)
{
    return p->fit_min_span;
}

static spvs_qf_t arrival_threshold(const spvs_q_ctl_params_t *p)
{
    return p->arrival_k;
}

/* Converted once (params_arrival). */
static int32_t parallax_gate(const spvs_q_ctl_params_t *p)
{
    return p->arrival_par_max;
}

static int32_t parallax_none(void)
{
    return -((int32_t)1 << SPVS_QCTL_PX);
}

/* Eq. (19): f = h11^2 + (h13 / alpha_x)^2 - 1 in Q27.  h13 / alpha_x =
 * c13 h13 (scaled); each square halved first so that the sum of two
 * squares below 2^62 stays below 2^62 (the halving's floor is 2^-55). */
static int32_t f_signal(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                        const spvs_q_ctl_input_t *in)
{
    uint32_t *sat = &c->sat;
    const int64_t h11 = in->H[SPVS_H11];
    const int64_t h13n = spvs_q_sat32(kx(p->c13, in->H[SPVS_H13], SPVS_QH, SPVS_QH, sat), sat);
    const int64_t f53 = ((h11 * h11) >> 1) + ((h13n * h13n) >> 1) - (ONE54 >> 1);
    return spvs_q_sat32(spvs_q_rshift_rnd64(f53, 26), sat);
}

/* h11 - h33, or alpha_y h32 (Method II), Q27. */
static int32_t translate_signal(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                                const spvs_q_ctl_input_t *in)
{
    if (p->method == SPVS_METHOD_II) {
        return spvs_q_sat32(kx(p->c32, in->H[SPVS_H32], SPVS_QH, SPVS_QH, &c->sat), &c->sat);
    }
    return spvs_q_sat32((int64_t)in->H[SPVS_H11] - in->H[SPVS_H33], &c->sat);
}

/* h33 - h11, saturated as D is for Methods I and III (translate_signal). */
static int32_t axial_signal(spvs_q_ctl_t *c, const spvs_q_ctl_input_t *in)
{
    return spvs_q_sat32((int64_t)in->H[SPVS_H33] - in->H[SPVS_H11], &c->sat);
}

/* Both kinds of step-2 signal, Q27, unclamped (int64). */
static void start_signals(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                          const spvs_q_ctl_input_t *in, int64_t *D, int64_t *Dy)
{
    *D = (int64_t)in->H[SPVS_H11] - in->H[SPVS_H33];
    *Dy = kx(p->c32, in->H[SPVS_H32], SPVS_QH, SPVS_QH, &c->sat);
}

/* det H - 1 in Q54, exact unless saturated (then far past any tol_det):
 * h13 h31 is the same product in scaled units as in pixels. */
static int64_t det_minus_1(spvs_q_ctl_t *c, const spvs_q_ctl_input_t *in)
{
    const int32_t *H = in->H;
    const int64_t a = (int64_t)H[SPVS_H11] * H[SPVS_H33];
    const int64_t b = (int64_t)H[SPVS_H13] * H[SPVS_H31];
    return spvs_q_add64(spvs_q_add64(a, -b, &c->sat), -ONE54, &c->sat);
}

static int32_t start_size(spvs_q_ctl_t *c, int32_t D)
{
    return spvs_q_sat32((int64_t)abs64(D), &c->sat);
}

static int64_t hold_below(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p)
{
    return kx(p->hold_heading_ratio, c->trans_d0, SPVS_QH, SPVS_QH, &c->sat);
}

/* The plane check's sums (control.c's plane_accumulate): the epipole's
 * unit direction (e_x, alpha_x) / |.| in Q30 from Q15 pixels (squares below
 * 2^61, the root below 2^31), P = h11 - h33 and Q = h13 / alpha_x +
 * alpha_x h31 in Q27; each product below 2^61, a sum of two below 2^62,
 * rounded to Q27 into int64 sums. */
static void plane_accumulate(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                                             const spvs_q_ctl_input_t *in)
{
    const int32_t *H = in->H;
    uint32_t *sat = &c->sat;
    const int64_t ex = spvs_q_rshift_rnd64(in->e_x, 1), ax = spvs_q_rshift_rnd64(p->alpha_x, 1);
    const uint32_t en = spvs_q_isqrt64((uint64_t)(ex * ex) + (uint64_t)(ax * ax));
    const int64_t side = in->e_side > 0 ? 1 : -1;
    const int64_t e1 = side * spvs_q_div64_32(ex * ((int64_t)1 << 30), (int32_t)en, sat);
    const int64_t e3 = side * spvs_q_div64_32(ax * ((int64_t)1 << 30), (int32_t)en, sat);
    const int64_t P = spvs_q_sat32((int64_t)H[SPVS_H11] - H[SPVS_H33], sat);
    const int64_t Q = spvs_q_sat32(kx(p->c13, H[SPVS_H13], SPVS_QH, SPVS_QH, sat) +
                                       kx(p->c31, H[SPVS_H31], SPVS_QH, SPVS_QH, sat),
                                   sat);
    const int64_t Y = spvs_q_sat32(kx(p->c32, H[SPVS_H32], SPVS_QH, SPVS_QH, sat), sat);
    const int64_t X = spvs_q_sat32(kx(p->c12, H[SPVS_H12], SPVS_QH, SPVS_QH, sat), sat);
    c->normal_est[0] += spvs_q_rshift_rnd64(-e1 * P - e3 * Q, 30);
    c->normal_est[2] += spvs_q_rshift_rnd64(e3 * P - e1 * Q, 30);
    c->normal_est[1] += spvs_q_rshift_rnd64(-(e3 * Y + e1 * X), 30);
}

/* |n_k| over min_signal_ratio |n|: compared squared, both sides
 * non-negative, so no square root is taken; false for n = 0. */
static int normal_has_signal(const spvs_q_ctl_t *c,
                                             const spvs_q_ctl_params_t *p, int k)
{
    spvs_qf_t sq[3];
    for (int i = 0; i < 3; i++) {
        const spvs_qf_t n = qf_of(c->normal_est[i], SPVS_QH);
        sq[i] = spvs_qf_mul(n, n);
    }
    const spvs_qf_t norm2 = spvs_qf_add(spvs_qf_add(sq[0], sq[1]), sq[2]);
    if (norm2.m == 0) {
        return 0;
    }
    return !spvs_qf_le(sq[k], spvs_qf_mul(p->min_signal_ratio2, norm2));
}

/* cos phi_t from h11 on the line (eq. 8), in Q40: a running mean, then an
 * exponential one (each update's rounding 2^-41). */
static void phit_mean(spvs_q_ctl_t *c, const spvs_q_ctl_input_t *in)
{
    const int64_t h11 = (int64_t)in->H[SPVS_H11] * ((int64_t)1 << (SPVS_QCTL_ODO - SPVS_QH));
    c->cos_phit += div_rnd(h11 - c->cos_phit, c->n_phit);
}

static void phit_first(spvs_q_ctl_t *c, const spvs_q_ctl_input_t *in)
{
    c->cos_phit = (int64_t)in->H[SPVS_H11] * ((int64_t)1 << (SPVS_QCTL_ODO - SPVS_QH));
}

/* Eq. (20): w = -k_w f, Q24 before its clamp. */
static int64_t w_eq20(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p, int32_t f)
{
    return -c->sign_w * kx(p->k_w, f, SPVS_QH, SPVS_QCTL_CMD, &c->sat);
}

static int64_t w_escape(const spvs_q_ctl_params_t *p, int8_t s)
{
    return -s * (int64_t)p->w_min_escape;
}

/* Eq. (21): w = -k_w h12. */
static int64_t w_eq21(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                      const spvs_q_ctl_input_t *in)
{
    return -c->sign_w * kx(p->k_w, in->H[SPVS_H12], SPVS_QH, SPVS_QCTL_CMD, &c->sat);
}

/* Eq. (11), cos phi_t from Q40 to Q27. */
static int64_t w_eq11(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                      const spvs_q_ctl_input_t *in)
{
    const int64_t cos27 = spvs_q_rshift_rnd64(c->cos_phit, SPVS_QCTL_ODO - SPVS_QH);
    const int32_t d = spvs_q_sat32(in->H[SPVS_H11] - cos27, &c->sat);
    return c->sign_sin_phit * kx(p->k_w11, d, SPVS_QH, SPVS_QCTL_CMD, &c->sat);
}

/* Eq. (22): w = -k_w e_x. */
static int64_t w_eq22(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                      const spvs_q_ctl_input_t *in)
{
    return -kx(p->k_w, in->e_x, SPVS_QCTL_PX, SPVS_QCTL_CMD, &c->sat);
}

/* control.c's w_ex: w = -k_w3 e_x. */
static int64_t w_ex(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p, const spvs_q_ctl_input_t *in)
{
    return -kx(p->k_w3, in->e_x, SPVS_QCTL_PX, SPVS_QCTL_CMD, &c->sat);
}

/* Eq. (17): w = -k_w3 h13, h13 in pixels (Q18). */
static int64_t w_eq17(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                      const spvs_q_ctl_input_t *in)
{
    return -kx(p->k_w3, in->H[SPVS_H13], QH13_PX, SPVS_QCTL_CMD, &c->sat);
}

/* Eqs. (20), (22): v = -k_v D (eq. 21 with D = alpha_y h32). */
static int64_t v_eq20(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p, int32_t D)
{
    return -c->sign_v * kx(p->k_v, D, SPVS_QH, SPVS_QCTL_CMD, &c->sat);
}

/* |v| Q24 times dt Q16 is Q40, below 2^31 x 2^32; the sum saturates
 * (flagged) past 2^23 m. */
static void odo_add(spvs_q_ctl_t *c, int32_t t)
{
    const uint64_t v = abs64(c->last_v);
    const int64_t dt = (int64_t)t - c->last_t;
    c->odo = spvs_q_add64(c->odo, (int64_t)(v * (uint64_t)dt), &c->sat);
}

static void line_clear(spvs_q_ctl_t *c)
{
    c->odo = 0;
    fit_clear(c);
}

/* Step 2's least-squares sums of D ~ a + b s and of ax = h33 - h11.  n, sum
 * s (Q24, s < 2^31, n < 2^32: below 2^63), sum D and sum ax (Q27) are exact
 * int64 sums; s^2, s D and s ax (exact int64 products) are summed in
 * spvs_qf_t, 2^-31 per addition. */
static void fit_add(spvs_q_ctl_t *c, int32_t s, int32_t D, int32_t ax)
{
    c->fit_ax += ax;
    c->fit_sax = spvs_qf_add(c->fit_sax, qf_of((int64_t)s * ax, SPVS_QCTL_S + SPVS_QH));
    if (c->fit_n < UINT32_MAX) {
        c->fit_n++;
    }
    c->fit_s += s;
    c->fit_ss = spvs_qf_add(c->fit_ss, qf_of((int64_t)s * s, 2 * SPVS_QCTL_S));
    c->fit_d += D;
    c->fit_sd = spvs_qf_add(c->fit_sd, qf_of((int64_t)s * D, SPVS_QCTL_S + SPVS_QH));
}

/* The line's value at s, written mean(D) + b (n s - sum s) / n, n s - sum s
 * exact (and the slopes kept for a re-entry); D while the distances spread
 * under SPVS_CTL_FIT_MIN_SPREAD_UM.  Sequential assignments to few named
 * values (spvs_qf_t results go through memory on the AAPCS). */
static int32_t fit_line(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                                        int32_t s, int32_t D)
{
    uint32_t *sat = &c->sat;
    const spvs_qf_t n = qf_of(c->fit_n, 0), S = qf_of(c->fit_s, SPVS_QCTL_S);
    spvs_qf_t den, t, iden, b;
    den = spvs_qf_mul(n, c->fit_ss);
    t = spvs_qf_mul(S, S);
    den = spvs_qf_sub(den, t); /* n^2 var(s) */
    t = spvs_qf_mul(n, n);
    t = spvs_qf_mul(p->fit_min_den, t);
    if (spvs_qf_le(den, t)) {
        return D;
    }
    iden = spvs_qf_recip(den, sat);
    b = spvs_qf_mul(n, c->fit_sd);
    t = spvs_qf_mul(S, qf_of(c->fit_d, SPVS_QH));
    b = spvs_qf_sub(b, t);
    b = spvs_qf_mul(b, iden);
    c->slope_sig = b;
    t = spvs_qf_mul(n, c->fit_sax);
    den = spvs_qf_mul(S, qf_of(c->fit_ax, SPVS_QH));
    t = spvs_qf_sub(t, den);
    c->slope_ax = spvs_qf_mul(t, iden);
    t = spvs_qf_mul(b, qf_of((int64_t)c->fit_n * s - c->fit_s, SPVS_QCTL_S));
    t = spvs_qf_add(qf_of(c->fit_d, SPVS_QH), t);
    t = spvs_qf_mul(t, spvs_qf_recip(n, sat));
    return spvs_qf_to_q32(t, SPVS_QH, sat);
}

/* A re-entered step 2's signal: D = d0 - sign(d0) |b| s, Q27. */
static int32_t reentry_remaining(spvs_q_ctl_t *c)
{
    uint32_t *sat = &c->sat;
    const int32_t d0 = c->reentry_d0;
    const spvs_qf_t run = spvs_qf_mul(qf_abs(c->slope_sig), qf_of(fit_distance(c), SPVS_QCTL_S));
    const int64_t D64 = (int64_t)d0 - sgn(d0) * spvs_qf_to_q64(run, SPVS_QH, sat);
    return spvs_q_sat32(D64, sat);
}

/* A residual in Q16 pixels held to +-1024 px, so that the sums of squares
 * (Q32) of SPVS_CTL_ARRIVAL_MAX_FRAMES frames stay under 2^62; a frame
 * that far from the target fails the check either way. */
static int32_t residual_clamp(int32_t v)
{
    const int32_t lim = (int32_t)1024 << SPVS_QCTL_PX;
    return v > lim ? lim : (v < -lim ? -lim : v);
}

/* Standing still after step 3: H - I summed exactly (Q27, at most
 * SPVS_CTL_ARRIVAL_MAX_FRAMES x 2^32), and the residuals in Q16 pixels
 * with their squares (control.c's arrival_add). */
static void arrival_add(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                                        const spvs_q_ctl_input_t *in, int with_parallax)
{
    const int32_t *H = in->H;
    int64_t e[6];
    e[0] = (int64_t)H[SPVS_H11] - ONE27;
    e[1] = H[SPVS_H12];
    e[2] = H[SPVS_H13];
    e[3] = H[SPVS_H31];
    e[4] = H[SPVS_H32];
    e[5] = (int64_t)H[SPVS_H33] - ONE27;
    uint32_t tel = 0;
    for (int k = 0; k < SPVS_CTL_ARRIVAL_RESIDUALS; k++) {
        int32_t v;
        if (k < 6) {
            c->arrive_sum[k] += e[k];
            v = spvs_qf_to_q32(spvs_qf_mul(qf_of(e[k], SPVS_QH), p->res_scale[k]), SPVS_QCTL_PX,
                               &tel);
        } else if (with_parallax) {
            v = k == 6 ? in->parallax_x : in->parallax_r;
        } else {
            break;
        }
        v = residual_clamp(v);
        c->arrive_res[k] += v;
        c->arrive_sq[k] += (int64_t)v * v;
    }
}

/* spvs_qf_t operations on pointers for the arrival check: a spvs_qf_t
 * result is returned through memory on the AAPCS, and each call site of
 * the value-returning forms keeps a slot of its own in the caller's frame.
 * d may be a or b. */
static void qmul(spvs_qf_t *d, const spvs_qf_t *a, const spvs_qf_t *b)
{
    *d = spvs_qf_mul(*a, *b);
}

static void qadd(spvs_qf_t *d, const spvs_qf_t *a, const spvs_qf_t *b)
{
    *d = spvs_qf_add(*a, *b);
}

/* One corner's share of the mean transfer, added to *all: returns 0 for
 * w <= 0.  Each value named once and updated in place through the pointer
 * forms above. */
static int corner_one(const spvs_q_ctl_params_t *p, const spvs_qf_t r[6],
                                      int k, spvs_qf_t *all, uint32_t *sat)
{
    const spvs_qf_t u = (k & 1) ? p->corner_x : spvs_qf_neg(p->corner_x);
    const spvs_qf_t v = (k & 2) ? p->corner_y : spvs_qf_neg(p->corner_y);
    spvs_qf_t g, t, a, b;
    /* h31 and h32 per pixel: 2^-9 of the scaled entries. */
    t = qf_scale2(r[3], -9);
    qmul(&g, &t, &u);
    t = qf_scale2(r[4], -9);
    qmul(&t, &t, &v);
    qadd(&g, &g, &t);
    qadd(&g, &g, &r[5]);
    t = qf_of(1, 0);
    qadd(&a, &t, &g); /* w */
    if (a.m <= 0) {
        return 0;
    }
    a = spvs_qf_recip(a, sat); /* 1 / w */
    qmul(&b, &r[0], &u);
    qmul(&t, &r[1], &v);
    qadd(&b, &b, &t); /* x1 - u */
    t = qf_scale2(r[2], 9); /* h13 in pixels */
    qadd(&b, &b, &t);
    qmul(&t, &u, &g);
    t = spvs_qf_neg(t);
    qadd(&b, &b, &t);
    qmul(&b, &b, &a); /* dx */
    qmul(&g, &g, &a); /* g / w */
    qmul(&g, &v, &g); /* -dy */
    qmul(&b, &b, &b);
    qmul(&g, &g, &g);
    qadd(&t, &b, &g);
    t = qf_scale2(qf_sqrt(t), -2); /* a corner's share of the mean */
    qadd(all, all, &t);
    return 1;
}

/* The mean corner transfer of H = I + r (control.c's corner_transfer), r
 * the averaged residual in scaled units (r[2] h13, r[3], r[4] h31, h32),
 * in spvs_qf_t, written without the cancellations of (H p) / w - p:
 * with g = r31 u + r32 v + r33 and w = 1 + g,
 *   dx = (r11 u + r12 v + r13 - u g) / w,  dy = -v g / w.
 * A corner with w <= 0 (behind the camera) makes it the largest value. */
static spvs_qf_t corner_transfer(const spvs_q_ctl_params_t *p,
                                                 const spvs_qf_t r[6], uint32_t *sat)
{
    spvs_qf_t all = qf_of(0, 0);
    for (int k = 0; k < 4; k++) {
        if (!corner_one(p, r, k, &all, sat)) {
            all.m = SPVS_Q_I32_MAX;
            all.e = 1000;
            break;
        }
    }
    return all;
}

/* control.c's residual_mean_sd: residual k's mean over n frames and its
 * standard deviation, pixels. */
static spvs_qf_t residual_mean_sd(spvs_q_ctl_t *c, int k, uint32_t n,
                                                  spvs_qf_t *sd)
{
    const spvs_qf_t inv = spvs_qf_recip(qf_of(n, 0), &c->sat);
    const spvs_qf_t sum = qf_of(c->arrive_res[k], SPVS_QCTL_PX);
    const spvs_qf_t mean = spvs_qf_mul(sum, inv);
    spvs_qf_t var = spvs_qf_add(qf_of(c->arrive_sq[k], 2 * SPVS_QCTL_PX),
                                spvs_qf_neg(spvs_qf_mul(mean, sum)));
    var = var.m > 0 ? qf_div(var, qf_of(n - 1u, 0), &c->sat) : qf_of(0, 0);
    var = spvs_qf_mul(var, spvs_qf_add(qf_of(1, 0), inv));
    const spvs_qf_t least = qf_div(qf_of(SPVS_CTL_ARRIVAL_SD_MIN_MPX, 0), qf_of(1000, 0), &c->sat);
    *sd = qf_sqrt(spvs_qf_add(var, spvs_qf_mul(least, least)));
    return mean;
}

/* control.c's residual_stat. */
static spvs_qf_t residual_stat(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p,
                                               int k, spvs_qf_t m, spvs_qf_t sd)
{
    spvs_qf_t zone = p->resolution;
    if (k == 2) {
        zone = qf_of(p->tol_h13, QH13_PX);
    } else if (k == 6) {
        zone = qf_div(spvs_qf_mul(zone, qf_of(SPVS_CTL_ARRIVAL_LATERAL_ZONE_X10, 0)),
                      qf_of(10, 0), &c->sat);
    }
    const spvs_qf_t beyond = spvs_qf_add(qf_abs(m), spvs_qf_neg(zone));
    return beyond.m > 0 ? qf_div(beyond, sd, &c->sat) : qf_of(0, 0);
}

static spvs_qf_t val_max(spvs_qf_t a, spvs_qf_t b)
{
    return spvs_qf_le(a, b) ? b : a;
}

static spvs_qf_t val_hypot(spvs_qf_t a, spvs_qf_t b)
{
    return qf_sqrt(spvs_qf_add(spvs_qf_mul(a, a), spvs_qf_mul(b, b)));
}

/* The averaged residual r (scaled units, as the sums), each residual's
 * statistic z in spvs_qf_t and, for the telemetry, the means and sds in
 * int32 Q16 (control.c's arrival_figures). */
static void arrival_figures(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p, spvs_qf_t r[6],
                            spvs_qf_t z[SPVS_CTL_ARRIVAL_RESIDUALS])
{
    uint32_t *sat = &c->sat;
    uint32_t tel = 0;
    spvs_qf_t t, a, m[SPVS_CTL_ARRIVAL_RESIDUALS], sd[SPVS_CTL_ARRIVAL_RESIDUALS];
    t = spvs_qf_recip(qf_of(c->arrive_n, 0), sat);
    for (int k = 0; k < 6; k++) {
        a = qf_of(c->arrive_sum[k], SPVS_QH);
        qmul(&r[k], &a, &t);
        m[k] = residual_mean_sd(c, k, c->arrive_n, &sd[k]);
        z[k] = residual_stat(c, p, k, m[k], sd[k]);
    }
    const int par = c->arrive_par_n >= 2u;
    for (int k = 6; k < SPVS_CTL_ARRIVAL_RESIDUALS; k++) {
        m[k] = sd[k] = z[k] = qf_of(0, 0);
        if (par) {
            m[k] = residual_mean_sd(c, k, c->arrive_par_n, &sd[k]);
            z[k] = residual_stat(c, p, k, m[k], sd[k]);
        }
    }
    c->arrival_corner_px = spvs_qf_to_q32(corner_transfer(p, r, sat), SPVS_QCTL_PX, &tel);
    c->arrival_lateral_px = spvs_qf_to_q32(par ? m[6] : m[0], SPVS_QCTL_PX, &tel);
    c->arrival_lateral_sd_px = spvs_qf_to_q32(par ? sd[6] : sd[0], SPVS_QCTL_PX, &tel);
    c->arrival_depth_px = spvs_qf_to_q32(par ? m[7] : m[5], SPVS_QCTL_PX, &tel);
    c->arrival_depth_sd_px = spvs_qf_to_q32(par ? sd[7] : sd[5], SPVS_QCTL_PX, &tel);
    c->arrival_h13_px = spvs_qf_to_q32(m[2], SPVS_QCTL_PX, &tel);
    c->arrival_h13_sd_px = spvs_qf_to_q32(sd[2], SPVS_QCTL_PX, &tel);
}

/* The statistic's telemetry in Q16 (its saturation is the telemetry's,
 * not the controller's). */
static void arrival_stat_keep(spvs_q_ctl_t *c, spvs_qf_t stat)
{
    uint32_t tel = 0;
    c->arrival_stat = spvs_qf_to_q32(stat, SPVS_QCTL_PX, &tel);
}

/* The frames' mean parallax, Q16 pixels, rounded. */
static int32_t parallax_mean(spvs_q_ctl_t *c)
{
    return spvs_q_sat32(div_rnd(c->arrive_par_sum, c->arrive_par_n), &c->sat);
}

static spvs_qf_t reentry_h33(const spvs_qf_t r[6])
{
    return spvs_qf_neg(r[5]);
}

static spvs_qf_t reentry_h33_scaled(spvs_q_ctl_t *c, const spvs_qf_t r[6])
{
    return spvs_qf_mul(r[5], qf_div(c->slope_sig, c->slope_ax, &c->sat));
}

static spvs_qf_t reentry_h32(const spvs_q_ctl_params_t *p, const spvs_qf_t r[6])
{
    return spvs_qf_mul(p->c32, r[4]);
}

static int32_t sig_from_val(spvs_q_ctl_t *c, spvs_qf_t v)
{
    return spvs_qf_to_q32(v, SPVS_QH, &c->sat);
}

/* spvs_q_ctl_reset keeping the sticky saturation flags. */
static void reset_for_new_start(spvs_q_ctl_t *c)
{
    const uint32_t sat = c->sat;
    spvs_q_ctl_reset(c);
    c->sat = sat;
}

#include "../control_steps.inc"

int spvs_q_ctl_params_check(const spvs_control_params_t *p)
{
    return params_rules(p);
}

void spvs_q_ctl_reset(spvs_q_ctl_t *c)
{
    SPVS_ASSERT(c != 0);
    reset_state(c);
}

int spvs_q_ctl_step(spvs_q_ctl_t *c, const spvs_q_ctl_params_t *p, const spvs_q_ctl_input_t *in,
                    int32_t *v, int32_t *w)
{
    if (c == 0 || p == 0 || in == 0 || v == 0 || w == 0) {
        return SPVS_E_ARG;
    }
    *v = 0;
    *w = 0;
    int64_t vc = 0, wc = 0;
    const int rc = control_update(c, p, in, &vc, &wc);
    if (rc != SPVS_OK) {
        return rc;
    }
    *v = clamp_cmd(vc, p->v_max);
    *w = clamp_cmd(wc, p->w_max);
    c->last_v = *v;
    return SPVS_OK;
}
