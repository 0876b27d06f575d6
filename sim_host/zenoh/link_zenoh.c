/*
 * link_zenoh.c - the simulator's Zenoh link; see sim/link_zenoh.h.
 *
 * Record format from the port (sim_host/zenoh/sim_port.py): u8 kind, u32
 * big-endian length, payload.  Frames to the port: u32 big-endian length,
 * payload.
 */
#define _GNU_SOURCE /* SOCK_CLOEXEC, MSG_NOSIGNAL */

#include "sim/link_zenoh.h"

#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include "sim/cli.h"
#include "sim/clock.h"
#include "sim/link_lockstep.h"
#include "wire.h"

#ifndef SPVS_SOURCE_DIR
#define SPVS_SOURCE_DIR "."
#endif
#define SPVS_ZENOH_PORT_NAME "sim_port.py"

extern char **environ;

/* The largest record the port may send: an error line or a state_t (140
 * bytes); anything longer is a protocol error, not a reason to allocate. */
#define REC_MAX_PAYLOAD 4096
#define RX_BUF_BYTES (2 * (5 + REC_MAX_PAYLOAD))
/* How long an answered frame may wait for its telemetry, which travels on
 * its own key expression and can arrive just after the command. */
#define STATE_GRACE_S 0.05
/* Python start-up and the zenoh import, on top of the subscriber wait. */
#define START_SLACK_S 15.0

typedef struct {
    pid_t pid;
    int fd;                 /* our end of the socket pair                   */
    int reaped;
    char robot[72];
    char endpoint[256];
    double timeout_s;
    double resend_s;        /* 0: never resend                              */
    int64_t run_id;
    sim_lockstep_t ls;      /* the frame awaited and its answer         */
    spvs_matches_t msg;
    uint8_t tx[4 + SPVS_WIRE_MATCHES_BYTES];
    unsigned tx_len;
    uint8_t rx[RX_BUF_BYTES];
    unsigned rx_len;
    char fatal[256];        /* text of an 'E' record                        */
    unsigned long lost_frames;  /* frames that needed a resend          */
    double longest_wait_s;      /* longest wait for one answer, seconds  */
    int failed;                 /* an exchange failed: no summary line   */
} link_zenoh_t;

static uint32_t be32(const uint8_t *p)
{
    return ((uint32_t)p[0] << 24) | ((uint32_t)p[1] << 16) |
           ((uint32_t)p[2] << 8) | (uint32_t)p[3];
}

/* Exit status of the port if it has exited, as text; "still running"
 * otherwise.  Reaps it. */
static void child_status(link_zenoh_t *l, char *buf, size_t len)
{
    int st = 0;
    if (!l->reaped && waitpid(l->pid, &st, WNOHANG) == l->pid) {
        l->reaped = 1;
        if (WIFEXITED(st))
            snprintf(buf, len, "exit status %d", WEXITSTATUS(st));
        else if (WIFSIGNALED(st))
            snprintf(buf, len, "killed by signal %d", WTERMSIG(st));
        else
            snprintf(buf, len, "ended");
        return;
    }
    snprintf(buf, len, l->reaped ? "ended" : "still running");
}

/* Send all of buf.  MSG_NOSIGNAL: a dead port must be an error here, not a
 * SIGPIPE that kills the simulator. */
static int send_all(int fd, const uint8_t *buf, size_t len)
{
    while (len > 0) {
        ssize_t n = send(fd, buf, len, MSG_NOSIGNAL);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return -1;
        }
        buf += n;
        len -= (size_t)n;
    }
    return 0;
}

/* Handle one complete record.  Returns 0, or -1 after an 'E' record (its
 * text kept in l->fatal) or a record kind that does not exist. */
