/*
 * link_dds.h - the simulator's link to spvs-node --dds across DDS with
 * ROS 2's names (docs/ROS2.md): frames out on /spvs/matches, answers in on
 * /spvs/state, in the domain of ROS_DOMAIN_ID (CYCLONEDDS_URI configures
 * Cyclone DDS).
 *
 * Lock-step on the State's seq, the exchange of sim/link_lockstep.h: the
 * node writes the /cmd_vel Twist of a frame and then its State, which
 * carries the command (v, w, step, status) and the telemetry, so the State
 * with the frame's seq is the answer.  Before the first frame the link
 * waits (within the timeout) until the node's reader and writer are
 * matched, so that the first frame is not sent into the void; a frame
 * still unanswered after 1 s is written again (the node answers a repeat
 * from its previous answer).  Each open link draws a fresh run_id.
 */
#ifndef SIM_LINK_DDS_H
#define SIM_LINK_DDS_H

#include "sim/link.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Open a DDS link.  timeout_s: longest wait for the answer to one frame,
 * seconds (> 0).  On success fills *out and returns 0; otherwise -1 with a
 * one-line reason in err. */
int sim_link_dds_open(double timeout_s, sim_link_t *out, char *err,
                      unsigned err_len);

#ifdef __cplusplus
}
#endif

#endif /* SIM_LINK_DDS_H */
