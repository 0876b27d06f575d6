/*
 * spvs_q.c - the update pipeline in fixed point (spvs_q.h): the flow and
 * rules of pipeline.inc (written once for both cores) on the Q stages;
 * the comments of pipeline.inc say why each step is made, these say where
 * the formats enter.
 */
#include <string.h>

#include "../core_util.h"
#include "spvs_q.h"

/* ---- the core's scalar, through its bits ---------------------------------- */

/* x 2^-f as the core's scalar, to nearest (spvs_q_ieee_bits). */
static spvs_real real_out(int64_t x, int f)
{
    spvs_real r;
#if SPVS_USE_DOUBLE
    const uint64_t b = spvs_q_ieee_bits(x, f, 52, 11);
#else
    const uint32_t b = (uint32_t)spvs_q_ieee_bits(x, f, 23, 8);
#endif
    memcpy(&r, &b, sizeof r);
    return r;
}

/* log2 of SPVS_COORD_SCALE, a power of two (points_q.h). */
static int log2_scale(void)
{
    return spvs_q_bitlen64((uint64_t)SPVS_COORD_SCALE) - 1;
}

/* x in Qf, or *sat flagged. */
static int32_t q_in(spvs_real x, int f, uint32_t *sat)
{
    return spvs_q_from_ieee(spvs_q_real_parts(x), f, sat, 0);
}

/* ---- parameters ------------------------------------------------------------ */

#if !SPVS_USE_DOUBLE
/* The float core's constant sqrtf(chi2 / 100.0f) as float bits: the
 * quotient rounded to 24 bits, then its square root rounded to 24 bits,
 * each from the exact integer result and a sticky bit for its remainder,
 * so each rounding is the FPU's (to nearest, ties to even). */
static uint32_t chi2_root_f32(void)
{
    const uint64_t num = (uint64_t)SPVS_INLIER_CHI2_X100 << 40;
    const uint64_t quo = num / 100u;
    const uint64_t qx = 2u * quo + (num != quo * 100u ? 1u : 0u);
    const spvs_q_ieee_t v = spvs_q_ieee_f32((uint32_t)spvs_q_ieee_bits((int64_t)qx, 41, 23, 8));
    /* sqrt(mant 2^e) with e made even and the radicand below 2^62. */
    uint64_t m = v.mant;
    int32_t e = v.exp2;
    if ((e & 1) != 0) {
        m <<= 1;
        e -= 1;
    }
    m <<= 36;
    e -= 36;
    const uint64_t r = spvs_q_isqrt64(m);
    const uint64_t rx = 2u * r + (r * r != m ? 1u : 0u);
    return (uint32_t)spvs_q_ieee_bits((int64_t)rx, 1 - (int)(e / 2), 23, 8);
}
#endif

/* spvs_inlier_px in integers.  Float32: the float core's two steps, each
 * rounded as the FPU rounds it: the constant sqrtf(chi2 / 100.0f)
 * (chi2_root_f32) and the product, whose 24 x 24-bit mantissa product is
 * exact in 48 bits and rounded once (real_out), so the result is the float
 * core's bit for bit.  Double: noise_px's mantissa rounded to 30 bits
 * times floor(sqrt(chi2) 2^25) (chi2 < 2^14, so chi2 2^50 < 2^64),
 * normalised to 62 bits, divided by 10 and rounded once: the square
 * root's floor is within 2^-25 of sqrt(chi2) >= 10, the rest within
 * 2^-30, a relative error below 2^-28.  NaN, infinities and zeros are
 * their own product with a positive constant. */
spvs_real spvs_q_inlier_px(const spvs_params_t *p)
{
    SPVS_ASSERT(p != 0);
    spvs_q_ieee_t v = spvs_q_real_parts(p->noise_px);
    if (v.nonfinite || v.mant == 0u) {
        return p->noise_px;
    }
#if !SPVS_USE_DOUBLE
    const spvs_q_ieee_t c = spvs_q_ieee_f32(chi2_root_f32());
    const int64_t x = (int64_t)(v.mant * c.mant);
    return real_out(v.neg ? -x : x, -(int)(v.exp2 + c.exp2));
#else
    const int drop = spvs_q_bitlen64(v.mant) - 30;
    if (drop > 0) {
        v.mant = (v.mant + ((uint64_t)1 << (drop - 1))) >> drop;
        v.exp2 += drop;
    }
    const uint64_t r = spvs_q_isqrt64((uint64_t)SPVS_INLIER_CHI2_X100 << 50);
    const uint64_t x = v.mant * r;
    const int up = 62 - spvs_q_bitlen64(x);
    const int64_t y = (int64_t)((x << up) / 10u);
    return real_out(v.neg ? -y : y, 25 + up - (int)v.exp2);
#endif
}

