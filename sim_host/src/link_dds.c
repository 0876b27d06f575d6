/*
 * link_dds.c - the simulator's DDS link; see sim/link_dds.h.
 */
#define _POSIX_C_SOURCE 200809L

#include "sim/link_dds.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ros_dds.h"
#include "sim/clock.h"
#include "sim/link_lockstep.h"
#include "wire.h"

/* Write an unanswered frame again after this, seconds.  DDS delivers a
 * reliable sample once the node is matched, so this only covers a node
 * that was not yet listening. */
#define RESEND_S 1.0
/* Samples taken per poll (the reader keeps SPVS_DDS_DEPTH). */
#define TAKE_MAX SPVS_DDS_DEPTH
/* LCM-encoded command and state, for the lock-step exchange. */
#define ENC_BYTES 512

typedef struct {
    dds_entity_t pp, wr_matches, rd_state, ws;
    double timeout_s;
    int64_t run_id;
    uint32_t domain;
    int matched;             /* the node was seen before the first frame */
    sim_lockstep_t ls;
    spvs_matches_t msg;
    spvs_dds_matches_t tx;
    spvs_dds_state_t rx;
} link_dds_t;

static void sleep_s(double s)
{
    struct timespec ts = { (time_t)s, (long)((s - floor(s)) * 1e9) };
    nanosleep(&ts, NULL);
}

/* Wait until the node's reader of /spvs/matches and its writer of
 * /spvs/state are matched with ours, at most timeout_s. */
static void wait_matched(link_dds_t *l)
{
    double t0 = sim_clock_now_s();
    while (sim_clock_now_s() - t0 < l->timeout_s) {
        dds_publication_matched_status_t pm;
        dds_subscription_matched_status_t sm;
        if (dds_get_publication_matched_status(l->wr_matches, &pm) == 0 &&
            dds_get_subscription_matched_status(l->rd_state, &sm) == 0 &&
            pm.current_count > 0 && sm.current_count > 0)
            return;
        sleep_s(0.01);
    }
}

static int io_send(void *ctx, char *err, unsigned err_len)
{
    link_dds_t *l = (link_dds_t *)ctx;
    spvs_dds_matches_from_lcm(&l->tx, &l->msg);
    dds_return_t r = dds_write(l->wr_matches, &l->tx);
    if (r < 0) {
        snprintf(err, err_len, "DDS link: writing frame %lld failed: %s",
                 (long long)l->msg.seq, dds_strretcode(r));
        return -1;
    }
    return 0;
}

/* One State sample as the command and state the exchange understands. */
static void on_state(link_dds_t *l, const spvs_dds_state_t *s)
{
    spvs_state_t st;
    spvs_cmd_t cmd;
    uint8_t buf[ENC_BYTES];
    spvs_dds_state_to_lcm(&st, &cmd, s);
    int n = spvs_state_t_encode(buf, 0, (int)sizeof(buf), &st);
    if (n > 0)
        (void)sim_lockstep_on_state(&l->ls, buf, n);
    n = spvs_cmd_t_encode(buf, 0, (int)sizeof(buf), &cmd);
    if (n > 0)
        (void)sim_lockstep_on_cmd(&l->ls, buf, n, NULL);
}

static int io_poll(void *ctx, double wait_s, char *err, unsigned err_len)
{
    link_dds_t *l = (link_dds_t *)ctx;
    dds_duration_t d = wait_s > 0.0 ? (dds_duration_t)(wait_s * 1e9) : 0;
    dds_return_t w = dds_waitset_wait(l->ws, NULL, 0, d);
    if (w < 0) {
        snprintf(err, err_len, "DDS link: wait failed: %s", dds_strretcode(w));
        return -1;
    }
    for (int k = 0; k < TAKE_MAX; k++) {
        void *samples[1] = { &l->rx };
        dds_sample_info_t info;
        dds_return_t n = dds_take(l->rd_state, samples, &info, 1, 1);
        if (n < 0) {
            snprintf(err, err_len, "DDS link: take failed: %s",
                     dds_strretcode(n));
            return -1;
        }
        if (n == 0)
            break;
        if (info.valid_data)
            on_state(l, &l->rx);
    }
    return 0;
}

