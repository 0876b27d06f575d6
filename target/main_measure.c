/*
 * main_measure.c - instruction counts of one spvs_update() on the
 * Cortex-M4F or the Cortex-M3 (soft-float), run under QEMU with -icount
 * shift=MEASURE_ICOUNT_SHIFT.
 *
 * QEMU's -icount mode advances the virtual clock by 2^shift ns per guest
 * instruction; SysTick counts the 25 MHz processor clock of that virtual
 * time (40 ns per tick), so instructions = ticks * 40 / 2^shift.  This is
 * an instruction count, not a cycle count: QEMU models no pipeline, wait
 * states or FPU latencies.  A loop of known length calibrates it first.
 *
 * Frames are synthetic, made here from one fixed seed: the default scene of
 * DESIGN.md section 5 (plane n ~ (0.3, -0.6, -0.75), d = 45 m, start pose
 * (-3, -10, -30 deg)), N matches of which 10 % are off-plane points (15-40 m
 * deep), a fraction of mismatches (random current positions), and 0.5 px
 * Gaussian-like noise (sum of uniforms) on the current image.
 *
 * Per (N, mismatch) case, printed one line each (tools/embedded_measure.sh
 * turns them into the table of docs/EMBEDDED.md):
 *   update_typ: one spvs_update() with default Method III parameters,
 *               after one warm-up frame (the measured one is the second);
 *   est_typ:    spvs_estimate_h() alone on the same frame and PRNG state;
 *   est_cap:    spvs_estimate_h() with a 0.02 px inlier threshold, so no
 *               hypothesis ever explains enough points and RANSAC runs to
 *               its cap, scoring every point of every hypothesis;
 *   update_cap: update_typ + est_cap, an upper bound of an update at the
 *               RANSAC cap (it counts validation and the typical hypotheses
 *               twice);
 *   stack:      deepest stack use of the typical spvs_update(), bytes.
 *
 * Built with MEASURE_FP_HELPERS=1 (spvs_measure_fp.elf, soft-float CPUs
 * only), the typical update also reports, per float helper and libm
 * function it called, the calls and the instructions spent in them
 * (fp_helpers.h), one "fp:" line each and an "fp_total:" line.  The
 * wrappers cost instructions of their own, so that image's update_typ is
 * larger than spvs_measure.elf's; compare the helpers' share with the
 * latter.
 */
#include <math.h>
#include <stdint.h>

#include "board.h"
#include "fmt.h"
#include "spvs/ransac.h"
#include "spvs/spvs.h"

#ifndef MEASURE_FP_HELPERS
#define MEASURE_FP_HELPERS 0
#endif
#if MEASURE_FP_HELPERS
#include "fp_helpers.h"
#endif

#ifndef MEASURE_ICOUNT_SHIFT
#define MEASURE_ICOUNT_SHIFT 8
#endif
#define NS_PER_TICK 40u /* 1e9 / BOARD_CPU_HZ */

static spvs_t core;
static spvs_match_t frame[SPVS_MAX_MATCHES];
static spvs_rng_t gen;

static uint32_t to_instructions(uint64_t ticks)
{
    /* Round to the nearest instruction. */
    uint64_t ns = ticks * NS_PER_TICK;
    return (uint32_t)((ns + (1u << (MEASURE_ICOUNT_SHIFT - 1))) >> MEASURE_ICOUNT_SHIFT);
}

static float uniform(float lo, float hi)
{
    return lo + (hi - lo) * (float)(spvs_rng_next(&gen) >> 8) * (1.0f / 16777216.0f);
}

/* Approximately N(0, sigma): the sum of 12 uniforms minus 6. */
static float gauss(float sigma)
{
    float s = -6.0f;
    for (int i = 0; i < 12; ++i) {
        s += uniform(0.0f, 1.0f);
    }
    return sigma * s;
}

