/*
 * link_zenoh.h - the simulator's link to a controller across Zenoh: frames
 * go out on spvs/<robot>/matches and the answer comes back on
 * spvs/<robot>/cmd (telemetry on spvs/<robot>/state), payloads LCM-encoded
 * (docs/ZENOH.md).  Normally spvs-zenoh-bridge carries them to spvs-node on
 * LCM.
 *
 * There is no C Zenoh library to link, so the link starts a small Python
 * process (sim_host/zenoh/sim_port.py, in the project's venv) and exchanges
 * length-prefixed frames with it over a socket pair on its stdin/stdout.
 * Every wait is bounded with poll(); the process is reaped on close.
 *
 * Lock-step as over LCM: exchange() sends frame seq and waits for the cmd
 * with that seq, ignoring others (watchdog stops have seq -1).  A frame
 * lost on the way (the bridge restarting, Zenoh still connecting) is sent
 * again every resend interval until answered or until the timeout; the node
 * answers a repeated frame from its last answer, so repeats never run the
 * controller twice.  The exchange is sim/link_lockstep.h's, as over LCM.
 *
 * Settings that spvs-sim has no option for come from the environment:
 *   SPVS_ZENOH_ROBOT     robot name in the key expressions (robot0)
 *   SPVS_ZENOH_RESEND_S  resend interval, seconds, 0 = never (0.5)
 *   SPVS_ZENOH_MODE      peer or client (peer)
 *   SPVS_PYTHON          interpreter (<source>/.venv/bin/python)
 *   SPVS_ZENOH_PORT      the port script (<source>/sim_host/zenoh/sim_port.py)
 */
#ifndef SIM_LINK_ZENOH_H
#define SIM_LINK_ZENOH_H

#include "sim/link.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Open a Zenoh link.
 * endpoint: Zenoh endpoint to connect to, e.g. "tcp/127.0.0.1:7447" (where
 *   spvs-zenoh-bridge listens);
 * timeout_s: longest wait for the answer to one frame, resends included,
 *   and for a subscriber of the matches to appear when opening, seconds
 *   (> 0).
 * On success fills *out (exchange and close) and returns 0; otherwise
 * returns -1 with a one-line reason in err (err_len bytes): no venv, the
 * port could not start, nobody subscribes to the matches, bad settings. */
int sim_link_zenoh_open(const char *endpoint, double timeout_s,
                        sim_link_t *out, char *err, unsigned err_len);

#ifdef __cplusplus
}
#endif

#endif /* SIM_LINK_ZENOH_H */
