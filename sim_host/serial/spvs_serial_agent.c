/*
 * spvs-serial-agent - bridges the controller on a microcontroller (the
 * serial link of docs/SERIAL.md) to LCM: SPVS_MATCHES in, SPVS_CMD and
 * SPVS_STATE out, the same messages as spvs-node, so spvs-sim, the Zenoh
 * bridge and the LCM tools work unchanged with the controller on the MCU.
 *
 * The device is a serial port or pty (a path, opened raw at --baud), a TCP
 * socket (tcp:HOST:PORT, e.g. QEMU's -serial tcp:127.0.0.1:PORT,server) or
 * a Unix socket (unix:PATH).  A lost connection is reopened every 100 ms
 * for --reconnect seconds.
 *
 * Per SPVS_MATCHES message: checked as spvs-node checks it (count, finite
 * values, feature index), then the wire's limits (seq 0..2^32-1, time
 * 0..2^32-1 ms, coordinates within +-2000 px); a refused message is
 * answered with a stop for its seq (SPVS_E_CAPACITY, SPVS_E_NONFINITE or
 * SPVS_E_RANGE) and never reaches the MCU.  Per frame from the MCU: a
 * RESULT becomes SPVS_STATE then SPVS_CMD (a REJECTED one a stop command
 * only), a WATCHDOG status a stop with seq -1 and SPVS_E_STALE, a BOOT
 * status (the MCU started or was reset) makes the agent send the
 * controller's set-up (CONFIG: method, seed, focal length, watchdog time)
 * again.  Frames that fail COBS, CRC, version
 * or length are counted and logged, never acted on.
 *
 * Exit status: 0 after SIGINT/SIGTERM, 1 when the device or LCM fails for
 * good, 2 on bad options.
 */
#define _DEFAULT_SOURCE
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netdb.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "spvs_serial.h"
#include "wire.h"

#define DEFAULT_URL "udpm://239.255.76.67:7667?ttl=0"
/* A repeat of the frame in flight is held back while the earlier copy is
 * still in the device's output queue, and this long after it left,
 * seconds; the hold doubles with each copy of the same frame, up to
 * REPEAT_HOLD_MAX_S. */
#define REPEAT_HOLD_S 0.5
#define REPEAT_HOLD_MAX_S 2.0

static volatile sig_atomic_t g_stop = 0;
static void on_signal(int sig)
{
    (void)sig;
    g_stop = 1;
}

typedef struct {
    uint32_t to_mcu;          /* matches frames written                      */
    uint32_t refused;         /* LCM messages refused before the wire        */
    uint32_t undecodable;     /* LCM messages that did not decode            */
    uint32_t dropped_offline; /* frames with no device to go to              */
    uint32_t results;         /* RESULT frames published                     */
    uint32_t rejected;        /* of them, REJECTED by the MCU                */
    uint32_t repeats;         /* of them, REPEAT answers                     */
    uint32_t watchdog;        /* WATCHDOG statuses (stops published)         */
    uint32_t boots;           /* BOOT statuses                               */
    uint32_t configs;         /* CONFIG frames sent                          */
    uint32_t bad_crc;         /* frames from the MCU failing the CRC         */
    uint32_t bad_framing;     /* failing COBS, size, version, length, type   */
    uint32_t connects;        /* device (re)opened                           */
    uint32_t held;            /* repeats of an unanswered frame held back    */
    uint32_t write_timeouts;  /* frames dropped: the device took no bytes    */
    uint32_t partial_at_open; /* a frame's tail read first after an open     */
} agent_stats_t;

