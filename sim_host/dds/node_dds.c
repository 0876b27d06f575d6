/*
 * node_dds.c - spvs-node --dds; see node_dds.h.
 */
#define _POSIX_C_SOURCE 200809L

#include "node_dds.h"

#include <stdio.h>
#include <string.h>

#include <lcm/lcm.h>

#include "node.h"
#include "ros_dds.h"
#include "sim/clock.h"

/* Messages the in-process bus can hold between two drains: one frame's
 * state and command, or one watchdog stop. */
#define DRAIN_MAX 8
/* Samples taken from /spvs/matches per wake-up (the reader keeps
 * SPVS_DDS_DEPTH). */
#define TAKE_MAX SPVS_DDS_DEPTH

typedef struct {
    dds_entity_t pp, rd_matches, wr_twist, wr_state, ws;
    lcm_t *bus;
    lcm_subscription_t *sub_cmd, *sub_state;
    spvs_node_t node;           /* the node's logic and its core           */
    spvs_state_t pending;       /* the state published before its command  */
    int has_pending;
    spvs_dds_matches_t rx;      /* one received sample                     */
    spvs_matches_t lcm_msg;
    uint8_t buf[SPVS_WIRE_MATCHES_BYTES];
    unsigned write_errors;
} node_dds_t;

static node_dds_t g_nd;  /* big (the core's buffers): not on the stack */

/* The Twist first, then the State: a client that waits for the State of
 * its frame knows that the command is out. */
static void send_cmd(node_dds_t *nd, const spvs_cmd_t *cmd,
                     const spvs_state_t *st)
{
    spvs_dds_twist_t tw;
    spvs_dds_state_t s;
    spvs_dds_twist_from_cmd(&tw, cmd);
    spvs_dds_state_from_lcm(&s, st, cmd);
    if (dds_write(nd->wr_twist, &tw) < 0)
        nd->write_errors++;
    if (dds_write(nd->wr_state, &s) < 0)
        nd->write_errors++;
}

static void on_bus_state(const lcm_recv_buf_t *rbuf, const char *ch, void *u)
{
    (void)ch;
    node_dds_t *nd = (node_dds_t *)u;
    nd->has_pending = spvs_state_t_decode(rbuf->data, 0,
                                          (int)rbuf->data_size,
                                          &nd->pending) >= 0;
}

static void on_bus_cmd(const lcm_recv_buf_t *rbuf, const char *ch, void *u)
{
    (void)ch;
    node_dds_t *nd = (node_dds_t *)u;
    spvs_cmd_t cmd;
    if (spvs_cmd_t_decode(rbuf->data, 0, (int)rbuf->data_size, &cmd) < 0)
        return;
    int with_state = nd->has_pending && nd->pending.seq == cmd.seq;
    send_cmd(nd, &cmd, with_state ? &nd->pending : NULL);
    nd->has_pending = 0;
}

/* Hand what the node published on the in-process bus to DDS. */
static void drain_bus(node_dds_t *nd)
{
    for (int k = 0; k < DRAIN_MAX; k++)
        if (lcm_handle_timeout(nd->bus, 0) <= 0)
            break;
}

static void on_sample(node_dds_t *nd, const spvs_dds_matches_t *m)
{
    spvs_dds_matches_to_lcm(&nd->lcm_msg, m);
    int len = spvs_matches_t_encode(nd->buf, 0, (int)sizeof(nd->buf),
                                    &nd->lcm_msg);
    if (len < 0)
        return;
    (void)spvs_node_on_bytes(&nd->node, nd->buf, len, sim_clock_now_s());
    drain_bus(nd);
}

static int take_all(node_dds_t *nd)
{
    for (int k = 0; k < TAKE_MAX; k++) {
        void *samples[1] = { &nd->rx };
        dds_sample_info_t info;
        dds_return_t n = dds_take(nd->rd_matches, samples, &info, 1, 1);
        if (n < 0) {
            fprintf(stderr, "spvs-node: error: DDS take failed: %s\n",
                    dds_strretcode(n));
            return -1;
        }
        if (n == 0)
            break;
        if (info.valid_data)
            on_sample(nd, &nd->rx);
    }
    return 0;
}

