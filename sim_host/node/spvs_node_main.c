/*
 * spvs_node_main.c - spvs-node: the controller as an LCM node, or with
 * --dds on DDS with ROS 2's names (node_dds.h).
 *
 * Subscribes to SPVS_MATCHES, runs the core (spvs_update) on each frame and
 * publishes SPVS_STATE and SPVS_CMD; a watchdog publishes stops while frames
 * are missing.  See node.h for the per-message rules and docs/LCM.md.
 * Exit status: 0 after SIGINT/SIGTERM, 1 when LCM fails, 2 on bad options.
 */
#define _POSIX_C_SOURCE 200809L

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "node.h"
#ifdef SPVS_HAVE_DDS
#include "node_dds.h"
#endif
#include "sim/cli.h"
#include "sim/clock.h"

#define DEFAULT_URL "udpm://239.255.76.67:7667?ttl=0"

static volatile sig_atomic_t g_stop = 0;

static void on_signal(int sig)
{
    (void)sig;
    g_stop = 1;
}

/* The settings of the command line that are not core parameters. */
typedef struct {
    long long method;
    const char *gains;
    const char *url;
    double watchdog_s;
    long long log_level;
    long long progress;
    int dds;
} node_opts_t;

/* An option: what --help says of it, and how it is read.  Options with a
 * setter decide the starting parameter set (read first, in any order);
 * the others (param = 1) are core parameters, applied over the defaults
 * of the method and the file in their command-line order. */
typedef struct {
    const char *name;    /* "--method"                                   */
    const char *metavar; /* the value in --help; NULL: a flag            */
    const char *help;    /* a '\n' starts a line under the first; NULL:
                            listed on the line of the option before      */
    void (*set)(node_opts_t *o, const char *name, const char *val);
    int param;           /* a core parameter (--k-w -> k_w, --param)     */
} node_opt_t;

static void set_method(node_opts_t *o, const char *name, const char *val)
{
    o->method = sim_cli_int(name, val, 1, 3);
}

static void set_gains(node_opts_t *o, const char *name, const char *val)
{
    (void)name;
    o->gains = val;
}

static void set_url(node_opts_t *o, const char *name, const char *val)
{
    (void)name;
    o->url = val;
}

static void set_watchdog(node_opts_t *o, const char *name, const char *val)
{
    o->watchdog_s = sim_cli_real(name, val, 0.0, 3600.0, SIM_CLI_OPEN_LO);
}

static void set_log_level(node_opts_t *o, const char *name, const char *val)
{
    o->log_level = sim_cli_int(name, val, 0, 3);
}

static void set_progress(node_opts_t *o, const char *name, const char *val)
{
    o->progress = sim_cli_int(name, val, 0, 1000000);
}

static void set_dds(node_opts_t *o, const char *name, const char *val)
{
    (void)name;
    (void)val;
#ifndef SPVS_HAVE_DDS
    sim_cli_fail("--dds: this build has no DDS support (cyclonedds-dev)");
#endif
    o->dds = 1;
}

/* Every option, in the order --help lists them. */
static const node_opt_t k_opts[] = {
    {"--method", "1|2|3", "control method (default 3)", set_method, 0},
    {"--gains", "FILE", "parameter file, lines 'name = value'", set_gains, 0},
    {"--k-w", "X", "gains and limits (override the file)", NULL, 1},
    {"--k-v", "X", NULL, NULL, 1},
    {"--k-w3", "X", NULL, NULL, 1},
    {"--k-w11", "X", NULL, NULL, 1},
    {"--v-max", "X", NULL, NULL, 1},
    {"--w-max", "X", NULL, NULL, 1},
    {"--alpha", "PX", "assumed focal length, pixels (default 800)", NULL, 1},
    {"--seed", "S", "RANSAC seed (default 0)", NULL, 1},
    {"--param", "NAME=VALUE", "any parameter by name (see below)", NULL, 1},
    {"--dds", NULL,
     "serve on DDS with ROS 2's names instead of LCM:\n"
     "/spvs/matches in, /cmd_vel and /spvs/state out,\n"
     "domain $ROS_DOMAIN_ID (docs/ROS2.md)",
     set_dds, 0},
    {"--lcm-url", "URL",
     "LCM provider (default $LCM_DEFAULT_URL or\n" DEFAULT_URL ")", set_url, 0},
    {"--watchdog", "S",
     "publish stops after S s without valid\n"
     "matches (default 0.5)",
     set_watchdog, 0},
    {"--progress", "N", "print a progress line every N frames (0 off)", set_progress, 0},
    {"--log-level", "L",
     "0 quiet, 1 errors (default), 2 info,\n"
     "3 every frame",
     set_log_level, 0},
    {"--help", NULL, "", NULL, 0},
};
#define N_OPTS (sizeof(k_opts) / sizeof(k_opts[0]))
#define HELP_COL 19