/* The conversions, after pipeline.inc's rules (pipeline_rules): a value
 * that rounds to 0 or to its bound in its Q format (noise_px, confidence,
 * epipole_sin_tol, max_frame_gap_s), or an offplane_px under the Q inlier
 * threshold, is SPVS_E_CONFIG too. */
static int params_from_real(spvs_q_params_t *q, const spvs_params_t *p)
{
    uint32_t sat = 0;
    const int32_t noise = q_in(p->noise_px, 16, &sat);
    const int32_t conf31 = q_in(p->confidence, 31, &sat);
    q->offplane_q16 = q_in(p->offplane_px, 16, &sat);
    const int32_t sin_tol = q_in(p->epipole_sin_tol, 30, &sat);
    q->max_frame_gap_s = q_in(p->max_frame_gap_s, 16, &sat);
    if (sat != 0u || noise <= 0 || noise >= (300 << 16) || conf31 <= 0 ||
        conf31 >= SPVS_Q_I32_MAX || sin_tol <= 0 || sin_tol >= (1 << 30) ||
        q->max_frame_gap_s <= 0) {
        return SPVS_E_CONFIG;
    }
    /* The inlier threshold noise_px sqrt(chi2 / 100) in Q16 pixels (for the
     * offplane_px rule), and its square in scaled units as spvs_qf_t:
     * noise^2 chi2 / 100 / SPVS_COORD_SCALE^2 (relative 2^-28). */
    const int64_t n2c = (int64_t)noise * noise * SPVS_INLIER_CHI2_X100;
    const int64_t inlier2 = n2c / 100;
    const int32_t inlier = (int32_t)spvs_q_isqrt64((uint64_t)inlier2);
    if (q->offplane_q16 < inlier) {
        return SPVS_E_CONFIG;
    }
    const spvs_qf_t hundred = spvs_qf_from_i64(100, 0);
    q->t2 = spvs_qf_mul(spvs_qf_from_i64(n2c, -32 - 2 * log2_scale()),
                        spvs_qf_recip(hundred, &sat));
    q->confidence_q32 = (uint32_t)conf31 << 1;
    q->sin_tol2_q30 = (int32_t)(((int64_t)sin_tol * sin_tol) >> 30);
    q->max_iters = p->max_iters;
    q->min_support = p->min_support;
    q->seed = p->seed;
    return spvs_q_ctl_params_from_real(&q->ctl_p, &p->ctl);
}

/* ---- the fixed-point core's side of pipeline.inc ---------------------------- */

typedef spvs_q_t pl_t;
typedef spvs_q_ctl_input_t pl_input_t;
typedef spvs_q_epipole_t pl_epipole_t;
typedef int32_t pl_time_t; /* s, Q16 */
typedef int64_t pl_wide_t;
typedef int32_t pl_ex_t;   /* px, Q16 */
typedef int32_t pl_par_t;  /* px, Q16 */
typedef int32_t pl_cmd_t;  /* m/s, rad/s, Q24 */
/* update is inlined into both entry points, so neither adds a frame to
 * the update's stack. */
#define SPVS_CORE_NAME(float_name, fixed_name) fixed_name
#define PL_INLINE SPVS_Q_INLINE

static int plane_estimate(spvs_q_t *s, uint32_t *iters)
{
    return spvs_q_plane_h_estimate(&s->est, s->p.t2, s->p.confidence_q32, s->p.max_iters,
                                   &s->rng, iters);
}

/* H (scaled units, Q27) in centred pixels: the scale is a power of two, so
 * h13 in pixels is the same integer in Q(27 - log2 scale) and h31, h32 in
 * Q(27 + log2 scale). */
