/*
 * test_fixed_spvs.c - the fixed-point pipeline's spvs_update_with_h and
 * spvs_inlier_px (fixed/spvs_q.h).
 *
 * In the fixed-point build (SPVS_FIXED=ON) through spvs.h's names, which
 * are the Q pipeline there; in the float build through spvs_q_*, beside
 * the float core, where the Q pipeline is also held against the float
 * core's spvs_update_with_h fed the same H:
 *
 *   - the H that the Q update estimated on a frame, read back from its
 *     output, given to spvs_update_with_h: the same step and status,
 *     commands within TOL_READBACK (the output's H is float32; bit for bit
 *     in the double build), on fresh controllers and over whole
 *     closed-loop runs;
 *   - (float build) the float and the Q spvs_update_with_h on the frames of
 *     float closed-loop runs, both given the float core's estimate: the
 *     same steps and statuses on every frame, commands within TOL_TWIN_*;
 *   - a NaN, infinite or out-of-range H: its status and (v, w) = (0, 0);
 *   - spvs_inlier_px against the exact threshold and, in float32, the
 *     float arithmetic's value bit for bit.
 */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "unity.h"
#include "unit_support.h"

#include "spvs/spvs.h"
#include "synth.h"
#include "synth_scene.h"

#if SPVS_USE_FIXED
/* The fixed-point build: spvs.h's pipeline is the Q pipeline. */
typedef spvs_t q_inst_t;
#define q_init spvs_init
#define q_update spvs_update
#define q_update_with_h spvs_update_with_h
#define q_inlier_px spvs_inlier_px
#else
#include "fixed/spvs_q.h"
typedef spvs_q_t q_inst_t;
#define q_init spvs_q_init
#define q_update spvs_q_update
#define q_update_with_h spvs_q_update_with_h
#define q_inlier_px spvs_q_inlier_px
#endif

#define DEG (SYNTH_PI / 180.0)
#define DT_S 0.1
#define MAX_FRAMES 1500
#define SIGMA_PX 0.5
#define MISMATCH 0.1

/* The estimated H read back from the output is float32 (the output's
 * scalar): each Q27 entry rounded to 24 bits, 2^-24 relative, where the
 * pipeline held it to 2^-27 of one.  Given back, the inliers, the
 * epipole and the control step see H moved by that much; the commands
 * move by gains (up to 40) times that: below 1e-5 m/s, rad/s. */
#define TOL_READBACK 1e-5

/* Q against float on the same H and frames: H enters the Q pipeline
 * rounded to 2^-27 (scaled units), the epipole's e_x differs by up to
 * 0.0057 px on random frames (docs/FIXED.md), the control step's commands
 * by 1e-5 (test_fixed_control's TOL_CMD). */
#define TOL_TWIN_V 2e-5
#define TOL_TWIN_W 2e-5

/* A frame's matches beyond this many pixels from the centre are left out. */
#define FRAME_LIM_PX 2000.0

/* The simulator's default scene (plane (0.3, -0.6, -0.75) at 45 m) with
 * noise sigma in the target image, drawn once. */
static void scene_default(synth_scene_t *s, uint64_t *rng, double sigma)
{
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    synth_scene_make(s, &pl, rng, sigma);
}

/* Eq. (7), the command held over the frame. */
static void plant(synth_pose_t *p, const spvs_output_t *out)
{
    p->x += -(double)out->v * sin(p->phi) * DT_S;
    p->z += (double)out->v * cos(p->phi) * DT_S;
    p->phi += (double)out->w * DT_S;
}

static const double starts[4][3] = {{-3, -10, -30}, {0, -8, -40}, {6, -6, 0}, {5, 2, -50}};

static void params(spvs_params_t *p, spvs_method_t method)
{
    spvs_params_default(p, method);
    p->noise_px = (spvs_real)SIGMA_PX;
}

static spvs_real nan_real(void)
{
    volatile spvs_real zero = SPVS_R(0.0);
    return zero / zero;
}

static spvs_real inf_real(void)
{
    volatile spvs_real zero = SPVS_R(0.0);
    return SPVS_R(1.0) / zero;
}

/* ---- (a) the estimate read back and given again ------------------------ */

