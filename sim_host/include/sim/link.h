/*
 * link.h - how the simulator reaches a controller: in the same process, or
 * across a transport (LCM, Zenoh).  The closed loop in spvs-sim is written
 * once against this interface.
 */
#ifndef SIM_LINK_H
#define SIM_LINK_H

#include <stdint.h>

#include "spvs/spvs.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sim_link {
    void *ctx;
    /* Hand frame `seq` (time t_s, seconds) with its n matches to the
     * controller and wait for the command that answers exactly this frame.
     * Fills *out (at least v, w, step, status; telemetry where the transport
     * carries it).  Returns 0, or a negative value with a one-line reason
     * written to err (err_len bytes) on a transport failure such as a
     * timeout. */
    int (*exchange)(void *ctx, uint32_t seq, double t_s,
                    const spvs_match_t *m, uint16_t n, spvs_output_t *out,
                    char *err, unsigned err_len);
    /* Release the link. */
    void (*close)(void *ctx);
} sim_link_t;

#ifdef __cplusplus
}
#endif

#endif /* SIM_LINK_H */
