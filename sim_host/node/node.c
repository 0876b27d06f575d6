/*
 * node.c - the controller node's message handling; see node.h.
 */
#define _POSIX_C_SOURCE 200809L

#include "node.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "sim/cli.h"
#include "sim/clock.h"

static void node_log(const spvs_node_t *node, int level, const char *what)
{
    if (node->log_level >= level)
        fprintf(stderr, "spvs-node: %s\n", what);
}

/* Publish telemetry first and the command last: a client in lock-step that
 * stops waiting when the command arrives then already holds the state. */
static void node_publish(spvs_node_t *node, const spvs_state_t *st,
                         const spvs_cmd_t *cmd)
{
    if (st && spvs_wire_publish_state(node->lcm, st) != 0)
        node->stats.publish_errors++;
    if (spvs_wire_publish_cmd(node->lcm, cmd) != 0) {
        node->stats.publish_errors++;
        node_log(node, 1, "error: publishing SPVS_CMD failed");
    }
}

static void node_publish_stop(spvs_node_t *node, int64_t seq, int64_t utime,
                              int status)
{
    spvs_cmd_t cmd;
    spvs_wire_cmd_stop(&cmd, seq, utime, status, (int)spvs_step(&node->core));
    node_publish(node, NULL, &cmd);
}

static void on_matches(const lcm_recv_buf_t *rbuf, const char *channel,
                       void *user)
{
    (void)channel;
    spvs_node_t *node = (spvs_node_t *)user;
    (void)spvs_node_on_bytes(node, rbuf->data, (int)rbuf->data_size,
                             sim_clock_now_s());
}

int spvs_node_init(spvs_node_t *node, lcm_t *lcm, const spvs_params_t *p,
                   double watchdog_s, double now_s)
{
    /* Keep the caller's settings that are not arguments. */
    int log_level = node->log_level;
    unsigned progress_every = node->progress_every;
    FILE *progress = node->progress;

    memset(node, 0, sizeof(*node));
    node->log_level = log_level;
    node->progress_every = progress_every;
    node->progress = progress ? progress : stdout;
    if (!(watchdog_s > 0.0) || !isfinite(watchdog_s))
        return SPVS_E_CONFIG;
    node->lcm = lcm;
    node->params = *p;
    node->watchdog_s = watchdog_s;
    node->last_valid_s = now_s;
    node->last_stop_s = now_s;
    int st = spvs_init(&node->core, &node->params);
    if (st != SPVS_OK)
        return st;
    node->sub = lcm_subscribe(lcm, SPVS_CH_MATCHES, on_matches, node);
    return node->sub ? SPVS_OK : SPVS_E_ARG;
}

void spvs_node_close(spvs_node_t *node)
{
    if (node->sub)
        lcm_unsubscribe(node->lcm, node->sub);
    node->sub = NULL;
}

