/*
 * fuzz_core.c - libFuzzer target for the core's update pipeline, written
 * once for both cores: built as fuzz_core it drives the float core
 * (spvs.h: spvs_update, spvs_estimate_h); built with FUZZ_CORE_FIXED=1 as
 * fuzz_core_fixed it drives the fixed-point core (firmware/src/fixed,
 * spvs_q.h: spvs_q_update, spvs_q_estimate_h) through the same decoding of
 * the same bytes.
 *
 * Each input drives one fresh controller instance through up to MAX_FRAMES
 * frames, so that the step logic, the off-plane memory and the time checks
 * see sequences, not just single frames.  The bytes choose, per frame:
 *   - how the matches are made: raw float bit patterns (NaN, infinities,
 *     denormals, huge values), a consistent scene seen from a pose that
 *     follows the controller's own commands (eq. 7), all points coincident,
 *     all points on one line, or every match a mismatch;
 *   - per-match damage to the consistent scene: NaN, +-Inf, huge, just out
 *     of range, a duplicate of the previous match, a swapped (mismatched)
 *     current point, a feature index out of range;
 *   - the count, from 0 to past SPVS_MAX_MATCHES;
 *   - the frame time: one period on, repeated, backwards, NaN, infinite, a
 *     gap longer than max_frame_gap_s, 40 s on (step timeouts), raw bits;
 *   - the plane, from a wall to a floor, and the start pose, which may be
 *     the target itself;
 *   - the estimation stage alone (spvs_estimate_h) instead of the update.
 *
 * Invariants checked after every call (a violation aborts, which libFuzzer
 * reports as a crash):
 *   - the returned status equals out.status and is one of spvs_status_t;
 *   - every error comes with v = w = 0 exactly, and so do steps DONE and
 *     FAILED;
 *   - v and w are finite and within v_max, w_max;
 *   - step is in 1..5; n_inliers <= n_matches.
 *
 * fuzz_core_fixed also runs the float core on the same frames and checks
 * that both report the same input errors (diff_check below).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "spvs/common.h"
#include "spvs/spvs.h"
#include "fuzz_reader.h"

#ifndef FUZZ_CORE_FIXED
#define FUZZ_CORE_FIXED 0
#endif

/* The core under test, chosen at compile time. */
#if FUZZ_CORE_FIXED
#include "spvs_q.h"
#define TARGET_NAME "fuzz_core_fixed"
typedef spvs_q_t core_t;
#define core_init spvs_q_init
#define core_update spvs_q_update
#define core_estimate_h spvs_q_estimate_h
#else
#define TARGET_NAME "fuzz_core"
typedef spvs_t core_t;
#define core_init spvs_init
#define core_update spvs_update
#define core_estimate_h spvs_estimate_h
#endif

#define MAX_FRAMES 16
/* Counts past the capacity exercise SPVS_E_CAPACITY. */
#define MAX_N (SPVS_MAX_MATCHES + 8)
#define N_PLANE_PTS 90
#define N_OFF_PTS 30
#define FOCAL_PX 800.0

static void fail(const char *what, int status, double v, double w, int step)
{
    fprintf(stderr, TARGET_NAME ": invariant broken: %s (status %d %s, v %g, "
                    "w %g, step %d)\n",
            what, status, spvs_status_str(status), v, w, step);
    abort();
}

#ifdef FUZZ_CORE_STATS
/* Built into replay_stats only: what a corpus reaches (statuses, steps). */
unsigned long fuzz_core_status_seen[SPVS_STATUS_COUNT];
unsigned long fuzz_core_step_seen[8];
#endif

