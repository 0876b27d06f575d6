/*
 * link_lcm.c - the simulator's LCM link; see sim/link_lcm.h.
 */
#define _POSIX_C_SOURCE 200809L

#include "sim/link_lcm.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "wire.h"

typedef struct {
    lcm_t *lcm;
    char url[256];
    double timeout_s;
    int64_t run_id;
    int64_t want_seq;
    int got_cmd;
    int got_state;
    spvs_cmd_t cmd;
    spvs_state_t state;
    spvs_cmd_t rx_cmd;       /* decode scratch */
    spvs_state_t rx_state;
    spvs_matches_t msg;
    /* sim_link_lcm_opts_t (keep_last mode): the command in force and the
     * newest one received while waiting. */
    char channel[64];
    int keep_last;
    double hold_max_s;
    int64_t applied_seq;     /* frame whose answer is in force (-2: none) */
    spvs_cmd_t applied;      /* the command in force                       */
    double applied_t_s;      /* frame time it was last renewed, seconds    */
    int got_newer;           /* a newer command than `applied` arrived     */
    spvs_cmd_t newer;
    lcm_subscription_t *sub_cmd;
    lcm_subscription_t *sub_state;
    uint32_t resends;        /* frames published again while waiting */
} link_lcm_t;

/* Wait before publishing an unanswered frame again, seconds. */
#define RESEND_S 0.25

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void on_cmd(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)channel;
    link_lcm_t *l = (link_lcm_t *)user;
    if (spvs_cmd_t_decode(rbuf->data, 0, (int)rbuf->data_size, &l->rx_cmd) < 0)
        return;
    if (l->rx_cmd.seq == l->want_seq && !l->got_cmd) {
        l->cmd = l->rx_cmd;
        l->got_cmd = 1;
    } else if (l->keep_last &&
               (l->rx_cmd.seq == -1 || l->rx_cmd.seq > l->applied_seq)) {
        /* A watchdog stop, or a late answer to a frame newer than the one
         * whose answer is in force: the base would act on it. */
        l->newer = l->rx_cmd;
        l->got_newer = 1;
    }
}

static void on_state(const lcm_recv_buf_t *rbuf, const char *channel,
                     void *user)
{
    (void)channel;
    link_lcm_t *l = (link_lcm_t *)user;
    if (spvs_state_t_decode(rbuf->data, 0, (int)rbuf->data_size,
                            &l->rx_state) < 0)
        return;
    if (l->rx_state.seq == l->want_seq) {
        l->state = l->rx_state;
        l->got_state = 1;
    }
}

/* Encode into a stack buffer and publish on the link's channel (wire.c's
 * publisher is fixed to SPVS_MATCHES). */
static int publish_frame(link_lcm_t *l)
{
    uint8_t buf[SPVS_WIRE_MATCHES_BYTES];
    int len = spvs_matches_t_encode(buf, 0, (int)sizeof(buf), &l->msg);
    if (len < 0)
        return -1;
    return lcm_publish(l->lcm, l->channel, buf, (unsigned)len) < 0 ? -1 : 0;
}

/* keep_last: no answer to this frame within the period.  The base acts on
 * the newest command it has, and stops once that is older than hold_max_s
 * of frame time.  Telemetry is not renewed (h_valid etc. are 0). */
static void keep_last_command(link_lcm_t *l, double t_s, spvs_output_t *out)
{
    if (l->got_newer) {
        l->applied = l->newer;
        if (l->newer.seq > l->applied_seq)
            l->applied_seq = l->newer.seq;
        l->applied_t_s = t_s;
        l->got_newer = 0;
    } else if (t_s - l->applied_t_s > l->hold_max_s) {
        /* Keep the step and status; only the motion stops. */
        l->applied.v = 0.0;
        l->applied.w = 0.0;
    }
    spvs_wire_output_from_msgs(out, &l->applied, NULL);
}

