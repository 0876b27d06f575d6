/*
 * app.c - the controller application's frame handling and watchdog; see
 * app.h.
 */
#include "app.h"

#include <string.h>

static void send(app_t *a, int len)
{
    if (len > 0) {
        (void)a->write(a->write_ctx, a->tx, (size_t)len);
    }
}

static void send_status(app_t *a, uint8_t reason, uint32_t now_ms)
{
    spvs_serial_status_frame_t *s = &a->st;
    s->reason = reason;
    s->step = a->configured ? spvs_step(&a->core) : 0u;
    s->method = a->configured ? a->cfg.method : 0u;
    s->seed = a->cfg.seed;
    s->alpha_px = a->cfg.alpha_px;
    s->run = a->run;
    s->last_seq = a->last_seq;
    s->age_ms = a->has_valid ? now_ms - a->last_valid_ms : 0xFFFFFFFFu;
    s->uptime_ms = now_ms - a->boot_ms;
    s->watchdog_ms = a->watchdog_ms;
    send(a, spvs_serial_encode_status(s, a->tx, sizeof(a->tx)));
}

static void send_result(app_t *a, const spvs_serial_result_t *r)
{
    send(a, spvs_serial_encode_result(r, a->tx, sizeof(a->tx)));
}

/* A stop for a frame that was refused: the core did not run. */
static void send_stop(app_t *a, const spvs_serial_matches_hdr_t *h, int status)
{
    spvs_serial_result_t r;
    memset(&r, 0, sizeof(r));
    r.run = h->run;
    r.seq = h->seq;
    r.t_ms = h->t_ms;
    r.flags = SPVS_SERIAL_F_REJECTED;
    r.out.status = (int16_t)status;
    r.out.step = a->configured ? spvs_step(&a->core) : 0u;
    r.out.n_matches = h->count;
    send_result(a, &r);
}

/* Whether a new focal length equals the one in force.  The new one is in
 * [1, 1e5] px (spvs_serial_parse_config), where equal floats are equal
 * bits: compared as bits, so that a CPU without FPU makes no soft-float
 * call for it. */
static int same_alpha(float alpha_new, float alpha_in_force)
{
    uint32_t a, b;
    memcpy(&a, &alpha_new, sizeof(a));
    memcpy(&b, &alpha_in_force, sizeof(b));
    return a == b;
}

static void on_config(app_t *a, const spvs_serial_frame_t *f)
{
    spvs_serial_config_t c;
    if (spvs_serial_parse_config(f, &c) != SPVS_SERIAL_OK) {
        ++a->st.rejected;
        return;
    }
    a->watchdog_ms = c.watchdog_ms ? c.watchdog_ms : APP_WATCHDOG_MS;
    a->cfg.watchdog_ms = c.watchdog_ms;
    if (!a->configured || c.method != a->cfg.method || c.seed != a->cfg.seed ||
        !same_alpha(c.alpha_px, a->cfg.alpha_px)) {
        spvs_params_t p;
        spvs_params_default(&p, (spvs_method_t)c.method);
        p.ctl.alpha_x = (spvs_real)c.alpha_px;
        p.ctl.alpha_y = (spvs_real)c.alpha_px;
        p.seed = c.seed;
        if (spvs_init(&a->core, &p) != SPVS_OK) {
            ++a->st.rejected;
            a->configured = 0u;
            return;
        }
        a->cfg = c;
        a->configured = 1u;
        a->has_run = 0u;
        a->has_last = 0u;
    }
}

