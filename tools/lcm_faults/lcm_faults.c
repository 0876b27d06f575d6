/*
 * lcm_faults.c - spvs-lcm-faults: a relay that forwards SPVS_MATCHES frames
 * from one LCM channel to another with transport faults, for the closed-loop
 * fault scenarios of docs/ROBUSTNESS.md:
 *
 *   spvs-sim --lcm-matches-channel SPVS_MATCHES_RAW --keep-last S
 *       -> SPVS_MATCHES_RAW -> spvs-lcm-faults -> SPVS_MATCHES -> spvs-node
 *       <- SPVS_CMD, SPVS_STATE (direct) <-
 *
 * Faults, each drawn per frame from a seeded generator (same seed, same
 * decisions for the same frame sequence):
 *   --drop P         the frame is lost
 *   --delay-max S    the frame leaves after a uniform delay in [0, S] seconds,
 *                    so later frames may overtake it
 *   --dup P          the frame is sent twice
 *   --reorder P      the frame is held back and sent just after the next one
 *   --time-back P    the frame's utime is moved back by 1..3 periods, so the
 *                    controller sees time going backwards
 *   --pause-after N --pause S
 *                    after frame seq N, nothing is forwarded for S seconds
 *                    (a camera or network stall longer than the watchdog)
 * Undecodable messages are forwarded untouched: the relay is a transport,
 * not a filter.  On SIGINT/SIGTERM it prints one line of counts on stdout
 * and exits 0.  Exit 1: LCM failed; 2: bad options.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lcm/lcm.h>

#include "lcmtypes/spvs_matches_t.h"
#include "sim/cli.h"
#include "sim/clock.h"

/* Frames waiting for their release time; a full queue sends at once. */
#define QUEUE_LEN 64
#define MSG_MAX 8192

typedef struct {
    double release_s; /* monotonic time to send                        */
    uint64_t order;   /* arrival order: ties leave first-in first-out   */
    int len;
    uint8_t buf[MSG_MAX];
} pending_t;

typedef struct {
    unsigned long received, forwarded, dropped, delayed, duplicated,
        reordered, time_back, paused, undecodable;
} counts_t;

typedef struct {
    lcm_t *lcm;
    const char *out_ch;
    double drop, delay_max_s, dup, reorder, time_back, period_s;
    long long pause_after;
    double pause_s;
    uint64_t rng;
    double pause_until_s;   /* forward nothing before this, monotonic s */
    long long pause_first, pause_last;
    int paused_once;
    pending_t queue[QUEUE_LEN];
    int n_queue;
    uint64_t next_order;
    int has_held;           /* a reordered frame waiting for the next one */
    pending_t held;
    spvs_matches_t msg;     /* decode buffer */
    counts_t c;
} relay_t;

static volatile sig_atomic_t g_stop = 0;

static void on_signal(int sig)
{
    (void)sig;
    g_stop = 1;
}