static int on_record(link_zenoh_t *l, uint8_t kind, const uint8_t *p,
                     uint32_t n)
{
    switch (kind) {
    case 'C':
        /* The bridge checked the bytes already; the fingerprint check in
         * decode still guards against anything else on the key. */
        (void)sim_lockstep_on_cmd(&l->ls, p, (int)n, NULL);
        return 0;
    case 'S':
        (void)sim_lockstep_on_state(&l->ls, p, (int)n);
        return 0;
    case 'R':
        return 0;
    case 'E':
        snprintf(l->fatal, sizeof(l->fatal), "%.*s",
                 (int)(n < 250 ? n : 250), (const char *)p);
        return -1;
    default:
        snprintf(l->fatal, sizeof(l->fatal),
                 "unknown record kind 0x%02x from the port", kind);
        return -1;
    }
}

/* Wait up to wait_s for input from the port and handle every complete
 * record.  Returns 1 if a record of kind `stop_kind` was among them, 0 if
 * not (time up or other records), -1 on an error (text in err). */
static int pump(link_zenoh_t *l, double wait_s, uint8_t stop_kind, char *err,
                unsigned err_len)
{
    struct pollfd pfd = { .fd = l->fd, .events = POLLIN, .revents = 0 };
    int ms = wait_s > 0.0 ? (int)ceil(wait_s * 1000.0) : 0;
    int r = poll(&pfd, 1, ms);
    if (r < 0) {
        if (errno == EINTR)
            return 0;
        snprintf(err, err_len, "Zenoh link: poll failed: %s", strerror(errno));
        return -1;
    }
    if (r == 0)
        return 0;
    ssize_t got = recv(l->fd, l->rx + l->rx_len, sizeof(l->rx) - l->rx_len,
                       MSG_DONTWAIT);
    if (got < 0 && (errno == EINTR || errno == EAGAIN ||
                    errno == EWOULDBLOCK))
        return 0;
    if (got < 0 && errno != ECONNRESET) {
        snprintf(err, err_len, "Zenoh link: reading from the port failed: %s",
                 strerror(errno));
        return -1;
    }
    if (got <= 0) {
        /* End of file, or a reset when the port exited without reading all
         * we sent: give it a moment to finish exiting so that its status
         * can be told. */
        char why[64];
        for (int k = 0; k < 50; ++k) {
            child_status(l, why, sizeof(why));
            if (l->reaped)
                break;
            usleep(10000);
        }
        snprintf(err, err_len, "Zenoh link: the port process (%s) stopped: "
                 "%s", SPVS_ZENOH_PORT_NAME, why);
        return -1;
    }
    l->rx_len += (unsigned)got;

    int seen = 0;
    unsigned off = 0;
    while (l->rx_len - off >= 5) {
        uint32_t n = be32(l->rx + off + 1);
        if (n > REC_MAX_PAYLOAD) {
            snprintf(err, err_len, "Zenoh link: record of %lu bytes from the "
                     "port, more than %d", (unsigned long)n, REC_MAX_PAYLOAD);
            return -1;
        }
        if (l->rx_len - off < 5 + n)
            break;
        uint8_t kind = l->rx[off];
        if (on_record(l, kind, l->rx + off + 5, n) != 0) {
            snprintf(err, err_len, "Zenoh link: %s", l->fatal);
            return -1;
        }
        if (kind == stop_kind)
            seen = 1;
        off += 5 + n;
    }
    memmove(l->rx, l->rx + off, l->rx_len - off);
    l->rx_len -= off;
    return seen;
}

/* sim_lockstep_io_t.send: the encoded frame in l->tx. */
static int io_send(void *ctx, char *err, unsigned err_len)
{
    link_zenoh_t *l = (link_zenoh_t *)ctx;
    if (send_all(l->fd, l->tx, l->tx_len) != 0) {
        int e = errno;
        char why[64];
        child_status(l, why, sizeof(why));
        snprintf(err, err_len, "Zenoh link: cannot send frame %u to the port "
                 "(%s): %s", (unsigned)l->ls.want_seq, why, strerror(e));
        return -1;
    }
    return 0;
}

/* sim_lockstep_io_t.poll: every complete record from the port. */
static int io_poll(void *ctx, double wait_s, char *err, unsigned err_len)
{
    return pump((link_zenoh_t *)ctx, wait_s, 0, err, err_len) < 0 ? -1 : 0;
}