typedef struct {
    int frames;      /* frames with an estimate, compared                     */
    int failed;      /* frames without one (both stopped)                     */
    int moving;      /* frames with a nonzero command                         */
    int cmd_equal;   /* frames whose commands are the same bits               */
    int inl_differ;  /* frames whose inlier counts differ                     */
    int step_differ; /* frames whose steps or statuses differ                 */
    double dv, dw;   /* largest command gaps                                  */
    int done;        /* runs ending in SPVS_STEP_DONE                         */
} readback_t;

static void readback_frame(readback_t *r, int rc_a, const spvs_output_t *oa, int rc_b,
                           const spvs_output_t *ob)
{
    r->frames++;
    if (rc_a != rc_b || oa->step != ob->step) {
        r->step_differ++;
    }
    if (oa->n_inliers != ob->n_inliers) {
        r->inl_differ++;
    }
    if (oa->v != 0 || oa->w != 0) {
        r->moving++;
    }
    if (oa->v == ob->v && oa->w == ob->w) {
        r->cmd_equal++;
    }
    r->dv = fmax(r->dv, fabs((double)oa->v - (double)ob->v));
    r->dw = fmax(r->dw, fabs((double)oa->w - (double)ob->w));
}

/* A runs spvs_update and drives the robot; B runs spvs_update_with_h on
 * the same frames with A's H.  Where A has no estimate, B is given a NaN
 * H, so both instances pass the same frame times and stop. */
static void readback_run(spvs_method_t method, const double start[3], uint64_t seed,
                         readback_t *r)
{
    static q_inst_t a, b;
    static synth_scene_t sc;
    static spvs_match_t m[SPVS_MAX_MATCHES];
    uint64_t rng = 0x9e3779b97f4a7c15ull ^ seed;
    scene_default(&sc, &rng, SIGMA_PX);
    spvs_params_t prm;
    params(&prm, method);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, q_init(&a, &prm));
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, q_init(&b, &prm));
    synth_pose_t pose = {start[0], start[1], start[2] * DEG};
    const spvs_real nan_h[9] = {nan_real(), 0, 0, 0, 1, 0, 0, 0, 1};
    spvs_output_t oa, ob;
    for (int k = 0; k < MAX_FRAMES; k++) {
        const uint16_t n = synth_scene_frame(&sc, &pose, SIGMA_PX, MISMATCH, FRAME_LIM_PX, &rng, m);
        const spvs_real t = (spvs_real)(k * DT_S);
        const int rc_a = q_update(&a, m, n, t, &oa);
        if (oa.h_valid) {
            const int rc_b = q_update_with_h(&b, m, n, t, oa.H, &ob);
            readback_frame(r, rc_a, &oa, rc_b, &ob);
        } else {
            const int rc_b = q_update_with_h(&b, m, n, t, nan_h, &ob);
            TEST_ASSERT_TRUE(rc_a != SPVS_OK && rc_b == SPVS_E_DEGENERATE);
            TEST_ASSERT_TRUE(oa.v == 0 && oa.w == 0 && ob.v == 0 && ob.w == 0);
            r->failed++;
        }
        plant(&pose, &oa);
        if (oa.step == SPVS_STEP_DONE || oa.step == SPVS_STEP_FAILED) {
            break;
        }
    }
    r->done += oa.step == SPVS_STEP_DONE;
}

static void test_readback_closed_loop(void)
{
    readback_t r;
    memset(&r, 0, sizeof r);
    for (int method = 1; method <= 3; method++) {
        for (int i = 0; i < 4; i++) {
            readback_run((spvs_method_t)method, starts[i], (uint64_t)(10 * method + i), &r);
        }
    }
    UNIT_NOTE("readback: %d runs, %d done; %d frames compared (%d moving, %d without H), "
           "commands equal bit for bit on %d, |dv| %.3g m/s, |dw| %.3g rad/s; inlier counts "
           "differ on %d, steps or statuses on %d\n", 12, r.done, r.frames, r.moving, r.failed, r.cmd_equal, r.dv, r.dw, r.inl_differ, r.step_differ);
    TEST_ASSERT_EQUAL_INT64(0, r.step_differ);
    TEST_ASSERT_TRUE(r.dv <= TOL_READBACK && r.dw <= TOL_READBACK);
    TEST_ASSERT_TRUE(r.moving > 1000);
    TEST_ASSERT_TRUE(r.done >= 10);
}

