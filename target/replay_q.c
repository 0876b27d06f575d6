/*
 * replay_q.c - replay a recorded closed-loop run of the host's fixed-point
 * core (replay_frames.h from SPVS_REPLAY_DIR: tools/make_replay.sh --fixed,
 * tests/golden/fixed/ by default) through spvs_init/spvs_update of the
 * fixed-point build with the same parameters (spvs_params_default(&p,
 * SPVS_METHOD_III), seed 0), and compare every answer with the host's BIT
 * FOR BIT: the fixed-point core computes in integers only, so the Cortex-M3
 * and the host must give the same command bits, status and step.  The
 * comparison reads the floats' bits; no float operation is made.
 */
#include <string.h>

#include "checks.h"

#include "fmt.h"
#include "spvs/spvs.h"

#include "replay_frames.h"
#include "replay_load.h"

static spvs_t replay_core;
static spvs_match_t replay_m[SPVS_MAX_MATCHES];

static uint32_t bits(float x)
{
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

static void out_hex(uint32_t v)
{
    static const char digits[] = "0123456789abcdef";
    char b[11] = "0x";
    for (int i = 0; i < 8; i++) {
        b[2 + i] = digits[(v >> (28 - 4 * i)) & 15u];
    }
    b[10] = '\0';
    out_str(b);
}

int replay_run(void)
{
    spvs_params_t p;
    spvs_params_default(&p, SPVS_METHOD_III);
    p.seed = 0u;
    if (spvs_init(&replay_core, &p) != SPVS_OK) {
        out_str("FAIL replay: spvs_init\n");
        return 1;
    }
    int fails = 0;
    uint8_t last_step = 0u;
    uint32_t switches = 0u, moving = 0u;
    for (uint32_t f = 0; f < SPVS_REPLAY_N_FRAMES; ++f) {
        const spvs_replay_frame_t *fr = &spvs_replay_frames[f];
        replay_load(fr, replay_m);
        spvs_output_t out;
        const int st = spvs_update(&replay_core, replay_m, fr->n, fr->t_s, &out);
        const int ok = st == fr->status && out.status == fr->status && out.step == fr->step &&
                       bits(out.v) == bits(fr->v) && bits(out.w) == bits(fr->w);
        if (!ok) {
            if (fails < 10) {
                replay_fail_head(fr, st, out.step);
                out_str(", v bits ");
                out_hex(bits(out.v));
                out_str(" (host ");
                out_hex(bits(fr->v));
                out_str("), w bits ");
                out_hex(bits(out.w));
                out_str(" (host ");
                out_hex(bits(fr->w));
                out_str(")\n");
            }
            ++fails;
        }
        moving += (bits(out.v) << 1) != 0u || (bits(out.w) << 1) != 0u;
        if (out.step != last_step) {
            ++switches;
            last_step = out.step;
        }
    }
    out_str("replay (fixed point): ");
    out_u32(SPVS_REPLAY_N_FRAMES);
    out_str(" frames, ");
    out_int(fails);
    out_str(" not bit for bit the host's, ");
    out_u32(moving);
    out_str(" moving commands, ");
    out_u32(switches);
    out_str(" step changes, final step ");
    out_u32(last_step);
    out_str("\n");
    return fails;
}
