/* link_fixed.c - the fixed-point core called directly (link_fixed.h). */
#include "sim/link_fixed.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "spvs_q.h"
#include "sim/link_inproc.h"

static int fixed_exchange(void *ctx, uint32_t seq, double t_s, const spvs_match_t *m,
                          uint16_t n, spvs_output_t *out, char *err, unsigned err_len)
{
    (void)seq;
    (void)err;
    (void)err_len;
    /* As the float link: the status is the controller's answer, in out. */
    int status = spvs_q_update((spvs_q_t *)ctx, m, n, (spvs_real)t_s, out);
    (void)status;
    return 0;
}

static void fixed_close(void *ctx)
{
    free(ctx);
}

int sim_link_fixed_open(const spvs_params_t *p, sim_link_t *out, char *err, unsigned err_len)
{
    memset(out, 0, sizeof(*out));
    spvs_q_t *s = calloc(1, sizeof(*s));
    if (s == NULL) {
        snprintf(err, err_len, "out of memory for the controller");
        return -1;
    }
    int rc = spvs_q_init(s, p);
    if (rc != SPVS_OK) {
        snprintf(err, err_len, "the fixed-point controller rejected its parameters: %s",
                 spvs_status_str(rc));
        free(s);
        return -1;
    }
    out->ctx = s;
    out->exchange = fixed_exchange;
    out->close = fixed_close;
    return 0;
}

int sim_run_fixed(const sim_config_t *c, sim_result_t *res, sim_frame_cb cb, void *user,
                  char *err, unsigned err_len)
{
    spvs_params_t p;
    sim_inproc_config_params(c, &p);
    sim_link_t link = {0};
    if (sim_link_fixed_open(&p, &link, err, err_len) != 0) {
        return -1;
    }
    int rc = sim_run(c, &link, res, cb, user, err, err_len);
    link.close(link.ctx);
    return rc;
}
