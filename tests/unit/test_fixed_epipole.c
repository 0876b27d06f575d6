/* test_fixed_epipole.c - the off-plane candidates, the off-plane memory and
 * the epipole in fixed point (firmware/src/fixed/offplane_q.c,
 * epipole_q.c) against the float stages (offplane.c, epipole.c): the
 * golden epipole cases, random frames with off-plane points between the
 * target camera and the plane, the statuses (SPVS_E_NO_PARALLAX: too few
 * candidates, all on the horizon row), an epipole at infinity, the
 * memory over sequences of frames, and the shared integer helpers
 * (transfer, square roots) against double.  Each test prints one line of
 * measured maxima (docs/FIXED.md). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "unity.h"
#include "unit_support.h"

#include "fixed/offplane_q.h"
#include "golden/golden_vectors.h"
#include "golden/golden_check.h"
#include "spvs/epipole.h"
#include "spvs/offplane.h"
#include "spvs/plane_h.h"
#include "spvs/spvs.h"
#include "synth.h"

#define S ((double)SPVS_COORD_SCALE)

/* ---- tolerances ------------------------------------------------------------ */

/* Golden cases (12 noise-free off-plane points): the Q e_x against the
 * truth within golden_check.h's float tolerance, max(0.5 px, 1e-3 |e_x|)
 * (GOLDEN_TOL_EX_*); and against the float estimate within TOL_GOLD_FQ_PX +
 * TOL_GOLD_FQ_REL |e_x|: the Q26 inputs (3.8e-6 px) and the unit
 * directions (2^-27) move e_x by far less; float's own error, cancellation
 * in l = p_cur x H p_tgt at 6e-8 of its terms, dominates. */
#define TOL_GOLD_FQ_PX 0.01
#define TOL_GOLD_FQ_REL 1e-5
/* Random frames (1 px noise): the two e_x agree within TOL_EX_PX +
 * TOL_EX_REL |e_x| where both have the same supporters: the same median
 * element(s) turned by the same angle, apart only by float's rounding of
 * the directions (above). */
#define TOL_EX_PX 0.05
#define TOL_EX_REL 1e-4
/* A candidate decided otherwise by the two builds must lie at the
 * threshold: its transfer error (double, on the Q inputs) within this of
 * offplane_px, relative: float's transfer error (6e-8 of |u| 512 px, 3e-5
 * px, 1e-5 of a 3 px threshold at worst), offplane_px rounded to Q16
 * (2^-17 px, 2.5e-6 of 3 px), the Q transfer's 7e-6 px. */
#define TOL_AT_THRESHOLD_REL 2e-5
/* Random frames whose supporters differ (a direction at the cone's edge,
 * within 1e-8 of sin_tol2 in Q): at most this share. */
#define TOL_SUPPORT_DIFFER_SHARE 0.02
/* The median parallax against float's: the supporters' transfer errors
 * in Q16 px (relative 2^-27 plus 1/2 unit, 7.6e-6 px) and float's
 * (6e-8 of |u|, 3e-5 px at 512 px). */
#define TOL_PARALLAX_PX 1e-3
/* The direction's components against float's (unit vectors). */
#define TOL_DIR 1e-5

/* The Q transfer error against double on the same Q inputs, pixels: the
 * fast path's Q28 roundings of w, g and the numerators (2^-29 each, over
 * w >= 0.45 in test_helpers' H: 2^-29 4.6 / 0.45 scaled = 1e-5 px), the
 * reciprocal's 2^-28 and du, dv's Q26 rounding (2^-27 scaled, 3.8e-6
 * px). */
#define TOL_TRANSFER_PX 1.5e-5

/* ---- helpers --------------------------------------------------------------- */

/* A float or double parameter read by its bits, as the fixed build will. */
static int32_t q_of_real(spvs_real v, int f)
{
    uint32_t sat = 0;
#if SPVS_USE_DOUBLE
    uint64_t b;
    memcpy(&b, &v, sizeof b);
    const int32_t q = spvs_q_from_ieee(spvs_q_ieee_f64(b), f, &sat, NULL);
#else
    uint32_t b;
    memcpy(&b, &v, sizeof b);
    const int32_t q = spvs_q_from_ieee(spvs_q_ieee_f32(b), f, &sat, NULL);
#endif
    TEST_ASSERT_EQUAL_INT64(0, sat);
    return q;
}

static double px_q16(int32_t v)
{
    return ldexp((double)v, -16);
}

static double q30(int32_t v)
{
    return ldexp((double)v, -30);
}

/* Both pipelines' state, static (the memory and stores are large). */
typedef struct {
    spvs_plane_h_t ef;
    spvs_q_plane_h_t eq;
    spvs_offplane_t of;
    spvs_q_offplane_t oq;
    spvs_epipole_work_t wf;
    spvs_q_epipole_work_t wq;
    spvs_real scratch_f[SPVS_MAX_OFFPLANE];
    int32_t scratch_q[SPVS_MAX_OFFPLANE];
} pipes_t;

static pipes_t g;