static void usage(FILE *f)
{
    fputs("usage: spvs-node [options]\n"
          "Controller node: SPVS_MATCHES in, SPVS_CMD and SPVS_STATE out.\n",
          f);
    for (size_t k = 0; k < N_OPTS; k++) {
        /* Options without help of their own share the next line's. */
        if (k_opts[k].help == NULL) {
            continue;
        }
        char left[96] = "";
        size_t used = 0;
        for (size_t j = k; j < N_OPTS && used < sizeof(left); j++) {
            if (j > k && k_opts[j].help != NULL) {
                break;
            }
            used += (size_t)snprintf(left + used, sizeof(left) - used, "%s%s%s%s",
                                     j > k ? " " : "", k_opts[j].name,
                                     k_opts[j].metavar ? " " : "",
                                     k_opts[j].metavar ? k_opts[j].metavar : "");
        }
        fprintf(f, "  %s", left);
        if (k_opts[k].help[0] == '\0') {
            fputc('\n', f);
            continue;
        }
        const int w = (int)strlen(left);
        if (w < HELP_COL) {
            fprintf(f, "%*s", HELP_COL - w, "");
        } else {
            fprintf(f, "\n  %*s", HELP_COL, "");
        }
        for (const char *c = k_opts[k].help; *c; c++) {
            if (*c == '\n') {
                fprintf(f, "\n  %*s", HELP_COL, "");
            } else {
                fputc(*c, f);
            }
        }
        fputc('\n', f);
    }
    fputs("parameters:", f);
    for (int i = 0; spvs_node_param_names[i]; i++)
        fprintf(f, "%s%s", i % 8 ? " " : "\n  ", spvs_node_param_names[i]);
    fprintf(f, "\n");
}

static const node_opt_t *find_opt(const char *name)
{
    for (size_t k = 0; k < N_OPTS; k++) {
        if (strcmp(k_opts[k].name, name) == 0)
            return &k_opts[k];
    }
    return NULL;
}

/* Pass 1: the options that decide the starting parameter set, so the
 * order on the command line does not matter; exits after --help or on a
 * bad option. */
static void read_options(int argc, char **argv, node_opts_t *o)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            exit(0);
        }
        if (strncmp(a, "--", 2) != 0)
            sim_cli_fail("unexpected argument: %s", a);
        const node_opt_t *opt = find_opt(a);
        if (opt != NULL && opt->metavar == NULL) {
            opt->set(o, a, NULL);
            continue;
        }
        if (i + 1 >= argc)
            sim_cli_fail("missing value for: %s", a);
        const char *v = argv[++i];
        if (opt == NULL)
            sim_cli_fail("unknown option: %s", a);
        if (opt->set != NULL)
            opt->set(o, a, v);
    }
}

/* Pass 2: the parameter options, in order, over the method's defaults and
 * the file. */
