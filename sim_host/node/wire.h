/*
 * wire.h - conversions between the core's structs and the LCM messages of
 * lcm_types/ (spvs_matches_t, spvs_cmd_t, spvs_state_t), and allocation-free
 * publishing.  Shared by spvs-node and the simulator's LCM link, so both ends
 * agree on units and checks.
 *
 * Units on the wire: pixels centred on the assumed principal point (float32),
 * time in microseconds (int64), v in m/s and w in rad/s (float64).
 */
#ifndef SPVS_NODE_WIRE_H
#define SPVS_NODE_WIRE_H

#include <stdint.h>

#include <lcm/lcm.h>

#include "lcmtypes/spvs_cmd_t.h"
#include "lcmtypes/spvs_matches_t.h"
#include "lcmtypes/spvs_state_t.h"
#include "spvs/spvs.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Channel names (DESIGN.md section 5). */
#define SPVS_CH_MATCHES "SPVS_MATCHES"
#define SPVS_CH_CMD "SPVS_CMD"
#define SPVS_CH_STATE "SPVS_STATE"

/* Capacity of the fixed-size arrays of spvs_matches_t (the literal in
 * lcm_types/matches_t.lcm).  wire.c checks it against SPVS_MAX_MATCHES. */
#define SPVS_WIRE_MAX_MATCHES \
    ((int)(sizeof(((spvs_matches_t *)0)->x_tgt) / sizeof(float)))

/* Bytes of the largest encoded spvs_matches_t (all arrays are fixed size, so
 * every message has this size). */
#define SPVS_WIRE_MATCHES_BYTES (8 + 3 * 8 + 2 + 256 * (4 + 4 * 4))

/* Fill msg from n core matches (n <= SPVS_MAX_MATCHES).  Entries past n are
 * zeroed so the encoded bytes depend only on the frame.
 * seq: frame number; utime: frame time, microseconds; run_id: this run.
 * Returns 0, or SPVS_E_CAPACITY when n is too large (msg untouched). */
int spvs_wire_matches_from_core(spvs_matches_t *msg, int64_t seq,
                                int64_t utime, int64_t run_id,
                                const spvs_match_t *m, uint16_t n);

/* A simulator frame as a matches message: checks the frame time t_s (finite,
 * 0..9e12 s), converts it to microseconds and fills msg as
 * spvs_wire_matches_from_core() does.  `who` names the link in the one-line
 * reason written to err on failure.  Returns 0 or -1. */
int spvs_wire_frame_from_sim(spvs_matches_t *msg, uint32_t seq, double t_s,
                             int64_t run_id, const spvs_match_t *m, uint16_t n,
                             const char *who, char *err, unsigned err_len);

/* Check a decoded matches message before it reaches the core.
 * Returns SPVS_OK; SPVS_E_CAPACITY (count negative or above the capacity);
 * SPVS_E_NONFINITE (a NaN or infinite coordinate among the first count);
 * SPVS_E_RANGE (a feature index outside 0..SPVS_MAX_FEATURES-1).
 * On error a one-line reason goes to err (err_len bytes, may be 0). */
int spvs_wire_matches_check(const spvs_matches_t *msg, char *err,
                            unsigned err_len);

/* Copy the first msg->count matches into m (capacity SPVS_MAX_MATCHES).
 * Only for a message that passed spvs_wire_matches_check().
 * Returns the number of matches. */
uint16_t spvs_wire_matches_to_core(const spvs_matches_t *msg,
                                   spvs_match_t *m);

/* Command and telemetry of one update, for frame (seq, utime). */
void spvs_wire_cmd_from_output(spvs_cmd_t *cmd, int64_t seq, int64_t utime,
                               const spvs_output_t *out);
void spvs_wire_state_from_output(spvs_state_t *st, int64_t seq,
                                 int64_t utime, const spvs_output_t *out);

/* A stop command (v = w = 0) with the given status and step. */
void spvs_wire_cmd_stop(spvs_cmd_t *cmd, int64_t seq, int64_t utime,
                        int status, int step);

/* Back to the core's output struct (what the simulator records).  st may be
 * NULL (no telemetry): then H, e_x, parallax and the counts are zero. */
void spvs_wire_output_from_msgs(spvs_output_t *out, const spvs_cmd_t *cmd,
                                const spvs_state_t *st);

/* Encode into a stack buffer and publish, without the heap allocation of the
 * generated _publish functions.  Return 0, or -1 when encoding or
 * lcm_publish fails. */
int spvs_wire_publish_matches(lcm_t *lcm, const spvs_matches_t *msg);
int spvs_wire_publish_cmd(lcm_t *lcm, const spvs_cmd_t *cmd);
int spvs_wire_publish_state(lcm_t *lcm, const spvs_state_t *st);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_NODE_WIRE_H */