static int exchange(link_zenoh_t *l, uint32_t seq, double t_s,
                    const spvs_match_t *m, uint16_t n, spvs_output_t *out,
                    char *err, unsigned err_len)
{
    if (spvs_wire_frame_from_sim(&l->msg, seq, t_s, l->run_id, m, n, "Zenoh link",
                                 err, err_len) != 0) {
        return -1;
    }
    int len = spvs_matches_t_encode(l->tx + 4, 0, SPVS_WIRE_MATCHES_BYTES,
                                    &l->msg);
    if (len < 0) {
        snprintf(err, err_len, "Zenoh link: encoding frame %u failed",
                 (unsigned)seq);
        return -1;
    }
    l->tx[0] = (uint8_t)((uint32_t)len >> 24);
    l->tx[1] = (uint8_t)((uint32_t)len >> 16);
    l->tx[2] = (uint8_t)((uint32_t)len >> 8);
    l->tx[3] = (uint8_t)len;
    l->tx_len = 4u + (unsigned)len;

    /* The telemetry travels on its own key expression and can arrive just
     * after the command: hence the grace time. */
    const sim_lockstep_io_t io = { l, io_send, io_poll };
    const sim_lockstep_timing_t tm = { l->timeout_s, l->resend_s,
                                       STATE_GRACE_S };
    sim_lockstep_stats_t st;
    int rc = sim_lockstep_exchange(&l->ls, seq, &io, &tm, &st, err, err_len);
    if (st.sends > 1)
        l->lost_frames++;
    if (rc < 0)
        return -1;
    if (rc == SIM_LOCKSTEP_TIMEOUT) {
        snprintf(err, err_len,
                 "Zenoh: no spvs/%s/cmd for frame %u within %.3g s, %d "
                 "sends (bridge at %s? node?)", l->robot, (unsigned)seq,
                 l->timeout_s, st.sends, l->endpoint);
        return -1;
    }
    if (st.waited_s > l->longest_wait_s)
        l->longest_wait_s = st.waited_s;
    sim_lockstep_output(&l->ls, n, out);
    return 0;
}

static int link_exchange(void *ctx, uint32_t seq, double t_s,
                         const spvs_match_t *m, uint16_t n, spvs_output_t *out,
                         char *err, unsigned err_len)
{
    link_zenoh_t *l = (link_zenoh_t *)ctx;
    int rc = exchange(l, seq, t_s, m, n, out, err, err_len);
    if (rc != 0)
        l->failed = 1;
    return rc;
}

/* Wait up to wait_s for the port to exit; 1 if it has been reaped. */
static int reap_within(link_zenoh_t *l, double wait_s)
{
    double end = sim_clock_now_s() + wait_s;
    while (!l->reaped) {
        int st;
        pid_t r = waitpid(l->pid, &st, WNOHANG);
        if (r == l->pid || (r < 0 && errno == ECHILD)) {
            l->reaped = 1;
            break;
        }
        if (sim_clock_now_s() >= end)
            return 0;
        usleep(10000);
    }
    return 1;
}

static void link_close(void *ctx)
{
    link_zenoh_t *l = (link_zenoh_t *)ctx;
    if (!l)
        return;
    if (l->fd >= 0) {
        /* End of input tells the port to close its session and exit. */
        shutdown(l->fd, SHUT_WR);
    }
    if (l->pid > 0 && !reap_within(l, 3.0)) {
        kill(l->pid, SIGTERM);
        if (!reap_within(l, 2.0)) {
            kill(l->pid, SIGKILL);
            (void)reap_within(l, 5.0);
        }
    }
    if (l->fd >= 0)
        close(l->fd);
    /* Frames that needed resending mean answers were lost (the bridge
     * restarted, the network dropped out): worth one line after a run that
     * otherwise succeeded.  After a failure the error line says enough. */
    if (l->lost_frames && !l->failed)
        fprintf(stderr, "spvs-sim: Zenoh link: %lu frames were sent again "
                "before their answer came (longest wait %.3g s)\n",
                l->lost_frames, l->longest_wait_s);
    free(l);
}

