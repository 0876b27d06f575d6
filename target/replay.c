/*
 * replay.c - replay a recorded closed-loop run (tests/golden/replay_frames.h,
 * made by tools/rec2c.py from a spvs-sim recording of the host float32
 * build) through spvs_init/spvs_update with the same parameters
 * (spvs_params_default(&p, SPVS_METHOD_III), seed 0), and compare every
 * command with the host's:
 *   |v - v_host| <= 1e-4 |v_host| + 1e-6 m/s, the same for w in rad/s,
 *   status and step exactly.
 * The tolerance allows the last-bit differences of the two libms (sqrtf,
 * logf) and compilers; any change of a decision (an inlier set, a step
 * switch, a gain sign) shows as a status, step or command far outside it.
 */
#include "checks.h"

#include "fmt.h"
#include "spvs/spvs.h"

/* From SPVS_REPLAY_DIR (target/CMakeLists.txt): tests/golden/ by default. */
#include "replay_frames.h"
#include "replay_load.h"

#define REPLAY_REL_TOL 1e-4f
#define REPLAY_ABS_TOL 1e-6f

/* The instance lives in .bss, as on a robot (it is several KiB). */
static spvs_t replay_core;
static spvs_match_t replay_m[SPVS_MAX_MATCHES];

static int close_enough(float got, float want)
{
    float d = got - want;
    if (d < 0.0f) {
        d = -d;
    }
    float a = want < 0.0f ? -want : want;
    return d <= REPLAY_REL_TOL * a + REPLAY_ABS_TOL;
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
    float worst_v = 0.0f, worst_w = 0.0f;
    uint8_t last_step = 0u;
    uint32_t switches = 0u;
    for (uint32_t f = 0; f < SPVS_REPLAY_N_FRAMES; ++f) {
        const spvs_replay_frame_t *fr = &spvs_replay_frames[f];
        replay_load(fr, replay_m);
        spvs_output_t out;
        int st = spvs_update(&replay_core, replay_m, fr->n, fr->t_s, &out);
        float dv = out.v - fr->v, dw = out.w - fr->w;
        dv = dv < 0.0f ? -dv : dv;
        dw = dw < 0.0f ? -dw : dw;
        if (!(dv <= worst_v)) {
            worst_v = dv;
        }
        if (!(dw <= worst_w)) {
            worst_w = dw;
        }
        int ok = st == fr->status && out.status == fr->status && out.step == fr->step &&
                 close_enough(out.v, fr->v) && close_enough(out.w, fr->w);
        if (!ok) {
            if (fails < 10) {
                replay_fail_head(fr, st, out.step);
                out_str(", v ");
                out_sci(out.v);
                out_str(" (host ");
                out_sci(fr->v);
                out_str("), w ");
                out_sci(out.w);
                out_str(" (host ");
                out_sci(fr->w);
                out_str(")\n");
            }
            ++fails;
        }
        if (out.step != last_step) {
            ++switches;
            last_step = out.step;
        }
    }
    out_str("replay: ");
    out_u32(SPVS_REPLAY_N_FRAMES);
    out_str(" frames, ");
    out_int(fails);
    out_str(" mismatched, ");
    out_u32(switches);
    out_str(" step changes, final step ");
    out_u32(last_step);
    out_str(", worst |dv| ");
    out_sci(worst_v);
    out_str(" m/s, worst |dw| ");
    out_sci(worst_w);
    out_str(" rad/s\n");
    return fails;
}
