/*
 * link_inproc.h - the controller in the simulator's own process: a
 * sim_link_t whose exchange() calls spvs_update() directly.
 */
#ifndef SIM_LINK_INPROC_H
#define SIM_LINK_INPROC_H

#include <stdint.h>

#include "sim/link.h"
#include "sim/sim.h"
#include "spvs/spvs.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The controller's parameters for a run: spvs_params_default() of `method`,
 * with the ASSUMED focal length alpha_px (pixels, x and y) and the seed. */
void sim_inproc_params(spvs_params_t *p, int method, double alpha_px,
                       uint32_t seed);

/* The parameters sim_run_inproc() gives the controller for configuration c:
 * sim_inproc_params() of its method, assumed focal length and seed, and its
 * arrival noise sigma when set. */
void sim_inproc_config_params(const sim_config_t *c, spvs_params_t *p);

/* Open an in-process link with a fresh controller (heap-allocated spvs_t)
 * initialised from p.  Close it with out->close(out->ctx).
 * Returns 0, or -1 with a reason in err (no memory, or spvs_init() refused
 * the parameters). */
int sim_link_inproc_open(const spvs_params_t *p, sim_link_t *out, char *err,
                         unsigned err_len);

/* One closed-loop run of configuration c against an in-process controller
 * with sim_inproc_params() of c (method, assumed focal length, seed): opens
 * the link, sim_run()s, closes it.  Returns sim_run()'s value, or -1 with a
 * reason in err when the link cannot be opened. */
int sim_run_inproc(const sim_config_t *c, sim_result_t *res, sim_frame_cb cb,
                   void *user, char *err, unsigned err_len);

#ifdef __cplusplus
}
#endif

#endif /* SIM_LINK_INPROC_H */