/* One frame's results of both pipelines. */
typedef struct {
    int rc_h;
    int rc_f, rc_q;
    spvs_epipole_t e_f;
    spvs_q_epipole_t e_q;
    int cand_equal;
    int cand_at_threshold; /* differing candidates, all at the threshold */
    int n_cand_diff;
    double at_dev; /* the largest |e / offplane_px - 1| of those points */
    double par_known_f, par_known_q;
    double par_f, par_q; /* the parallax handed to remember */
} frame_res_t;

/* The transfer error (pixels, double) of a Q row under a Q H. */
static double transfer_px_d(const int32_t H[9], const int32_t p[4])
{
    double h[9], r[4];
    for (int k = 0; k < 9; k++) {
        h[k] = ldexp((double)H[k], -SPVS_QH);
    }
    for (int k = 0; k < 4; k++) {
        r[k] = ldexp((double)p[k], -SPVS_QC);
    }
    const double w = h[6] * r[0] + h[7] * r[1] + h[8];
    if (!(w > 1e-6)) {
        return -1;
    }
    const double du = (h[0] * r[0] + h[1] * r[1] + h[2]) / w - r[2], dv = r[1] / w - r[3];
    return S * sqrt(du * du + dv * dv);
}

/* The candidates of the two builds: equal, or differing only at the
 * threshold (every point taken by one build alone has a forward or back
 * transfer error within TOL_AT_THRESHOLD_REL of offplane_px). */
static void compare_candidates(double off_px, frame_res_t *r)
{
    r->cand_equal = g.of.n_cand == g.oq.n_cand && g.of.n_cand_known == g.oq.n_cand_known &&
                    memcmp(g.of.cand, g.oq.cand, g.of.n_cand * sizeof g.of.cand[0]) == 0;
    r->cand_at_threshold = 1;
    r->n_cand_diff = 0;
    r->at_dev = 0;
    if (r->cand_equal) {
        return;
    }
    static uint8_t in_f[SPVS_MAX_MATCHES], in_q[SPVS_MAX_MATCHES];
    memset(in_f, 0, sizeof in_f);
    memset(in_q, 0, sizeof in_q);
    for (uint16_t k = 0; k < g.of.n_cand; k++) {
        in_f[g.of.cand[k]] = 1;
    }
    for (uint16_t k = 0; k < g.oq.n_cand; k++) {
        in_q[g.oq.cand[k]] = 1;
    }
    int32_t Hi[9];
    spvs_real Hf[9];
    const int has_inv = spvs_h_inverse(g.ef.H_sc, Hf) == SPVS_OK;
    if (has_inv) {
        TEST_ASSERT_EQUAL_INT64(0, spvs_q_h_from_real(Hf, Hi));
    }
    for (uint16_t i = 0; i < g.eq.n_pts; i++) {
        if (in_f[i] == in_q[i]) {
            continue;
        }
        r->n_cand_diff++;
        int32_t p[4];
        spvs_q_pts_row(&g.eq.pts, i, p);
        const int32_t b[4] = {p[2], p[3], p[0], p[1]};
        const double ef = transfer_px_d(g.eq.H, p);
        const double eb = has_inv ? transfer_px_d(Hi, b) : -1;
        const double dev = fmin(fabs(ef / off_px - 1), eb >= 0 ? fabs(eb / off_px - 1) : 1e300);
        r->cand_at_threshold &= dev <= TOL_AT_THRESHOLD_REL;
        r->at_dev = fmax(r->at_dev, dev);
    }
}

/* One frame through both pipelines as spvs.c's after_h runs them: split
 * by the memory, load, H (float's estimate; the Q pipeline takes the same
 * H in Q27 and the same inliers, so that these stages alone are
 * compared), collect, the remembered features' parallax, the epipole,
 * remember. */