static void check_output(int rc, const spvs_output_t *out,
                         const spvs_params_t *p, uint16_t n, int estimate_only)
{
    const double v = (double)out->v, w = (double)out->w;
    const int step = out->step;
    if (rc != out->status) {
        fail("return value differs from out.status", rc, v, w, step);
    }
    if (rc > 0 || rc <= -SPVS_STATUS_COUNT) {
        fail("status outside spvs_status_t", rc, v, w, step);
    }
    if (rc == SPVS_E_ARG || rc == SPVS_E_CONFIG) {
        fail("valid pointers and parameters reported as bad", rc, v, w, step);
    }
    if (!isfinite(v) || !isfinite(w)) {
        fail("non-finite command", rc, v, w, step);
    }
    if ((rc != SPVS_OK || estimate_only) && (v != 0.0 || w != 0.0)) {
        fail("an error or an estimate-only call commands motion", rc, v, w,
             step);
    }
    if (fabs(v) > (double)p->ctl.v_max * (1.0 + 1e-6) ||
        fabs(w) > (double)p->ctl.w_max * (1.0 + 1e-6)) {
        fail("command past the saturation limits", rc, v, w, step);
    }
    if (!estimate_only) {
        if (step < SPVS_STEP_ROTATE || step > SPVS_STEP_FAILED) {
            fail("step outside 1..5", rc, v, w, step);
        }
        if ((step == SPVS_STEP_DONE || step == SPVS_STEP_FAILED) &&
            (v != 0.0 || w != 0.0)) {
            fail("DONE or FAILED commands motion", rc, v, w, step);
        }
    }
    if (out->n_matches != n || out->n_inliers > out->n_matches) {
        fail("match counts inconsistent", rc, v, w, step);
    }
#ifdef FUZZ_CORE_STATS
    fuzz_core_status_seen[-rc]++;
    if (!estimate_only) {
        fuzz_core_step_seen[step]++;
    }
#endif
}

/* The world of the consistent scene: plane points on n^T X = -d and
 * off-plane points between the camera and the plane, both fixed by the
 * input's first bytes; the robot pose follows the commands (eq. 7). */
typedef struct {
    double X[N_PLANE_PTS + N_OFF_PTS][3];
    double x_m, z_m, phi_rad;
} world_t;

static void world_make(world_t *wd, reader_t *r)
{
    /* Any plane facing the target camera, from a wall (n_y = 0) to a floor
     * (n_z = 0), so that the plane checks of the methods are reached. */
    double n[3] = {rd_range(r, -0.6, 0.6), rd_range(r, -1.0, 1.0),
                   -rd_range(r, 0.0, 1.0)};
    double norm = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(norm > 1e-3)) {
        n[2] = -1.0;
        norm = 1.0;
    }
    for (int k = 0; k < 3; k++) {
        n[k] /= norm;
    }
    const double d_m = rd_range(r, 2.0, 60.0);
    uint32_t h = rd_u32(r) | 1u;
    for (int i = 0; i < N_PLANE_PTS + N_OFF_PTS; i++) {
        /* xorshift32 picks a target pixel; the ray through it meets the
         * plane (plane points) or stops short of it (off-plane points). */
        h ^= h << 13;
        h ^= h >> 17;
        h ^= h << 5;
        double u = (double)(h % 600u) - 300.0;
        double v = (double)((h >> 10) % 440u) - 220.0;
        double ray[3] = {u / FOCAL_PX, v / FOCAL_PX, 1.0};
        double nr = n[0] * ray[0] + n[1] * ray[1] + n[2] * ray[2];
        double lambda = nr < -1e-3 ? -d_m / nr : d_m;
        if (i >= N_PLANE_PTS) {
            lambda *= 0.35 + 0.5 * (double)((h >> 20) % 100u) / 100.0;
        }
        for (int k = 0; k < 3; k++) {
            wd->X[i][k] = lambda * ray[k];
        }
    }
    /* Byte 128, 0, 128 is exactly the target pose (0, 0, 0). */
    wd->x_m = ((double)rd_u8(r) - 128.0) / 32.0;
    wd->z_m = -(double)rd_u8(r) / 21.0;
    wd->phi_rad = ((double)rd_u8(r) - 128.0) / 100.0;
}

