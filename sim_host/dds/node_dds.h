/*
 * node_dds.h - spvs-node --dds: the controller node served on DDS with
 * ROS 2's names (docs/ROS2.md).
 *
 * The node's rules are node.h's, run unchanged: each /spvs/matches sample
 * goes to spvs_node_on_bytes() as the LCM message it equals, on an
 * in-process LCM bus (memq://), and what the node publishes there is sent
 * on DDS: every SPVS_CMD as a Twist on /cmd_vel, then the State of the same
 * frame on /spvs/state.  So a bad, old or repeated frame gets the answer it
 * gets over LCM (a stop with its status), and the watchdog's stops go out
 * as zero Twists with a State of seq -1.  On SIGINT or SIGTERM the node
 * sends a last zero Twist (and a State of seq -1, status SPVS_E_STALE)
 * before it leaves the domain.
 */
#ifndef SPVS_NODE_DDS_H
#define SPVS_NODE_DDS_H

#include <signal.h>

#include "spvs/spvs.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    double watchdog_s;        /* stops after this long without a frame    */
    int log_level;            /* as spvs_node_t's                          */
    unsigned progress_every;  /* progress line every N frames, 0 off       */
} spvs_node_dds_opts_t;

/* Run the node on the domain of ROS_DOMAIN_ID until *stop becomes non-zero.
 * Returns 0 after a stop, 1 when DDS or the in-process bus fails, 2 when
 * ROS_DOMAIN_ID or the parameters are rejected (a one-line error on
 * stderr in every failing case). */
int spvs_node_dds_run(const spvs_params_t *p, const spvs_node_dds_opts_t *o,
                      volatile sig_atomic_t *stop);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_NODE_DDS_H */