static void frame_both(const spvs_match_t *m, uint16_t n, uint32_t seed, const spvs_params_t *p,
                       int q_own_h, frame_res_t *r)
{
    memset(r, 0, sizeof *r);
    const uint16_t *ord_f = NULL, *ord_q = NULL;
    uint16_t np_f = n, np_q = n;
    if (g.of.n_known != 0u) {
        np_f = spvs_offplane_split(&g.of, m, n, g.ef.idx);
        ord_f = g.ef.idx;
    }
    if (g.oq.n_known != 0u) {
        np_q = spvs_q_offplane_split(&g.oq, m, n, g.eq.idx);
        ord_q = g.eq.idx;
    }
    r->rc_h = spvs_plane_h_load(&g.ef, m, n, ord_f, np_f);
    TEST_ASSERT_EQUAL_INT64(r->rc_h, spvs_q_plane_h_load(&g.eq, m, n, ord_q, np_q));
    if (r->rc_h != SPVS_OK) {
        return;
    }
    spvs_rng_t rng;
    spvs_rng_seed(&rng, seed);
    uint32_t iters = 0;
    r->rc_h = spvs_plane_h_estimate(&g.ef, spvs_inlier_px(p), p->confidence, p->max_iters, &rng,
                                    &iters);
    if (r->rc_h != SPVS_OK) {
        return;
    }
    if (q_own_h) {
        /* The whole fixed-point chain: the Q estimator's own H and inliers
         * from the same seed. */
        uint32_t sat = 0;
        const spvs_real t = spvs_inlier_px(p) * (SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
        const spvs_qf_t t2 = spvs_q_t2_from_real(t * t, &sat);
        const uint32_t conf_q32 = (uint32_t)((double)p->confidence * 4294967296.0);
        spvs_rng_seed(&rng, seed);
        r->rc_h = spvs_q_plane_h_estimate(&g.eq, t2, conf_q32, p->max_iters, &rng, &iters);
        if (r->rc_h != SPVS_OK) {
            return;
        }
    } else {
        TEST_ASSERT_EQUAL_INT64(0, spvs_q_h_from_real(g.ef.H_sc, g.eq.H));
        memcpy(g.eq.mask, g.ef.mask, sizeof g.eq.mask);
        g.eq.n_inliers = g.ef.n_inliers;
    }

    const int32_t off_q = q_of_real(p->offplane_px, 16);
    const spvs_real sin_tol2 = p->epipole_sin_tol * p->epipole_sin_tol;
    const int32_t tol_q = q_of_real(sin_tol2, 30);
    spvs_offplane_collect(&g.of, &g.ef, p->offplane_px);
    spvs_q_offplane_collect(&g.oq, &g.eq, off_q);
    compare_candidates((double)p->offplane_px, r);

    spvs_real par_f = spvs_offplane_known_parallax_px(&g.of, g.ef.H_sc, g.scratch_f);
    int32_t par_q = spvs_q_offplane_known_parallax_q16(&g.oq, g.eq.H, g.scratch_q);
    r->par_known_f = (double)par_f;
    r->par_known_q = px_q16(par_q);
    r->rc_f = spvs_epipole_estimate(g.ef.H_sc, (const spvs_real(*)[4])g.of.cand_pts, g.of.cand_ord,
                                    g.of.n_cand, sin_tol2, p->min_support, &r->e_f, g.of.support,
                                    &g.wf);
    r->rc_q = spvs_q_epipole_estimate(g.eq.H, (const int32_t(*)[4])g.oq.cand_pts, g.oq.cand_ord,
                                      g.oq.n_cand, tol_q, p->min_support, &r->e_q, g.oq.support,
                                      &g.wq);
    if (par_f < SPVS_R(0.0) && r->rc_f == SPVS_OK) {
        par_f = r->e_f.parallax_px;
    }
    if (par_q < 0 && r->rc_q == SPVS_OK) {
        par_q = r->e_q.parallax_q16;
    }
    r->par_f = (double)par_f;
    r->par_q = px_q16(par_q);
    spvs_offplane_remember(&g.of, &g.ef, r->rc_f == SPVS_OK, par_f, p->offplane_px);
    spvs_q_offplane_remember(&g.oq, &g.eq, r->rc_q == SPVS_OK, par_q, off_q);
}

/* A random planar-motion frame (the pose and plane ranges of
 * fixed_scene.h) with n_off points off the plane between the target
 * camera and the plane (synth_frame: depth 15..40 m), sigma px of noise in
 * both images, a share `out` of the plane points mismatched. */
static uint16_t random_frame(uint64_t *rng, int n_plane, int n_off, double sigma, double out,
                             spvs_match_t *m, synth_pose_t *pose)
{
    synth_plane_t pl;
    pose->x = -6 + 12 * synth_uniform(rng);
    pose->z = -12 + 13 * synth_uniform(rng);
    pose->phi = (-45 + 90 * synth_uniform(rng)) * SYNTH_PI / 180;
    synth_plane(&pl, -0.6 + 1.2 * synth_uniform(rng), -0.8 + 1.6 * synth_uniform(rng),
                -(0.3 + synth_uniform(rng)), 30 + 30 * synth_uniform(rng));
    static uint8_t on_plane[SPVS_MAX_MATCHES];
    const uint16_t n = synth_frame(pose, &pl, 800, n_plane, n_off, sigma, rng, m, on_plane);
    for (uint16_t i = 0; i < n; i++) {
        m[i].x_tgt = (spvs_real)(m[i].x_tgt + sigma * synth_gauss(rng));
        m[i].y_tgt = (spvs_real)(m[i].y_tgt + sigma * synth_gauss(rng));
        if (on_plane[i] && synth_uniform(rng) < out) {
            m[i].x_cur = (spvs_real)((synth_uniform(rng) - 0.5) * 640);
            m[i].y_cur = (spvs_real)((synth_uniform(rng) - 0.5) * 480);
        }
    }
    return n;
}

/* ---- the shared integer helpers -------------------------------------------- */

/* spvs_q_rsqrt / spvs_q_sqrt_q52_px16 over every bit length, and the
 * transfer against double on random rows and H. */
static void test_helpers(void)
{
    uint64_t rng = 77;
    double worst_rs = 0, worst_sq = 0;
    for (int t = 0; t < 200000; t++) {
        const int b = 1 + t % 63;
        uint64_t x = ((uint64_t)(synth_uniform(&rng) * 9007199254740992.0) << 11) |
                     (uint64_t)(synth_uniform(&rng) * 2048);
        x >>= 64 - b;
        x |= (uint64_t)1 << (b - 1);
        int half;
        uint32_t f;
        const uint32_t y = spvs_q_rsqrt(x, &half, &f);
        const double ref = 1 / sqrtl((long double)x);
        const double got = ldexp((double)y, -30 - half);
        worst_rs = fmax(worst_rs, fabs(got / ref - 1));
        const double sq = px_q16(spvs_q_sqrt_q52_px16(x));
        const double sref = (double)(sqrtl((long double)x) * 0x1p-26L) * S;
        /* Relative 2^-27 plus 1/2 unit of Q16. */
        worst_sq = fmax(worst_sq, fabs(sq - sref) / (sref * 0x1p-27 + 0x1p-17));
    }
    double worst_tr = 0;
    for (int t = 0; t < 100000; t++) {
        int32_t H[9] = {0}, p[4];
        const double h[9] = {0.6 + 0.8 * synth_uniform(&rng), 0.2 * (synth_uniform(&rng) - 0.5),
                             2 * (synth_uniform(&rng) - 0.5), 0, 1, 0,
                             0.5 * (synth_uniform(&rng) - 0.5), 0.2 * (synth_uniform(&rng) - 0.5),
                             0.7 + 0.6 * synth_uniform(&rng)};
        for (int k = 0; k < 9; k++) {
            H[k] = (int32_t)lrint(ldexp(h[k], SPVS_QH));
        }
        for (int k = 0; k < 4; k++) {
            p[k] = (int32_t)lrint(ldexp((synth_uniform(&rng) - 0.5) * (k % 2 ? 0.94 : 1.25), 26));
        }
        const double ref = transfer_px_d(H, p);
        const int64_t e2 = spvs_q_transfer_err2(H, p);
        TEST_ASSERT_TRUE((e2 < 0) == (ref < 0));
        if (e2 < 0) {
            continue;
        }
        const double got = sqrt(ldexp((double)e2, -52)) * S;
        worst_tr = fmax(worst_tr, fabs(got - ref));
    }
    UNIT_NOTE("helpers: rsqrt relative error %.3g (2^%.1f); sqrt to Q16 px %.3g of its bound; "
                  "transfer error in the image %.3g px\n", worst_rs, log2(worst_rs), worst_sq, worst_tr);
    TEST_ASSERT_TRUE(worst_rs <= 0x1p-27);
    TEST_ASSERT_TRUE(worst_sq <= 1.0);
    TEST_ASSERT_TRUE(worst_tr <= TOL_TRANSFER_PX);
}

/* ---- the golden epipole cases ---------------------------------------------- */

static void test_epipole_golden(void)
{
    static spvs_epipole_work_t wf;
    static spvs_q_epipole_work_t wq;
    double worst_truth = 0, worst_fq = 0, worst_truth_f = 0;
    const int32_t tol_q = q_of_real(GOLDEN_EPI_SIN_TOL2, 30);
    for (int c = 0; c < SPVS_GOLDEN_N_E; c++) {
        const spvs_golden_e_t *ge = &spvs_golden_e[c];
        spvs_real pts[SPVS_GOLDEN_N_OFF][4], H[9];
        int32_t qp[SPVS_GOLDEN_N_OFF][4], Hq[9];
        uint16_t cand[SPVS_GOLDEN_N_OFF];
        uint8_t sup_f[SPVS_GOLDEN_N_OFF], sup_q[SPVS_GOLDEN_N_OFF];
        golden_to_scaled(ge->pts, SPVS_GOLDEN_N_OFF, pts);
        for (int i = 0; i < SPVS_GOLDEN_N_OFF; i++) {
            for (int k = 0; k < 4; k++) {
                qp[i][k] = (int32_t)lrint(ldexp(ge->pts[i][k] / S, SPVS_QC));
            }
            cand[i] = (uint16_t)i;
        }
        golden_h_copy(ge->H, H);
        spvs_h_rescale(H, SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
        const double hs[9] = {ge->H[0], ge->H[1], ge->H[2] / S, 0, 1, 0,
                              ge->H[6] * S, ge->H[7] * S, ge->H[8]};
        for (int k = 0; k < 9; k++) {
            Hq[k] = (int32_t)lrint(ldexp(hs[k], SPVS_QH));
        }
        spvs_epipole_t ef;
        spvs_q_epipole_t eq;
        const int rc_f = spvs_epipole_estimate(H, (const spvs_real(*)[4])pts, cand,
                                               SPVS_GOLDEN_N_OFF, GOLDEN_EPI_SIN_TOL2,
                                               GOLDEN_EPI_MIN_SUPPORT, &ef, sup_f, &wf);
        const int rc_q = spvs_q_epipole_estimate(Hq, (const int32_t(*)[4])qp, cand,
                                                 SPVS_GOLDEN_N_OFF, tol_q, GOLDEN_EPI_MIN_SUPPORT,
                                                 &eq, sup_q, &wq);
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, rc_f);
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, rc_q);
        const double truth = ge->e_x_px, exq = px_q16(eq.e_x_q16);
        const double tol_truth = fmax((double)GOLDEN_TOL_EX_PX, (double)GOLDEN_TOL_EX_REL * fabs(truth));
        TEST_ASSERT_TRUE(fabs(exq - truth) <= tol_truth);
        TEST_ASSERT_TRUE(fabs(exq - (double)ef.e_x_px) <= TOL_GOLD_FQ_PX + TOL_GOLD_FQ_REL * fabs(truth));
        TEST_ASSERT_EQUAL_INT64(ge->e_cam[2] > 0, eq.dir_z > 0);
        TEST_ASSERT_EQUAL_INT64(ef.n_support, eq.n_support);
        TEST_ASSERT_EQUAL_INT64(SPVS_GOLDEN_N_OFF, eq.n_support);
        TEST_ASSERT_EQUAL_MEMORY(sup_q, sup_f, sizeof sup_f);
        worst_truth = fmax(worst_truth, fabs(exq - truth));
        worst_truth_f = fmax(worst_truth_f, fabs((double)ef.e_x_px - truth));
        worst_fq = fmax(worst_fq, fabs(exq - (double)ef.e_x_px));
    }
    UNIT_NOTE("epipole golden: %d cases, e_x against the truth: Q %.3g px, float %.3g px; Q "
                  "against float %.3g px; signs and supports equal\n", SPVS_GOLDEN_N_E, worst_truth, worst_truth_f, worst_fq);
}

