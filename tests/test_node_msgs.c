/*
 * test_node_msgs.c - the controller node's answers to good and bad
 * SPVS_MATCHES messages.
 *
 * Two modes, same checks:
 *   - default: the node's handler (node.h) runs in this process over the
 *     in-process LCM provider memq://;
 *   - SPVS_NODE_URL set: a separate spvs-node process listens on that URL
 *     (started by tests/lcm/node_robust.sh inside a loopback-only network
 *     namespace with --watchdog 0.3); this process only publishes and
 *     listens.
 * The expected answer for a valid frame comes from a reference controller
 * (spvs_update on the same, wire-rounded matches, same parameters: method 3
 * defaults, seed 0), so "the right answer" is the core's own, bit for bit.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "node.h"
#include "sim/clock.h"
#include "wire.h"

#define MAX_RX 64
#define WATCHDOG_S 0.3

static lcm_t *g_lcm;
static spvs_node_t g_node;  /* in-process node (memq mode only) */
static int g_external;
static spvs_cmd_t g_rx[MAX_RX];
static int g_nrx;
static spvs_state_t g_state; /* last state received */
static spvs_t g_ref;         /* reference controller */
static spvs_params_t g_params;

/* ---- a small synthetic scene (DESIGN.md section 1 conventions) -------- */

static uint64_t g_lcg = 12345u;
static double urand(void)
{
    g_lcg = g_lcg * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(g_lcg >> 11) * (1.0 / 9007199254740992.0);
}

typedef struct {
    double X[125][3];
    int n;
} scene_t;
static scene_t g_scene;

static void scene_make(void)
{
    const double alpha = 800.0, d = 45.0;
    double n[3] = {0.3, -0.6, -0.75};
    double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; k++)
        n[k] /= nn;
    g_scene.n = 0;
    for (int i = 0; i < 125; i++) {
        double r[3] = {(urand() - 0.5) * 560.0 / alpha,
                       (urand() - 0.5) * 400.0 / alpha, 1.0};
        /* 100 points on the plane n^T X = -d, 25 in front of it. */
        double depth = i < 100 ? -d / (n[0] * r[0] + n[1] * r[1] + n[2])
                               : 15.0 + 25.0 * urand();
        for (int k = 0; k < 3; k++)
            g_scene.X[i][k] = depth * r[k];
        g_scene.n++;
    }
}

/* Matches seen from pose (x, z, phi): world -> camera R(phi) of eq. (3). */
static uint16_t scene_matches(double x, double z, double phi, spvs_match_t *m)
{
    const double alpha = 800.0;
    double c = cos(phi), s = sin(phi);
    uint16_t n = 0;
    for (int i = 0; i < g_scene.n; i++) {
        const double *X = g_scene.X[i];
        double dx = X[0] - x, dy = X[1], dz = X[2] - z;
        double xc = c * dx + s * dz, yc = dy, zc = -s * dx + c * dz;
        if (zc < 1.0)
            continue;
        m[n].x_tgt = (spvs_real)(alpha * X[0] / X[2]);
        m[n].y_tgt = (spvs_real)(alpha * X[1] / X[2]);
        m[n].x_cur = (spvs_real)(alpha * xc / zc);
        m[n].y_cur = (spvs_real)(alpha * yc / zc);
        m[n].feature = (uint16_t)i;
        n++;
    }
    return n;
}

/* ---- transport helpers ---------------------------------------------- */

static void on_cmd(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch;
    (void)u;
    spvs_cmd_t c;
    if (spvs_cmd_t_decode(rb->data, 0, (int)rb->data_size, &c) < 0)
        return;
    if (g_nrx < MAX_RX)
        g_rx[g_nrx++] = c;
}

static void on_state(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
    (void)ch;
    (void)u;
    (void)spvs_state_t_decode(rb->data, 0, (int)rb->data_size, &g_state);
}

static void pump(double seconds)
{
    double end = sim_clock_now_s() + seconds;
    for (;;) {
        double left = end - sim_clock_now_s();
        if (left <= 0)
            break;
        int ms = (int)(left * 1000.0) + 1;
        lcm_handle_timeout(g_lcm, ms > 20 ? 20 : ms);
        if (!g_external)
            spvs_node_tick(&g_node, sim_clock_now_s());
    }
}

