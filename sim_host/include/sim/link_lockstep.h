/*
 * link_lockstep.h - the lock-step exchange of the simulator's links to a
 * controller node, written once for every transport (LCM, Zenoh).
 *
 * One frame at a time: send it, wait for the command whose seq equals the
 * frame's, ignoring any other (watchdog stops have seq -1, answers to other
 * senders or to earlier frames), and send it again every resend interval
 * while no answer comes, until the timeout.  The node answers a repeated
 * frame from its previous answer and never runs the controller twice, so a
 * resend cannot change the result.  The telemetry (SPVS_STATE, the same
 * seq) is published by the node just before the command; once the command
 * is here, the exchange waits at most a grace time for it.
 *
 * A transport gives two functions: send the frame, and poll for input,
 * handing each message it receives to sim_lockstep_on_cmd or
 * sim_lockstep_on_state.  Every wait is bounded by the timeout.
 */
#ifndef SIM_LINK_LOCKSTEP_H
#define SIM_LINK_LOCKSTEP_H

#include <stdint.h>

#include "lcmtypes/spvs_cmd_t.h"
#include "lcmtypes/spvs_state_t.h"
#include "spvs/spvs.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What has arrived for the frame awaited. */
typedef struct {
    int64_t want_seq;    /* frame awaited; -1 before the first         */
    int got_cmd;
    int got_state;
    spvs_cmd_t cmd;      /* valid when got_cmd                         */
    spvs_state_t state;  /* valid when got_state                       */
} sim_lockstep_t;

/* A transport. */
typedef struct {
    void *ctx;
    /* Send the frame awaited (again).  Returns 0, or -1 with a one-line
     * reason in err. */
    int (*send)(void *ctx, char *err, unsigned err_len);
    /* Wait up to wait_s seconds (0: do not wait, take only what is there)
     * for input and hand every message to sim_lockstep_on_cmd/_on_state.
     * Returns 0 (messages or not), or -1 with a one-line reason in err. */
    int (*poll)(void *ctx, double wait_s, char *err, unsigned err_len);
} sim_lockstep_io_t;

/* Times of one exchange, seconds. */
typedef struct {
    double timeout_s;     /* longest wait for the command, from the first
                           * send, resends included (> 0)              */
    double resend_s;      /* send again after this; 0: never            */
    double state_grace_s; /* after the command, wait this long for the
                           * state; 0: only what has already arrived    */
} sim_lockstep_timing_t;

/* What one exchange took. */
typedef struct {
    int sends;            /* times the frame went out (1: no resend)    */
    double waited_s;      /* first send to command, seconds             */
} sim_lockstep_stats_t;

/* sim_lockstep_exchange's results. */
#define SIM_LOCKSTEP_ANSWERED 0
#define SIM_LOCKSTEP_TIMEOUT 1

/* Nothing awaited yet. */
void sim_lockstep_init(sim_lockstep_t *ls);

/* An SPVS_CMD payload (len bytes, LCM-encoded).  Kept when it answers the
 * frame awaited and no answer has been kept yet.  The decoded command goes
 * to *decoded when it is not NULL.  Returns 1 kept, 0 decoded but not kept,
 * -1 undecodable (dropped). */
int sim_lockstep_on_cmd(sim_lockstep_t *ls, const void *data, int len,
                        spvs_cmd_t *decoded);

/* An SPVS_STATE payload.  Kept when its seq is the frame awaited.  Returns
 * 1 kept, 0 not, -1 undecodable. */
int sim_lockstep_on_state(sim_lockstep_t *ls, const void *data, int len);

/* Await frame seq: send it through io and wait as described above.
 * Returns SIM_LOCKSTEP_ANSWERED (ls->cmd holds the answer, ls->state the
 * telemetry when ls->got_state), SIM_LOCKSTEP_TIMEOUT (no answer within
 * timeout_s), or -1 when send or poll failed (their reason in err).  *st
 * (may be NULL) is filled in every case. */
int sim_lockstep_exchange(sim_lockstep_t *ls, int64_t seq,
                          const sim_lockstep_io_t *io,
                          const sim_lockstep_timing_t *tm,
                          sim_lockstep_stats_t *st, char *err,
                          unsigned err_len);

/* The answer as the core's output struct, as the simulator records it: with
 * the telemetry when it came, otherwise with zero telemetry and n (the
 * frame's match count) as the number of matches. */
void sim_lockstep_output(const sim_lockstep_t *ls, uint16_t n,
                         spvs_output_t *out);

#ifdef __cplusplus
}
#endif

#endif /* SIM_LINK_LOCKSTEP_H */