/* ---- random frames --------------------------------------------------------- */

#define N_FRAMES 600

static void test_epipole_random(void)
{
    static spvs_match_t m[SPVS_MAX_MATCHES];
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    uint64_t rng = 4242;
    int frames = 0, cand_differ = 0, cand_pts_differ = 0, no_par = 0, ok = 0, clamped = 0;
    int sup_differ = 0, behind = 0;
    double worst_ex = 0, worst_ex_rel = 0, worst_par = 0, worst_dir = 0;
    long n_cand = 0;
    for (int c = 0; c < N_FRAMES; c++) {
        synth_pose_t pose;
        /* Every 8th frame has 0-2 off-plane points: too few supporters. */
        const int n_off = (c % 8 == 0) ? (int)(synth_uniform(&rng) * 3) : 3 + (int)(synth_uniform(&rng) * 40);
        const int n_plane = 30 + (int)(synth_uniform(&rng) * 180);
        const uint16_t n = random_frame(&rng, n_plane, n_off, 1.0, 0.3 * synth_uniform(&rng), m, &pose);
        spvs_offplane_reset(&g.of);
        spvs_q_offplane_reset(&g.oq);
        frame_res_t r;
        frame_both(m, n, (uint32_t)(100 + c), &p, 0, &r);
        if (r.rc_h != SPVS_OK) {
            continue;
        }
        frames++;
        n_cand += g.oq.n_cand;
        TEST_ASSERT_TRUE(r.cand_at_threshold);
        if (!r.cand_equal) {
            cand_differ++;
            cand_pts_differ += r.n_cand_diff;
            continue;
        }
        TEST_ASSERT_EQUAL_INT64(r.rc_q, r.rc_f);
        if (r.rc_f != SPVS_OK) {
            TEST_ASSERT_EQUAL_INT64(SPVS_E_NO_PARALLAX, r.rc_q);
            no_par++;
            continue;
        }
        ok++;
        if (r.e_f.n_support != r.e_q.n_support ||
            memcmp(g.of.support, g.oq.support, g.of.n_cand) != 0) {
            sup_differ++;
            continue;
        }
        const double exf = (double)r.e_f.e_x_px, exq = px_q16(r.e_q.e_x_q16);
        TEST_ASSERT_TRUE(fabs(exq - exf) <= TOL_EX_PX + TOL_EX_REL * fabs(exf));
        TEST_ASSERT_EQUAL_INT64(r.e_f.dir_z > 0, r.e_q.dir_z > 0);
        clamped += fabs(exf) >= 20000;
        behind += r.e_q.dir_z < 0;
        if (fabs(exf) < 2000) {
            worst_ex = fmax(worst_ex, fabs(exq - exf));
        } else {
            worst_ex_rel = fmax(worst_ex_rel, fabs(exq - exf) / fabs(exf));
        }
        worst_dir = fmax(worst_dir, fmax(fabs(q30(r.e_q.dir_x) - (double)r.e_f.dir_x),
                                         fabs(q30(r.e_q.dir_z) - (double)r.e_f.dir_z)));
        worst_par = fmax(worst_par, fabs(px_q16(r.e_q.parallax_q16) - (double)r.e_f.parallax_px));
    }
    UNIT_NOTE("epipole random: %d frames, %ld candidates; candidate lists differ in %d frames "
                  "(%d points, all at the threshold); statuses equal: %d SPVS_OK, %d "
                  "SPVS_E_NO_PARALLAX; supporters differ in %d; e_x apart %.3g px (|e_x| < 2000 "
                  "px), %.3g relative beyond; dir %.3g, parallax %.3g px; %d behind, %d clamped\n", frames, n_cand, cand_differ, cand_pts_differ, ok, no_par, sup_differ, worst_ex, worst_ex_rel, worst_dir, worst_par, behind, clamped);
    TEST_ASSERT_TRUE(frames > N_FRAMES / 2);
    TEST_ASSERT_TRUE(no_par >= N_FRAMES / 16);
    TEST_ASSERT_TRUE(ok >= N_FRAMES / 2);
    TEST_ASSERT_TRUE((double)sup_differ <= TOL_SUPPORT_DIFFER_SHARE * ok);
    TEST_ASSERT_TRUE(worst_dir <= TOL_DIR);
    TEST_ASSERT_TRUE(worst_par <= TOL_PARALLAX_PX);
}