/* Image of world point i in the current camera (R of eq. 3), pixels centred
 * on the principal point.  Returns 0 when the point is behind the camera. */
static int world_project(const world_t *wd, int i, double *x, double *y)
{
    const double c = cos(wd->phi_rad), s = sin(wd->phi_rad);
    const double dx = wd->X[i][0] - wd->x_m, dz = wd->X[i][2] - wd->z_m;
    const double Xc = c * dx + s * dz;
    const double Zc = -s * dx + c * dz;
    if (!(Zc > 0.1)) {
        return 0;
    }
    *x = FOCAL_PX * Xc / Zc;
    *y = FOCAL_PX * wd->X[i][1] / Zc;
    return 1;
}

static uint16_t make_scene(reader_t *r, const world_t *wd, spvs_match_t *m,
                           uint16_t n_want)
{
    uint16_t n = 0;
    const int n_pts = N_PLANE_PTS + N_OFF_PTS;
    for (int i = 0; i < n_pts && n < n_want; i++) {
        double xc, yc;
        if (!world_project(wd, i, &xc, &yc)) {
            continue;
        }
        spvs_match_t *q = &m[n];
        q->x_tgt = (spvs_real)(FOCAL_PX * wd->X[i][0] / wd->X[i][2]);
        q->y_tgt = (spvs_real)(FOCAL_PX * wd->X[i][1] / wd->X[i][2]);
        q->x_cur = (spvs_real)xc;
        q->y_cur = (spvs_real)yc;
        q->feature = (uint16_t)i;
        n++;
    }
    /* Damage: one code byte per match, most of them harmless. */
    const spvs_real zero = (spvs_real)(r->at > r->n ? 1 : 0) * SPVS_R(0.0);
    for (uint16_t i = 0; i < n; i++) {
        uint8_t code = rd_u8(r);
        spvs_match_t *q = &m[i];
        switch (code) {
        case 1: q->x_cur = zero / zero; break;
        case 2: q->y_tgt = SPVS_R(1.0) / zero; break;
        case 3: q->x_tgt = -SPVS_R(1.0) / zero; break;
        case 4: q->y_cur = SPVS_REAL_MAX; break;
        case 5: q->x_cur = (spvs_real)(SPVS_MAX_COORD_PX + 1); break;
        case 6: if (i > 0) { m[i] = m[i - 1]; } break;
        case 7: if (i > 0) {
                spvs_real t = q->x_cur;
                q->x_cur = m[i - 1].x_cur;
                m[i - 1].x_cur = t;
            } break;
        case 8: q->feature = (uint16_t)(SPVS_MAX_FEATURES + rd_u8(r)); break;
        case 9: q->x_cur = (spvs_real)rd_range(r, -320.0, 320.0);
                q->y_cur = (spvs_real)rd_range(r, -240.0, 240.0); break;
        case 10: q->y_tgt = SPVS_R(0.0); q->y_cur = SPVS_R(0.0); break;
        default: break;
        }
    }
    return n;
}

static uint16_t make_raw(reader_t *r, spvs_match_t *m, uint16_t n)
{
    for (uint16_t i = 0; i < n; i++) {
        m[i].x_tgt = (spvs_real)rd_float_bits(r);
        m[i].y_tgt = (spvs_real)rd_float_bits(r);
        m[i].x_cur = (spvs_real)rd_float_bits(r);
        m[i].y_cur = (spvs_real)rd_float_bits(r);
        m[i].feature = rd_u16(r);
    }
    return n;
}

/* Degenerate layouts: every point the same, or every point on one line
 * (in both images), optionally with a few exact duplicates. */
