/* link_lockstep.c - the lock-step exchange of the links (sim/link_lockstep.h). */
#include "sim/link_lockstep.h"

#include <math.h>
#include <string.h>

#include "sim/clock.h"
#include "wire.h"

void sim_lockstep_init(sim_lockstep_t *ls)
{
    memset(ls, 0, sizeof(*ls));
    ls->want_seq = -1;
}

int sim_lockstep_on_cmd(sim_lockstep_t *ls, const void *data, int len,
                        spvs_cmd_t *decoded)
{
    spvs_cmd_t cmd;
    if (spvs_cmd_t_decode(data, 0, len, &cmd) < 0)
        return -1;
    if (decoded)
        *decoded = cmd;
    /* The first answer counts: a repeated frame is answered again with the
     * same command, which changes nothing. */
    if (cmd.seq != ls->want_seq || ls->got_cmd)
        return 0;
    ls->cmd = cmd;
    ls->got_cmd = 1;
    return 1;
}

int sim_lockstep_on_state(sim_lockstep_t *ls, const void *data, int len)
{
    spvs_state_t st;
    if (spvs_state_t_decode(data, 0, len, &st) < 0)
        return -1;
    if (st.seq != ls->want_seq)
        return 0;
    ls->state = st;
    ls->got_state = 1;
    return 1;
}

int sim_lockstep_exchange(sim_lockstep_t *ls, int64_t seq,
                          const sim_lockstep_io_t *io,
                          const sim_lockstep_timing_t *tm,
                          sim_lockstep_stats_t *st, char *err,
                          unsigned err_len)
{
    sim_lockstep_stats_t local;
    if (!st)
        st = &local;
    st->sends = 0;
    st->waited_s = 0.0;
    ls->want_seq = seq;
    ls->got_cmd = 0;
    ls->got_state = 0;

    /* Bounded by the deadline whatever arrives: poll returns at the latest
     * at the next resend or at the deadline. */
    const double start = sim_clock_now_s();
    const double deadline = start + tm->timeout_s;
    double next_send = start;
    while (!ls->got_cmd) {
        const double t = sim_clock_now_s();
        if (t >= next_send) {
            if (io->send(io->ctx, err, err_len) != 0)
                return -1;
            st->sends++;
            next_send = tm->resend_s > 0.0 ? t + tm->resend_s : HUGE_VAL;
        }
        if (t >= deadline)
            return SIM_LOCKSTEP_TIMEOUT;
        const double wait = (next_send < deadline ? next_send : deadline) - t;
        if (io->poll(io->ctx, wait, err, err_len) != 0)
            return -1;
    }
    st->waited_s = sim_clock_now_s() - start;

    /* The state normally came first; otherwise give it the grace time,
     * and always look once at what is already queued. */
    const double grace_end = sim_clock_now_s() + tm->state_grace_s;
    while (!ls->got_state) {
        const double left = grace_end - sim_clock_now_s();
        if (io->poll(io->ctx, left > 0.0 ? left : 0.0, err, err_len) != 0)
            return -1;
        if (left <= 0.0)
            break;
    }
    return SIM_LOCKSTEP_ANSWERED;
}

void sim_lockstep_output(const sim_lockstep_t *ls, uint16_t n,
                         spvs_output_t *out)
{
    spvs_wire_output_from_msgs(out, &ls->cmd,
                               ls->got_state ? &ls->state : NULL);
    if (!ls->got_state)
        out->n_matches = n;
}