/* Environment variable as a number in [lo, hi], or def when unset. */
static int env_number(const char *name, double def, double lo, double hi,
                      double *out, char *err, unsigned err_len)
{
    const char *s = getenv(name);
    if (!s || !*s) {
        *out = def;
        return 0;
    }
    char why[200];
    if (sim_cli_parse_real(name, s, lo, hi, SIM_CLI_CLOSED, out, why,
                           sizeof(why)) != 0) {
        snprintf(err, err_len, "Zenoh link: %s", why);
        return -1;
    }
    return 0;
}

static int robot_ok(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n > 64)
        return 0;
    for (size_t i = 0; i < n; ++i) {
        char c = s[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
              (c >= '0' && c <= '9') || c == '_' || c == '.' || c == '-'))
            return 0;
    }
    return 1;
}

/* What the environment and the caller choose for the port. */
typedef struct {
    const char *robot;
    const char *mode;
    double resend_s;
    char python[1024];
    char port[1024];
} port_setup_t;

/* The caller's arguments and the SPVS_ZENOH_* variables, checked.  0, or
 * -1 with the reason in err. */
static int check_setup(const char *endpoint, double timeout_s,
                       const sim_link_t *out, port_setup_t *ps, char *err,
                       unsigned err_len)
{
    if (!out || !(timeout_s > 0.0) || !isfinite(timeout_s)) {
        snprintf(err, err_len, "Zenoh link: timeout must be positive seconds");
        return -1;
    }
    if (!endpoint || strlen(endpoint) < 5 || strlen(endpoint) > 200 ||
        !strchr(endpoint, '/')) {
        snprintf(err, err_len, "Zenoh link: endpoint '%s' is not of the form "
                 "tcp/HOST:PORT", endpoint ? endpoint : "(null)");
        return -1;
    }
    ps->robot = getenv("SPVS_ZENOH_ROBOT");
    if (!ps->robot || !*ps->robot)
        ps->robot = "robot0";
    if (!robot_ok(ps->robot)) {
        snprintf(err, err_len, "Zenoh link: SPVS_ZENOH_ROBOT='%.70s' must be "
                 "1..64 characters from A-Z a-z 0-9 _ . -", ps->robot);
        return -1;
    }
    ps->mode = getenv("SPVS_ZENOH_MODE");
    if (!ps->mode || !*ps->mode)
        ps->mode = "peer";
    if (strcmp(ps->mode, "peer") != 0 && strcmp(ps->mode, "client") != 0) {
        snprintf(err, err_len, "Zenoh link: SPVS_ZENOH_MODE='%.40s' is not "
                 "peer or client", ps->mode);
        return -1;
    }
    return env_number("SPVS_ZENOH_RESEND_S", 0.5, 0.0, 3600.0, &ps->resend_s,
                      err, err_len);
}

/* The Python and the port's script: $SPVS_PYTHON and $SPVS_ZENOH_PORT, else
 * the source tree's venv and sim_port.py.  0, or -1 with the reason in err
 * when either is not there. */
static int find_port(port_setup_t *ps, char *err, unsigned err_len)
{
    const char *s = getenv("SPVS_PYTHON");
    if (s && *s)
        snprintf(ps->python, sizeof(ps->python), "%s", s);
    else
        snprintf(ps->python, sizeof(ps->python), "%s/.venv/bin/python",
                 SPVS_SOURCE_DIR);
    s = getenv("SPVS_ZENOH_PORT");
    if (s && *s)
        snprintf(ps->port, sizeof(ps->port), "%s", s);
    else
        snprintf(ps->port, sizeof(ps->port),
                 "%s/sim_host/zenoh/" SPVS_ZENOH_PORT_NAME, SPVS_SOURCE_DIR);
    if (access(ps->python, X_OK) != 0) {
        snprintf(err, err_len, "Zenoh link: no Python at %.150s: run "
                 "scripts/setup_venv.sh (or set SPVS_PYTHON)", ps->python);
        return -1;
    }
    if (access(ps->port, R_OK) != 0) {
        snprintf(err, err_len, "Zenoh link: cannot read %.150s (set "
                 "SPVS_ZENOH_PORT)", ps->port);
        return -1;
    }
    return 0;
}