/* SplitMix64: a uniform number in [0, 1). */
static double uniform(relay_t *r)
{
    uint64_t z = (r->rng += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

static void send_now(relay_t *r, const uint8_t *buf, int len)
{
    if (lcm_publish(r->lcm, r->out_ch, buf, (unsigned)len) == 0)
        r->c.forwarded++;
}

/* Queue a frame for release_s; with the queue full it goes out now. */
static void enqueue(relay_t *r, const uint8_t *buf, int len, double release_s)
{
    if (r->n_queue >= QUEUE_LEN) {
        send_now(r, buf, len);
        return;
    }
    pending_t *p = &r->queue[r->n_queue++];
    p->release_s = release_s;
    p->order = r->next_order++;
    p->len = len;
    memcpy(p->buf, buf, (size_t)len);
}

/* Send every queued frame whose time has come, earliest first.  Returns the
 * time of the next release, or a large value when none is queued. */
static double release_due(relay_t *r, double t)
{
    for (;;) {
        int best = -1;
        for (int i = 0; i < r->n_queue; i++) {
            const pending_t *p = &r->queue[i];
            if (p->release_s <= t &&
                (best < 0 || p->release_s < r->queue[best].release_s ||
                 (p->release_s == r->queue[best].release_s &&
                  p->order < r->queue[best].order)))
                best = i;
        }
        if (best < 0)
            break;
        send_now(r, r->queue[best].buf, r->queue[best].len);
        r->queue[best] = r->queue[--r->n_queue];
    }
    double next = t + 3600.0;
    for (int i = 0; i < r->n_queue; i++)
        if (r->queue[i].release_s < next)
            next = r->queue[i].release_s;
    return next;
}

static void on_frame(const lcm_recv_buf_t *rbuf, const char *channel,
                     void *user)
{
    (void)channel;
    relay_t *r = (relay_t *)user;
    const double t = sim_clock_now_s();
    int len = (int)rbuf->data_size;
    r->c.received++;
    if (len > MSG_MAX || spvs_matches_t_decode(rbuf->data, 0, len, &r->msg) < 0) {
        r->c.undecodable++;
        send_now(r, rbuf->data, len);
        return;
    }
    const long long seq = (long long)r->msg.seq;

    /* Every draw is made for every frame, in the same order, so that one
     * fault's setting does not change another's decisions. */
    const double u_drop = uniform(r), u_delay = uniform(r), u_dup = uniform(r);
    const double u_reorder = uniform(r), u_back = uniform(r), u_k = uniform(r);

    if (t < r->pause_until_s) {
        r->c.paused++;
        if (r->pause_first < 0)
            r->pause_first = seq;
        r->pause_last = seq;
        return;
    }
    if (u_drop < r->drop) {
        r->c.dropped++;
        return;
    }

    static uint8_t buf[MSG_MAX];
    memcpy(buf, rbuf->data, (size_t)len);
    if (u_back < r->time_back) {
        /* Re-encode with the time moved back by 1, 2 or 3 periods. */
        int k = 1 + (int)(u_k * 3.0);
        r->msg.utime -= (int64_t)llround((double)k * r->period_s * 1e6);
        int n = spvs_matches_t_encode(buf, 0, MSG_MAX, &r->msg);
        if (n > 0) {
            len = n;
            r->c.time_back++;
        }
    }

    double release = t;
    if (r->delay_max_s > 0.0) {
        release = t + u_delay * r->delay_max_s;
        if (release > t)
            r->c.delayed++;
    }
    const int held_before = r->has_held;
    if (!held_before && u_reorder < r->reorder) {
        r->held.len = len;
        memcpy(r->held.buf, buf, (size_t)len);
        r->has_held = 1;
        r->c.reordered++;
    } else {
        enqueue(r, buf, len, release);
        if (u_dup < r->dup) {
            enqueue(r, buf, len, release);
            r->c.duplicated++;
        }
        if (held_before) {
            /* The held frame follows the one that overtook it. */
            enqueue(r, r->held.buf, r->held.len, release);
            r->has_held = 0;
        }
    }
    release_due(r, t);

    if (r->pause_after >= 0 && seq == r->pause_after && !r->paused_once) {
        r->pause_until_s = t + r->pause_s;
        r->paused_once = 1;
    }
}

/* Seeds and frame numbers: integers up to 10^15. */
#define MAX_COUNT 1000000000000000LL

/* What the command line sets: the relay's fault settings and the two
 * ends of the relay. */
typedef struct {
    relay_t *r;
    const char *url;
    const char *in_ch;
} faults_cli_t;

static void set_url(faults_cli_t *c, const char *o, const char *v) { (void)o; c->url = v; }
static void set_in(faults_cli_t *c, const char *o, const char *v) { (void)o; c->in_ch = v; }
static void set_out(faults_cli_t *c, const char *o, const char *v) { (void)o; c->r->out_ch = v; }
static void set_seed(faults_cli_t *c, const char *o, const char *v)
{
    c->r->rng = (uint64_t)sim_cli_int(o, v, 0, MAX_COUNT);
}
static void set_drop(faults_cli_t *c, const char *o, const char *v)
{
    c->r->drop = sim_cli_real(o, v, 0.0, 1.0, SIM_CLI_CLOSED);
}
static void set_delay(faults_cli_t *c, const char *o, const char *v)
{
    c->r->delay_max_s = sim_cli_real(o, v, 0.0, 60.0, SIM_CLI_CLOSED);
}
static void set_dup(faults_cli_t *c, const char *o, const char *v)
{
    c->r->dup = sim_cli_real(o, v, 0.0, 1.0, SIM_CLI_CLOSED);
}
static void set_reorder(faults_cli_t *c, const char *o, const char *v)
{
    c->r->reorder = sim_cli_real(o, v, 0.0, 1.0, SIM_CLI_CLOSED);
}
static void set_time_back(faults_cli_t *c, const char *o, const char *v)
{
    c->r->time_back = sim_cli_real(o, v, 0.0, 1.0, SIM_CLI_CLOSED);
}
static void set_period(faults_cli_t *c, const char *o, const char *v)
{
    c->r->period_s = sim_cli_real(o, v, 1e-3, 60.0, SIM_CLI_CLOSED);
}
static void set_pause_after(faults_cli_t *c, const char *o, const char *v)
{
    c->r->pause_after = sim_cli_int(o, v, 0, MAX_COUNT);
}
static void set_pause(faults_cli_t *c, const char *o, const char *v)
{
    c->r->pause_s = sim_cli_real(o, v, 0.0, 3600.0, SIM_CLI_CLOSED);
}

/* One option: the parser and --help read the same table (a '\n' in help
 * continues the text under its first line; set NULL: --help). */
typedef struct {
    const char *name;
    const char *metavar;
    const char *help;
    void (*set)(faults_cli_t *c, const char *opt, const char *v);
} fault_opt_t;

static const fault_opt_t k_opts[] = {
    {"--lcm-url", "URL", "LCM provider (default $LCM_DEFAULT_URL)", set_url},
    {"--in", "CH", "channel listened to (SPVS_MATCHES_RAW)", set_in},
    {"--out", "CH", "channel forwarded to (SPVS_MATCHES)", set_out},
    {"--seed", "S", "fault generator seed, integer >= 0 (1)", set_seed},
    {"--drop", "P", "fraction of frames lost, [0, 1] (0)", set_drop},
    {"--delay-max", "S", "uniform delay of each frame, [0, S] seconds (0)", set_delay},
    {"--dup", "P", "fraction of frames sent twice (0)", set_dup},
    {"--reorder", "P", "fraction of frames sent after the next one (0)", set_reorder},
    {"--time-back", "P", "fraction of frames whose utime goes back 1..3\nperiods (0)",
     set_time_back},
    {"--period", "S", "control period for --time-back, seconds (0.1)", set_period},
    {"--pause-after", "N", "after frame seq N forward nothing for --pause S", set_pause_after},
    {"--pause", "S", "pause length, seconds (0)", set_pause},
    {"--help", NULL, "this text", NULL},
};
#define N_OPTS (sizeof(k_opts) / sizeof(k_opts[0]))

/* The option column's width in --help (sim_cli_help_option). */
#define HELP_COL 20

static void usage(void)
{
    fputs("usage: spvs-lcm-faults [options]\n"
          "Forwards SPVS_MATCHES frames between LCM channels with faults.\n",
          stdout);
    for (size_t k = 0; k < N_OPTS; k++)
        sim_cli_help_option(stdout, HELP_COL, k_opts[k].name, k_opts[k].metavar, k_opts[k].help);
    fputs("On SIGINT/SIGTERM: one line of counts on stdout, exit 0.\n", stdout);
}

int main(int argc, char **argv)
{
    static relay_t r;
    faults_cli_t cli = {&r, getenv("LCM_DEFAULT_URL"), "SPVS_MATCHES_RAW"};
    r.out_ch = "SPVS_MATCHES";
    r.period_s = 0.1;
    r.pause_after = -1;
    r.pause_first = -1;
    r.pause_last = -1;
    r.rng = 1;
    sim_cli_program("spvs-lcm-faults");

    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const fault_opt_t *o = NULL;
        for (size_t k = 0; k < N_OPTS && o == NULL; k++)
            if (strcmp(a, k_opts[k].name) == 0)
                o = &k_opts[k];
        if (o != NULL && o->set == NULL) {
            usage();
            return 0;
        }
        if (i + 1 >= argc)
            sim_cli_fail("missing value for: %s", a);
        const char *v = argv[++i];
        if (o == NULL)
            sim_cli_fail("unknown option: %s", a);
        o->set(&cli, o->name, v);
    }
    const char *url = cli.url;
    const char *in_ch = cli.in_ch;
    if (strcmp(in_ch, r.out_ch) == 0)
        sim_cli_fail("--in and --out must differ: %s", in_ch);

    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    r.lcm = lcm_create(url);
    if (!r.lcm) {
        fprintf(stderr, "spvs-lcm-faults: cannot open LCM at '%s'\n",
                url ? url : "(default)");
        return 1;
    }
    if (!lcm_subscribe(r.lcm, in_ch, on_frame, &r)) {
        fprintf(stderr, "spvs-lcm-faults: cannot subscribe to %s\n", in_ch);
        lcm_destroy(r.lcm);
        return 1;
    }
    int rc = 0;
    double next = sim_clock_now_s() + 3600.0;
    while (!g_stop) {
        /* Wake for the next release or every 20 ms, whichever is first. */
        double wait = next - sim_clock_now_s();
        int ms = wait < 0.0 ? 0 : wait > 0.02 ? 20 : (int)ceil(wait * 1000.0);
        if (lcm_handle_timeout(r.lcm, ms) < 0 && !g_stop) {
            fprintf(stderr, "spvs-lcm-faults: LCM receive failed\n");
            rc = 1;
            break;
        }
        next = release_due(&r, sim_clock_now_s());
    }
    printf("lcm_faults: received %lu forwarded %lu dropped %lu delayed %lu "
           "duplicated %lu reordered %lu time_back %lu paused %lu "
           "undecodable %lu pause_first %lld pause_last %lld\n",
           r.c.received, r.c.forwarded, r.c.dropped, r.c.delayed,
           r.c.duplicated, r.c.reordered, r.c.time_back, r.c.paused,
           r.c.undecodable, r.pause_first, r.pause_last);
    fflush(stdout);
    lcm_destroy(r.lcm);
    return rc;
}