/* Two fresh controllers at poses along the way from each start: three
 * frames 0.1 s apart (a controller commands a stop on its first two
 * frames, while the epipole's side and the gain signs settle), A
 * estimating, B given A's estimate of each. */
static void test_readback_fresh(void)
{
    static q_inst_t a, b;
    static synth_scene_t sc;
    static spvs_match_t m[SPVS_MAX_MATCHES];
    readback_t r;
    memset(&r, 0, sizeof r);
    for (int method = 1; method <= 3; method++) {
        uint64_t rng = 0x51ed270b27a1f3c5ull ^ (uint64_t)method;
        scene_default(&sc, &rng, SIGMA_PX);
        spvs_params_t prm;
        params(&prm, (spvs_method_t)method);
        for (int i = 0; i < 4; i++) {
            for (int j = 0; j < 10; j++) {
                const double f = 1.0 - j / 10.0;
                synth_pose_t pose = {starts[i][0] * f, starts[i][1] * f, starts[i][2] * f * DEG};
                TEST_ASSERT_EQUAL_INT64(SPVS_OK, q_init(&a, &prm));
                TEST_ASSERT_EQUAL_INT64(SPVS_OK, q_init(&b, &prm));
                for (int k = 0; k < 3; k++) {
                    const uint16_t n =
                        synth_scene_frame(&sc, &pose, SIGMA_PX, MISMATCH, FRAME_LIM_PX, &rng, m);
                    const spvs_real t = (spvs_real)(1.0 + k * DT_S);
                    spvs_output_t oa, ob;
                    const int rc_a = q_update(&a, m, n, t, &oa);
                    TEST_ASSERT_TRUE(oa.h_valid);
                    const int rc_b = q_update_with_h(&b, m, n, t, oa.H, &ob);
                    readback_frame(&r, rc_a, &oa, rc_b, &ob);
                    TEST_ASSERT_EQUAL_INT64(1, ob.h_valid);
                    TEST_ASSERT_EQUAL_INT64(0, ob.ransac_iters);
                    plant(&pose, &oa);
                }
            }
        }
    }
    UNIT_NOTE("fresh: %d frames (%d moving): commands equal bit for bit on %d, |dv| %.3g m/s, "
           "|dw| %.3g rad/s; inlier counts differ on %d, steps or statuses on %d\n", r.frames, r.moving, r.cmd_equal, r.dv, r.dw, r.inl_differ, r.step_differ);
    TEST_ASSERT_EQUAL_INT64(0, r.step_differ);
    TEST_ASSERT_TRUE(r.dv <= TOL_READBACK && r.dw <= TOL_READBACK);
    TEST_ASSERT_TRUE(r.moving >= 100);
}

/* ---- bad H: its status and a stop ------------------------------------- */

/* A moving controller (three frames with the true H), then a frame with H:
 * its status, and a stop. */
static void bad_h_case(const spvs_real H[9], int expect)
{
    static q_inst_t q;
    static synth_scene_t sc;
    static spvs_match_t m[SPVS_MAX_MATCHES];
    uint64_t rng = 77;
    scene_default(&sc, &rng, 0.0);
    spvs_params_t prm;
    params(&prm, SPVS_METHOD_I);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, q_init(&q, &prm));
    const synth_pose_t pose = {-3, -10, -30 * DEG};
    double Hd[9];
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    synth_H(&pose, &pl, 800, Hd);
    spvs_real Ht[9];
    for (int k = 0; k < 9; k++) {
        Ht[k] = (spvs_real)Hd[k];
    }
    const uint16_t n = synth_scene_frame(&sc, &pose, 0.0, 0.0, FRAME_LIM_PX, &rng, m);
    spvs_output_t out;
    for (int k = 1; k <= 3; k++) {
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, q_update_with_h(&q, m, n, (spvs_real)(k * DT_S), Ht, &out));
    }
    TEST_ASSERT_TRUE(out.v != 0 || out.w != 0);
    out.v = out.w = SPVS_R(9.0);
    const int rc = q_update_with_h(&q, m, n, SPVS_R(0.4), H, &out);
    TEST_ASSERT_EQUAL_INT64(expect, rc);
    TEST_ASSERT_EQUAL_INT64(expect, out.status);
    TEST_ASSERT_TRUE(out.v == 0 && out.w == 0);
    TEST_ASSERT_EQUAL_INT64(0, out.h_valid);
    /* The next frame with a good H runs again. */
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, q_update_with_h(&q, m, n, SPVS_R(0.5), Ht, &out));
}