typedef struct {
    const char *device;
    long baud;
    const char *url;
    spvs_serial_config_t cfg;
    double reconnect_s;
    int log_level;
    const char *summary_path;
    const char *ready_path;
    int ready_done;

    int fd;
    int need_delim;           /* a partial frame went out: end it first      */
    int fresh;                /* no delimiter read since the device opened   */
    lcm_t *lcm;
    spvs_serial_rx_t rx;
    agent_stats_t st;
    spvs_serial_status_frame_t mcu; /* last status from the MCU */
    int have_mcu;
    int last_step;
    int64_t fwd_seq, fwd_utime;     /* last frame forwarded           */
    int64_t fwd_run;
    double fwd_t;                   /* when it went out               */
    double fwd_left_t;              /* when it had left the output
                                       queue (< 0: not seen yet)      */
    int fwd_answered;               /* the MCU has answered it        */
    double fwd_hold_s;              /* the hold before its next copy  */
    double last_config_s;
    spvs_matches_t msg;
    spvs_match_t m[SPVS_MAX_MATCHES];
    uint8_t wire[SPVS_SERIAL_MAX_WIRE];
} agent_t;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void logf_(agent_t *a, int level, const char *fmt, ...)
{
    if (a->log_level < level)
        return;
    va_list ap;
    fputs("spvs-serial-agent: ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

/* ---- the device ------------------------------------------------------------ */

static speed_t baud_const(long b)
{
    switch (b) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    case 1000000: return B1000000;
    case 2000000: return B2000000;
    case 3000000: return B3000000;
    case 4000000: return B4000000;
    default: return B0;
    }
}

static int open_tcp(const char *spec, char *err, size_t err_len)
{
    char host[256];
    const char *colon = strrchr(spec, ':');
    if (!colon || colon == spec || (size_t)(colon - spec) >= sizeof(host)) {
        snprintf(err, err_len, "tcp device '%s' is not tcp:HOST:PORT", spec);
        return -2;
    }
    memcpy(host, spec, (size_t)(colon - spec));
    host[colon - spec] = '\0';
    struct addrinfo hints, *res = NULL;
    memset(&hints, 0, sizeof(hints));
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    int rc = getaddrinfo(host, colon + 1, &hints, &res);
    if (rc != 0) {
        snprintf(err, err_len, "tcp:%s: %s", spec, gai_strerror(rc));
        return -2;
    }
    int fd = -1;
    for (struct addrinfo *p = res; p; p = p->ai_next) {
        fd = socket(p->ai_family, p->ai_socktype, p->ai_protocol);
        if (fd < 0)
            continue;
        if (connect(fd, p->ai_addr, p->ai_addrlen) == 0)
            break;
        close(fd);
        fd = -1;
    }
    freeaddrinfo(res);
    if (fd < 0)
        snprintf(err, err_len, "tcp:%s: %s", spec, strerror(errno));
    return fd;
}

static int open_unix(const char *path, char *err, size_t err_len)
{
    struct sockaddr_un sa;
    memset(&sa, 0, sizeof(sa));
    sa.sun_family = AF_UNIX;
    if (strlen(path) >= sizeof(sa.sun_path)) {
        snprintf(err, err_len, "unix:%s: path too long", path);
        return -2;
    }
    strcpy(sa.sun_path, path);
    int fd = socket(AF_UNIX, SOCK_STREAM, 0);
    if (fd < 0 || connect(fd, (struct sockaddr *)&sa, sizeof(sa)) != 0) {
        snprintf(err, err_len, "unix:%s: %s", path, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    return fd;
}

static int open_tty(const char *path, long baud, char *err, size_t err_len)
{
    int fd = open(path, O_RDWR | O_NOCTTY);
    if (fd < 0) {
        /* A port that is not there yet (a USB adapter being plugged in) is
         * waited for; one that can never be opened is an error now. */
        int again = errno == ENOENT || errno == EBUSY || errno == EAGAIN;
        snprintf(err, err_len, "%s: %s", path, strerror(errno));
        return again ? -1 : -2;
    }
    struct termios t;
    if (tcgetattr(fd, &t) != 0) {
        snprintf(err, err_len, "%s: not a terminal: %s", path, strerror(errno));
        close(fd);
        return -2;
    }
    cfmakeraw(&t);
    t.c_cflag |= CLOCAL | CREAD;
    /* VMIN 1 with O_NONBLOCK: no data reads as EAGAIN, so a read of 0
     * bytes can only mean the end, as on the sockets. */
    t.c_cc[VMIN] = 1;
    t.c_cc[VTIME] = 0;
    speed_t sp = baud_const(baud);
    if (cfsetispeed(&t, sp) != 0 || cfsetospeed(&t, sp) != 0 ||
        tcsetattr(fd, TCSANOW, &t) != 0) {
        snprintf(err, err_len, "%s: cannot set %ld baud: %s", path, baud,
                 strerror(errno));
        close(fd);
        return -2;
    }
    /* What arrived before raw mode was taken through the line discipline
     * (echo, CR-LF mapping): not the MCU's bytes as sent. */
    (void)tcflush(fd, TCIFLUSH);
    return fd;
}

/* Returns an fd, -1 when the device is not there yet (retry), -2 for a
 * device that can never work. */
static int open_device(agent_t *a, char *err, size_t err_len)
{
    int fd;
    if (strncmp(a->device, "tcp:", 4) == 0)
        fd = open_tcp(a->device + 4, err, err_len);
    else if (strncmp(a->device, "unix:", 5) == 0)
        fd = open_unix(a->device + 5, err, err_len);
    else
        fd = open_tty(a->device, a->baud, err, err_len);
    if (fd >= 0)
        fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
    return fd;
}

/* Bytes written to the device that its far end has not taken yet: the tty
 * driver's output queue (TIOCOUTQ), or what the peer of a Unix socket has
 * not read (SIOCOUTQ, the same request on Linux).  0 where the driver
 * cannot say (a pty; TCP, whose count ends at the peer's kernel). */
static int device_outq(const agent_t *a)
{
    int n = 0;
    if (a->fd < 0 || ioctl(a->fd, TIOCOUTQ, &n) != 0 || n < 0)
        return 0;
    return n;
}

/* The frame in flight has left the output queue: note when, once. */
static void note_frame_left(agent_t *a, double t)
{
    if (a->fwd_seq >= 0 && !a->fwd_answered && a->fwd_left_t < 0.0 &&
        device_outq(a) == 0)
        a->fwd_left_t = t;
}

static void close_device(agent_t *a, const char *why)
{
    if (a->fd >= 0) {
        logf_(a, 1, "device %s lost (%s); reconnecting", a->device, why);
        close(a->fd);
        a->fd = -1;
    }
    spvs_serial_rx_init(&a->rx);
    a->need_delim = 0;
}

/* Write all n bytes, waiting up to WRITE_WAIT_S for room.  When the other
 * end stops reading (a full pty, a stalled port) the rest of the frame is
 * dropped and a delimiter goes out before the next one, so the receiver
 * throws the partial frame away and loses nothing else. */
#define WRITE_WAIT_S 5.0
static int write_all(agent_t *a, const uint8_t *p, size_t n)
{
    if (a->need_delim) {
        static const uint8_t zero = 0;
        if (write(a->fd, &zero, 1) == 1)
            a->need_delim = 0;
    }
    size_t done = 0;
    double deadline = now_s() + WRITE_WAIT_S;
    while (done < n && a->fd >= 0) {
        ssize_t w = write(a->fd, p + done, n - done);
        if (w > 0) {
            done += (size_t)w;
            continue;
        }
        if (w < 0 && (errno == EAGAIN || errno == EINTR)) {
            if (now_s() > deadline) {
                a->st.write_timeouts++;
                a->need_delim = done > 0;
                logf_(a, 1, "device %s takes no bytes for %.0f s; frame dropped",
                      a->device, WRITE_WAIT_S);
                return -1;
            }
            struct pollfd pf = { a->fd, POLLOUT, 0 };
            (void)poll(&pf, 1, 50);
            continue;
        }
        close_device(a, w < 0 ? strerror(errno) : "closed");
        return -1;
    }
    return done == n ? 0 : -1;
}

static void send_config(agent_t *a)
{
    int len = spvs_serial_encode_config(&a->cfg, a->wire, sizeof(a->wire));
    if (len > 0 && write_all(a, a->wire, (size_t)len) == 0) {
        a->st.configs++;
        a->last_config_s = now_s();
        logf_(a, 2, "sent set-up: method %u, seed %u, alpha %g px, watchdog %u ms",
              (unsigned)a->cfg.method, (unsigned)a->cfg.seed,
              (double)a->cfg.alpha_px, (unsigned)a->cfg.watchdog_ms);
    }
}

/* ---- LCM side ------------------------------------------------------------------ */

static void publish_stop(agent_t *a, int64_t seq, int64_t utime, int status)
{
    spvs_cmd_t cmd;
    spvs_wire_cmd_stop(&cmd, seq, utime, status, a->last_step);
    if (spvs_wire_publish_cmd(a->lcm, &cmd) != 0)
        logf_(a, 1, "publishing SPVS_CMD failed");
}

static uint32_t run_tag(int64_t run_id)
{
    uint64_t u = (uint64_t)run_id;
    return (uint32_t)(u ^ (u >> 32));
}

static void on_matches(const lcm_recv_buf_t *rbuf, const char *channel,
                       void *user)
{
    (void)channel;
    agent_t *a = (agent_t *)user;
    if (spvs_matches_t_decode(rbuf->data, 0, (int)rbuf->data_size, &a->msg) < 0) {
        a->st.undecodable++;
        logf_(a, 1, "SPVS_MATCHES: %u bytes do not decode; dropped",
              (unsigned)rbuf->data_size);
        return;
    }
    char err[160];
    int st = spvs_wire_matches_check(&a->msg, err, sizeof(err));
    if (st != SPVS_OK) {
        a->st.refused++;
        logf_(a, 1, "SPVS_MATCHES %s; answered with a stop", err);
        publish_stop(a, a->msg.seq, a->msg.utime, st);
        return;
    }
    uint16_t n = spvs_wire_matches_to_core(&a->msg, a->m);
    uint32_t t_ms = 0;
    if (a->msg.seq < 0 || a->msg.seq > (int64_t)UINT32_MAX ||
        spvs_serial_ms_from_utime(a->msg.utime, &t_ms) != SPVS_SERIAL_OK) {
        a->st.refused++;
        logf_(a, 1, "frame %lld: seq or time %lld us outside the serial "
              "link's range; answered with a stop", (long long)a->msg.seq,
              (long long)a->msg.utime);
        publish_stop(a, a->msg.seq, a->msg.utime, SPVS_E_RANGE);
        return;
    }
    spvs_serial_matches_hdr_t h = { run_tag(a->msg.run_id), (uint32_t)a->msg.seq,
                                    t_ms, n };
    int len = spvs_serial_encode_matches(&h, a->m, a->wire, sizeof(a->wire));
    if (len < 0) {
        a->st.refused++;
        logf_(a, 1, "frame %lld: a coordinate beyond +-%d px; answered with "
              "a stop", (long long)a->msg.seq,
              SPVS_SERIAL_Q_MAX / SPVS_SERIAL_PX_SCALE);
        publish_stop(a, a->msg.seq, a->msg.utime, SPVS_E_RANGE);
        return;
    }
    /* The sender repeats a frame it has no answer for (spvs-sim every
     * 0.25 s).  While the first copy is still on its way (in the device's
     * output queue: a slow line, or an emulated UART that takes a byte at
     * a time) or the MCU may still be working on it, a second copy would
     * only queue behind it, and the next frame behind both: when copies
     * come faster than the line drains, the queue grows without end.  So a
     * repeat is held back until the first copy has left the queue and
     * REPEAT_HOLD_S more; after that it goes out, in case the first was
     * damaged on the way.  A pty or TCP cannot tell what is still queued
     * (device_outq reads 0), so there the hold is all that spaces the
     * copies: it doubles with each copy of one frame, so that a line
     * slower than the hold (QEMU's UART on a loaded host) gets fewer and
     * fewer copies instead of a queue of them. */
    double t = now_s();
    int repeat = a->msg.seq == a->fwd_seq && a->msg.run_id == a->fwd_run &&
                 !a->fwd_answered;
    if (repeat) {
        note_frame_left(a, t);
        if (a->fwd_left_t < 0.0 || t - a->fwd_left_t < a->fwd_hold_s) {
            a->st.held++;
            return;
        }
    }
    if (a->fd < 0) {
        a->st.dropped_offline++;
        logf_(a, 1, "frame %lld: no device; dropped", (long long)a->msg.seq);
        return;
    }
    if (!repeat)
        a->fwd_hold_s = REPEAT_HOLD_S;
    else if (a->fwd_hold_s < REPEAT_HOLD_MAX_S)
        a->fwd_hold_s *= 2.0;
    a->fwd_seq = a->msg.seq;
    a->fwd_utime = a->msg.utime;
    a->fwd_run = a->msg.run_id;
    a->fwd_t = t;
    a->fwd_left_t = -1.0;
    a->fwd_answered = 0;
    if (write_all(a, a->wire, (size_t)len) == 0) {
        a->st.to_mcu++;
        logf_(a, 3, "frame %lld: %u matches, %d bytes to the MCU",
              (long long)a->msg.seq, (unsigned)n, len);
    }
}

/* ---- MCU side ------------------------------------------------------------------- */

static void on_result(agent_t *a, const spvs_serial_result_t *r)
{
    int64_t seq = (int64_t)r->seq;
    int64_t utime = seq == a->fwd_seq ? a->fwd_utime : (int64_t)r->t_ms * 1000;
    a->st.results++;
    a->last_step = r->out.step;
    if (seq == a->fwd_seq)
        a->fwd_answered = 1;
    if (r->flags & SPVS_SERIAL_F_REPEAT)
        a->st.repeats++;
    if (r->flags & SPVS_SERIAL_F_REJECTED) {
        a->st.rejected++;
        logf_(a, 1, "MCU refused frame %lld: %s; stop", (long long)seq,
              spvs_status_str(r->out.status));
        publish_stop(a, seq, utime, r->out.status);
        return;
    }
    spvs_state_t state;
    spvs_cmd_t cmd;
    spvs_wire_state_from_output(&state, seq, utime, &r->out);
    spvs_wire_cmd_from_output(&cmd, seq, utime, &r->out);
    if (spvs_wire_publish_state(a->lcm, &state) != 0 ||
        spvs_wire_publish_cmd(a->lcm, &cmd) != 0)
        logf_(a, 1, "publishing frame %lld's answer failed", (long long)seq);
    logf_(a, 3, "frame %lld: step %u v %.6g w %.6g status %s%s",
          (long long)seq, (unsigned)r->out.step, (double)r->out.v,
          (double)r->out.w, spvs_status_str(r->out.status),
          (r->flags & SPVS_SERIAL_F_REPEAT) ? " (repeat)" : "");
}

static void on_status(agent_t *a, const spvs_serial_status_frame_t *s)
{
    a->mcu = *s;
    a->have_mcu = 1;
    if (s->reason == SPVS_SERIAL_S_BOOT) {
        a->st.boots++;
        logf_(a, 1, "MCU booted (watchdog %u ms); stop, sending the set-up",
              (unsigned)s->watchdog_ms);
        /* Whatever it commanded before a reset no longer holds. */
        a->last_step = 0;
        publish_stop(a, -1, 0, SPVS_E_STALE);
        send_config(a);
        return;
    }
    if (s->reason == SPVS_SERIAL_S_WATCHDOG) {
        a->st.watchdog++;
        if (s->age_ms == 0xFFFFFFFFu)
            logf_(a, 2, "MCU watchdog: no valid frame yet; stop");
        else
            logf_(a, 2, "MCU watchdog: no valid frame for %u ms; stop",
                  (unsigned)s->age_ms);
        a->last_step = s->step;
        publish_stop(a, -1, 0, SPVS_E_STALE);
    }
    int same = s->method == a->cfg.method && s->seed == a->cfg.seed &&
               s->alpha_px == a->cfg.alpha_px &&
               s->watchdog_ms == a->cfg.watchdog_ms;
    if (!same && now_s() - a->last_config_s > 0.2)
        send_config(a);
    if (same && a->ready_path && !a->ready_done) {
        /* The MCU runs with the set-up: tell whoever waits for it. */
        FILE *f = fopen(a->ready_path, "w");
        if (f) {
            fprintf(f, "ready\n");
            fclose(f);
            a->ready_done = 1;
        }
        logf_(a, 2, "MCU ready: method %u, seed %u", (unsigned)s->method,
              (unsigned)s->seed);
    }
    logf_(a, 3, "MCU status: updates %u, repeats %u, stale %u, rejected %u, "
          "crc errors %u, framing errors %u, overruns %u, watchdog stops %u",
          (unsigned)s->updates, (unsigned)s->repeats, (unsigned)s->stale,
          (unsigned)s->rejected, (unsigned)s->crc_errors,
          (unsigned)s->framing_errors, (unsigned)s->overruns,
          (unsigned)s->watchdog_stops);
}

static void bad_frame(agent_t *a, int st)
{
    if (st == SPVS_SERIAL_E_CRC)
        a->st.bad_crc++;
    else
        a->st.bad_framing++;
    uint32_t total = a->st.bad_crc + a->st.bad_framing;
    /* Every one of the first ten, then one line per hundred. */
    if (total <= 10 || total % 100 == 0)
        logf_(a, 1, "bad frame from the MCU (%s); %u so far, dropped",
              spvs_serial_status_str(st), (unsigned)total);
}

static void on_device_frame(agent_t *a)
{
    spvs_serial_frame_t f;
    int st = spvs_serial_unpack(a->rx.buf, a->rx.n, &f);
    int first = a->fresh;
    a->fresh = 0;
    if (st != SPVS_SERIAL_OK && first) {
        /* The device was opened while the MCU was sending (a port or pty
         * opened mid-frame): the first bytes are the tail of a frame, not
         * a damaged one. */
        a->st.partial_at_open++;
        logf_(a, 2, "the first %u bytes after opening %s end a frame sent "
              "before; dropped", (unsigned)a->rx.n, a->device);
        return;
    }
    if (st != SPVS_SERIAL_OK) {
        bad_frame(a, st);
        return;
    }
    if (f.type == SPVS_SERIAL_T_RESULT) {
        spvs_serial_result_t r;
        st = spvs_serial_parse_result(&f, &r);
        if (st == SPVS_SERIAL_OK) {
            on_result(a, &r);
            return;
        }
    } else if (f.type == SPVS_SERIAL_T_STATUS) {
        spvs_serial_status_frame_t s;
        st = spvs_serial_parse_status(&f, &s);
        if (st == SPVS_SERIAL_OK) {
            on_status(a, &s);
            return;
        }
    } else {
        st = SPVS_SERIAL_E_TYPE;
    }
    bad_frame(a, st);
}

static void read_device(agent_t *a)
{
    uint8_t buf[4096];
    /* At most 64 reads per pass, so LCM is served in between. */
    for (int k = 0; k < 64 && a->fd >= 0; k++) {
        ssize_t r = read(a->fd, buf, sizeof(buf));
        if (r == 0) {
            close_device(a, "closed by the other end");
            return;
        }
        if (r < 0) {
            if (errno != EAGAIN && errno != EINTR)
                close_device(a, strerror(errno));
            return;
        }
        for (ssize_t i = 0; i < r; i++) {
            int got = spvs_serial_rx_push(&a->rx, buf[i]);
            if (got == 1)
                on_device_frame(a);
            else if (got == SPVS_SERIAL_E_OVERSIZE)
                bad_frame(a, got);
        }
    }
}

/* ---- the summary ------------------------------------------------------------- */

static void write_summary(const agent_t *a)
{
    const agent_stats_t *s = &a->st;
    char line[1024];
    snprintf(line, sizeof(line),
             "{\"to_mcu\":%u,\"refused\":%u,\"undecodable\":%u,"
             "\"dropped_offline\":%u,\"results\":%u,\"rejected\":%u,"
             "\"repeats\":%u,\"watchdog\":%u,\"boots\":%u,\"configs\":%u,"
             "\"bad_crc\":%u,\"bad_framing\":%u,\"connects\":%u,"
             "\"held\":%u,\"write_timeouts\":%u,\"partial_at_open\":%u,"
             "\"mcu\":",
             s->to_mcu, s->refused, s->undecodable, s->dropped_offline,
             s->results, s->rejected, s->repeats, s->watchdog, s->boots,
             s->configs, s->bad_crc, s->bad_framing, s->connects, s->held,
             s->write_timeouts, s->partial_at_open);
    char mcu[512] = "null";
    if (a->have_mcu) {
        const spvs_serial_status_frame_t *m = &a->mcu;
        snprintf(mcu, sizeof(mcu),
                 "{\"updates\":%u,\"repeats\":%u,\"stale\":%u,\"rejected\":%u,"
                 "\"crc_errors\":%u,\"framing_errors\":%u,\"overruns\":%u,"
                 "\"watchdog_stops\":%u,\"watchdog_ms\":%u,\"age_ms\":%u,"
                 "\"uptime_ms\":%u,\"method\":%u}",
                 m->updates, m->repeats, m->stale, m->rejected, m->crc_errors,
                 m->framing_errors, m->overruns, m->watchdog_stops,
                 m->watchdog_ms, m->age_ms, m->uptime_ms, (unsigned)m->method);
    }
    fprintf(stderr, "spvs-serial-agent: summary %s%s}\n", line, mcu);
    if (a->summary_path) {
        FILE *f = fopen(a->summary_path, "w");
        if (f) {
            fprintf(f, "%s%s}\n", line, mcu);
            fclose(f);
        }
    }
}

/* ---- the command line: one table for the parser and --help ------------------- */

/* s as a number in [lo, hi] into *out; 0, or -1 when it is not one. */
static int parse_num(const char *s, double lo, double hi, double *out)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || errno || !(v >= lo && v <= hi))
        return -1;
    *out = v;
    return 0;
}

/* The same for a whole number. */
static int parse_whole(const char *s, double lo, double hi, double *out)
{
    return parse_num(s, lo, hi, out) != 0 || *out != floor(*out) ? -1 : 0;
}

/* Each setter stores the value in the agent; 0, or -1 to refuse it. */
static int set_device(agent_t *a, const char *v)
{
    a->device = v;
    return 0;
}

static int set_baud(agent_t *a, const char *v)
{
    double d;
    if (parse_num(v, 1, 4e6, &d) != 0 || baud_const((long)d) == B0 ||
        d != floor(d))
        return -1;
    a->baud = (long)d;
    return 0;
}

static int set_method(agent_t *a, const char *v)
{
    double d;
    if (parse_whole(v, 1, 3, &d) != 0)
        return -1;
    a->cfg.method = (uint8_t)d;
    return 0;
}

static int set_seed(agent_t *a, const char *v)
{
    double d;
    if (parse_whole(v, 0, 4294967295.0, &d) != 0)
        return -1;
    a->cfg.seed = (uint32_t)d;
    return 0;
}

static int set_alpha(agent_t *a, const char *v)
{
    double d;
    if (parse_num(v, 1, 1e5, &d) != 0)
        return -1;
    a->cfg.alpha_px = (float)d;
    return 0;
}

static int set_watchdog(agent_t *a, const char *v)
{
    double d;
    if (parse_whole(v, SPVS_SERIAL_WATCHDOG_MIN_MS, SPVS_SERIAL_WATCHDOG_MAX_MS,
                    &d) != 0)
        return -1;
    a->cfg.watchdog_ms = (uint16_t)d;
    return 0;
}

static int set_url(agent_t *a, const char *v)
{
    a->url = v;
    return 0;
}

static int set_reconnect(agent_t *a, const char *v)
{
    double d;
    if (parse_num(v, 0, 3600, &d) != 0)
        return -1;
    a->reconnect_s = d;
    return 0;
}

static int set_summary(agent_t *a, const char *v)
{
    a->summary_path = v;
    return 0;
}

static int set_ready(agent_t *a, const char *v)
{
    a->ready_path = v;
    return 0;
}

static int set_log_level(agent_t *a, const char *v)
{
    double d;
    if (parse_whole(v, 0, 3, &d) != 0)
        return -1;
    a->log_level = (int)d;
    return 0;
}

/* The default is written in the help text itself, not added after it. */
#define OPT_DEFAULT_IN_TEXT 1

typedef struct {
    const char *name;    /* "--baud"                                        */
    const char *metavar; /* the value in --help; NULL: takes no value       */
    const char *help;    /* a '\n' starts a line indented under the first   */
    const char *def;     /* the default, given to set before the command
                            line is read and shown after the help as
                            " (def)"; NULL: none                           */
    int flags;           /* OPT_DEFAULT_IN_TEXT                             */
    int (*set)(agent_t *a, const char *v);
    const char *refusal; /* the error when set refuses the value            */
} agent_opt_t;

/* Every option, in the order --help lists them.  --lcm-url's default is
 * $LCM_DEFAULT_URL when set, so agent_defaults sets it. */
static const agent_opt_t k_opts[] = {
    { "--device", "DEV", "/dev/ttyUSB0, a pty path, tcp:HOST:PORT or\n"
      "unix:PATH (QEMU's -serial tcp:...,server)", NULL, 0, set_device, NULL },
    { "--baud", "N", "serial ports: 9600 .. 4000000", "921600", 0, set_baud,
      "not a supported rate" },
    { "--method", "1|2|3", "controller method sent to the MCU", "3", 0,
      set_method, "not 1, 2 or 3" },
    { "--seed", "S", "RANSAC seed, 0..4294967295", "0", 0, set_seed,
      "not an integer in 0..4294967295" },
    { "--alpha", "PX", "assumed focal length, pixels", "800", 0, set_alpha,
      "not a focal length in 1..1e5 px" },
    { "--watchdog-ms", "MS", "the MCU stops the robot after MS ms without\n"
      "a valid frame, 50..10000", "300", 0, set_watchdog,
      "not an integer in 50..10000" },
    { "--lcm-url", "URL", "LCM provider ($LCM_DEFAULT_URL or\n" DEFAULT_URL
      ")", NULL, 0, set_url, NULL },
    { "--reconnect", "S", "keep trying to (re)open the device for S s", "10",
      0, set_reconnect, "not 0..3600 s" },
    { "--summary", "FILE", "write the counters as JSON at exit", NULL, 0,
      set_summary, NULL },
    { "--ready-file", "FILE", "create FILE once the MCU runs with the set-up",
      NULL, 0, set_ready, NULL },
    { "--log-level", "L", "0 quiet, 1 errors (default), 2 info, 3 every frame",
      "1", OPT_DEFAULT_IN_TEXT, set_log_level, "not 0..3" },
    { "--help", NULL, NULL, NULL, 0, NULL, NULL },
};
#define N_OPTS (sizeof(k_opts) / sizeof(k_opts[0]))

/* The option column is this wide; a help text's later lines start under
 * its first. */
#define HELP_COL 19

static void usage(FILE *f)
{
    fputs("usage: spvs-serial-agent --device DEV [options]\n"
          "Bridges the controller on a microcontroller (serial link,\n"
          "docs/SERIAL.md) to LCM: SPVS_MATCHES in, SPVS_CMD and SPVS_STATE out.\n",
          f);
    for (size_t k = 0; k < N_OPTS; k++) {
        const agent_opt_t *o = &k_opts[k];
        if (!o->help) {
            fprintf(f, "  %s\n", o->name);
            continue;
        }
        char left[64];
        snprintf(left, sizeof(left), "%s %s", o->name, o->metavar);
        fprintf(f, "  %-*s", HELP_COL, left);
        for (const char *c = o->help; *c; c++) {
            if (*c == '\n')
                fprintf(f, "\n  %*s", HELP_COL, "");
            else
                fputc(*c, f);
        }
        if (o->def && !(o->flags & OPT_DEFAULT_IN_TEXT))
            fprintf(f, " (%s)", o->def);
        fputc('\n', f);
    }
    fputs("Exit status: 0 after SIGINT/SIGTERM, 1 device or LCM failure,\n"
          "2 bad options.\n", f);
}

static int bad_opt(const char *what, const char *arg)
{
    fprintf(stderr, "spvs-serial-agent: %s%s%s (see --help)\n", what,
            arg ? ": " : "", arg ? arg : "");
    return 2;
}

static const agent_opt_t *find_opt(const char *name)
{
    for (size_t k = 0; k < N_OPTS; k++) {
        if (strcmp(k_opts[k].name, name) == 0)
            return &k_opts[k];
    }
    return NULL;
}

/* The defaults: the table's, then what is not an option's. */
static void agent_defaults(agent_t *a)
{
    for (size_t k = 0; k < N_OPTS; k++) {
        if (k_opts[k].def)
            (void)k_opts[k].set(a, k_opts[k].def);
    }
    a->url = getenv("LCM_DEFAULT_URL");
    if (!a->url)
        a->url = DEFAULT_URL;
    a->fd = -1;
    a->fwd_seq = -1;
    a->last_config_s = -1e9;
}

/* Reads the command line into a.  Returns -1 to run, else the exit
 * status: 0 after --help, 2 on a bad option (the error line printed). */
static int parse_command_line(agent_t *a, int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        const char *name = argv[i];
        const agent_opt_t *o = find_opt(name);
        if (o && !o->metavar) {
            usage(stdout);
            return 0;
        }
        if (i + 1 >= argc)
            return bad_opt(strncmp(name, "--", 2) == 0 ? "option needs a value"
                                                       : "unexpected argument",
                           name);
        const char *v = argv[++i];
        if (!o)
            return bad_opt("unknown option", name);
        if (o->set(a, v) != 0) {
            fprintf(stderr, "spvs-serial-agent: %s: %s: %s (see --help)\n",
                    o->name, o->refusal, v);
            return 2;
        }
    }
    if (!a->device)
        return bad_opt("--device is required", NULL);
    return -1;
}