/* The collect at its threshold: offplane_px set to each rejected point's
 * own float transfer error in turn (its forward error, the larger
 * decision), so that the point lies on the threshold in float; the two
 * builds may decide it either way, and any other point only within
 * TOL_AT_THRESHOLD_REL of it. */
static void test_collect_threshold(void)
{
    static spvs_match_t m[SPVS_MAX_MATCHES];
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    uint64_t rng = 555;
    int runs = 0, differ = 0, pts_differ = 0, frames = 0;
    double worst_dev = 0;
    for (int c = 0; c < 40; c++) {
        synth_pose_t pose;
        const uint16_t n = random_frame(&rng, 120, 30, 1.0, 0.2, m, &pose);
        if (spvs_plane_h_load(&g.ef, m, n, NULL, 0) != SPVS_OK) {
            continue;
        }
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_plane_h_load(&g.eq, m, n, NULL, 0));
        spvs_rng_t r;
        spvs_rng_seed(&r, (uint32_t)c);
        uint32_t iters = 0;
        if (spvs_plane_h_estimate(&g.ef, spvs_inlier_px(&p), p.confidence, p.max_iters, &r,
                                  &iters) != SPVS_OK) {
            continue;
        }
        frames++;
        TEST_ASSERT_EQUAL_INT64(0, spvs_q_h_from_real(g.ef.H_sc, g.eq.H));
        memcpy(g.eq.mask, g.ef.mask, sizeof g.eq.mask);
        for (uint16_t i = 0; i < g.ef.n_plane; i++) {
            spvs_real row[4];
            spvs_pts_row(&g.ef.pts, i, row);
            const spvs_real e2 = spvs_h_transfer_err2(g.ef.H_sc, row);
            if (g.ef.mask[i] || !(e2 > SPVS_R(0.0))) {
                continue;
            }
            const spvs_real off = (spvs_real)SPVS_COORD_SCALE * SPVS_SQRT(e2);
            spvs_offplane_reset(&g.of);
            spvs_q_offplane_reset(&g.oq);
            spvs_offplane_collect(&g.of, &g.ef, off);
            spvs_q_offplane_collect(&g.oq, &g.eq, q_of_real(off, 16));
            frame_res_t fr;
            compare_candidates((double)off, &fr);
            TEST_ASSERT_TRUE(fr.cand_at_threshold);
            runs++;
            differ += !fr.cand_equal;
            pts_differ += fr.n_cand_diff;
            worst_dev = fmax(worst_dev, fr.at_dev);
        }
    }
    UNIT_NOTE("collect at the threshold: %d frames, %d collects with offplane_px at a point's "
                  "own transfer error; candidate lists differ in %d (%d points), the farthest "
                  "%.2g of offplane_px from it\n", frames, runs, differ, pts_differ, worst_dev);
    TEST_ASSERT_TRUE(runs >= 200);
}