/* Fill frame[0..n) for the default scene; returns the count made. */
/* A frame of n matches, mismatch_pct % of them mismatched and a tenth of
 * the rest off the plane, seen from the robot at (x m, z m, phi_deg), 0.5
 * px of noise in the current image.  Unless in_view, the current image is
 * not clipped (as in the simulator); in_view keeps the points that a
 * 640 x 480 camera sees. */
static uint16_t make_frame_at(uint16_t n, uint32_t mismatch_pct, float x, float z, float phi_deg,
                              int in_view)
{
    const float alpha = 800.0f;
    const float phi = phi_deg * 3.14159265f / 180.0f;
    const float cp = cosf(phi), sp = sinf(phi);
    float nx = 0.3f, ny = -0.6f, nz = -0.75f;
    const float nn = sqrtf(nx * nx + ny * ny + nz * nz);
    nx /= nn;
    ny /= nn;
    nz /= nn;
    const float d = 45.0f;
    uint16_t n_off = (uint16_t)(n / 10u);
    uint16_t n_bad = (uint16_t)((n * mismatch_pct) / 100u);
    uint16_t made = 0;
    /* Bounded: each draw either makes a point or is rejected, and the
     * default scene accepts most draws. */
    for (uint32_t tries = 0; made < n && tries < 100000u; ++tries) {
        float u = uniform(-320.0f, 320.0f), v = uniform(-240.0f, 240.0f);
        float rx = u / alpha, ry = v / alpha;
        float nr = nx * rx + ny * ry + nz;
        if (!(nr < -1e-3f)) {
            continue;
        }
        float depth = -d / nr;
        if (made < n_off) {
            /* An off-plane point in front of the plane. */
            float zo = uniform(15.0f, 40.0f);
            if (!(zo < depth)) {
                continue;
            }
            depth = zo;
        }
        float X = rx * depth, Y = ry * depth, Z = depth;
        /* Current camera: R(phi) (X - c), eq. (3). */
        float Xc = cp * (X - x) + sp * (Z - z);
        float Zc = -sp * (X - x) + cp * (Z - z);
        if (!(Zc > 1.0f)) {
            continue;
        }
        if (in_view && !(fabsf(alpha * Xc / Zc) < 320.0f && fabsf(alpha * Y / Zc) < 240.0f)) {
            continue;
        }
        spvs_match_t *m = &frame[made];
        m->feature = made;
        m->x_tgt = u;
        m->y_tgt = v;
        m->x_cur = alpha * Xc / Zc + gauss(0.5f);
        m->y_cur = alpha * Y / Zc + gauss(0.5f);
        if (made >= n - n_bad) {
            m->x_cur = uniform(-320.0f, 320.0f);
            m->y_cur = uniform(-240.0f, 240.0f);
        }
        ++made;
    }
    return made;
}

/* The nine cases' frame: the homing run's start (-3, -10, -30 deg). */
static uint16_t make_frame(uint16_t n, uint32_t mismatch_pct)
{
    return make_frame_at(n, mismatch_pct, -3.0f, -10.0f, -30.0f, 0);
}

/* Keep the compiler from moving work across the measured region: the
 * pointer is "changed" by an empty asm, so the call must use it after. */
#define BARRIER(p) __asm__ volatile("" : "+r"(p) : : "memory")

static uint32_t measure_update(spvs_t *s, uint16_t n, float t, spvs_output_t *out, int *st)
{
    const spvs_match_t *m = frame;
    BARRIER(m);
    uint64_t t0 = board_ticks();
    BARRIER(m);
    *st = spvs_update(s, m, n, t, out);
    BARRIER(out);
    uint64_t t1 = board_ticks();
    return to_instructions(t1 - t0);
}

static uint32_t measure_estimate(spvs_t *s, uint16_t n, spvs_output_t *out, int *st)
{
    const spvs_match_t *m = frame;
    BARRIER(m);
    uint64_t t0 = board_ticks();
    BARRIER(m);
    *st = spvs_estimate_h(s, m, n, out);
    BARRIER(out);
    uint64_t t1 = board_ticks();
    return to_instructions(t1 - t0);
}

