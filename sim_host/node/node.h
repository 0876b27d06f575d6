/*
 * node.h - the controller node's message handling, apart from its main loop
 * so that tests can drive it over any LCM provider (memq:// in-process).
 *
 * Behaviour for each message on SPVS_MATCHES (docs/LCM.md):
 *   - undecodable bytes: one-line error on stderr, dropped (no frame number
 *     to answer);
 *   - a new run_id: the core is reset (a new run starts from scratch);
 *   - count outside 0..capacity, non-finite values, bad feature index: error
 *     on stderr, stop command for that seq with SPVS_E_CAPACITY,
 *     SPVS_E_NONFINITE or SPVS_E_RANGE; the core is not run;
 *   - seq equal to the last accepted one (duplicate): the previous state and
 *     command are published again; the core is not run twice;
 *   - seq older than the last accepted one: stop command for that seq with
 *     SPVS_E_STALE; the core is not run;
 *   - otherwise: spvs_update() at t_s = utime / 1e6, then SPVS_STATE and
 *     SPVS_CMD (in that order) carrying that seq.
 * Watchdog: while no frame has been accepted for watchdog_s seconds (wall
 * clock), a stop command with seq = -1 and SPVS_E_STALE goes out every
 * watchdog_s seconds.
 */
#ifndef SPVS_NODE_H
#define SPVS_NODE_H

#include <stdint.h>
#include <stdio.h>

#include <lcm/lcm.h>

#include "wire.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Counters of what the node has seen since spvs_node_init. */
typedef struct {
    uint32_t frames;       /* frames run through the core                  */
    uint32_t duplicates;   /* answered again from the last answer          */
    uint32_t out_of_order; /* older seq: answered with a stop              */
    uint32_t rejected;     /* bad count or values: answered with a stop    */
    uint32_t undecodable;  /* dropped                                      */
    uint32_t watchdog;     /* watchdog stops published                     */
    uint32_t runs;         /* distinct run_ids seen                        */
    uint32_t publish_errors;
} spvs_node_stats_t;

typedef struct {
    lcm_t *lcm;              /* not owned                                  */
    spvs_params_t params;
    double watchdog_s;       /* > 0                                         */
    int log_level;           /* 0 quiet, 1 errors, 2 info, 3 every frame    */
    unsigned progress_every; /* print a progress line every N frames, 0 off */
    FILE *progress;          /* where progress lines go (stdout)            */

    spvs_t core;
    uint8_t has_run;
    int64_t run_id;
    uint8_t has_last;
    int64_t last_seq;
    spvs_cmd_t last_cmd;
    spvs_state_t last_state;
    double last_valid_s;     /* monotonic time of the last accepted frame   */
    double last_stop_s;      /* monotonic time of the last watchdog stop    */
    spvs_node_stats_t stats;

    spvs_matches_t msg;      /* decode buffer: fixed size, no heap          */
    spvs_match_t m[SPVS_MAX_MATCHES];
    lcm_subscription_t *sub;
} spvs_node_t;

/* Set up the node with core parameters p and subscribe it to SPVS_MATCHES on
 * lcm.  now_s: monotonic clock, seconds (sim_clock_now_s() of sim/clock.h;
 * starts the watchdog).
 * Returns SPVS_OK, SPVS_E_CONFIG (p rejected by spvs_init, or watchdog_s not
 * positive) or SPVS_E_ARG (subscribing failed). */
int spvs_node_init(spvs_node_t *node, lcm_t *lcm, const spvs_params_t *p,
                   double watchdog_s, double now_s);

/* Handle one raw SPVS_MATCHES message (what the subscription calls).
 * now_s: monotonic clock, seconds.  Returns the status sent with the answer
 * (SPVS_OK or a core status for a processed frame, the rejection status for
 * a stop), or SPVS_E_ARG when the bytes were dropped unanswered. */
int spvs_node_on_bytes(spvs_node_t *node, const void *data, int len,
                       double now_s);

/* Watchdog: call often (every few tens of ms).  Publishes a stop when frames
 * have been missing for watchdog_s.  Returns 1 if it published one, else 0. */
int spvs_node_tick(spvs_node_t *node, double now_s);

/* Unsubscribe (the lcm_t stays with the caller). */
void spvs_node_close(spvs_node_t *node);

/* Set one named parameter from text, the names of the node's --gains file
 * and of its flags with '-' written '_' (k_w, k_v, k_w3, k_w11, v_max, w_max,
 * alpha, noise_px, ...).  Returns 0, or -1 with a one-line reason in err for
 * an unknown name or a value that does not parse. */
int spvs_node_param_set(spvs_params_t *p, const char *name, const char *value,
                        char *err, unsigned err_len);

/* Read a gains file: lines "name = value" or "name value", '#' comments.
 * Returns 0, or -1 with "FILE:LINE: reason" in err. */
int spvs_node_params_load(spvs_params_t *p, const char *path, char *err,
                          unsigned err_len);

/* Names accepted by spvs_node_param_set, NULL-terminated (for --help). */
extern const char *const spvs_node_param_names[];

#ifdef __cplusplus
}
#endif

#endif /* SPVS_NODE_H */