static void h_out(const int32_t H[9], spvs_real out[9])
{
    const int ls = log2_scale();
    for (int k = 0; k < 9; k++) {
        const int f = k == 2 ? SPVS_QH - ls : (k == 6 || k == 7 ? SPVS_QH + ls : SPVS_QH);
        out[k] = real_out(H[k], f);
    }
}

/* H_px (centred pixels, h22 = 1; row 2 taken as (0, 1, 0)) as Q27 in
 * scaled units, read through its bits: the scale is a power of two, so h13
 * in pixels is the Q27 integer read as Q(27 - log2 scale), h31 and h32 per
 * pixel as Q(27 + log2 scale) (h_out's formats the other way).  Returns 0,
 * or SPVS_Q_NONFINITE (a NaN or infinite entry of rows 1 and 3) and/or
 * SPVS_Q_SAT (an entry outside (-16, 16) in scaled units). */
static uint32_t h_in(const spvs_real H_px[9], int32_t Hq[9])
{
    const int ls = log2_scale();
    uint32_t sat = 0;
    for (int k = 0; k < 9; k++) {
        if (k >= 3 && k <= 5) {
            continue;
        }
        const int f = k == 2 ? SPVS_QH - ls : (k == 6 || k == 7 ? SPVS_QH + ls : SPVS_QH);
        Hq[k] = q_in(H_px[k], f, &sat);
        /* +-16 itself is outside (-16, 16): it would clamp to the limit. */
        sat |= (Hq[k] == SPVS_Q_I32_MAX || Hq[k] == SPVS_Q_I32_MIN) ? SPVS_Q_SAT : 0u;
    }
    Hq[3] = 0;
    Hq[4] = (int32_t)1 << SPVS_QH;
    Hq[5] = 0;
    return sat;
}

/* plane_h.c's spvs_plane_h_adopt on the Q estimator: H_px (pixels) as the
 * loaded frame's estimate, its inliers among the plane candidates by the
 * Q inlier count at the pipeline's threshold.  SPVS_OK,
 * SPVS_E_DEGENERATE for a non-finite entry (float's status), SPVS_E_RANGE
 * for an entry outside the Q27 range (the estimator's own models never
 * leave it), SPVS_E_NO_CONSENSUS for fewer than SPVS_MIN_INLIERS inliers.
 * Out of line, so that its H on the stack is not in estimate()'s frame
 * under RANSAC's deepest path. */
static SPVS_Q_NOINLINE int adopt_h(spvs_q_t *s, const spvs_real H_px[9])
{
    spvs_q_plane_h_t *const e = &s->est;
    int32_t Hq[9];
    const uint32_t sat = h_in(H_px, Hq);
    if ((sat & SPVS_Q_NONFINITE) != 0u) {
        return SPVS_E_DEGENERATE;
    }
    if (sat != 0u) {
        return SPVS_E_RANGE;
    }
    memcpy(e->H, Hq, sizeof e->H);
    e->thr = spvs_q_thr(s->p.t2);
    e->n_inliers = spvs_q_pts_score(&e->pts, e->n_plane, e->H, &e->thr, 0, e->mask);
    return e->n_inliers < SPVS_MIN_INLIERS ? SPVS_E_NO_CONSENSUS : SPVS_OK;
}

static void h_to_output(const spvs_q_t *s, spvs_output_t *out)
{
    h_out(s->est.H, out->H);
}

/* t_s in Q16 seconds: SPVS_E_NONFINITE, or SPVS_E_RANGE past 32768 s. */
static int time_in(spvs_real t_s, int32_t *t)
{
    uint32_t sat = 0;
    *t = q_in(t_s, 16, &sat);
    if ((sat & SPVS_Q_NONFINITE) != 0u) {
        return SPVS_E_NONFINITE;
    }
    return sat != 0u ? SPVS_E_RANGE : SPVS_OK;
}

static int frame_epipole(spvs_q_t *s, spvs_q_epipole_t *ep, int32_t *parallax)
{
    spvs_q_offplane_t *const o = &s->off;
    spvs_q_offplane_collect(o, &s->est, s->p.offplane_q16);
    *parallax = spvs_q_offplane_known_parallax_q16(o, s->est.H, s->scratch);
    /* The parallax's direction, for the arrival check only. */
    const int dir = s->ctl.arriving && *parallax >= 0;
    s->lateral_q16 = dir ? spvs_q_offplane_known_direction_q16(o, s->est.H, 0, s->scratch) : 0;
    s->radial_q16 =
        dir ? spvs_q_offplane_known_direction_q16(o, s->est.H, &s->lateral_q16, s->scratch) : 0;
    return spvs_q_epipole_estimate(s->est.H, (const int32_t(*)[4])o->cand_pts, o->cand_ord,
                                   o->n_cand, s->p.sin_tol2_q30, s->p.min_support, ep,
                                   o->support, &s->ework) == SPVS_OK;
}