static void test_bad_h(void)
{
    const spvs_real good[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    /* NaN and infinity in each entry of rows 1 and 3: float's status. */
    const int rows13[6] = {0, 1, 2, 6, 7, 8};
    for (int i = 0; i < 6; i++) {
        spvs_real H[9];
        memcpy(H, good, sizeof H);
        H[rows13[i]] = nan_real();
        bad_h_case(H, SPVS_E_DEGENERATE);
        H[rows13[i]] = -inf_real();
        bad_h_case(H, SPVS_E_DEGENERATE);
    }
    /* Beyond the Q27 range: h11, h12, h33 at 16, h13 at 8192 px, h31 and
     * h32 at 1/32 per pixel. */
    const spvs_real lim[9] = {16, 16, 8192, 0, 0, 0, SPVS_R(1.0) / 32, SPVS_R(1.0) / 32, 16};
    for (int i = 0; i < 6; i++) {
        spvs_real H[9];
        memcpy(H, good, sizeof H);
        H[rows13[i]] = lim[rows13[i]];
        bad_h_case(H, SPVS_E_RANGE);
        H[rows13[i]] = -lim[rows13[i]];
        bad_h_case(H, SPVS_E_RANGE);
    }
    /* Just inside the range: a model, which explains no match here. */
    spvs_real H[9];
    memcpy(H, good, sizeof H);
    H[2] = SPVS_R(8000.0);
    bad_h_case(H, SPVS_E_NO_CONSENSUS);
    /* The middle row is taken as (0, 1, 0), whatever it holds. */
    static q_inst_t q;
    spvs_params_t prm;
    params(&prm, SPVS_METHOD_II);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, q_init(&q, &prm));
    static spvs_match_t m[SPVS_MAX_MATCHES];
    static synth_scene_t sc;
    uint64_t rng = 5;
    scene_default(&sc, &rng, 0.0);
    const synth_pose_t at = {0, 0, 0};
    const uint16_t n = synth_scene_frame(&sc, &at, 0.0, 0.0, FRAME_LIM_PX, &rng, m);
    memcpy(H, good, sizeof H);
    H[3] = nan_real();
    H[4] = SPVS_R(3.0);
    spvs_output_t out;
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, q_update_with_h(&q, m, n, SPVS_R(0.1), H, &out));
    TEST_ASSERT_TRUE(out.H[3] == 0 && out.H[4] == 1 && out.H[5] == 0);
    /* At the target every match, off the plane or not, fits H = I. */
    TEST_ASSERT_EQUAL_INT64(n, out.n_inliers);
    /* NULL H, and NULL output. */
    out.v = SPVS_R(9.0);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, q_update_with_h(&q, m, n, SPVS_R(0.2), 0, &out));
    TEST_ASSERT_TRUE(out.v == 0 && out.w == 0 && out.status == SPVS_E_ARG);
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, q_update_with_h(&q, m, n, SPVS_R(0.2), good, 0));
    TEST_ASSERT_EQUAL_INT64(SPVS_E_ARG, q_update_with_h(0, m, n, SPVS_R(0.2), good, &out));
}

/* ---- spvs_inlier_px ---------------------------------------------------- */

/* Relative error against noise sqrt(chi2 / 100) in long double, over
 * random noise values of every exponent of the scalar's normal range. */