static uint16_t make_degenerate(reader_t *r, spvs_match_t *m, uint16_t n,
                                int collinear)
{
    const double a = rd_range(r, -300.0, 300.0), b = rd_range(r, -200.0, 200.0);
    const double ka = rd_range(r, -2.0, 2.0), kb = rd_range(r, -2.0, 2.0);
    const double shift = rd_range(r, -50.0, 50.0);
    for (uint16_t i = 0; i < n; i++) {
        double s = collinear ? (double)i - 0.5 * (double)n : 0.0;
        m[i].x_tgt = (spvs_real)(a + s);
        m[i].y_tgt = (spvs_real)(b + ka * s);
        m[i].x_cur = (spvs_real)(a + shift + 1.1 * s);
        m[i].y_cur = (spvs_real)(b + kb * s);
        m[i].feature = (uint16_t)(i % SPVS_MAX_FEATURES);
    }
    return n;
}

/* Every current point unrelated to its target point. */
static uint16_t make_mismatches(reader_t *r, spvs_match_t *m, uint16_t n)
{
    uint32_t h = rd_u32(r) | 1u;
    for (uint16_t i = 0; i < n; i++) {
        double v[4];
        for (int k = 0; k < 4; k++) {
            h ^= h << 13;
            h ^= h >> 17;
            h ^= h << 5;
            v[k] = (double)(h % 640u) - 320.0;
        }
        m[i].x_tgt = (spvs_real)v[0];
        m[i].y_tgt = (spvs_real)(0.75 * v[1]);
        m[i].x_cur = (spvs_real)v[2];
        m[i].y_cur = (spvs_real)(0.75 * v[3]);
        m[i].feature = (uint16_t)i;
    }
    return n;
}

static double next_time(reader_t *r, double t_s, double *dt_s)
{
    const double zero = (double)(r->at > r->n ? 1 : 0) * 0.0;
    uint8_t code = rd_u8(r);
    switch (code % 13u) {
    case 0: return t_s;                      /* repeated: stale            */
    case 1: return t_s - 0.1;                /* backwards                  */
    case 2: return zero / zero;              /* NaN                        */
    case 3: return 1.0 / zero;               /* +Inf                       */
    case 4: return t_s + 5.0;                /* gap past max_frame_gap_s   */
    case 5: return (double)rd_float_bits(r); /* anything                   */
    case 6: *dt_s = rd_range(r, 0.01, 0.5); return t_s + *dt_s;
    case 7: return t_s + 40.0;               /* towards the step timeout   */
    default: *dt_s = 0.1; return t_s + 0.1;  /* one control period         */
    }
}

#if FUZZ_CORE_FIXED
/* The differential check: the float core (the reference) sees the same
 * frames, and both must report the same input error for the same frame.
 * By spvs_q.h and docs/FIXED.md the fixed-point core has spvs_update's
 * contract and statuses, its loader makes the float loader's checks, and
 * it differs only in the time's Q16 range: |t_s| >= 32768 s is
 * SPVS_E_RANGE, and two times that are one in Q16 make the second
 * SPVS_E_STALE.  Everything after the checks (H, the memory, the command)
 * may part by the rounding of the two arithmetics, so only the checks are
 * compared.  They depend on the frame and on the last accepted time (an
 * estimate-only call has no time), which the driver follows here; where the documented Q16 rules make the two
 * cores accept different times, the histories part and the comparison ends
 * for the rest of the input.
 *
 * A frame with both a non-finite value and an out-of-range one gets the
 * status of its first bad value in match order from both cores. */

#ifdef FUZZ_CORE_STATS
/* Frames the check compared, and inputs where the cores' times parted. */
unsigned long fuzz_core_diff_compared;
unsigned long fuzz_core_diff_parted;
#endif

typedef struct {
    spvs_t ref;
    int in_step;    /* both cores have accepted the same frame times     */
    int has_last;
    spvs_real last_t;
} diff_t;

static void diff_fail(const char *what, int frame, int rc_q, int rc_f)
{
    fprintf(stderr, TARGET_NAME ": the cores disagree: %s (frame %d: fixed %d %s, float %d %s)\n",
            what, frame, rc_q, spvs_status_str(rc_q), rc_f, spvs_status_str(rc_f));
    abort();
}

