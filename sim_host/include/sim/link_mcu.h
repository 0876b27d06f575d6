/*
 * link_mcu.h - the simulator's link to the controller on the emulated
 * Cortex-M4F: QEMU (mps2-an386) runs the controller application
 * (target/app/), spvs-serial-agent bridges its UART to LCM, and the frames
 * go through the LCM link (link_lcm.h), lock-step.  docs/SERIAL.md.
 *
 * And the serial link's quantisation in process (--quantize-serial): the
 * frames of any link rounded as the wire rounds them (coordinates to
 * 1/16 px, times to milliseconds), so an in-process run is fed exactly what
 * the MCU is fed.
 */
#ifndef SIM_LINK_MCU_H
#define SIM_LINK_MCU_H

#include <stdint.h>

#include "sim/link.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    const char *image;     /* application image; NULL: the build's       */
    const char *lcm_url;   /* LCM provider the agent and the link use     */
    double timeout_s;      /* longest wait for one answer, seconds        */
    int method;            /* 1..3, sent to the MCU                       */
    uint32_t seed;         /* RANSAC seed, sent to the MCU                */
    double alpha_px;       /* assumed focal length, pixels                */
    int quiet;             /* 1: no progress lines on stderr              */
} sim_link_mcu_opts_t;

/* The image the build made (target/ cross build), for --mcu-image's
 * default. */
const char *sim_link_mcu_default_image(void);

/* Start QEMU and the agent, wait until the MCU has taken the set-up (at
 * most 30 s), then open the LCM link.  Closing the link stops both; so
 * does SIGINT, SIGTERM or SIGHUP, and their death with the simulator
 * (PR_SET_PDEATHSIG).  Returns 0, or -1 with a one-line reason in err. */
int sim_link_mcu_open(const sim_link_mcu_opts_t *o, sim_link_t *out,
                      char *err, unsigned err_len);

/* Wrap *link (which the wrapper then owns and closes) so that every frame
 * is quantised as on the serial link before it goes through.  A frame the
 * wire cannot carry is answered with a stop (SPVS_E_RANGE), as the agent
 * answers it.  Returns 0 or -1 (no memory) with a reason in err. */
int sim_link_quantize_wrap(sim_link_t *link, char *err, unsigned err_len);

#ifdef __cplusplus
}
#endif

#endif /* SIM_LINK_MCU_H */
