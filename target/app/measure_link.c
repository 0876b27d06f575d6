/*
 * measure_link.c - instructions per frame of the controller application's
 * three stages on the Cortex-M4F, run under QEMU with -icount shift=8 (as
 * spvs_measure.elf; see main_measure.c for how ticks become instructions):
 *   decode: the frame's bytes through the stream splitter, COBS decode and
 *           CRC check (spvs_serial_unpack), and the matches parsed into the
 *           core's structs (spvs_serial_parse_matches);
 *   update: spvs_update() on them;
 *   encode: the RESULT frame encoded (spvs_serial_encode_result).
 * The frames are the recorded closed-loop run of the replay test
 * (tests/golden/replay_frames.h, 125 matches each, Method III, seed 0),
 * encoded here with the same codec as the host agent uses.  Printed: the
 * wire size of a frame and mean and largest count of each stage.
 */
#include <stdint.h>

#include "board.h"
#include "fmt.h"
#include "replay_frames.h"
#include "spvs/spvs.h"
#include "spvs_serial.h"

#ifndef MEASURE_ICOUNT_SHIFT
#define MEASURE_ICOUNT_SHIFT 8
#endif
#define NS_PER_TICK 40u

static spvs_t core;
static spvs_match_t m_in[SPVS_MAX_MATCHES];
static spvs_match_t m_out[SPVS_MAX_MATCHES];
static uint8_t wire[SPVS_SERIAL_MAX_WIRE];
static uint8_t tx[SPVS_SERIAL_WIRE_BYTES(SPVS_SERIAL_RESULT_BODY)];
static spvs_serial_rx_t rx;

static uint32_t to_instructions(uint64_t ticks)
{
    uint64_t ns = ticks * NS_PER_TICK;
    return (uint32_t)((ns + (1u << (MEASURE_ICOUNT_SHIFT - 1))) >> MEASURE_ICOUNT_SHIFT);
}

typedef struct {
    uint64_t sum;
    uint32_t max;
    uint32_t n;
} stat_t;

static void add(stat_t *s, uint32_t v)
{
    s->sum += v;
    s->n++;
    if (v > s->max) {
        s->max = v;
    }
}

static void report(const char *name, const stat_t *s)
{
    out_str(name);
    out_str(": mean=");
    out_u32(s->n ? (uint32_t)(s->sum / s->n) : 0u);
    out_str(" max=");
    out_u32(s->max);
    out_str(" frames=");
    out_u32(s->n);
    out_str("\n");
}

int main(void)
{
    board_ticks_start();
    out_str("spvs " SPVS_TARGET_CPU_NAME " serial link measurement (icount shift ");
    out_int(MEASURE_ICOUNT_SHIFT);
    out_str(")\n");
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    p.seed = 0u;
    if (spvs_init(&core, &p) != SPVS_OK) {
        out_str("FAIL: spvs_init\n");
        return 1;
    }
    stat_t dec = { 0, 0, 0 }, upd = { 0, 0, 0 }, enc = { 0, 0, 0 };
    uint32_t wire_max = 0u, fails = 0u;
    for (uint32_t k = 0; k < SPVS_REPLAY_N_FRAMES; ++k) {
        const spvs_replay_frame_t *fr = &spvs_replay_frames[k];
        uint16_t n = fr->n > SPVS_MAX_MATCHES ? (uint16_t)SPVS_MAX_MATCHES : fr->n;
        for (uint16_t i = 0; i < n; ++i) {
            const spvs_replay_match_t *rm = &spvs_replay_matches[fr->first + i];
            m_in[i].feature = rm->feature;
            m_in[i].x_tgt = spvs_replay_tgt[rm->feature][0];
            m_in[i].y_tgt = spvs_replay_tgt[rm->feature][1];
            m_in[i].x_cur = rm->x_cur;
            m_in[i].y_cur = rm->y_cur;
        }
        spvs_serial_matches_hdr_t h = { 1u, fr->seq, (uint32_t)(fr->t_s * 1000.0f + 0.5f), n };
        int len = spvs_serial_encode_matches(&h, m_in, wire, sizeof(wire));
        if (len <= 0) {
            ++fails;
            continue;
        }
        if ((uint32_t)len > wire_max) {
            wire_max = (uint32_t)len;
        }

        uint64_t t0 = board_ticks();
        int got = 0;
        for (int i = 0; i < len; ++i) {
            if (spvs_serial_rx_push(&rx, wire[i]) == 1) {
                got = 1;
            }
        }
        spvs_serial_frame_t f;
        spvs_serial_matches_hdr_t hd;
        int st = got ? spvs_serial_unpack(rx.buf, rx.n, &f) : SPVS_SERIAL_E_SHORT;
        if (st == SPVS_SERIAL_OK) {
            st = spvs_serial_parse_matches(&f, &hd, m_out, SPVS_MAX_MATCHES);
        }
        uint64_t t1 = board_ticks();
        if (st != SPVS_SERIAL_OK) {
            ++fails;
            continue;
        }
        add(&dec, to_instructions(t1 - t0));

        spvs_serial_result_t r;
        t0 = board_ticks();
        int ust = spvs_update(&core, m_out, hd.count,
                              (spvs_real)spvs_serial_s_from_ms(hd.t_ms), &r.out);
        t1 = board_ticks();
        (void)ust; /* the status is in r.out, sent with the result */
        add(&upd, to_instructions(t1 - t0));

        r.run = hd.run;
        r.seq = hd.seq;
        r.t_ms = hd.t_ms;
        r.flags = 0u;
        t0 = board_ticks();
        int elen = spvs_serial_encode_result(&r, tx, sizeof(tx));
        t1 = board_ticks();
        if (elen <= 0) {
            ++fails;
            continue;
        }
        add(&enc, to_instructions(t1 - t0));
    }
    out_str("matches frame on the wire: largest ");
    out_u32(wire_max);
    out_str(" B; result frame ");
    out_u32(SPVS_SERIAL_WIRE_BYTES(SPVS_SERIAL_RESULT_BODY));
    out_str(" B at most\n");
    report("decode", &dec);
    report("update", &upd);
    report("encode", &enc);
    out_str(fails ? "RESULT: FAIL\n" : "RESULT: PASS\n");
    return fails ? 1 : 0;
}
