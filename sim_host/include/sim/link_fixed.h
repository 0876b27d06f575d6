/*
 * link_fixed.h - the fixed-point core in the simulator's own process: a
 * sim_link_t whose exchange() calls spvs_q_update() (firmware/src/fixed,
 * docs/FIXED.md), the same interface as the float core's in-process link,
 * so a closed loop can be judged on the fixed-point arithmetic.
 */
#ifndef SIM_LINK_FIXED_H
#define SIM_LINK_FIXED_H

#include "sim/link.h"
#include "sim/sim.h"
#include "spvs/spvs.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Open a link with a fresh fixed-point controller (heap-allocated)
 * initialised from p.  Close it with out->close(out->ctx).  Returns 0, or
 * -1 with a reason in err (no memory, or spvs_q_init() refused p). */
int sim_link_fixed_open(const spvs_params_t *p, sim_link_t *out, char *err, unsigned err_len);

/* sim_run_inproc() on the fixed-point core: the same parameters
 * (sim_inproc_config_params). */
int sim_run_fixed(const sim_config_t *c, sim_result_t *res, sim_frame_cb cb, void *user,
                  char *err, unsigned err_len);

#ifdef __cplusplus
}
#endif

#endif /* SIM_LINK_FIXED_H */
