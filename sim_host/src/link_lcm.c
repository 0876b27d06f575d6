/*
 * link_lcm.c - the simulator's LCM link; see sim/link_lcm.h.
 */
#define _POSIX_C_SOURCE 200809L

#include "sim/link_lcm.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/clock.h"
#include "sim/link_lockstep.h"
#include "wire.h"

typedef struct {
    lcm_t *lcm;
    char url[256];
    double timeout_s;
    int64_t run_id;
    sim_lockstep_t ls;       /* the frame awaited and its answer */
    spvs_cmd_t rx_cmd;       /* decode scratch */
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
} link_lcm_t;

/* Wait before publishing an unanswered frame again, seconds. */
#define RESEND_S 0.25

static void on_cmd(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)channel;
    link_lcm_t *l = (link_lcm_t *)user;
    int kept = sim_lockstep_on_cmd(&l->ls, rbuf->data, (int)rbuf->data_size,
                                   &l->rx_cmd);
    if (kept == 0 && l->keep_last &&
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
    (void)sim_lockstep_on_state(&l->ls, rbuf->data, (int)rbuf->data_size);
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

/* sim_lockstep_io_t.send: the frame in l->msg. */
static int io_send(void *ctx, char *err, unsigned err_len)
{
    link_lcm_t *l = (link_lcm_t *)ctx;
    if (publish_frame(l) != 0) {
        snprintf(err, err_len, "LCM link: publishing frame %u on %s failed",
                 (unsigned)l->ls.want_seq, l->url);
        return -1;
    }
    return 0;
}

/* sim_lockstep_io_t.poll: lcm_handle_timeout hands over one message per
 * call, so after the wait take what else is queued, a bounded number. */
static int io_poll(void *ctx, double wait_s, char *err, unsigned err_len)
{
    link_lcm_t *l = (link_lcm_t *)ctx;
    int ms = wait_s > 0.0 ? (int)ceil(wait_s * 1000.0) : 0;
    int r = lcm_handle_timeout(l->lcm, ms);
    for (int k = 0; k < 4 && r > 0; k++)
        r = lcm_handle_timeout(l->lcm, 0);
    if (r < 0) {
        snprintf(err, err_len, "LCM link: receive failed on %s", l->url);
        return -1;
    }
    return 0;
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

    /* UDP may lose the frame, or the node may not have subscribed yet when
     * a run starts: hence the resends.  The node publishes the state
     * before the command, so it is normally here already: no grace time. */
    const sim_lockstep_io_t io = { l, io_send, io_poll };
    const sim_lockstep_timing_t tm = { l->timeout_s, RESEND_S, 0.0 };
    int rc = sim_lockstep_exchange(&l->ls, seq, &io, &tm, NULL, err, err_len);
    if (rc < 0)
        return -1;
    if (rc == SIM_LOCKSTEP_TIMEOUT && l->keep_last) {
        keep_last_command(l, t_s, out);
        return 0;
    }
    if (rc == SIM_LOCKSTEP_TIMEOUT) {
        snprintf(err, err_len,
                 "LCM link: no SPVS_CMD for frame %u within %.3g s on %s "
                 "(is spvs-node running on that URL?)",
                 (unsigned)seq, l->timeout_s, l->url);
        return -1;
    }
    sim_lockstep_output(&l->ls, n, out);
    l->applied = l->ls.cmd;
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
    sim_lockstep_init(&l->ls);
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
    /* A node still running from an earlier run resets its controller. */
    l->run_id = sim_clock_run_id();
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
