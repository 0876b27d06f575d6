/*
 * test_lockstep.c - the lock-step exchange shared by the LCM and Zenoh links
 * (sim/link_lockstep.h), driven through a mock transport: the answer kept is
 * the first command with the frame's seq (watchdog stops, answers to other
 * frames and repeats are not), the number of sends when answers are lost,
 * the timeout, the telemetry that comes before or after the command, and
 * failures of the transport passed on with their reason.
 */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>

#include "sim/link_lockstep.h"

#define SEQ 5

typedef struct {
    sim_lockstep_t *ls;
    int answer_after; /* answer once this many sends went out; 0: never     */
    int state_when;   /* 0: no state, 1: before the command, 2: poll after  */
    int noise;        /* deliver other frames' answers and stops first      */
    int fail_send;
    int fail_poll;
    int sends;
    int polls;
    int answered;
    int state_pending;
} mock_t;

static void deliver_cmd(mock_t *m, int64_t seq, double v)
{
    spvs_cmd_t c;
    memset(&c, 0, sizeof c);
    c.seq = seq;
    c.utime = seq * 100000;
    c.v = v;
    c.w = -0.25;
    c.step = 2;
    c.status = 0;
    uint8_t buf[256];
    int len = spvs_cmd_t_encode(buf, 0, (int)sizeof buf, &c);
    assert_true(len > 0);
    (void)sim_lockstep_on_cmd(m->ls, buf, len, NULL);
}

static void deliver_state(mock_t *m, int64_t seq, int16_t n_matches)
{
    spvs_state_t s;
    memset(&s, 0, sizeof s);
    s.seq = seq;
    for (int i = 0; i < 9; i++)
        s.H[i] = 0.5 * (double)(i + 1);
    s.h_valid = 1;
    s.n_matches = n_matches;
    s.n_inliers = 90;
    uint8_t buf[512];
    int len = spvs_state_t_encode(buf, 0, (int)sizeof buf, &s);
    assert_true(len > 0);
    (void)sim_lockstep_on_state(m->ls, buf, len);
}

static int mock_send(void *ctx, char *err, unsigned err_len)
{
    mock_t *m = ctx;
    if (m->fail_send) {
        snprintf(err, err_len, "mock: send failed");
        return -1;
    }
    m->sends++;
    return 0;
}

static int mock_poll(void *ctx, double wait_s, char *err, unsigned err_len)
{
    mock_t *m = ctx;
    m->polls++;
    if (m->fail_poll) {
        snprintf(err, err_len, "mock: poll failed");
        return -1;
    }
    if (m->noise) {
        deliver_cmd(m, -1, 0.0);      /* a watchdog stop          */
        deliver_cmd(m, SEQ - 1, 7.0); /* a late answer            */
        deliver_state(m, SEQ - 1, 11);
    }
    if (m->state_pending) {
        deliver_state(m, SEQ, 123);
        m->state_pending = 0;
        return 0;
    }
    if (m->answer_after > 0 && m->sends >= m->answer_after && !m->answered) {
        if (m->state_when == 1)
            deliver_state(m, SEQ, 123);
        deliver_cmd(m, SEQ, 0.5);
        /* The same frame answered again (a resend): not the one kept. */
        deliver_cmd(m, SEQ, 9.0);
        m->answered = 1;
        m->state_pending = m->state_when == 2;
        return 0;
    }
    /* Nothing arrives: block as a transport would, a little at most. */
    double s = wait_s < 0.2 ? wait_s : 0.2;
    struct timespec ts = { 0, (long)(s * 1e9) };
    nanosleep(&ts, NULL);
    return 0;
}

typedef struct {
    sim_lockstep_t ls;
    mock_t m;
    sim_lockstep_io_t io;
    sim_lockstep_timing_t tm;
    sim_lockstep_stats_t st;
    char err[128];
} fixture_t;

static fixture_t *fixture(void)
{
    static fixture_t f;
    memset(&f, 0, sizeof f);
    sim_lockstep_init(&f.ls);
    f.m.ls = &f.ls;
    f.io.ctx = &f.m;
    f.io.send = mock_send;
    f.io.poll = mock_poll;
    f.tm.timeout_s = 10.0;
    f.tm.resend_s = 0.0;
    f.tm.state_grace_s = 0.0;
    return &f;
}

static int run(fixture_t *f)
{
    return sim_lockstep_exchange(&f->ls, SEQ, &f->io, &f->tm, &f->st, f->err,
                                 sizeof f->err);
}

static void first_matching_answer_kept(void **state)
{
    (void)state;
    fixture_t *f = fixture();
    f->m.answer_after = 1;
    f->m.state_when = 1;
    f->m.noise = 1;
    assert_int_equal(run(f), SIM_LOCKSTEP_ANSWERED);
    assert_int_equal(f->st.sends, 1);
    assert_int_equal(f->m.sends, 1);
    assert_true(f->ls.got_cmd && f->ls.got_state);
    assert_int_equal(f->ls.cmd.seq, SEQ);
    /* Not the stop (0), not the late answer (7), not the repeat (9). */
    assert_true(f->ls.cmd.v == 0.5);
    assert_int_equal(f->ls.state.seq, SEQ);
    assert_int_equal(f->ls.state.n_matches, 123);

    spvs_output_t out;
    sim_lockstep_output(&f->ls, 17, &out);
    assert_true(out.v == (spvs_real)0.5 && out.w == (spvs_real)-0.25);
    assert_int_equal(out.step, 2);
    assert_int_equal(out.n_matches, 123);
    assert_int_equal(out.n_inliers, 90);
    assert_int_equal(out.h_valid, 1);
    assert_true(out.H[8] == (spvs_real)4.5);
}