/* ---- main ---------------------------------------------------------------------- */

/* Signals, LCM and the subscription.  0, or 1 with the error printed. */
static int agent_start(agent_t *a)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);

    a->lcm = lcm_create(a->url);
    if (!a->lcm) {
        fprintf(stderr, "spvs-serial-agent: cannot open LCM '%s' (no multicast "
                "route? see docs/LCM.md)\n", a->url);
        return 1;
    }
    if (!lcm_subscribe(a->lcm, SPVS_CH_MATCHES, on_matches, a)) {
        fprintf(stderr, "spvs-serial-agent: subscribing to %s failed\n",
                SPVS_CH_MATCHES);
        return 1;
    }
    spvs_serial_rx_init(&a->rx);
    return 0;
}

/* With no device open, a try at most every 100 ms.  Returns 0, or 1 when
 * the device cannot be opened for good or --reconnect ran out since
 * offline_since (the error printed). */
static int try_open(agent_t *a, double offline_since, double *last_try)
{
    double t = now_s();
    if (t - *last_try < 0.1)
        return 0;
    char err[300];
    *last_try = t;
    int fd = open_device(a, err, sizeof(err));
    if (fd == -2) {
        fprintf(stderr, "spvs-serial-agent: %s\n", err);
        return 1;
    }
    if (fd >= 0) {
        a->fd = fd;
        a->fresh = 1;
        a->st.connects++;
        logf_(a, 2, "device %s open", a->device);
        send_config(a);
    } else if (t - offline_since > a->reconnect_s) {
        fprintf(stderr, "spvs-serial-agent: %s (gave up after %.3g s)\n", err,
                a->reconnect_s);
        return 1;
    }
    return 0;
}