int spvs_node_on_bytes(spvs_node_t *node, const void *data, int len,
                       double now_s)
{
    char err[160];
    spvs_matches_t *msg = &node->msg;

    /* Fixed-size arrays: decoding writes only into *msg and never allocates,
     * whatever the bytes say.  A wrong fingerprint or a short buffer fails
     * here, and without a trusted seq there is no frame to answer. */
    if (spvs_matches_t_decode(data, 0, len, msg) < 0) {
        node->stats.undecodable++;
        snprintf(err, sizeof(err),
                 "error: undecodable SPVS_MATCHES message (%d bytes), dropped",
                 len);
        node_log(node, 1, err);
        return SPVS_E_ARG;
    }

    /* A new run (the simulator restarted) begins with a fresh controller, as
     * the in-process loop does, so both give the same result. */
    if (!node->has_run || msg->run_id != node->run_id) {
        if (node->has_run) {
            snprintf(err, sizeof(err), "new run %lld: controller reset",
                     (long long)msg->run_id);
            node_log(node, 2, err);
        }
        spvs_reset(&node->core);
        node->has_run = 1;
        node->run_id = msg->run_id;
        node->has_last = 0;
        node->stats.runs++;
    }

    int st = spvs_wire_matches_check(msg, err, sizeof(err));
    if (st != SPVS_OK) {
        node->stats.rejected++;
        if (node->log_level >= 1)
            fprintf(stderr, "spvs-node: error: %s: stop\n", err);
        node_publish_stop(node, msg->seq, msg->utime, st);
        return st;
    }

    if (node->has_last && msg->seq == node->last_seq) {
        /* The sender missed our answer and asked again: the same answer,
         * since running the core twice on one frame would change its state
         * (hold counters, off-plane memory). */
        node->stats.duplicates++;
        node_publish(node, &node->last_state, &node->last_cmd);
        return node->last_cmd.status;
    }
    if (node->has_last && msg->seq < node->last_seq) {
        node->stats.out_of_order++;
        snprintf(err, sizeof(err),
                 "frame %lld arrived after frame %lld: stale, stop",
                 (long long)msg->seq, (long long)node->last_seq);
        node_log(node, 2, err);
        node_publish_stop(node, msg->seq, msg->utime, SPVS_E_STALE);
        return SPVS_E_STALE;
    }

    uint16_t n = spvs_wire_matches_to_core(msg, node->m);
    spvs_output_t out;
    memset(&out, 0, sizeof(out));
    double t_s = (double)msg->utime * 1e-6;
    st = spvs_update(&node->core, node->m, n, (spvs_real)t_s, &out);
    (void)st; /* also in out.status, which is what goes on the wire */

    spvs_wire_state_from_output(&node->last_state, msg->seq, msg->utime, &out);
    spvs_wire_cmd_from_output(&node->last_cmd, msg->seq, msg->utime, &out);
    node->has_last = 1;
    node->last_seq = msg->seq;
    node->last_valid_s = now_s;
    node->last_stop_s = now_s;
    node->stats.frames++;
    node_publish(node, &node->last_state, &node->last_cmd);

    if (node->log_level >= 3)
        fprintf(stderr,
                "spvs-node: frame %lld t %.3f s: %u matches, %u inliers, "
                "step %u, v %.4f m/s, w %.4f rad/s, %s\n",
                (long long)msg->seq, t_s, (unsigned)out.n_matches,
                (unsigned)out.n_inliers, (unsigned)out.step, (double)out.v,
                (double)out.w, spvs_status_str(out.status));
    if (node->progress_every && node->stats.frames % node->progress_every == 0) {
        fprintf(node->progress,
                "[node] frame %6lld  t %7.2f s  step %u  v %+.3f m/s  "
                "w %+.4f rad/s  inliers %3u  %s\n",
                (long long)msg->seq, t_s, (unsigned)out.step, (double)out.v,
                (double)out.w, (unsigned)out.n_inliers,
                spvs_status_str(out.status));
        fflush(node->progress);
    }
    return out.status;
}

int spvs_node_tick(spvs_node_t *node, double now_s)
{
    if (now_s - node->last_valid_s < node->watchdog_s ||
        now_s - node->last_stop_s < node->watchdog_s)
        return 0;
    /* Log only the first stop of a silence, not one line per period. */
    if (node->last_stop_s <= node->last_valid_s)
        node_log(node, 2, "watchdog: no valid matches, publishing stops");
    node->last_stop_s = now_s;
    node->stats.watchdog++;
    node_publish_stop(node, -1, 0, SPVS_E_STALE);
    return 1;
}

/* ---- parameters ------------------------------------------------------- */

typedef enum { P_REAL, P_U16, P_U32 } ptype_t;

typedef struct {
    const char *name;
    size_t offset;
    ptype_t type;
} pdesc_t;