static void test_inlier_px(void)
{
    const long double c = sqrtl((long double)SPVS_INLIER_CHI2_X100 / 100.0L);
    uint64_t rng = 99;
    double worst = 0;
    int differ = 0, n = 0, n_edge = 0;
    for (int i = 0; i < 200000; i++) {
        /* Float32: down to subnormal results and up to infinity. */
        const double e = (synth_uniform(&rng) - 0.5) * 2 * (SPVS_USE_DOUBLE ? 1000 : 150);
        spvs_real noise = (spvs_real)(synth_uniform(&rng) + 0.5) * (spvs_real)exp2(e);
        if (i & 1) {
            noise = -noise;
        }
        spvs_params_t p;
        spvs_params_default(&p, SPVS_METHOD_I);
        p.noise_px = noise;
        const spvs_real r = q_inlier_px(&p);
        const long double exact = (long double)noise * c;
        if (isfinite(noise) && fabsl(exact) >= 4.0L * (SPVS_USE_DOUBLE ? DBL_MIN : FLT_MIN) &&
            fabsl(exact) <= 0.25L * (SPVS_USE_DOUBLE ? DBL_MAX : FLT_MAX)) {
            /* A normal result: relative error. */
            worst = fmax(worst, (double)fabsl(((long double)r - exact) / exact));
            n++;
        } else {
            n_edge++;
        }
#if !SPVS_USE_DOUBLE
        /* Float32: the float core's value bit for bit (its constant and
         * its product, each rounded as the FPU rounds).  In double the
         * fixed-point build's 2^-28 is many ulps. */
        const float f = (float)noise * sqrtf((float)SPVS_INLIER_CHI2_X100 / 100.0f);
        if (memcmp(&r, &f, sizeof f) != 0) {
            differ++;
        }
#if !SPVS_USE_FIXED
        TEST_ASSERT_TRUE(memcmp(&f, &(spvs_real){spvs_inlier_px(&p)}, sizeof f) == 0);
#endif
#endif
    }
    UNIT_NOTE("spvs_inlier_px: %d values with a normal result, largest relative error %.3g "
           "(2^%.1f); %d subnormal, infinite or near it", n, worst, log2(worst), n_edge);
#if SPVS_USE_DOUBLE
    UNIT_NOTE("\n");
#else
    UNIT_NOTE("; %d of all differ from the float arithmetic's bits\n", differ);
#endif
    TEST_ASSERT_EQUAL_INT64(0, differ);
#if SPVS_USE_DOUBLE
    /* 2^-28 of the computation, half an ulp of the scalar's rounding. */
    TEST_ASSERT_TRUE(worst <= ldexp(1.0, -28) + DBL_EPSILON / 2);
#else
    /* The float arithmetic's: chi2 / 100 rounded (2^-24, halved by the
     * root), the root rounded (2^-24), the product rounded (2^-24). */
    TEST_ASSERT_TRUE(worst <= 2.5 * ldexp(1.0, -24));
#endif
    /* The default's threshold: 3.03 px at 1 px, exact where float is. */
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_I);
    p.noise_px = SPVS_R(1.0);
    TEST_ASSERT_TRUE(fabs((double)q_inlier_px(&p) - 3.0347981810) < 1e-6);
    p.noise_px = nan_real();
    TEST_ASSERT_TRUE(isnan((double)q_inlier_px(&p)));
    p.noise_px = inf_real();
    TEST_ASSERT_TRUE(isinf((double)q_inlier_px(&p)));
    p.noise_px = SPVS_R(0.0);
    TEST_ASSERT_TRUE(q_inlier_px(&p) == 0);
}

#if !SPVS_USE_FIXED
/* ---- (b) against the float core's spvs_update_with_h ------------------- */

typedef struct {
    int frames, moving, step_differ, status_differ, switches;
    double dv, dw;
    int done_f, done_q;
} twin_t;

/* The float core's estimate (E, spvs_update) is given to the float (F)
 * and the Q (Q) spvs_update_with_h on the same frames; F drives the
 * robot. */
static void twin_run(spvs_method_t method, const double start[3], uint64_t seed, twin_t *r)
{
    static spvs_t e, f;
    static spvs_q_t q;
    static synth_scene_t sc;
    static spvs_match_t m[SPVS_MAX_MATCHES];
    uint64_t rng = 0x2545f4914f6cdd1dull ^ seed;
    scene_default(&sc, &rng, SIGMA_PX);
    spvs_params_t prm;
    params(&prm, method);
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_init(&e, &prm));
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_init(&f, &prm));
    TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_init(&q, &prm));
    synth_pose_t pose = {start[0], start[1], start[2] * DEG};
    const spvs_real nan_h[9] = {nan_real(), 0, 0, 0, 1, 0, 0, 0, 1};
    spvs_output_t oe, of, oq;
    int last_step = -1;
    for (int k = 0; k < MAX_FRAMES; k++) {
        const uint16_t n = synth_scene_frame(&sc, &pose, SIGMA_PX, MISMATCH, FRAME_LIM_PX, &rng, m);
        const spvs_real t = (spvs_real)(k * DT_S);
        const int rc_e = spvs_update(&e, m, n, t, &oe);
        TEST_ASSERT_EQUAL_INT64(oe.status, rc_e);
        const spvs_real *H = oe.h_valid ? oe.H : nan_h;
        const int rc_f = spvs_update_with_h(&f, m, n, t, H, &of);
        const int rc_q = spvs_q_update_with_h(&q, m, n, t, H, &oq);
        r->frames++;
        r->status_differ += rc_f != rc_q;
        r->step_differ += of.step != oq.step;
        r->moving += of.v != 0 || of.w != 0;
        r->switches += last_step >= 0 && of.step != last_step;
        last_step = of.step;
        r->dv = fmax(r->dv, fabs((double)of.v - (double)oq.v));
        r->dw = fmax(r->dw, fabs((double)of.w - (double)oq.w));
        plant(&pose, &of);
        if (of.step == SPVS_STEP_DONE || of.step == SPVS_STEP_FAILED) {
            break;
        }
    }
    r->done_f += of.step == SPVS_STEP_DONE;
    r->done_q += oq.step == SPVS_STEP_DONE;
}