static int link_exchange(void *ctx, uint32_t seq, double t_s,
                         const spvs_match_t *m, uint16_t n, spvs_output_t *out,
                         char *err, unsigned err_len)
{
    link_lcm_t *l = (link_lcm_t *)ctx;
    if (spvs_wire_frame_from_sim(&l->msg, seq, t_s, l->run_id, m, n, "LCM link",
                                 err, err_len) != 0) {
        return -1;
    }
    l->want_seq = seq;
    l->got_cmd = 0;
    l->got_state = 0;
    if (publish_frame(l) != 0) {
        snprintf(err, err_len, "LCM link: publishing frame %u on %s failed",
                 (unsigned)seq, l->url);
        return -1;
    }

    /* Wait for the answer, bounded by the timeout whatever else arrives.
     * UDP may lose the frame, or the node may not have subscribed yet when
     * a run starts, so the frame goes out again every RESEND_S; the node
     * answers a repeated frame with its previous answer and never runs the
     * core twice, so this cannot change the result. */
    double t_sent = now_s();
    double deadline = t_sent + l->timeout_s;
    while (!l->got_cmd) {
        double t = now_s();
        if (t - t_sent >= RESEND_S) {
            if (publish_frame(l) != 0) {
                snprintf(err, err_len,
                         "LCM link: publishing frame %u on %s failed",
                         (unsigned)seq, l->url);
                return -1;
            }
            l->resends++;
            t_sent = t;
        }
        double left = deadline - t;
        if (left <= 0.0 && l->keep_last) {
            keep_last_command(l, t_s, out);
            return 0;
        }
        if (left <= 0.0) {
            snprintf(err, err_len,
                     "LCM link: no SPVS_CMD for frame %u within %.3g s on %s "
                     "(is spvs-node running on that URL?)",
                     (unsigned)seq, l->timeout_s, l->url);
            return -1;
        }
        double wait = left < RESEND_S ? left : RESEND_S;
        int ms = (int)ceil(wait * 1000.0);
        if (lcm_handle_timeout(l->lcm, ms > 0 ? ms : 1) < 0) {
            snprintf(err, err_len, "LCM link: receive failed on %s", l->url);
            return -1;
        }
    }
    /* The node publishes the state before the command, so it is normally
     * here already; take whatever else is queued without waiting. */
    for (int k = 0; k < 4 && !l->got_state; k++)
        if (lcm_handle_timeout(l->lcm, 0) <= 0)
            break;
    spvs_wire_output_from_msgs(out, &l->cmd, l->got_state ? &l->state : NULL);
    if (!l->got_state)
        out->n_matches = n;
    l->applied = l->cmd;
    l->applied_seq = (int64_t)seq;
    l->applied_t_s = t_s;
    l->got_newer = 0;
    return 0;
}

static void link_close(void *ctx)
{
    link_lcm_t *l = (link_lcm_t *)ctx;
    if (!l)
        return;
    if (l->sub_cmd)
        lcm_unsubscribe(l->lcm, l->sub_cmd);
    if (l->sub_state)
        lcm_unsubscribe(l->lcm, l->sub_state);
    lcm_destroy(l->lcm);
    free(l);
}

int sim_link_lcm_open(const char *url, double timeout_s, sim_link_t *out,
                      char *err, unsigned err_len)
{
    return sim_link_lcm_open_opts(url, timeout_s, NULL, out, err, err_len);
}

int sim_link_lcm_open_opts(const char *url, double timeout_s,
                           const sim_link_lcm_opts_t *opts, sim_link_t *out,
                           char *err, unsigned err_len)
{
    if (!out || !(timeout_s > 0.0) || !isfinite(timeout_s)) {
        snprintf(err, err_len, "LCM link: timeout must be positive seconds");
        return -1;
    }
    link_lcm_t *l = (link_lcm_t *)calloc(1, sizeof(*l));
    if (!l) {
        snprintf(err, err_len, "LCM link: out of memory");
        return -1;
    }
    snprintf(l->url, sizeof(l->url), "%s", url ? url : "(LCM default URL)");
    l->timeout_s = timeout_s;
    l->want_seq = -1;
    const char *ch = opts && opts->matches_channel ? opts->matches_channel
                                                   : SPVS_CH_MATCHES;
    if (strlen(ch) == 0 || strlen(ch) >= sizeof(l->channel)) {
        snprintf(err, err_len, "LCM link: channel name must have 1..%u "
                 "characters", (unsigned)sizeof(l->channel) - 1);
        free(l);
        return -1;
    }
    snprintf(l->channel, sizeof(l->channel), "%s", ch);
    l->keep_last = opts ? opts->keep_last : 0;
    l->hold_max_s = opts ? opts->hold_max_s : 0.0;
    if (l->keep_last && !(l->hold_max_s > 0.0 && isfinite(l->hold_max_s))) {
        snprintf(err, err_len, "LCM link: hold time must be positive seconds");
        free(l);
        return -1;
    }
    /* Before the first answer the base stands still. */
    l->applied_seq = -2;
    l->applied.seq = -2;
    /* A run id that differs from any earlier run's, so that a node still
     * running from one resets its controller. */
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    l->run_id = ((int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec) ^
                ((int64_t)getpid() << 40);
    l->lcm = lcm_create(url);
    if (!l->lcm) {
        snprintf(err, err_len, "LCM link: cannot open '%s' (no multicast "
                 "route? see docs/LCM.md)", l->url);
        free(l);
        return -1;
    }
    l->sub_cmd = lcm_subscribe(l->lcm, SPVS_CH_CMD, on_cmd, l);
    l->sub_state = lcm_subscribe(l->lcm, SPVS_CH_STATE, on_state, l);
    if (!l->sub_cmd || !l->sub_state) {
        snprintf(err, err_len, "LCM link: subscribing on '%s' failed", l->url);
        link_close(l);
        return -1;
    }
    out->ctx = l;
    out->exchange = link_exchange;
    out->close = link_close;
    return 0;
}