#define PR(name, field) {name, offsetof(spvs_params_t, field), P_REAL}
static const pdesc_t pdesc[] = {
    PR("k_w", ctl.k_w),
    PR("k_v", ctl.k_v),
    PR("k_w3", ctl.k_w3),
    PR("k_w11", ctl.k_w11),
    PR("v_max", ctl.v_max),
    PR("w_max", ctl.w_max),
    PR("w_min_escape", ctl.w_min_escape),
    PR("alpha_x", ctl.alpha_x),
    PR("alpha_y", ctl.alpha_y),
    PR("tol_align", ctl.tol_align),
    PR("tol_translate", ctl.tol_translate),
    PR("tol_h13_px", ctl.tol_h13_px),
    PR("lock_ex_px", ctl.lock_ex_px),
    PR("switch_parallax_px", ctl.switch_parallax_px),
    PR("min_signal_ratio", ctl.min_signal_ratio),
    PR("step_timeout_s", ctl.step_timeout_s),
    {"hold_frames", offsetof(spvs_params_t, ctl.hold_frames), P_U16},
    PR("noise_px", noise_px),
    PR("confidence", confidence),
    {"max_iters", offsetof(spvs_params_t, max_iters), P_U32},
    PR("offplane_px", offplane_px),
    PR("epipole_sin_tol", epipole_sin_tol),
    {"min_support", offsetof(spvs_params_t, min_support), P_U16},
    PR("max_frame_gap_s", max_frame_gap_s),
    {"seed", offsetof(spvs_params_t, seed), P_U32},
};
#undef PR

const char *const spvs_node_param_names[] = {
    "alpha", "k_w", "k_v", "k_w3", "k_w11", "v_max", "w_max", "w_min_escape",
    "alpha_x", "alpha_y", "tol_align", "tol_translate", "tol_h13_px",
    "lock_ex_px", "switch_parallax_px", "min_signal_ratio", "step_timeout_s",
    "hold_frames", "noise_px", "confidence", "max_iters", "offplane_px",
    "epipole_sin_tol", "min_support", "max_frame_gap_s", "seed", NULL};

int spvs_node_param_set(spvs_params_t *p, const char *name, const char *value,
                        char *err, unsigned err_len)
{
    /* "alpha" sets both focal lengths: the nominal camera has square pixels. */
    if (strcmp(name, "alpha") == 0) {
        if (spvs_node_param_set(p, "alpha_x", value, err, err_len) != 0)
            return -1;
        return spvs_node_param_set(p, "alpha_y", value, err, err_len);
    }
    for (size_t i = 0; i < sizeof(pdesc) / sizeof(pdesc[0]); i++) {
        if (strcmp(name, pdesc[i].name) != 0)
            continue;
        char *field = (char *)p + pdesc[i].offset;
        if (pdesc[i].type == P_REAL) {
            double x;
            if (sim_cli_parse_real(name, value, -SIM_CLI_INF, SIM_CLI_INF,
                                   SIM_CLI_CLOSED, &x, err, err_len) != 0)
                return -1;
            *(spvs_real *)(void *)field = (spvs_real)x;
        } else {
            long long u;
            long long max = pdesc[i].type == P_U16 ? 65535 : 4294967295LL;
            if (sim_cli_parse_int(name, value, 0, max, &u, err, err_len) != 0)
                return -1;
            if (pdesc[i].type == P_U16)
                *(uint16_t *)(void *)field = (uint16_t)u;
            else
                *(uint32_t *)(void *)field = (uint32_t)u;
        }
        return 0;
    }
    snprintf(err, err_len, "unknown parameter '%s'", name);
    return -1;
}

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\n' ||
                     s[n - 1] == '\r'))
        s[--n] = '\0';
    return s;
}

int spvs_node_params_load(spvs_params_t *p, const char *path, char *err,
                          unsigned err_len)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        snprintf(err, err_len, "%s: %s", path, strerror(errno));
        return -1;
    }
    char line[256];
    char why[160];
    unsigned lineno = 0;
    int rc = 0;
    while (fgets(line, sizeof(line), f)) {
        lineno++;
        if (!strchr(line, '\n') && !feof(f)) {
            snprintf(err, err_len, "%s:%u: line too long", path, lineno);
            rc = -1;
            break;
        }
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        char *s = trim(line);
        if (*s == '\0')
            continue;
        char *sep = strpbrk(s, "= \t");
        if (!sep) {
            snprintf(err, err_len, "%s:%u: expected 'name = value'", path,
                     lineno);
            rc = -1;
            break;
        }
        *sep = '\0';
        char *value = trim(sep + 1);
        if (*value == '=')
            value = trim(value + 1);
        if (spvs_node_param_set(p, trim(s), value, why, sizeof(why)) != 0) {
            snprintf(err, err_len, "%s:%u: %s", path, lineno, why);
            rc = -1;
            break;
        }
    }
    fclose(f);
    return rc;
}