static void on_matches(app_t *a, const spvs_serial_frame_t *f, uint32_t now_ms)
{
    spvs_serial_matches_hdr_t h;
    memset(&h, 0, sizeof(h));
    int st = spvs_serial_parse_matches(f, &h, a->m, SPVS_MAX_MATCHES);
    if (st != SPVS_SERIAL_OK) {
        ++a->st.rejected;
        /* Only a frame whose fixed part arrived has a seq to answer. */
        if (f->len >= SPVS_SERIAL_MATCHES_FIXED) {
            send_stop(a, &h, st == SPVS_SERIAL_E_COUNT ? SPVS_E_CAPACITY
                             : st == SPVS_SERIAL_E_RANGE ? SPVS_E_RANGE
                                                         : SPVS_E_ARG);
        }
        return;
    }
    if (!a->configured) {
        ++a->st.rejected;
        send_stop(a, &h, SPVS_E_CONFIG);
        return;
    }
    if (!a->has_run || h.run != a->run) {
        spvs_reset(&a->core);
        a->run = h.run;
        a->has_run = 1u;
        a->has_last = 0u;
    }
    if (a->has_last && h.seq == a->last_seq) {
        ++a->st.repeats;
        a->has_valid = 1u;
        a->last_valid_ms = now_ms;
        spvs_serial_result_t r = a->last;
        r.flags |= SPVS_SERIAL_F_REPEAT;
        send_result(a, &r);
        return;
    }
    if (a->has_last && h.seq < a->last_seq) {
        ++a->st.stale;
        send_stop(a, &h, SPVS_E_STALE);
        return;
    }
    spvs_serial_result_t *r = &a->last;
    int ust = spvs_update(&a->core, a->m, h.count, (spvs_real)spvs_serial_s_from_ms(h.t_ms),
                          &r->out);
    (void)ust; /* the status travels in r->out.status */
    r->run = h.run;
    r->seq = h.seq;
    r->t_ms = h.t_ms;
    r->flags = (uint8_t)((r->out.h_valid ? SPVS_SERIAL_F_H_VALID : 0u) |
                         (r->out.e_valid ? SPVS_SERIAL_F_E_VALID : 0u) |
                         (r->out.eq11 ? SPVS_SERIAL_F_EQ11 : 0u));
    a->has_last = 1u;
    a->last_seq = h.seq;
    a->has_valid = 1u;
    a->last_valid_ms = now_ms;
    ++a->st.updates;
    a->st.status = r->out.status;
    send_result(a, r);
}

static void on_frame(app_t *a, uint32_t now_ms)
{
    spvs_serial_frame_t f;
    int st = spvs_serial_unpack(a->rx.buf, a->rx.n, &f);
    if (st == SPVS_SERIAL_E_CRC) {
        ++a->st.crc_errors;
        return;
    }
    if (st != SPVS_SERIAL_OK) {
        ++a->st.framing_errors;
        return;
    }
    if (f.type == SPVS_SERIAL_T_MATCHES) {
        on_matches(a, &f, now_ms);
    } else if (f.type == SPVS_SERIAL_T_CONFIG) {
        on_config(a, &f);
        /* Answer with the set-up in force, so the host sees it took. */
        send_status(a, SPVS_SERIAL_S_PERIODIC, now_ms);
    } else {
        ++a->st.rejected;
    }
}

void app_init(app_t *a, app_write_fn write, void *write_ctx, uint32_t now_ms)
{
    memset(a, 0, sizeof(*a));
    a->write = write;
    a->write_ctx = write_ctx;
    spvs_serial_rx_init(&a->rx);
    a->watchdog_ms = APP_WATCHDOG_MS;
    a->boot_ms = now_ms;
    a->last_stop_ms = now_ms;
    a->last_status_ms = now_ms;
    /* The robot stands still until the watchdog has a first frame. */
    a->last_valid_ms = now_ms;
    send_status(a, SPVS_SERIAL_S_BOOT, now_ms);
}

void app_on_byte(app_t *a, uint8_t b, uint32_t now_ms)
{
    int r = spvs_serial_rx_push(&a->rx, b);
    if (r == 1) {
        on_frame(a, now_ms);
    } else if (r == SPVS_SERIAL_E_OVERSIZE) {
        ++a->st.framing_errors;
    }
}

void app_on_overrun(app_t *a)
{
    ++a->st.overruns;
    /* A byte of this frame is gone: skip to the next delimiter. */
    a->rx.overflow = 1u;
}

void app_tick(app_t *a, uint32_t now_ms)
{
    uint32_t since = a->has_valid ? now_ms - a->last_valid_ms : now_ms - a->boot_ms;
    if (since >= a->watchdog_ms && now_ms - a->last_stop_ms >= a->watchdog_ms) {
        a->last_stop_ms = now_ms;
        ++a->st.watchdog_stops;
        send_status(a, SPVS_SERIAL_S_WATCHDOG, now_ms);
    }
    if (now_ms - a->last_status_ms >= APP_STATUS_PERIOD_MS) {
        a->last_status_ms = now_ms;
        send_status(a, SPVS_SERIAL_S_PERIODIC, now_ms);
    }
}