/* Calibration: a loop of exactly 2 instructions per pass (subs, bne). */
static uint32_t calibrate(uint32_t passes)
{
    uint32_t r = passes;
    uint64_t t0 = board_ticks();
    __asm__ volatile("1: subs %0, %0, #1\n\t"
                     "bne 1b"
                     : "+r"(r)
                     :
                     : "cc");
    uint64_t t1 = board_ticks();
    return to_instructions(t1 - t0);
}

static void kv(const char *key, uint32_t value)
{
    out_str(" ");
    out_str(key);
    out_str("=");
    out_u32(value);
}

/* The typical update at N = 256 / 20 % (as the nine cases' one) on frames
 * that a 640 x 480 camera sees from five of the six starts of the paper's
 * Figure 5, SPREAD_SEEDS frames from each: a line per frame, then the
 * median, least and largest, so that one frame's figure is not the only
 * one (docs/EMBEDDED.md).  The sixth start, (5 m, 2 m, -50 deg), sees
 * none of the target's points in such an image.  Returns the number of
 * frames whose update failed. */
#define SPREAD_POSES 5u
#define SPREAD_SEEDS 5u
#define SPREAD_FRAMES (SPREAD_POSES * SPREAD_SEEDS)

static int measure_spread(void)
{
    static const float fig5[SPREAD_POSES][3] = {{-3.0f, -10.0f, -30.0f},
                                                {0.0f, -8.0f, -40.0f},
                                                {6.0f, -6.0f, 0.0f},
                                                {-6.0f, 4.0f, 20.0f},
                                                {6.0f, 8.0f, 10.0f}};
    static uint32_t u[SPREAD_FRAMES];
    uint32_t k = 0;
    int fails = 0;
    for (uint32_t i = 0; i < SPREAD_POSES; ++i) {
        for (uint32_t s = 0; s < SPREAD_SEEDS; ++s) {
            spvs_rng_seed(&gen, 2000u + i * SPREAD_SEEDS + s);
            uint16_t n = make_frame_at(256u, 20u, fig5[i][0], fig5[i][1], fig5[i][2], 1);
            spvs_params_t p;
            spvs_params_default(&p, SPVS_METHOD_III);
            spvs_output_t out;
            int st_w, st_u;
            if (spvs_init(&core, &p) != SPVS_OK) {
                return 1;
            }
            (void)measure_update(&core, n, 0.0f, &out, &st_w);
            u[k] = measure_update(&core, n, 0.1f, &out, &st_u);
            if (st_u < 0) {
                ++fails;
            }
            out_str("spread:");
            kv("pose", i);
            kv("seed", s);
            kv("n", n);
            out_str(" status=");
            out_int(st_u);
            kv("inliers", out.n_inliers);
            kv("iters", out.ransac_iters);
            kv("update_typ", u[k]);
            out_str("\n");
            ++k;
        }
    }
    /* Insertion sort; bound: SPREAD_FRAMES values. */
    for (uint32_t a = 1; a < k; ++a) {
        const uint32_t v = u[a];
        uint32_t b = a;
        for (; b > 0u && u[b - 1u] > v; --b) {
            u[b] = u[b - 1u];
        }
        u[b] = v;
    }
    out_str("spread_summary:");
    kv("frames", k);
    kv("median", u[k / 2u]);
    kv("least", u[0]);
    kv("largest", u[k - 1u]);
    out_str("\n");
    return fails;
}