/* Wait (bounded) for the command answering seq; NULL when none came. */
static const spvs_cmd_t *wait_cmd(int64_t seq, double timeout_s)
{
    double end = sim_clock_now_s() + timeout_s;
    while (sim_clock_now_s() < end) {
        for (int i = 0; i < g_nrx; i++)
            if (g_rx[i].seq == seq)
                return &g_rx[i];
        lcm_handle_timeout(g_lcm, 10);
        if (!g_external)
            spvs_node_tick(&g_node, sim_clock_now_s());
    }
    for (int i = 0; i < g_nrx; i++)
        if (g_rx[i].seq == seq)
            return &g_rx[i];
    return NULL;
}

static void send_raw(const void *buf, int len)
{
    g_nrx = 0;
    assert_int_equal(lcm_publish(g_lcm, SPVS_CH_MATCHES, buf, (unsigned)len), 0);
}

static void send_msg(const spvs_matches_t *msg)
{
    static uint8_t buf[SPVS_WIRE_MATCHES_BYTES];
    int len = spvs_matches_t_encode(buf, 0, (int)sizeof(buf), msg);
    assert_int_equal(len, SPVS_WIRE_MATCHES_BYTES);
    send_raw(buf, len);
}

static int64_t g_run = 1000;

/* Frame seq of the robot at pose k of a short approach. */
static void make_frame(spvs_matches_t *msg, int64_t seq)
{
    spvs_match_t m[SPVS_MAX_MATCHES];
    double k = (double)seq;
    uint16_t n = scene_matches(-3.0 + 0.01 * k, -10.0 + 0.02 * k,
                               -0.5236 + 0.01 * k, m);
    assert_true(n >= 100);
    assert_int_equal(spvs_wire_matches_from_core(msg, seq, seq * 100000,
                                                 g_run, m, n),
                     SPVS_OK);
}

/* Feed the reference controller exactly what the node decodes. */
static void reference(const spvs_matches_t *msg, spvs_output_t *out)
{
    static spvs_match_t m[SPVS_MAX_MATCHES];
    uint16_t n = spvs_wire_matches_to_core(msg, m);
    int rc = spvs_update(&g_ref, m, n,
                         (spvs_real)((double)msg->utime * 1e-6), out);
    assert_int_equal(rc, out->status);
}

static void expect_answer(const spvs_cmd_t *c, const spvs_output_t *ref)
{
    assert_non_null(c);
    assert_int_equal(c->status, ref->status);
    assert_int_equal(c->step, ref->step);
    /* The node's float result travels as float64: exact. */
    assert_true(c->v == (double)ref->v);
    assert_true(c->w == (double)ref->w);
}

static void expect_stop(const spvs_cmd_t *c, int status)
{
    assert_non_null(c);
    assert_int_equal(c->status, status);
    assert_true(c->v == 0.0 && c->w == 0.0);
}

/* ---- fixtures ---------------------------------------------------------- */

static int setup(void **state)
{
    (void)state;
    const char *url = getenv("SPVS_NODE_URL");
    g_external = url && *url;
    g_lcm = lcm_create(g_external ? url : "memq://");
    if (!g_lcm)
        return -1;
    spvs_params_default(&g_params, SPVS_METHOD_III);
    g_params.seed = 0;
    if (spvs_init(&g_ref, &g_params) != SPVS_OK)
        return -1;
    if (!g_external) {
        g_node.log_level = 0;
        if (spvs_node_init(&g_node, g_lcm, &g_params, WATCHDOG_S,
                           sim_clock_now_s()) != SPVS_OK)
            return -1;
    }
    lcm_subscribe(g_lcm, SPVS_CH_CMD, on_cmd, NULL);
    lcm_subscribe(g_lcm, SPVS_CH_STATE, on_state, NULL);
    scene_make();
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    if (!g_external)
        spvs_node_close(&g_node);
    lcm_destroy(g_lcm);
    return 0;
}

/* Start every test on a fresh run: the node resets for a new run_id. */
static void new_run(void)
{
    g_run++;
    spvs_reset(&g_ref);
}

/* ---- tests --------------------------------------------------------------- */

/* Valid frames get the core's answer, with the same seq, and the state
 * message carries the same H; at least one frame moves the robot. */