static void resent_until_answered(void **state)
{
    (void)state;
    fixture_t *f = fixture();
    /* The first two frames are lost: the third send is answered. */
    f->m.answer_after = 3;
    f->m.state_when = 1;
    f->tm.resend_s = 0.01;
    assert_int_equal(run(f), SIM_LOCKSTEP_ANSWERED);
    assert_int_equal(f->st.sends, 3);
    assert_int_equal(f->m.sends, 3);
    assert_true(f->st.waited_s >= 0.02 && f->st.waited_s < 10.0);
    assert_true(f->ls.cmd.v == 0.5);
}

static void timeout_without_resend(void **state)
{
    (void)state;
    fixture_t *f = fixture();
    f->tm.timeout_s = 0.05;
    assert_int_equal(run(f), SIM_LOCKSTEP_TIMEOUT);
    assert_int_equal(f->st.sends, 1);
    assert_false(f->ls.got_cmd);
}

static void timeout_with_resends(void **state)
{
    (void)state;
    fixture_t *f = fixture();
    f->tm.timeout_s = 0.1;
    f->tm.resend_s = 0.02;
    f->m.noise = 1; /* other frames' answers do not end the wait */
    assert_int_equal(run(f), SIM_LOCKSTEP_TIMEOUT);
    /* The first send and at least one resend; resends at least 0.02 s
     * apart within 0.1 s, plus the one made when the deadline is seen. */
    assert_true(f->st.sends >= 2);
    assert_true(f->st.sends <= 7);
    assert_int_equal(f->st.sends, f->m.sends);
    assert_false(f->ls.got_cmd);
}

static void state_after_the_command(void **state)
{
    (void)state;
    /* The state comes in the poll after the command: taken with no grace
     * time (it is already there), and with one. */
    for (int k = 0; k < 2; k++) {
        fixture_t *f = fixture();
        f->m.answer_after = 1;
        f->m.state_when = 2;
        f->tm.state_grace_s = k ? 1.0 : 0.0;
        assert_int_equal(run(f), SIM_LOCKSTEP_ANSWERED);
        assert_true(f->ls.got_state);
        assert_int_equal(f->m.polls, 2);
        spvs_output_t out;
        sim_lockstep_output(&f->ls, 17, &out);
        assert_int_equal(out.n_matches, 123);
    }
}

static void no_state(void **state)
{
    (void)state;
    fixture_t *f = fixture();
    f->m.answer_after = 1;
    f->m.state_when = 0;
    assert_int_equal(run(f), SIM_LOCKSTEP_ANSWERED);
    assert_false(f->ls.got_state);
    /* One poll for the command, one look at what is queued after it. */
    assert_int_equal(f->m.polls, 2);
    spvs_output_t out;
    sim_lockstep_output(&f->ls, 17, &out);
    assert_true(out.v == (spvs_real)0.5);
    assert_int_equal(out.n_matches, 17);
    assert_int_equal(out.h_valid, 0);
    assert_int_equal(out.n_inliers, 0);
}

static void transport_failures(void **state)
{
    (void)state;
    fixture_t *f = fixture();
    f->m.fail_send = 1;
    assert_int_equal(run(f), -1);
    assert_string_equal(f->err, "mock: send failed");
    assert_int_equal(f->st.sends, 0);

    f = fixture();
    f->m.fail_poll = 1;
    assert_int_equal(run(f), -1);
    assert_string_equal(f->err, "mock: poll failed");
    assert_int_equal(f->st.sends, 1);
}

static void payloads(void **state)
{
    (void)state;
    sim_lockstep_t ls;
    sim_lockstep_init(&ls);
    assert_int_equal(ls.want_seq, -1);
    ls.want_seq = SEQ;

    spvs_cmd_t c, got;
    memset(&c, 0, sizeof c);
    c.seq = SEQ + 1;
    uint8_t buf[256];
    int len = spvs_cmd_t_encode(buf, 0, (int)sizeof buf, &c);
    assert_true(len > 0);
    /* Another frame's answer: decoded, handed back, not kept. */
    memset(&got, 0, sizeof got);
    assert_int_equal(sim_lockstep_on_cmd(&ls, buf, len, &got), 0);
    assert_int_equal(got.seq, SEQ + 1);
    assert_false(ls.got_cmd);
    /* Cut short, or a wrong fingerprint: dropped. */
    assert_int_equal(sim_lockstep_on_cmd(&ls, buf, len - 1, &got), -1);
    buf[0] ^= 0xff;
    assert_int_equal(sim_lockstep_on_cmd(&ls, buf, len, &got), -1);
    assert_int_equal(sim_lockstep_on_state(&ls, buf, len), -1);
    assert_false(ls.got_cmd || ls.got_state);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(first_matching_answer_kept),
        cmocka_unit_test(resent_until_answered),
        cmocka_unit_test(timeout_without_resend),
        cmocka_unit_test(timeout_with_resends),
        cmocka_unit_test(state_after_the_command),
        cmocka_unit_test(no_state),
        cmocka_unit_test(transport_failures),
        cmocka_unit_test(payloads),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