/* The whole fixed-point chain (the Q estimator's H and inliers, then the Q
 * stages) against the float chain on the frames of test_epipole_random:
 * the estimators part only where RANSAC takes another path
 * (test_fixed_plane_h), so the epipoles agree on most frames. */
#define TOL_CHAIN_AGREE_SHARE 0.9
#define TOL_CHAIN_PX 0.5

static void test_epipole_chain(void)
{
    static spvs_match_t m[SPVS_MAX_MATCHES];
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    uint64_t rng = 4242;
    int both_ok = 0, agree = 0, status_differ = 0;
    for (int c = 0; c < N_FRAMES; c++) {
        synth_pose_t pose;
        const int n_off = (c % 8 == 0) ? (int)(synth_uniform(&rng) * 3) : 3 + (int)(synth_uniform(&rng) * 40);
        const int n_plane = 30 + (int)(synth_uniform(&rng) * 180);
        const uint16_t n = random_frame(&rng, n_plane, n_off, 1.0, 0.3 * synth_uniform(&rng), m, &pose);
        spvs_offplane_reset(&g.of);
        spvs_q_offplane_reset(&g.oq);
        frame_res_t r;
        frame_both(m, n, (uint32_t)(100 + c), &p, 1, &r);
        if (r.rc_h != SPVS_OK) {
            continue;
        }
        status_differ += r.rc_f != r.rc_q;
        if (r.rc_f != SPVS_OK || r.rc_q != SPVS_OK) {
            continue;
        }
        both_ok++;
        const double exf = (double)r.e_f.e_x_px, exq = px_q16(r.e_q.e_x_q16);
        agree += fabs(exq - exf) <= TOL_CHAIN_PX + TOL_EX_REL * fabs(exf) &&
                 (r.e_q.dir_z > 0) == (r.e_f.dir_z > 0);
    }
    UNIT_NOTE("epipole chain: %d frames with an epipole in both, e_x within %.1f px (+ %.0e "
                  "rel) and the same side in %d (%.1f %%); statuses differ in %d\n", both_ok, TOL_CHAIN_PX, TOL_EX_REL, agree, 100.0 * agree / both_ok, status_differ);
    TEST_ASSERT_TRUE(both_ok >= N_FRAMES / 2);
    TEST_ASSERT_TRUE(agree >= TOL_CHAIN_AGREE_SHARE * both_ok);
}