/* The cores have accepted different frame times: no more comparing. */
static void diff_part(diff_t *d)
{
    d->in_step = 0;
#ifdef FUZZ_CORE_STATS
    fuzz_core_diff_parted++;
#endif
}

/* t in Q16 as spvs_q_from_ieee rounds it: to nearest, ties away from zero
 * (exact in double for |t| < 32768). */
static double q16(spvs_real t)
{
    return round((double)t * 65536.0);
}

static int is_load_error(int rc)
{
    return rc == SPVS_E_NONFINITE || rc == SPVS_E_RANGE;
}

static int is_input_error(int rc)
{
    return rc == SPVS_E_ARG || rc == SPVS_E_CAPACITY || rc == SPVS_E_NONFINITE ||
           rc == SPVS_E_RANGE || rc == SPVS_E_STALE;
}

/* The time's checks: 1 when both cores took t, and the frame's own checks
 * follow; 0 when the verdict was compared here (or the histories parted). */
static int diff_time(diff_t *d, int frame, spvs_real t, int rc_q, int rc_f)
{
    if (!isfinite(t)) {
        if (rc_q != SPVS_E_NONFINITE || rc_f != SPVS_E_NONFINITE) {
            diff_fail("a non-finite time", frame, rc_q, rc_f);
        }
        return 0;
    }
    const int float_takes = !d->has_last || t > d->last_t;
    if (fabs((double)t) >= 32768.0) {
        if (rc_q != SPVS_E_RANGE) {
            diff_fail("a time outside Q16 seconds is not out_of_range_input", frame, rc_q, rc_f);
        }
        if (float_takes) {
            diff_part(d);
        } else if (rc_f != SPVS_E_STALE) {
            diff_fail("a time not after the last is not stale (float)", frame, rc_q, rc_f);
        }
        return 0;
    }
    if (!float_takes) {
        if (rc_q != SPVS_E_STALE || rc_f != SPVS_E_STALE) {
            diff_fail("a time not after the last", frame, rc_q, rc_f);
        }
        return 0;
    }
    if (d->has_last && !(q16(t) > q16(d->last_t))) {
        if (rc_q != SPVS_E_STALE) {
            diff_fail("a time one with the last in Q16 is not stale", frame, rc_q, rc_f);
        }
        diff_part(d);
        return 0;
    }
    d->has_last = 1;
    d->last_t = t;
    return 1;
}

static void diff_check(diff_t *d, int frame, const spvs_match_t *m, uint16_t n, spvs_real t,
                       int estimate_only, int rc_q, int rc_f)
{
    if (!d->in_step) {
        return;
    }
#ifdef FUZZ_CORE_STATS
    fuzz_core_diff_compared++;
#endif
    if (!estimate_only && !diff_time(d, frame, t, rc_q, rc_f)) {
        return;
    }
    if (n > SPVS_MAX_MATCHES) {
        if (rc_q != SPVS_E_CAPACITY || rc_f != SPVS_E_CAPACITY) {
            diff_fail("more matches than SPVS_MAX_MATCHES", frame, rc_q, rc_f);
        }
        return;
    }
    if (n < 3u) {
        if (rc_q != SPVS_E_TOO_FEW || rc_f != SPVS_E_TOO_FEW) {
            diff_fail("fewer than 3 matches", frame, rc_q, rc_f);
        }
        return;
    }
    /* The loader's checks (spvs.h, docs/FIXED.md): a NaN or infinite
     * coordinate, one beyond SPVS_MAX_COORD_PX, a feature index out of
     * range. */
    int nonfinite = 0, range = 0;
    for (uint16_t i = 0; i < n; i++) {
        const spvs_real c[4] = {m[i].x_tgt, m[i].y_tgt, m[i].x_cur, m[i].y_cur};
        for (int k = 0; k < 4; k++) {
            if (!isfinite(c[k])) {
                nonfinite = 1;
            } else if (fabs((double)c[k]) > (double)SPVS_MAX_COORD_PX) {
                range = 1;
            }
        }
        range |= m[i].feature >= SPVS_MAX_FEATURES;
    }
    if (nonfinite || range) {
        if (!is_load_error(rc_q) || !is_load_error(rc_f)) {
            diff_fail("a bad value in the frame is not a load error", frame, rc_q, rc_f);
        }
        if (rc_q != rc_f) {
            diff_fail("a bad value in the frame", frame, rc_q, rc_f);
        }
        return;
    }
    if (is_input_error(rc_q) || is_input_error(rc_f)) {
        diff_fail("an input error on a valid frame", frame, rc_q, rc_f);
    }
}
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* Big: static, as on the robot. */
    static core_t s;
    static spvs_match_t m[MAX_N];
    static world_t wd;
    reader_t r = {data, size, 0};

    const uint8_t head = rd_u8(&r);
    spvs_params_t p;
    spvs_params_default(&p, (spvs_method_t)(1 + head % 3u));
    p.seed = rd_u8(&r);
    if (core_init(&s, &p) != SPVS_OK) {
        fail("default parameters rejected", SPVS_E_CONFIG, 0.0, 0.0, 0);
    }