#if MEASURE_FP_HELPERS
/* The helpers' calls and instructions in the update just measured. */
static void report_fp(uint16_t n, uint32_t mismatch_pct, uint32_t update)
{
    uint32_t calls = 0u, instr = 0u;
    for (uint32_t k = 0; k < fp_helpers_count(); ++k) {
        const fp_helper_stat_t *h = fp_helpers_stat(k);
        if (h->calls == 0u) {
            continue;
        }
        /* fp_helpers.h: the ticks leave out one instruction per call. */
        uint32_t hi = to_instructions(h->ticks) + h->calls;
        out_str("fp:");
        kv("n", n);
        kv("mismatch_pct", mismatch_pct);
        out_str(" name=");
        out_str(h->name);
        kv("calls", h->calls);
        kv("instructions", hi);
        out_str("\n");
        calls += h->calls;
        instr += hi;
    }
    out_str("fp_total:");
    kv("n", n);
    kv("mismatch_pct", mismatch_pct);
    kv("calls", calls);
    kv("instructions", instr);
    kv("update_typ", update);
    out_str("\n");
}
#endif

int main(void)
{
    board_ticks_start();
    out_str("spvs " SPVS_TARGET_CPU_NAME " measurement image (icount shift ");
    out_int(MEASURE_ICOUNT_SHIFT);
    out_str(")\n");
    /* The board-read overhead is measured with an empty region and is
     * reported, not subtracted: it is a few dozen instructions. */
    uint64_t e0 = board_ticks();
    uint64_t e1 = board_ticks();
    out_str("calibration:");
    kv("empty", to_instructions(e1 - e0));
    kv("loop_100000x2", calibrate(100000u));
    kv("loop_1000000x2", calibrate(1000000u));
    out_str("\n");

    static const uint16_t sizes[3] = {64u, 128u, 256u};
    static const uint32_t bad_pct[3] = {0u, 20u, 40u};
    int fails = 0;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            spvs_rng_seed(&gen, 1000u + (uint32_t)(i * 3 + j));
            uint16_t n = make_frame(sizes[i], bad_pct[j]);
            spvs_params_t p;
            spvs_params_default(&p, SPVS_METHOD_III);
            spvs_output_t out;
            int st_w, st_u, st_e, st_c;

            /* Typical update: warm up on the frame, measure the next one. */
            if (spvs_init(&core, &p) != SPVS_OK) {
                return 1;
            }
            (void)measure_update(&core, n, 0.0f, &out, &st_w);
#if MEASURE_FP_HELPERS
            fp_helpers_start();
#endif
            uintptr_t sp0 = board_stack_paint();
            uint32_t u_typ = measure_update(&core, n, 0.1f, &out, &st_u);
            uint32_t stack = board_stack_used_since(sp0);
#if MEASURE_FP_HELPERS
            fp_helpers_stop();
            report_fp(n, bad_pct[j], u_typ);
#endif
            uint32_t it_u = out.ransac_iters, inl = out.n_inliers;

            /* The estimation stage alone, same state as the measured update. */
            if (spvs_init(&core, &p) != SPVS_OK) {
                return 1;
            }
            (void)measure_update(&core, n, 0.0f, &out, &st_w);
            uint32_t e_typ = measure_estimate(&core, n, &out, &st_e);
            uint32_t it_e = out.ransac_iters;

            /* RANSAC at its cap. */
            p.noise_px = 0.0066f; /* a Sampson threshold of 0.02 px */
            p.offplane_px = 6.0f;
            if (spvs_init(&core, &p) != SPVS_OK) {
                return 1;
            }
            uint32_t e_cap = measure_estimate(&core, n, &out, &st_c);
            uint32_t it_c = out.ransac_iters;
            if (it_c != p.max_iters) {
                ++fails; /* the cap case did not reach the cap */
            }

            out_str("case:");
            kv("n", n);
            kv("mismatch_pct", bad_pct[j]);
            out_str(" status=");
            out_int(st_u);
            kv("inliers", inl);
            kv("iters", it_u);
            kv("update_typ", u_typ);
            kv("est_typ", e_typ);
            kv("est_iters", it_e);
            kv("est_cap", e_cap);
            kv("cap_iters", it_c);
            kv("update_cap", u_typ + e_cap);
            kv("stack", stack);
            out_str("\n");
        }
    }
    fails += measure_spread();
    out_str("sizeof(spvs_t)=");
    out_u32((uint32_t)sizeof(spvs_t));
    out_str("\n");
    return fails;
}