static void test_valid_frames_match_core(void **state)
{
    (void)state;
    new_run();
    static spvs_matches_t msg;
    int moving = 0;
    for (int64_t seq = 0; seq < 6; seq++) {
        spvs_output_t ref;
        make_frame(&msg, seq);
        reference(&msg, &ref);
        send_msg(&msg);
        const spvs_cmd_t *c = wait_cmd(seq, 2.0);
        expect_answer(c, &ref);
        assert_int_equal(g_state.seq, seq);
        for (int k = 0; k < 9; k++)
            assert_true(g_state.H[k] == (double)ref.H[k]);
        assert_int_equal(g_state.n_inliers, ref.n_inliers);
        assert_true(g_state.arrival_corner_px == (double)ref.arrival_corner_px);
        assert_true(g_state.arrival_stat == (double)ref.arrival_stat);
        assert_true(g_state.arrival_threshold == (double)ref.arrival_threshold);
        assert_true(g_state.arrival_lateral_sd_px == (double)ref.arrival_lateral_sd_px);
        assert_true(g_state.arrival_depth_sd_px == (double)ref.arrival_depth_sd_px);
        assert_true(g_state.arrival_h13_sd_px == (double)ref.arrival_h13_sd_px);
        assert_true(g_state.arrival_parallax_px == (double)ref.arrival_parallax_px);
        assert_int_equal(g_state.arrival_frames, ref.arrival_frames);
        assert_int_equal(g_state.arriving, ref.arriving);
        if (ref.status == SPVS_OK && (ref.v != 0 || ref.w != 0))
            moving++;
    }
    assert_true(moving > 0);
}

/* An output through state_t and back (wire.c, both ways): the layout
 * docs/LCM.md and docs/ZENOH.md give (fingerprint, 225 bytes), and every
 * arrival check figure exact (statistic, threshold, each residual and its sd), the parallax's -1 (none seen) included. */
static void test_state_round_trip(void **state)
{
    (void)state;
    assert_true((uint64_t)__spvs_state_t_get_hash() == 0x62032d1020f36306ull);
    spvs_output_t out, back;
    memset(&out, 0, sizeof out);
    out.step = SPVS_STEP_ALIGN;
    out.status = SPVS_OK;
    out.n_inliers = 97;
    out.arrival_corner_px = (spvs_real)0.75;
    out.arrival_stat = (spvs_real)3.4375;
    out.arrival_threshold = (spvs_real)4.0;
    out.arrival_lateral_px = (spvs_real)0.5;
    out.arrival_lateral_sd_px = (spvs_real)0.1875;
    out.arrival_depth_px = (spvs_real)-0.25;
    out.arrival_depth_sd_px = (spvs_real)0.0625;
    out.arrival_h13_px = (spvs_real)-0.125;
    out.arrival_h13_sd_px = (spvs_real)0.046875;
    out.arrival_frames = 21;
    out.arrival_reentries = 2;
    out.arrival_next = SPVS_STEP_ROTATE;
    out.arriving = 1;
    const spvs_real parallax[2] = {(spvs_real)2.9, (spvs_real)-1.0};
    for (int i = 0; i < 2; i++) {
        out.arrival_parallax_px = parallax[i];
        spvs_state_t st, st_back;
        spvs_wire_state_from_output(&st, 7, 700000, &out);
        assert_true(st.arrival_parallax_px == (double)parallax[i]);
        uint8_t buf[256];
        const int len = spvs_state_t_encode(buf, 0, (int)sizeof buf, &st);
        assert_int_equal(len, 225);
        assert_int_equal(spvs_state_t_encoded_size(&st), 225);
        assert_int_equal(spvs_state_t_decode(buf, 0, len, &st_back), len);
        spvs_cmd_t cmd;
        spvs_wire_cmd_from_output(&cmd, 7, 700000, &out);
        spvs_wire_output_from_msgs(&back, &cmd, &st_back);
        assert_true(back.arrival_corner_px == out.arrival_corner_px);
        assert_true(back.arrival_stat == out.arrival_stat);
        assert_true(back.arrival_threshold == out.arrival_threshold);
        assert_true(back.arrival_lateral_px == out.arrival_lateral_px);
        assert_true(back.arrival_lateral_sd_px == out.arrival_lateral_sd_px);
        assert_true(back.arrival_depth_px == out.arrival_depth_px);
        assert_true(back.arrival_depth_sd_px == out.arrival_depth_sd_px);
        assert_true(back.arrival_h13_px == out.arrival_h13_px);
        assert_true(back.arrival_h13_sd_px == out.arrival_h13_sd_px);
        assert_true(back.arrival_parallax_px == parallax[i]);
        assert_int_equal(back.arrival_frames, 21);
        assert_int_equal(back.arrival_reentries, 2);
        assert_int_equal(back.arrival_next, SPVS_STEP_ROTATE);
        assert_int_equal(back.arriving, 1);
        assert_int_equal(back.n_inliers, 97);
    }
}