/* Serves LCM and the device until a signal (0) or a failure for good (1). */
static int agent_run(agent_t *a)
{
    int lfd = lcm_get_fileno(a->lcm);
    double offline_since = now_s();
    double last_try = -1e9;
    while (!g_stop) {
        if (a->fd < 0 && try_open(a, offline_since, &last_try) != 0)
            return 1;
        struct pollfd pf[2] = { { lfd, POLLIN, 0 }, { a->fd, POLLIN, 0 } };
        int np = a->fd >= 0 ? 2 : 1;
        int pr = poll(pf, (nfds_t)np, 50);
        if (pr < 0 && errno != EINTR) {
            fprintf(stderr, "spvs-serial-agent: poll: %s\n", strerror(errno));
            return 1;
        }
        if (pr > 0 && (pf[0].revents & POLLIN) && lcm_handle(a->lcm) != 0) {
            fprintf(stderr, "spvs-serial-agent: LCM receive failed\n");
            return 1;
        }
        if (np == 2 && pr > 0 && (pf[1].revents & (POLLIN | POLLHUP | POLLERR)))
            read_device(a);
        note_frame_left(a, now_s());
        if (a->fd >= 0)
            offline_since = now_s();
    }
    return 0;
}

int main(int argc, char **argv)
{
    static agent_t a;
    agent_defaults(&a);
    int rc = parse_command_line(&a, argc, argv);
    if (rc >= 0)
        return rc;
    rc = agent_start(&a);
    if (rc != 0)
        return rc;
    rc = agent_run(&a);
    write_summary(&a);
    if (a.fd >= 0)
        close(a.fd);
    lcm_destroy(a.lcm);
    return rc;
}