/* ---- statuses and the epipole at infinity ---------------------------------- */

static void test_epipole_statuses(void)
{
    static spvs_epipole_work_t wf;
    static spvs_q_epipole_work_t wq;
    static spvs_match_t m[64];
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    /* Side-on: the current camera 3 m to the side of the target, the same
     * heading: e = -R c = (-3, 0, 0), at infinity. */
    const synth_pose_t side = {3.0, 0.0, 0.0};
    uint64_t rng = 99;
    const uint16_t n = synth_frame(&side, &pl, 800, 0, 30, 0.0, &rng, m, NULL);
    double Hd[9];
    synth_H(&side, &pl, 800, Hd);
    spvs_real H[9], pts[64][4];
    int32_t Hq[9], qp[64][4];
    uint16_t cand[64];
    for (int k = 0; k < 9; k++) {
        H[k] = (spvs_real)Hd[k];
    }
    spvs_h_rescale(H, SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
    TEST_ASSERT_EQUAL_INT64(0, spvs_q_h_from_real(H, Hq));
    for (uint16_t i = 0; i < n; i++) {
        const double v[4] = {m[i].x_tgt, m[i].y_tgt, m[i].x_cur, m[i].y_cur};
        for (int k = 0; k < 4; k++) {
            pts[i][k] = (spvs_real)(v[k] / S);
            qp[i][k] = (int32_t)lrint(ldexp(v[k] / S, SPVS_QC));
        }
        cand[i] = i;
    }
    const int32_t tol_q = q_of_real(SPVS_R(0.01), 30);
    spvs_epipole_t ef;
    spvs_q_epipole_t eq;
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_epipole_estimate(H, (const spvs_real(*)[4])pts, cand, n, SPVS_R(0.01), 3,
                                           &ef, NULL, &wf));
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_epipole_estimate(Hq, (const int32_t(*)[4])qp, cand, n, tol_q, 3, &eq,
                                             NULL, &wq));
    /* Clamped to the same side: e_x = -3 / 0 from the left (e1 < 0). */
    TEST_ASSERT_EQUAL_INT64(ef.e_x_px > 0 ? SPVS_Q_EPIPOLE_MAX_Q16 : -SPVS_Q_EPIPOLE_MAX_Q16, eq.e_x_q16);
    TEST_ASSERT_TRUE(fabs((double)ef.e_x_px) == 20000.0);
    const double dz_inf = q30(eq.dir_z);
    TEST_ASSERT_TRUE(fabs(dz_inf) < 1e-6);
    TEST_ASSERT_TRUE(fabs(fabs(q30(eq.dir_x)) - 1) < 1e-7);
    TEST_ASSERT_EQUAL_INT64(ef.n_support, eq.n_support);
    const double ex_inf = px_q16(eq.e_x_q16);

    /* Two candidates with three supporters needed. */
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NO_PARALLAX, spvs_epipole_estimate(H, (const spvs_real(*)[4])pts, cand, 2, SPVS_R(0.01), 3,
                                           &ef, NULL, &wf));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NO_PARALLAX, spvs_q_epipole_estimate(Hq, (const int32_t(*)[4])qp, cand, 2, tol_q, 3, &eq,
                                             NULL, &wq));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NO_PARALLAX, spvs_q_epipole_estimate(Hq, (const int32_t(*)[4])qp, cand, 0, tol_q, 1, &eq,
                                             NULL, &wq));
    /* All on the horizon row: no line says anything. */
    for (uint16_t i = 0; i < n; i++) {
        pts[i][1] = pts[i][3] = SPVS_R(0.0);
        qp[i][1] = qp[i][3] = 0;
    }
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NO_PARALLAX, spvs_epipole_estimate(H, (const spvs_real(*)[4])pts, cand, n, SPVS_R(0.01), 3,
                                           &ef, NULL, &wf));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_NO_PARALLAX, spvs_q_epipole_estimate(Hq, (const int32_t(*)[4])qp, cand, n, tol_q, 3, &eq,
                                             NULL, &wq));
    /* Arguments. */
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_q_epipole_estimate(NULL, (const int32_t(*)[4])qp, cand, n, tol_q, 3, &eq,
                                             NULL, &wq));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_q_epipole_estimate(Hq, (const int32_t(*)[4])qp, cand,
                                             SPVS_MAX_OFFPLANE + 1, tol_q, 3, &eq, NULL, &wq));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, spvs_q_epipole_estimate(Hq, (const int32_t(*)[4])qp, cand, n, tol_q, 0, &eq,
                                             NULL, &wq));
    UNIT_NOTE("epipole statuses: at infinity both clamped to %+.0f px, Q dir_z %.2g; too few "
                  "candidates and the horizon row SPVS_E_NO_PARALLAX in both\n", ex_inf, dz_inf);
}

/* ---- the memory over sequences --------------------------------------------- */

#define N_SEQ 12
#define SEQ_FRAMES 30
#define SEQ_PLANE 120
#define SEQ_OFF 30

/* A sequence: fixed world points (plane and off-plane, features 0..n-1),
 * seen from poses along a line towards the target, 0.7 px of noise in
 * the current image, 10 % of the plane matches mismatched each frame.
 * After every frame both memories must be equal. */