static void test_twin_float(void)
{
    twin_t r;
    memset(&r, 0, sizeof r);
    for (int method = 1; method <= 3; method++) {
        for (int i = 0; i < 4; i++) {
            twin_run((spvs_method_t)method, starts[i], (uint64_t)(100 * method + i), &r);
        }
    }
    UNIT_NOTE("float vs Q, the float estimate given to both: 12 runs, %d frames (%d moving, %d "
           "step changes); |dv| %.3g m/s, |dw| %.3g rad/s; statuses differ on %d, steps on "
           "%d; done %d (float) %d (Q)\n", r.frames, r.moving, r.switches, r.dv, r.dw, r.status_differ, r.step_differ, r.done_f, r.done_q);
    TEST_ASSERT_EQUAL_INT64(0, r.status_differ);
    TEST_ASSERT_EQUAL_INT64(0, r.step_differ);
    TEST_ASSERT_TRUE(r.dv <= TOL_TWIN_V && r.dw <= TOL_TWIN_W);
    TEST_ASSERT_TRUE(r.moving > 1000);
    TEST_ASSERT_EQUAL_INT64(r.done_q, r.done_f);
}

/* A non-finite H: the same status in both cores. */
static void test_twin_bad_h(void)
{
    static spvs_t f;
    static spvs_q_t q;
    static synth_scene_t sc;
    static spvs_match_t m[SPVS_MAX_MATCHES];
    uint64_t rng = 3;
    scene_default(&sc, &rng, 0.0);
    spvs_params_t prm;
    params(&prm, SPVS_METHOD_III);
    const synth_pose_t pose = {-3, -10, -30 * DEG};
    const uint16_t n = synth_scene_frame(&sc, &pose, 0.0, 0.0, FRAME_LIM_PX, &rng, m);
    const int rows13[6] = {0, 1, 2, 6, 7, 8};
    for (int i = 0; i < 6; i++) {
        spvs_real H[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        H[rows13[i]] = i & 1 ? nan_real() : inf_real();
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_init(&f, &prm));
        TEST_ASSERT_EQUAL_INT64(SPVS_OK, spvs_q_init(&q, &prm));
        spvs_output_t of, oq;
        const int rc_f = spvs_update_with_h(&f, m, n, SPVS_R(0.1), H, &of);
        const int rc_q = spvs_q_update_with_h(&q, m, n, SPVS_R(0.1), H, &oq);
        TEST_ASSERT_EQUAL_INT64(SPVS_E_DEGENERATE, rc_f);
        TEST_ASSERT_EQUAL_INT64(rc_f, rc_q);
        TEST_ASSERT_TRUE(of.v == 0 && of.w == 0 && oq.v == 0 && oq.w == 0);
    }
}
#endif

void suite_fixed_spvs(void)
{
    UNIT_SUITE_FILE();
    RUN_TEST(test_readback_fresh);
    RUN_TEST(test_readback_closed_loop);
    RUN_TEST(test_bad_h);
    RUN_TEST(test_inlier_px);
#if !SPVS_USE_FIXED
    RUN_TEST(test_twin_float);
    RUN_TEST(test_twin_bad_h);
#endif
}

UNIT_MAIN(suite_fixed_spvs)