static int open_dds(node_dds_t *nd, uint32_t domain)
{
    char err[200];
    nd->pp = spvs_dds_participant(domain, err, sizeof(err));
    if (nd->pp < 0) {
        fprintf(stderr, "spvs-node: error: %s\n", err);
        return -1;
    }
    dds_qos_t *q = spvs_dds_qos();
    dds_entity_t t_m = dds_create_topic(nd->pp, &spvs_msgs_msg_dds__Matches__desc,
                                        SPVS_DDS_TOPIC_MATCHES, q, NULL);
    dds_entity_t t_c = dds_create_topic(nd->pp, &geometry_msgs_msg_dds__Twist__desc,
                                        SPVS_DDS_TOPIC_CMD_VEL, q, NULL);
    dds_entity_t t_s = dds_create_topic(nd->pp, &spvs_msgs_msg_dds__State__desc,
                                        SPVS_DDS_TOPIC_STATE, q, NULL);
    nd->rd_matches = t_m < 0 ? t_m : dds_create_reader(nd->pp, t_m, q, NULL);
    nd->wr_twist = t_c < 0 ? t_c : dds_create_writer(nd->pp, t_c, q, NULL);
    nd->wr_state = t_s < 0 ? t_s : dds_create_writer(nd->pp, t_s, q, NULL);
    dds_delete_qos(q);
    if (nd->rd_matches < 0 || nd->wr_twist < 0 || nd->wr_state < 0) {
        fprintf(stderr, "spvs-node: error: cannot create the DDS topics, "
                        "reader and writers on domain %u\n", (unsigned)domain);
        return -1;
    }
    nd->ws = dds_create_waitset(nd->pp);
    dds_entity_t rc = dds_create_readcondition(nd->rd_matches,
                                               DDS_ANY_STATE);
    if (nd->ws < 0 || rc < 0 || dds_waitset_attach(nd->ws, rc, 0) < 0) {
        fprintf(stderr, "spvs-node: error: cannot create the DDS waitset\n");
        return -1;
    }
    return 0;
}

int spvs_node_dds_run(const spvs_params_t *p, const spvs_node_dds_opts_t *o,
                      volatile sig_atomic_t *stop)
{
    node_dds_t *nd = &g_nd;
    char err[200];
    uint32_t domain;
    if (spvs_dds_domain(&domain, err, sizeof(err)) != 0) {
        fprintf(stderr, "spvs-node: %s\n", err);
        return 2;
    }
    memset(nd, 0, sizeof(*nd));
    nd->bus = lcm_create("memq://");
    if (!nd->bus) {
        fprintf(stderr, "spvs-node: error: cannot open the in-process bus\n");
        return 1;
    }
    nd->node.log_level = o->log_level;
    nd->node.progress_every = o->progress_every;
    nd->node.progress = stdout;
    int st = spvs_node_init(&nd->node, nd->bus, p, o->watchdog_s,
                            sim_clock_now_s());
    if (st != SPVS_OK) {
        fprintf(stderr, "spvs-node: parameters rejected by the core: %s\n",
                spvs_status_str(st));
        lcm_destroy(nd->bus);
        return 2;
    }
    nd->sub_cmd = lcm_subscribe(nd->bus, SPVS_CH_CMD, on_bus_cmd, nd);
    nd->sub_state = lcm_subscribe(nd->bus, SPVS_CH_STATE, on_bus_state, nd);
    int rc = 0;
    if (!nd->sub_cmd || !nd->sub_state || open_dds(nd, domain) != 0)
        rc = 1;
    if (rc == 0 && o->log_level >= 2)
        fprintf(stderr, "spvs-node: DDS domain %u, %s in, %s and %s out, "
                "watchdog %.2f s\n", (unsigned)domain, SPVS_DDS_TOPIC_MATCHES,
                SPVS_DDS_TOPIC_CMD_VEL, SPVS_DDS_TOPIC_STATE, o->watchdog_s);

    while (rc == 0 && !*stop) {
        /* Short waits keep the watchdog and the signal check responsive. */
        dds_return_t w = dds_waitset_wait(nd->ws, NULL, 0, DDS_MSECS(50));
        if (w < 0 && !*stop) {
            fprintf(stderr, "spvs-node: error: DDS wait failed: %s\n",
                    dds_strretcode(w));
            rc = 1;
            break;
        }
        if (take_all(nd) != 0) {
            rc = 1;
            break;
        }
        if (spvs_node_tick(&nd->node, sim_clock_now_s()))
            drain_bus(nd);
    }

    if (nd->wr_twist > 0 && nd->wr_state > 0) {
        /* The robot must not drive on after the controller is gone. */
        spvs_cmd_t last;
        spvs_wire_cmd_stop(&last, -1, 0, SPVS_E_STALE,
                           (int)spvs_step(&nd->node.core));
        send_cmd(nd, &last, NULL);
    }
    if (o->log_level >= 2)
        fprintf(stderr,
                "spvs-node: exit: %u frames, %u duplicates, %u out of order, "
                "%u rejected, %u watchdog stops, %u runs, %u write errors\n",
                nd->node.stats.frames, nd->node.stats.duplicates,
                nd->node.stats.out_of_order, nd->node.stats.rejected,
                nd->node.stats.watchdog, nd->node.stats.runs,
                nd->write_errors);
    /* Deleting the participant waits (Cyclone DDS's writer linger) for the
     * readers to acknowledge the last stop. */
    if (nd->pp > 0)
        dds_delete(nd->pp);
    spvs_node_close(&nd->node);
    if (nd->sub_cmd)
        lcm_unsubscribe(nd->bus, nd->sub_cmd);
    if (nd->sub_state)
        lcm_unsubscribe(nd->bus, nd->sub_state);
    lcm_destroy(nd->bus);
    return rc;
}
