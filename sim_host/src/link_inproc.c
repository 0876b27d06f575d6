/* link_inproc.c - the controller called directly (link_inproc.h). */
#include "sim/link_inproc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void sim_inproc_params(spvs_params_t *p, int method, double alpha_px,
                       uint32_t seed)
{
    spvs_params_default(p, (spvs_method_t)method);
    p->ctl.alpha_x = (spvs_real)alpha_px;
    p->ctl.alpha_y = (spvs_real)alpha_px;
    p->seed = seed;
}

static int inproc_exchange(void *ctx, uint32_t seq, double t_s,
                           const spvs_match_t *m, uint16_t n,
                           spvs_output_t *out, char *err, unsigned err_len)
{
    (void)seq;
    (void)err;
    (void)err_len;
    /* The status is in out->status; a bad frame is the controller's answer,
     * not a transport failure. */
    int status = spvs_update((spvs_t *)ctx, m, n, (spvs_real)t_s, out);
    (void)status;
    return 0;
}

static void inproc_close(void *ctx)
{
    free(ctx);
}

int sim_link_inproc_open(const spvs_params_t *p, sim_link_t *out, char *err,
                         unsigned err_len)
{
    memset(out, 0, sizeof(*out));
    spvs_t *s = calloc(1, sizeof(*s));
    if (s == NULL) {
        snprintf(err, err_len, "out of memory for the controller");
        return -1;
    }
    int rc = spvs_init(s, p);
    if (rc != SPVS_OK) {
        snprintf(err, err_len, "controller rejected its parameters: %s",
                 spvs_status_str(rc));
        free(s);
        return -1;
    }
    out->ctx = s;
    out->exchange = inproc_exchange;
    out->close = inproc_close;
    return 0;
}

void sim_inproc_config_params(const sim_config_t *c, spvs_params_t *p)
{
    sim_inproc_params(p, c->method, c->focal_assumed_mm / c->pixel_mm, (uint32_t)c->seed);
    if (c->arrival_sigma_px > 0.0) {
        p->ctl.arrival_sigma_px = (spvs_real)c->arrival_sigma_px;
    }
}

int sim_run_inproc(const sim_config_t *c, sim_result_t *res, sim_frame_cb cb,
                   void *user, char *err, unsigned err_len)
{
    spvs_params_t p;
    sim_inproc_config_params(c, &p);
    sim_link_t link;
    if (sim_link_inproc_open(&p, &link, err, err_len) != 0) {
        return -1;
    }
    int rc = sim_run(c, &link, res, cb, user, err, err_len);
    link.close(link.ctx);
    return rc;
}