/* A burst of duplicates gets the previous answer each time, and the core is
 * not run again: the next frame still equals the reference fed once. */
static void test_duplicates_answer_again(void **state)
{
    (void)state;
    new_run();
    static spvs_matches_t msg;
    spvs_output_t ref;
    for (int64_t seq = 0; seq < 3; seq++) {
        make_frame(&msg, seq);
        reference(&msg, &ref);
        send_msg(&msg);
        expect_answer(wait_cmd(seq, 2.0), &ref);
    }
    uint32_t frames_before = g_node.stats.frames;
    for (int k = 0; k < 5; k++) {
        send_msg(&msg); /* seq 2 again */
        expect_answer(wait_cmd(2, 2.0), &ref);
    }
    if (!g_external)
        assert_int_equal(g_node.stats.frames, frames_before);
    make_frame(&msg, 3);
    reference(&msg, &ref);
    send_msg(&msg);
    expect_answer(wait_cmd(3, 2.0), &ref);
}

/* Older frames are answered with a stop (SPVS_E_STALE) and never reach the
 * core; the next new frame gets the right answer. */
static void test_out_of_order_stops(void **state)
{
    (void)state;
    new_run();
    static spvs_matches_t msg;
    spvs_output_t ref;
    for (int64_t seq = 0; seq < 5; seq++) {
        make_frame(&msg, seq);
        reference(&msg, &ref);
        send_msg(&msg);
        expect_answer(wait_cmd(seq, 2.0), &ref);
    }
    for (int64_t seq = 3; seq >= 0; seq--) {
        make_frame(&msg, seq);
        send_msg(&msg);
        expect_stop(wait_cmd(seq, 2.0), SPVS_E_STALE);
    }
    if (!g_external) {
        /* The in-process node's books: four stale frames kept from the core. */
        assert_int_equal(g_node.stats.out_of_order, 4);
    }
    uint32_t frames_before = g_node.stats.frames;
    make_frame(&msg, 5);
    reference(&msg, &ref);
    send_msg(&msg);
    expect_answer(wait_cmd(5, 2.0), &ref);
    if (!g_external)
        assert_int_equal(g_node.stats.frames, frames_before + 1);
}

/* count above the capacity or negative: a stop with SPVS_E_CAPACITY; NaN or
 * infinite coordinates: SPVS_E_NONFINITE; a feature index out of range:
 * SPVS_E_RANGE.  The node stays up and answers the next frame right. */
static void test_bad_content_stops(void **state)
{
    (void)state;
    new_run();
    static spvs_matches_t msg;
    spvs_output_t ref;
    volatile float zero = 0.0f;

    make_frame(&msg, 0);
    reference(&msg, &ref);
    send_msg(&msg);
    expect_answer(wait_cmd(0, 2.0), &ref);

    make_frame(&msg, 1);
    msg.count = SPVS_MAX_MATCHES + 44;
    send_msg(&msg);
    expect_stop(wait_cmd(1, 2.0), SPVS_E_CAPACITY);

    make_frame(&msg, 2);
    msg.count = -3;
    send_msg(&msg);
    expect_stop(wait_cmd(2, 2.0), SPVS_E_CAPACITY);

    make_frame(&msg, 3);
    msg.x_cur[7] = zero / zero;
    send_msg(&msg);
    expect_stop(wait_cmd(3, 2.0), SPVS_E_NONFINITE);

    make_frame(&msg, 4);
    msg.y_tgt[0] = 1.0f / zero;
    send_msg(&msg);
    expect_stop(wait_cmd(4, 2.0), SPVS_E_NONFINITE);

    make_frame(&msg, 5);
    msg.feature[3] = 70000;
    send_msg(&msg);
    expect_stop(wait_cmd(5, 2.0), SPVS_E_RANGE);

    /* A NaN past count is never read. */
    make_frame(&msg, 6);
    msg.x_cur[SPVS_MAX_MATCHES - 1] = zero / zero;
    assert_true(msg.count < SPVS_MAX_MATCHES);
    reference(&msg, &ref);
    send_msg(&msg);
    expect_answer(wait_cmd(6, 2.0), &ref);
}