static void test_memory_sequences(void)
{
    static spvs_match_t m[SPVS_MAX_MATCHES];
    static double X[SEQ_PLANE + SEQ_OFF][3], uv[SEQ_PLANE + SEQ_OFF][2];
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    uint64_t rng = 31337;
    int frames = 0, known_max = 0, frames_known = 0, cand_differ = 0;
    double worst_known_par = 0;
    for (int s = 0; s < N_SEQ; s++) {
        synth_plane_t pl;
        synth_plane(&pl, -0.3 + 0.6 * synth_uniform(&rng), -0.5 + synth_uniform(&rng), -1.0,
                    40 + 10 * synth_uniform(&rng));
        int nw = 0;
        for (int i = 0; i < SEQ_PLANE + SEQ_OFF; i++) {
            const double u = (synth_uniform(&rng) - 0.5) * 560, v = (synth_uniform(&rng) - 0.5) * 400;
            if (i < SEQ_PLANE) {
                if (!synth_plane_point(&pl, 800, u, v, X[nw])) {
                    continue;
                }
            } else {
                const double z = 12 + 20 * synth_uniform(&rng);
                X[nw][0] = u / 800 * z;
                X[nw][1] = v / 800 * z;
                X[nw][2] = z;
            }
            uv[nw][0] = u;
            uv[nw][1] = v;
            nw++;
        }
        const synth_pose_t start = {-4 + 8 * synth_uniform(&rng), -10 + 3 * synth_uniform(&rng),
                                    (-25 + 50 * synth_uniform(&rng)) * SYNTH_PI / 180};
        spvs_offplane_reset(&g.of);
        spvs_q_offplane_reset(&g.oq);
        for (int f = 0; f < SEQ_FRAMES; f++) {
            const double a = (double)f / SEQ_FRAMES;
            const synth_pose_t pose = {start.x * (1 - a), start.z * (1 - a), start.phi * (1 - a)};
            uint16_t n = 0;
            for (int i = 0; i < nw; i++) {
                double pc[2];
                if (!synth_project(&pose, 800, X[i], pc) || fabs(pc[0]) > 600 || fabs(pc[1]) > 450) {
                    continue;
                }
                m[n].x_tgt = (spvs_real)uv[i][0];
                m[n].y_tgt = (spvs_real)uv[i][1];
                m[n].x_cur = (spvs_real)(pc[0] + 0.7 * synth_gauss(&rng));
                m[n].y_cur = (spvs_real)(pc[1] + 0.7 * synth_gauss(&rng));
                if (i < SEQ_PLANE && synth_uniform(&rng) < 0.1) {
                    m[n].x_cur = (spvs_real)((synth_uniform(&rng) - 0.5) * 640);
                    m[n].y_cur = (spvs_real)((synth_uniform(&rng) - 0.5) * 480);
                }
                m[n].feature = (uint16_t)i;
                n++;
            }
            frame_res_t r;
            frame_both(m, n, (uint32_t)(7 * s + f), &p, 0, &r);
            if (r.rc_h != SPVS_OK) {
                continue;
            }
            frames++;
            TEST_ASSERT_TRUE(r.cand_at_threshold);
            cand_differ += !r.cand_equal;
            TEST_ASSERT_EQUAL_INT64(r.rc_q, r.rc_f);
            TEST_ASSERT_EQUAL_MEMORY(g.oq.score, g.of.score, sizeof g.of.score);
            TEST_ASSERT_EQUAL_INT64(g.oq.n_known, g.of.n_known);
            if (r.par_known_f < 0 && r.par_known_q < 0) {
                /* None in view: -1 px in both. */
                TEST_ASSERT_TRUE(r.par_known_f == -1.0 && r.par_known_q == -1.0);
            } else {
                TEST_ASSERT_TRUE(r.par_known_f >= 0 && r.par_known_q >= 0);
                worst_known_par = fmax(worst_known_par, fabs(r.par_known_q - r.par_known_f));
                frames_known++;
            }
            known_max = g.oq.n_known > known_max ? g.oq.n_known : known_max;
        }
    }
    UNIT_NOTE("memory: %d sequences, %d frames, memories equal after every frame; up to %d "
                  "features known, %d frames with remembered candidates, their parallax apart "
                  "%.3g px; candidate lists differ in %d frames; inverse out of Q27 range in %u\n", N_SEQ, frames, known_max, frames_known, worst_known_par, cand_differ, (unsigned)g.oq.hi_out_of_range);
    TEST_ASSERT_TRUE(frames >= N_SEQ * SEQ_FRAMES / 2);
    TEST_ASSERT_TRUE(known_max >= 5);
    TEST_ASSERT_TRUE(frames_known >= frames / 2);
    TEST_ASSERT_TRUE(worst_known_par <= TOL_PARALLAX_PX);
}

void suite_fixed_epipole(void)
{
    UNIT_SUITE_FILE();
    RUN_TEST(test_helpers);
    RUN_TEST(test_epipole_golden);
    RUN_TEST(test_epipole_statuses);
    RUN_TEST(test_collect_threshold);
    RUN_TEST(test_epipole_random);
    RUN_TEST(test_epipole_chain);
    RUN_TEST(test_memory_sequences);
}

UNIT_MAIN(suite_fixed_epipole)