#if FUZZ_CORE_FIXED
    static diff_t d;
    if (spvs_init(&d.ref, &p) != SPVS_OK) {
        fail("default parameters rejected (float)", SPVS_E_CONFIG, 0.0, 0.0, 0);
    }
    d.in_step = 1;
    d.has_last = 0;
    d.last_t = SPVS_R(0.0);
#endif
    world_make(&wd, &r);

    const int frames = 1 + (int)(rd_u8(&r) % MAX_FRAMES);
    double t_s = 0.0;
    for (int f = 0; f < frames && r.at < r.n; f++) {
        const uint8_t mode = rd_u8(&r);
        double dt_s = 0.1;
        t_s = next_time(&r, t_s, &dt_s);
        uint16_t n;
        switch (mode % 8u) {
        case 0:
            n = (uint16_t)(rd_u16(&r) % (MAX_N + 1));
            n = make_raw(&r, m, n);
            break;
        case 1: n = make_degenerate(&r, m, (uint16_t)(rd_u8(&r) % 40u), 0); break;
        case 2: n = make_degenerate(&r, m, (uint16_t)(rd_u16(&r) % (MAX_N + 1)), 1); break;
        case 3: n = make_mismatches(&r, m, (uint16_t)(rd_u16(&r) % (MAX_N + 1))); break;
        default:
            n = make_scene(&r, &wd, m, (uint16_t)(rd_u8(&r) % (N_PLANE_PTS + N_OFF_PTS + 1)));
            break;
        }
        spvs_output_t out;
        const spvs_real t = (spvs_real)t_s;
        const int estimate_only = (mode & 0x80u) && (mode % 8u) < 4u;
        const int rc = estimate_only ? core_estimate_h(&s, m, n, &out)
                                     : core_update(&s, m, n, t, &out);
#if FUZZ_CORE_FIXED
        spvs_output_t out_f;
        const int rc_f = estimate_only ? spvs_estimate_h(&d.ref, m, n, &out_f)
                                       : spvs_update(&d.ref, m, n, t, &out_f);
        diff_check(&d, f, m, n, t, estimate_only, rc, rc_f);
#endif
        check_output(rc, &out, &p, n, estimate_only);

        /* The robot moves on the command for one period (eq. 7), so that the
         * next consistent frame sees the result of this one. */
        if (isfinite(dt_s) && dt_s > 0.0) {
            const double v = (double)out.v, w = (double)out.w;
            wd.x_m += -v * sin(wd.phi_rad) * dt_s;
            wd.z_m += v * cos(wd.phi_rad) * dt_s;
            wd.phi_rad += w * dt_s;
        }
    }
    return 0;
}