/* Truncated, garbage and empty messages are dropped without an answer; the
 * node then answers a valid frame right. */
static void test_undecodable_dropped(void **state)
{
    (void)state;
    new_run();
    static spvs_matches_t msg;
    static uint8_t buf[SPVS_WIRE_MATCHES_BYTES + 64];
    spvs_output_t ref;

    make_frame(&msg, 0);
    reference(&msg, &ref);
    send_msg(&msg);
    expect_answer(wait_cmd(0, 2.0), &ref);

    make_frame(&msg, 1);
    int len = spvs_matches_t_encode(buf, 0, (int)sizeof(buf), &msg);
    assert_true(len > 100);
    send_raw(buf, len / 2);            /* truncated */
    send_raw(buf, 9);                  /* fingerprint and one byte */
    for (int i = 0; i < (int)sizeof(buf); i++)
        buf[i] = (uint8_t)(urand() * 256.0);
    send_raw(buf, (int)sizeof(buf));   /* garbage */
    send_raw(buf, 0);                  /* empty */
    pump(0.2);
    for (int i = 0; i < g_nrx; i++)
        assert_int_equal(g_rx[i].seq, -1); /* watchdog stops only */

    reference(&msg, &ref);
    send_msg(&msg);
    expect_answer(wait_cmd(1, 2.0), &ref);
}

/* No valid frames for the watchdog time: stops with seq -1 and
 * SPVS_E_STALE, repeated; duplicates do not feed the watchdog. */
static void test_watchdog_stops(void **state)
{
    (void)state;
    new_run();
    static spvs_matches_t msg;
    spvs_output_t ref;
    make_frame(&msg, 0);
    reference(&msg, &ref);
    send_msg(&msg);
    expect_answer(wait_cmd(0, 2.0), &ref);

    /* Within the watchdog time: no stop. */
    g_nrx = 0;
    pump(WATCHDOG_S * 0.5);
    for (int i = 0; i < g_nrx; i++)
        assert_int_not_equal(g_rx[i].seq, -1);

    /* Duplicates keep arriving, but the watchdog still fires. */
    double t0 = sim_clock_now_s();
    int stops = 0;
    while (sim_clock_now_s() - t0 < WATCHDOG_S * 3.5) {
        send_msg(&msg);
        pump(0.05);
        for (int i = 0; i < g_nrx; i++)
            if (g_rx[i].seq == -1) {
                expect_stop(&g_rx[i], SPVS_E_STALE);
                stops++;
            }
    }
    assert_in_range(stops, 2, 4);
}

/* A new run_id resets the controller: its first frame gets the answer of a
 * fresh controller even with a lower seq than the last run's. */
static void test_new_run_resets(void **state)
{
    (void)state;
    new_run();
    static spvs_matches_t msg;
    spvs_output_t ref;
    for (int64_t seq = 0; seq < 4; seq++) {
        make_frame(&msg, seq);
        reference(&msg, &ref);
        send_msg(&msg);
        expect_answer(wait_cmd(seq, 2.0), &ref);
    }
    new_run();
    make_frame(&msg, 0);
    reference(&msg, &ref);
    send_msg(&msg);
    expect_answer(wait_cmd(0, 2.0), &ref);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_valid_frames_match_core),
        cmocka_unit_test(test_state_round_trip),
        cmocka_unit_test(test_duplicates_answer_again),
        cmocka_unit_test(test_out_of_order_stops),
        cmocka_unit_test(test_bad_content_stops),
        cmocka_unit_test(test_undecodable_dropped),
        cmocka_unit_test(test_watchdog_stops),
        cmocka_unit_test(test_new_run_resets),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
