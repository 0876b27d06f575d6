/*
 * link_lcm.h - the simulator's link to a controller across LCM (spvs-node).
 *
 * Lock-step: exchange() publishes frame seq on SPVS_MATCHES and waits for the
 * SPVS_CMD whose seq equals it, ignoring any other (watchdog stops, answers
 * to other senders); the SPVS_STATE with the same seq, published by the node
 * just before the command, fills the telemetry.  A run is thus deterministic
 * and runs as fast as the two processes allow.  Each open link draws a fresh
 * run_id, so a running node resets its controller for the new run.
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

#ifdef __cplusplus
}
#endif

#endif /* SIM_LINK_LCM_H */