static void apply_params(int argc, char **argv, spvs_params_t *p)
{
    char err[256];
    for (int i = 1; i < argc; i++) {
        const node_opt_t *opt = find_opt(argv[i]);
        if (opt == NULL || opt->metavar == NULL) {
            continue;
        }
        const char *a = argv[i];
        const char *v = argv[++i];
        if (!opt->param) {
            continue;
        }
        char name[64];
        const char *value = v;
        if (strcmp(a, "--param") == 0) {
            const char *eq = strchr(v, '=');
            if (!eq || (size_t)(eq - v) >= sizeof(name))
                sim_cli_fail("--param wants NAME=VALUE, not: %s", v);
            memcpy(name, v, (size_t)(eq - v));
            name[eq - v] = '\0';
            value = eq + 1;
        } else {
            /* --k-w3 -> k_w3 */
            size_t n = strlen(a + 2);
            for (size_t k = 0; k <= n && k < sizeof(name); k++)
                name[k] = a[2 + k] == '-' ? '_' : a[2 + k];
        }
        if (spvs_node_param_set(p, name, value, err, sizeof(err)) != 0)
            sim_cli_fail("bad parameter: %s", err);
    }
}

static void install_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    /* No SA_RESTART: a signal should cut the wait in lcm_handle_timeout. */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
}

/* The node on LCM until a signal: 0, 1 when LCM fails, 2 when the core
 * refuses the parameters. */
static int run_lcm(const node_opts_t *o, const spvs_params_t *p)
{
    lcm_t *lcm = lcm_create(o->url);
    if (!lcm) {
        fprintf(stderr, "spvs-node: cannot open LCM at '%s' (no multicast "
                        "route? see docs/LCM.md)\n", o->url);
        return 1;
    }
    static spvs_node_t node; /* big (the core's buffers): not on the stack */
    node.log_level = (int)o->log_level;
    node.progress_every = (unsigned)o->progress;
    node.progress = stdout;
    int st = spvs_node_init(&node, lcm, p, o->watchdog_s, sim_clock_now_s());
    if (st != SPVS_OK) {
        fprintf(stderr, "spvs-node: parameters rejected by the core: %s\n",
                spvs_status_str(st));
        lcm_destroy(lcm);
        return 2;
    }
    if (o->log_level >= 2)
        fprintf(stderr, "spvs-node: method %lld, %s, watchdog %.2f s\n",
                o->method, o->url, o->watchdog_s);
    int rc = 0;
    while (!g_stop) {
        /* Short waits keep the watchdog and the signal check responsive. */
        int r = lcm_handle_timeout(lcm, 50);
        if (r < 0 && !g_stop) {
            fprintf(stderr, "spvs-node: error: LCM receive failed\n");
            rc = 1;
            break;
        }
        spvs_node_tick(&node, sim_clock_now_s());
    }
    if (o->log_level >= 2)
        fprintf(stderr,
                "spvs-node: exit: %u frames, %u duplicates, %u out of order, "
                "%u rejected, %u undecodable, %u watchdog stops, %u runs\n",
                node.stats.frames, node.stats.duplicates,
                node.stats.out_of_order, node.stats.rejected,
                node.stats.undecodable, node.stats.watchdog, node.stats.runs);
    spvs_node_close(&node);
    lcm_destroy(lcm);
    return rc;
}

int main(int argc, char **argv)
{
    node_opts_t o = {3, NULL, getenv("LCM_DEFAULT_URL"), 0.5, 1, 0, 0};
    if (!o.url || !*o.url)
        o.url = DEFAULT_URL;
    sim_cli_program("spvs-node");
    read_options(argc, argv, &o);

    spvs_params_t p;
    char err[256];
    spvs_params_default(&p, (spvs_method_t)o.method);
    if (o.gains && spvs_node_params_load(&p, o.gains, err, sizeof(err)) != 0)
        sim_cli_fail("--gains: %s", err);
    apply_params(argc, argv, &p);

    install_signals();
#ifdef SPVS_HAVE_DDS
    if (o.dds) {
        spvs_node_dds_opts_t dopt = { o.watchdog_s, (int)o.log_level,
                                      (unsigned)o.progress };
        return spvs_node_dds_run(&p, &dopt, &g_stop);
    }
#endif
    return run_lcm(&o, &p);
}
