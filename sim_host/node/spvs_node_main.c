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

static void usage(FILE *f)
{
    fprintf(f,
        "usage: spvs-node [options]\n"
        "Controller node: SPVS_MATCHES in, SPVS_CMD and SPVS_STATE out.\n"
        "  --method 1|2|3     control method (default 3)\n"
        "  --gains FILE       parameter file, lines 'name = value'\n"
        "  --k-w X --k-v X --k-w3 X --k-w11 X --v-max X --w-max X\n"
        "                     gains and limits (override the file)\n"
        "  --alpha PX         assumed focal length, pixels (default 800)\n"
        "  --seed S           RANSAC seed (default 0)\n"
        "  --param NAME=VALUE any parameter by name (see below)\n"
        "  --dds              serve on DDS with ROS 2's names instead of LCM:\n"
        "                     /spvs/matches in, /cmd_vel and /spvs/state out,\n"
        "                     domain $ROS_DOMAIN_ID (docs/ROS2.md)\n"
        "  --lcm-url URL      LCM provider (default $LCM_DEFAULT_URL or\n"
        "                     " DEFAULT_URL ")\n"
        "  --watchdog S       publish stops after S s without valid\n"
        "                     matches (default 0.5)\n"
        "  --progress N       print a progress line every N frames (0 off)\n"
        "  --log-level L      0 quiet, 1 errors (default), 2 info,\n"
        "                     3 every frame\n"
        "  --help\n"
        "parameters:");
    for (int i = 0; spvs_node_param_names[i]; i++)
        fprintf(f, "%s%s", i % 8 ? " " : "\n  ", spvs_node_param_names[i]);
    fprintf(f, "\n");
}

int main(int argc, char **argv)
{
    long long method = 3;
    const char *gains = NULL;
    const char *url = getenv("LCM_DEFAULT_URL");
    double watchdog_s = 0.5;
    long long log_level = 1;
    long long progress = 0;
    int dds = 0;
    char err[256];

    if (!url || !*url)
        url = DEFAULT_URL;
    sim_cli_program("spvs-node");

    /* Pass 1: options that decide the starting parameter set, so the order
     * on the command line does not matter: defaults of the method, then the
     * file, then the flags. */
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 0;
        }
        if (strncmp(a, "--", 2) != 0)
            sim_cli_fail("unexpected argument: %s", a);
        if (strcmp(a, "--dds") == 0) {
#ifndef SPVS_HAVE_DDS
            sim_cli_fail("--dds: this build has no DDS support "
                         "(cyclonedds-dev)");
#endif
            dds = 1;
            continue;
        }
        if (i + 1 >= argc)
            sim_cli_fail("missing value for: %s", a);
        const char *v = argv[++i];
        if (strcmp(a, "--method") == 0) {
            method = sim_cli_int(a, v, 1, 3);
        } else if (strcmp(a, "--gains") == 0) {
            gains = v;
        } else if (strcmp(a, "--lcm-url") == 0) {
            url = v;
        } else if (strcmp(a, "--watchdog") == 0) {
            watchdog_s = sim_cli_real(a, v, 0.0, 3600.0, SIM_CLI_OPEN_LO);
        } else if (strcmp(a, "--log-level") == 0) {
            log_level = sim_cli_int(a, v, 0, 3);
        } else if (strcmp(a, "--progress") == 0) {
            progress = sim_cli_int(a, v, 0, 1000000);
        } else if (strcmp(a, "--k-w") && strcmp(a, "--k-v") &&
                   strcmp(a, "--k-w3") && strcmp(a, "--k-w11") &&
                   strcmp(a, "--v-max") && strcmp(a, "--w-max") &&
                   strcmp(a, "--alpha") && strcmp(a, "--seed") &&
                   strcmp(a, "--param")) {
            sim_cli_fail("unknown option: %s", a);
        }
    }

    spvs_params_t p;
    spvs_params_default(&p, (spvs_method_t)method);
    if (gains && spvs_node_params_load(&p, gains, err, sizeof(err)) != 0)
        sim_cli_fail("--gains: %s", err);

    /* Pass 2: the parameter flags, in order, over the file. */
    for (int i = 1; i + 1 < argc; i += 2) {
        const char *a = argv[i];
        if (strcmp(a, "--dds") == 0) {
            i--; /* a flag: the next argument is an option */
            continue;
        }
        const char *v = argv[i + 1];
        char name[64];
        const char *value = v;
        if (strcmp(a, "--param") == 0) {
            const char *eq = strchr(v, '=');
            if (!eq || (size_t)(eq - v) >= sizeof(name))
                sim_cli_fail("--param wants NAME=VALUE, not: %s", v);
            memcpy(name, v, (size_t)(eq - v));
            name[eq - v] = '\0';
            value = eq + 1;
        } else if (strcmp(a, "--k-w") == 0 || strcmp(a, "--k-v") == 0 ||
                   strcmp(a, "--k-w3") == 0 || strcmp(a, "--k-w11") == 0 ||
                   strcmp(a, "--v-max") == 0 || strcmp(a, "--w-max") == 0 ||
                   strcmp(a, "--alpha") == 0 || strcmp(a, "--seed") == 0) {
            /* --k-w3 -> k_w3 */
            size_t n = strlen(a + 2);
            if (n >= sizeof(name))
                sim_cli_fail("option too long: %s", a);
            for (size_t k = 0; k <= n; k++)
                name[k] = a[2 + k] == '-' ? '_' : a[2 + k];
        } else {
            continue;
        }
        if (spvs_node_param_set(&p, name, value, err, sizeof(err)) != 0)
            sim_cli_fail("bad parameter: %s", err);
    }

    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    /* No SA_RESTART: a signal should cut the wait in lcm_handle_timeout. */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);

#ifdef SPVS_HAVE_DDS
    if (dds) {
        spvs_node_dds_opts_t dopt = { watchdog_s, (int)log_level,
                                      (unsigned)progress };
        return spvs_node_dds_run(&p, &dopt, &g_stop);
    }
#else
    (void)dds;
#endif

    lcm_t *lcm = lcm_create(url);
    if (!lcm) {
        fprintf(stderr, "spvs-node: cannot open LCM at '%s' (no multicast "
                        "route? see docs/LCM.md)\n", url);
        return 1;
    }

    static spvs_node_t node; /* big (the core's buffers): not on the stack */
    node.log_level = (int)log_level;
    node.progress_every = (unsigned)progress;
    node.progress = stdout;
    int st = spvs_node_init(&node, lcm, &p, watchdog_s, sim_clock_now_s());
    if (st != SPVS_OK) {
        fprintf(stderr, "spvs-node: parameters rejected by the core: %s\n",
                spvs_status_str(st));
        lcm_destroy(lcm);
        return 2;
    }
    if (log_level >= 2)
        fprintf(stderr, "spvs-node: method %lld, %s, watchdog %.2f s\n",
                method, url, watchdog_s);

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

    if (log_level >= 2)
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
