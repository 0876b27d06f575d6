/*
 * link_lcm.h - the simulator's link to a controller across LCM (spvs-node).
 *
 * Lock-step: exchange() publishes frame seq on SPVS_MATCHES and waits for the
 * SPVS_CMD whose seq equals it, ignoring any other (watchdog stops, answers
 * to other senders); the SPVS_STATE with the same seq, published by the node
 * just before the command, fills the telemetry.  A run is thus deterministic
 * and runs as fast as the two processes allow.  A frame still unanswered
 * after 0.25 s is published again (a lost datagram, or a node that was not
 * yet listening); the node answers a repeat with its previous answer, so
 * this never changes the result.  Each open link draws a fresh
 * run_id, so a running node resets its controller for the new run.
 * The exchange itself is sim/link_lockstep.h's, shared with the Zenoh link.
 */
#ifndef SIM_LINK_LCM_H
#define SIM_LINK_LCM_H

#include "sim/link.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Open an LCM link.
 * url: LCM provider URL (NULL: LCM's default, $LCM_DEFAULT_URL);
 * timeout_s: longest wait for the answer to one frame, seconds (> 0).
 * On success fills *out (exchange and close) and returns 0; otherwise
 * returns -1 with a one-line reason in err (err_len bytes). */
int sim_link_lcm_open(const char *url, double timeout_s, sim_link_t *out,
                      char *err, unsigned err_len);

/* Options for a link across a lossy transport (docs/ROBUSTNESS.md; the
 * fault relay tools/lcm_faults sits between the simulator and the node). */
typedef struct {
    /* Channel the frames go out on; NULL: SPVS_MATCHES.  The relay listens
     * there and forwards to SPVS_MATCHES. */
    const char *matches_channel;
    /* 0: lock-step, an unanswered frame is a link error (as above).
     * 1: what a robot base does: when no answer arrives within timeout_s
     * (one control period), drive on the newest command received so far -
     * a late answer to an earlier frame, a watchdog stop of the node, or
     * the command in force - and go on with the next frame.  Answers to
     * frames older than the one in force are ignored. */
    int keep_last;
    /* keep_last: the base's own timeout.  A command older than this (frame
     * time, seconds, > 0) with nothing received since is replaced by a stop,
     * so a dead node cannot leave the robot driving. */
    double hold_max_s;
} sim_link_lcm_opts_t;

/* sim_link_lcm_open with options (opts NULL: the defaults above, which give
 * exactly sim_link_lcm_open).  Returns 0 or -1 with a reason in err. */
int sim_link_lcm_open_opts(const char *url, double timeout_s,
                           const sim_link_lcm_opts_t *opts, sim_link_t *out,
                           char *err, unsigned err_len);

#ifdef __cplusplus
}
#endif

#endif /* SIM_LINK_LCM_H */