static int link_exchange(void *ctx, uint32_t seq, double t_s,
                         const spvs_match_t *m, uint16_t n, spvs_output_t *out,
                         char *err, unsigned err_len)
{
    link_dds_t *l = (link_dds_t *)ctx;
    if (spvs_wire_frame_from_sim(&l->msg, seq, t_s, l->run_id, m, n,
                                 "DDS link", err, err_len) != 0)
        return -1;
    if (!l->matched) {
        wait_matched(l);
        l->matched = 1;
    }
    const sim_lockstep_io_t io = { l, io_send, io_poll };
    const sim_lockstep_timing_t tm = { l->timeout_s, RESEND_S, 0.0 };
    int rc = sim_lockstep_exchange(&l->ls, seq, &io, &tm, NULL, err, err_len);
    if (rc < 0)
        return -1;
    if (rc == SIM_LOCKSTEP_TIMEOUT) {
        snprintf(err, err_len,
                 "DDS link: no %s for frame %u within %.3g s on domain %u "
                 "(is spvs-node --dds running there?)",
                 SPVS_DDS_TOPIC_STATE, (unsigned)seq, l->timeout_s,
                 (unsigned)l->domain);
        return -1;
    }
    sim_lockstep_output(&l->ls, n, out);
    return 0;
}

static void link_close(void *ctx)
{
    link_dds_t *l = (link_dds_t *)ctx;
    if (!l)
        return;
    if (l->pp > 0)
        dds_delete(l->pp);
    free(l);
}

int sim_link_dds_open(double timeout_s, sim_link_t *out, char *err,
                      unsigned err_len)
{
    if (!out || !(timeout_s > 0.0) || !isfinite(timeout_s)) {
        snprintf(err, err_len, "DDS link: timeout must be positive seconds");
        return -1;
    }
    link_dds_t *l = (link_dds_t *)calloc(1, sizeof(*l));
    if (!l) {
        snprintf(err, err_len, "DDS link: out of memory");
        return -1;
    }
    l->timeout_s = timeout_s;
    sim_lockstep_init(&l->ls);
    l->run_id = sim_clock_run_id();
    if (spvs_dds_domain(&l->domain, err, err_len) != 0) {
        free(l);
        return -1;
    }
    l->pp = spvs_dds_participant(l->domain, err, err_len);
    if (l->pp < 0) {
        free(l);
        return -1;
    }
    dds_qos_t *q = spvs_dds_qos();
    dds_entity_t t_m = dds_create_topic(l->pp, &spvs_msgs_msg_dds__Matches__desc,
                                        SPVS_DDS_TOPIC_MATCHES, q, NULL);
    dds_entity_t t_s = dds_create_topic(l->pp, &spvs_msgs_msg_dds__State__desc,
                                        SPVS_DDS_TOPIC_STATE, q, NULL);
    l->wr_matches = t_m < 0 ? t_m : dds_create_writer(l->pp, t_m, q, NULL);
    l->rd_state = t_s < 0 ? t_s : dds_create_reader(l->pp, t_s, q, NULL);
    dds_delete_qos(q);
    l->ws = dds_create_waitset(l->pp);
    dds_entity_t rc = l->rd_state < 0 ? l->rd_state :
        dds_create_readcondition(l->rd_state, DDS_ANY_STATE);
    if (l->wr_matches < 0 || l->rd_state < 0 || l->ws < 0 || rc < 0 ||
        dds_waitset_attach(l->ws, rc, 0) < 0) {
        snprintf(err, err_len, "DDS link: cannot create the topics, writer "
                 "and reader on domain %u", (unsigned)l->domain);
        link_close(l);
        return -1;
    }
    out->ctx = l;
    out->exchange = link_exchange;
    out->close = link_close;
    return 0;
}