/* Starts the port with l->fd as our end of its input and output.  0, or
 * -1 with the reason in err (l->fd then closed, l not freed). */
static int spawn_port(link_zenoh_t *l, port_setup_t *ps, double wait_s,
                      char *err, unsigned err_len)
{
    /* One socket pair serves as the port's stdin and stdout: unlike a pipe
     * it takes MSG_NOSIGNAL, and shutdown() gives the port its end of
     * input while its answers can still be read. */
    int sv[2];
    if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) != 0) {
        snprintf(err, err_len, "Zenoh link: socketpair failed: %s",
                 strerror(errno));
        return -1;
    }
    char wait_arg[32];
    snprintf(wait_arg, sizeof(wait_arg), "%.3f", wait_s);
    char *argv[] = { ps->python, "-u", ps->port, "--robot", l->robot,
                     "--connect", l->endpoint, "--mode", (char *)ps->mode,
                     "--wait", wait_arg, NULL };
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, sv[1], 0);
    posix_spawn_file_actions_adddup2(&fa, sv[1], 1);
    int rc = posix_spawn(&l->pid, ps->python, &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    close(sv[1]);
    l->fd = sv[0];
    if (rc != 0) {
        snprintf(err, err_len, "Zenoh link: cannot start %.150s: %s",
                 ps->python, strerror(rc));
        close(l->fd);
        return -1;
    }
    return 0;
}

/* Waits for the port's ready record: its publisher then has a subscriber.
 * 0, or -1 with the reason in err. */
static int await_ready(link_zenoh_t *l, double wait_s, char *err,
                       unsigned err_len)
{
    double deadline = sim_clock_now_s() + wait_s + START_SLACK_S;
    for (;;) {
        double left = deadline - sim_clock_now_s();
        if (left <= 0.0) {
            snprintf(err, err_len, "Zenoh link: the port did not become ready "
                     "within %.3g s", wait_s + START_SLACK_S);
            return -1;
        }
        int r = pump(l, left, 'R', err, err_len);
        if (r < 0)
            return -1;
        if (r == 1)
            return 0;
    }
}

int sim_link_zenoh_open(const char *endpoint, double timeout_s,
                        sim_link_t *out, char *err, unsigned err_len)
{
    port_setup_t ps;
    if (check_setup(endpoint, timeout_s, out, &ps, err, err_len) != 0 ||
        find_port(&ps, err, err_len) != 0)
        return -1;

    link_zenoh_t *l = (link_zenoh_t *)calloc(1, sizeof(*l));
    if (!l) {
        snprintf(err, err_len, "Zenoh link: out of memory");
        return -1;
    }
    l->fd = -1;
    l->pid = -1;
    l->timeout_s = timeout_s;
    l->resend_s = ps.resend_s;
    sim_lockstep_init(&l->ls);
    snprintf(l->robot, sizeof(l->robot), "%s", ps.robot);
    snprintf(l->endpoint, sizeof(l->endpoint), "%s", endpoint);
    /* A node still running from an earlier run resets its controller. */
    l->run_id = sim_clock_run_id();

    /* The port waits for a subscriber of the matches for the timeout, but
     * at least long enough for the Zenoh peers to exchange declarations. */
    double wait_s = timeout_s > 3.0 ? timeout_s : 3.0;
    if (spawn_port(l, &ps, wait_s, err, err_len) != 0) {
        free(l);
        return -1;
    }
    if (await_ready(l, wait_s, err, err_len) != 0) {
        link_close(l);
        return -1;
    }
    out->ctx = l;
    out->exchange = link_exchange;
    out->close = link_close;
    return 0;
}