static int32_t ep_x(const spvs_q_epipole_t *ep)
{
    return ep->e_x_q16;
}

static int32_t ep_parallax(const spvs_q_epipole_t *ep)
{
    return ep->parallax_q16;
}

static void offplane_learn(spvs_q_t *s, int e_ok, int32_t parallax)
{
    spvs_q_offplane_remember(&s->off, &s->est, e_ok, parallax, s->p.offplane_q16);
}

static void sort_ex(int32_t *v, uint16_t n)
{
    spvs_q_sort_i32(v, n);
}

static void input_epipole(spvs_q_ctl_input_t *in, int32_t x, int8_t side,
                          const spvs_q_epipole_t *ep)
{
    (void)ep;
    in->e_x = x;
    in->e_side = side;
}

/* The controller's input but for the epipole: H in Q27 scaled units. */
static void control_input(const spvs_q_t *s, spvs_q_ctl_input_t *in, int32_t t, int e_ok,
                          int32_t parallax, const spvs_output_t *out)
{
    memcpy(in->H, s->est.H, sizeof in->H);
    in->e_x = 0;
    in->e_side = 0;
    in->parallax = parallax;
    in->parallax_x = s->lateral_q16;
    in->parallax_r = s->radial_q16;
    in->t = t;
    in->e_valid = (uint8_t)e_ok;
    in->n_inliers = out->n_inliers;
}

static int32_t input_ex(const spvs_q_ctl_input_t *in)
{
    return in->e_x;
}

static int control_step(spvs_q_t *s, const spvs_q_ctl_input_t *in, int32_t *v, int32_t *w)
{
    return spvs_q_ctl_step(&s->ctl, &s->p.ctl_p, in, v, w);
}

/* A command, m/s or rad/s Q24. */
static spvs_real cmd_out(int32_t x)
{
    return real_out(x, SPVS_QCTL_CMD);
}

/* e_x, a parallax or an arrival figure, pixels Q16. */
static spvs_real px_out(int32_t x)
{
    return real_out(x, SPVS_QCTL_PX);
}

/* The arrival statistic, Q16. */
static spvs_real stat_out(int32_t x)
{
    return real_out(x, SPVS_QCTL_PX);
}

static spvs_real threshold_out(const spvs_q_t *s)
{
    uint32_t tel = 0;
    return real_out(spvs_qf_to_q32(s->p.ctl_p.arrival_k, SPVS_QCTL_PX, &tel), SPVS_QCTL_PX);
}

#include "../pipeline.inc"

int spvs_q_init(spvs_q_t *s, const spvs_params_t *p)
{
    if (s == 0 || p == 0) {
        return SPVS_E_ARG;
    }
    int rc = pipeline_rules(p);
    if (rc != SPVS_OK) {
        return rc;
    }
    rc = params_from_real(&s->p, p);
    if (rc != SPVS_OK) {
        return rc;
    }
    spvs_q_reset(s);
    return SPVS_OK;
}


void spvs_q_reset(spvs_q_t *s)
{
    SPVS_ASSERT(s != 0);
    spvs_q_ctl_reset(&s->ctl);
    spvs_rng_seed(&s->rng, s->p.seed);
    reset_frames(s);
    spvs_q_offplane_reset(&s->off);
}

int spvs_q_estimate_h(spvs_q_t *s, const spvs_match_t *m, uint16_t n, spvs_output_t *out)
{
    return estimate_only(s, m, n, out);
}

int spvs_q_update(spvs_q_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                  spvs_output_t *out)
{
    return update(s, m, n, t_s, 0, out);
}

int spvs_q_update_with_h(spvs_q_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                         const spvs_real H_px[9], spvs_output_t *out)
{
    return update_with_h(s, m, n, t_s, H_px, out);
}
