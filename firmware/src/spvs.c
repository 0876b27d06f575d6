/*
 * spvs.c - the update pipeline: validate, estimate H, find the epipole and
 * the parallax, remember off-plane features, run the controller.
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "spvs/spvs.h"
#include "core_util.h"

#if SPVS_SIMD_COLUMNS
/* load_frame reads a match's four coordinates as one vector. */
_Static_assert(offsetof(spvs_match_t, x_tgt) == 0 &&
                   offsetof(spvs_match_t, y_cur) == 3 * sizeof(spvs_real),
               "the coordinates of a match are contiguous");
#endif

/* Off-plane memory: a feature counts as off the plane at this score. */
#define OFFPLANE_ON 2
#define OFFPLANE_MAX 3
#define OFFPLANE_MIN (-3)
/* Fewest plane inliers that make a consensus. */
#define MIN_INLIERS 8u

void spvs_params_default(spvs_params_t *p, spvs_method_t method)
{
    SPVS_ASSERT(p != 0);
    spvs_control_params_default(&p->ctl, method);
    p->inlier_px = SPVS_R(3.0);
    p->confidence = SPVS_R(0.99);
    p->max_iters = SPVS_RANSAC_MAX_ITERS;
    p->offplane_px = SPVS_R(8.0);
    p->epipole_sin_tol = SPVS_R(0.1);
    p->min_support = 3;
    p->max_frame_gap_s = SPVS_R(1.0);
    p->seed = 0;
}

/* Gauss-Newton steps of the final refit, which starts from the linear fit
 * on the same inliers (the re-selection below).  One step is enough: a
 * second changes the benchmark's median corner errors by less than 0.1 %,
 * and over 900 noisy closed-loop runs per method (the six Figure 5 poses,
 * 1 px, 150 seeds) Methods I, II and III converge in 834, 661 and 801 runs
 * with one step and 815, 654 and 803 with two.  The step is kept only if it
 * lowers the transfer error. */
#define FINAL_GN_STEPS 1u

static int params_check(const spvs_params_t *p)
{
    int rc = spvs_control_params_check(&p->ctl);
    if (rc != SPVS_OK) {
        return rc;
    }
    if (!(p->inlier_px > SPVS_R(0.0) && p->inlier_px < SPVS_R(1000.0)) ||
        !(p->confidence > SPVS_R(0.0) && p->confidence < SPVS_R(1.0)) ||
        p->max_iters < 1u || p->max_iters > SPVS_RANSAC_MAX_ITERS ||
        !(p->offplane_px >= p->inlier_px) ||
        !(p->epipole_sin_tol > SPVS_R(0.0) && p->epipole_sin_tol < SPVS_R(1.0)) ||
        p->min_support < 1u ||
        !(p->max_frame_gap_s > SPVS_R(0.0))) {
        return SPVS_E_CONFIG;
    }
    return SPVS_OK;
}

int spvs_init(spvs_t *s, const spvs_params_t *p)
{
    if (s == 0 || p == 0) {
        return SPVS_E_ARG;
    }
    int rc = params_check(p);
    if (rc != SPVS_OK) {
        return rc;
    }
    s->p = *p;
    spvs_reset(s);
    return SPVS_OK;
}

void spvs_reset(spvs_t *s)
{
    SPVS_ASSERT(s != 0);
    spvs_control_reset(&s->ctl);
    spvs_rng_seed(&s->rng, s->p.seed);
    s->last_t_s = SPVS_R(0.0);
    s->last_good_t_s = SPVS_R(0.0);
    s->has_last = 0;
    s->has_good = 0;
    s->n_plane = 0;
    s->n_pts = 0;
    s->n_ehist = 0;
    s->i_ehist = 0;
    for (uint32_t i = 0; i < SPVS_MAX_FEATURES; i++) {
        s->offplane[i] = 0;
    }
    s->n_offplane_known = 0;
}

/* ---- the planar-motion estimator for RANSAC ----------------------------- */

/* Coordinate k of point i, in whichever layout the build keeps. */
#if SPVS_SIMD_COLUMNS
#define PT(s, i, k) ((s)->col[k][i])
#else
#define PT(s, i, k) ((s)->pts[i][k])
#endif

/* Point i as a row (x_tgt, y_tgt, x_cur, y_cur): the stored row, or where
 * the points are in columns, a copy made in buf. */
static SPVS_ALWAYS_INLINE const spvs_real *point_row(const spvs_t *s, uint16_t i,
                                                     spvs_real buf[4])
{
#if SPVS_SIMD_COLUMNS
    for (int k = 0; k < 4; k++) {
        buf[k] = PT(s, i, k);
    }
    return buf;
#else
    (void)buf;
    return s->pts[i];
#endif
}

static int est_fit(void *ctx, const uint16_t *sample, spvs_real *model)
{
    const spvs_t *s = (const spvs_t *)ctx;
#if SPVS_SIMD_COLUMNS
    const spvs_real *const cols[4] = {s->col[0], s->col[1], s->col[2], s->col[3]};
    return spvs_h_solve3_cols(cols, sample, model);
#else
    return spvs_h_solve3_rows((const spvs_real(*)[4])s->pts, sample, model);
#endif
}

#define HP_R spvs_real
#define HP_M int32_t
#define HP_SUFFIX
#include "h_point.inc"
#if SPVS_SIMD_COLUMNS
#define HP_R spvs_v4
#define HP_M spvs_v4i
#define HP_SUFFIX _v
#include "h_point.inc"
#endif

/* Points counted between two bail-out tests (and, on SIMD lanes, between
 * two tests of the exact early exit). */
#define SCORE_BLOCK 16
/* The bail-out test stops counting a model once its count so far is more
 * than BAIL_SIGMAS standard deviations below what a model with `need`
 * inliers would show on as many points. */
#define BAIL_SIGMAS 3

#if SPVS_SIMD_COLUMNS
/* The inliers of H among points i..i + SCORE_BLOCK of the columns c, marked
 * in mask[i..] when with_mask; returns their count. */
static SPVS_ALWAYS_INLINE int32_t score_block(const spvs_real *h,
                                              const spvs_real (*c)[SPVS_MAX_MATCHES], size_t i,
                                              spvs_real t2, uint8_t *mask, int with_mask)
{
    spvs_v4i cnt = {0};
    SPVS_UNROLL
    for (size_t r = i; r < i + SCORE_BLOCK; r += SPVS_VLANES) {
        spvs_v4 e;
        const spvs_v4i in = hp_inlier_v(h, spvs_v4_load(&c[0][r]), spvs_v4_load(&c[1][r]),
                                         spvs_v4_load(&c[2][r]), spvs_v4_load(&c[3][r]), t2, &e);
        cnt -= in;
        if (with_mask) {
            spvs_v4_store_flags(in, mask + r);
        }
    }
    /* The four lane counts added by two swaps (no lane extractions). */
    cnt += SPVS_V4_SHUFFLE(cnt, 2, 3, 0, 1);
    cnt += SPVS_V4_SHUFFLE(cnt, 1, 0, 3, 2);
    return (int32_t)cnt[0];
}
#endif

/* Counts the inliers among points [i, end) one at a time into *inl, marking
 * them in mask when it is not NULL; returns 0 at the first point that leaves
 * more than max_out outliers so far (the count can no longer reach `need`),
 * 1 otherwise. */
static SPVS_ALWAYS_INLINE int score_points(const spvs_t *s, const spvs_real *h, size_t i,
                                           size_t end, spvs_real t2, int32_t max_out,
                                           uint8_t *mask, int32_t *inl)
{
    for (size_t r = i; r < end; r++) {
        spvs_real e;
        const int32_t ok =
            hp_inlier(h, PT(s, r, 0), PT(s, r, 1), PT(s, r, 2), PT(s, r, 3), t2, &e);
        *inl += ok;
        if (mask) {
            mask[r] = (uint8_t)ok;
        }
        if ((int32_t)(r + 1) - *inl > max_out) {
            return 0;
        }
    }
    return 1;
}

/* Counts the inliers (hp_inlier) of H among the first n points and, when
 * mask is not NULL, marks them.  Stops early, returning a count below
 * `need`, once `need` cannot be reached (on SIMD lanes tested every
 * SCORE_BLOCK points, else at every point) or once the bail-out test says
 * it will not be: after every SCORE_BLOCK points, a count more than
 * BAIL_SIGMAS binomial standard deviations below the fraction need / n of
 * the points seen so far.  For a
 * model as good as `need` that happens with a probability of about 0.1 %
 * per test; a contaminated sample's model is dropped after 16 to 48 points
 * instead of after n - need outliers.  The points are in spread order
 * (load_frame), so every stretch of them looks like the whole.  Counts and
 * masks, and where the test is made, are the same on every target. */
static uint16_t score_first(const spvs_t *s, size_t n, const spvs_real *H, spvs_real t2,
                            uint16_t need, uint8_t *mask)
{
    const int32_t max_out = need <= n ? (int32_t)(n - need) : 0;
    /* The bail-out test in integers of points: a shortfall d = p m - inl
     * after m points fails when d > 0 and d^2 > BAIL_SIGMAS^2 m p (1 - p). */
    const spvs_real p = need <= n ? (spvs_real)need / (spvs_real)n : SPVS_R(1.0);
    const spvs_real bail_var = (spvs_real)(BAIL_SIGMAS * BAIL_SIGMAS) * p * (SPVS_R(1.0) - p);
    /* A local copy: the mask stores cannot then alias the model. */
    spvs_real h[9];
    for (int k = 0; k < 9; k++) {
        h[k] = H[k];
    }
    int32_t inl = 0;
    size_t i = 0;
    /* Bound: n / SCORE_BLOCK blocks, then fewer than SCORE_BLOCK points. */
    for (; i + SCORE_BLOCK <= n; i += SCORE_BLOCK) {
#if SPVS_SIMD_COLUMNS
        inl += mask ? score_block(h, s->col, i, t2, mask, 1)
                    : score_block(h, s->col, i, t2, mask, 0);
        /* More outliers so far than `need` allows: it cannot be reached. */
        if ((int32_t)(i + SCORE_BLOCK) - inl > max_out) {
            return (uint16_t)inl;
        }
#else
        if (!score_points(s, h, i, i + SCORE_BLOCK, t2, max_out, mask, &inl)) {
            return (uint16_t)inl;
        }
#endif
        const spvs_real m_pts = (spvs_real)(i + SCORE_BLOCK);
        const spvs_real d = p * m_pts - (spvs_real)inl;
        if (d > SPVS_R(0.0) && d * d > bail_var * m_pts) {
            return (uint16_t)inl;
        }
    }
    (void)score_points(s, h, i, n, t2, max_out, mask, &inl);
    return (uint16_t)inl;
}

/* The count of score_first over all the plane points (the estimator's
 * score). */
static uint16_t est_score(void *ctx, const spvs_real *H, spvs_real t2, uint16_t need,
                          uint8_t *mask)
{
    const spvs_t *s = (const spvs_t *)ctx;
    return score_first(s, s->n_plane, H, t2, need, mask);
}

/* Tie-break cost of H: the inliers' squared algebraic residual (*e2 of
 * hp_inlier), summed in COST_LANES interleaved lanes (point i to lane
 * i mod COST_LANES, each lane in point order, the lanes added as
 * (0 + 1) + (2 + 3)): on SIMD lanes a row of points at a time, elsewhere
 * lane by lane, with the same bits. */
#define COST_LANES 4
static spvs_real est_cost(void *ctx, const spvs_real *H, spvs_real t2)
{
    const spvs_t *s = (const spvs_t *)ctx;
    const uint16_t n = s->n_plane;
    spvs_real lane[COST_LANES] = {SPVS_R(0.0), SPVS_R(0.0), SPVS_R(0.0), SPVS_R(0.0)};
    uint16_t i0 = 0;
#if SPVS_SIMD_COLUMNS
    _Static_assert(SPVS_VLANES == COST_LANES, "a vector holds one row of lanes");
    /* An outlier adds +0, which leaves a lane's sum (never -0) as it was. */
    spvs_v4 acc = {0};
    /* Bound: n / COST_LANES rows. */
    for (; i0 + COST_LANES <= n; i0 = (uint16_t)(i0 + COST_LANES)) {
        spvs_v4 e;
        const spvs_v4i in =
            hp_inlier_v(H, spvs_v4_load(&s->col[0][i0]), spvs_v4_load(&s->col[1][i0]),
                        spvs_v4_load(&s->col[2][i0]), spvs_v4_load(&s->col[3][i0]), t2, &e);
        acc += (spvs_v4)((spvs_v4i)e & in);
    }
    for (int j = 0; j < COST_LANES; j++) {
        lane[j] = acc[j];
    }
#endif
    /* The rest of each lane, in point order.  Bound: n points. */
    for (uint16_t j = 0; j < COST_LANES; j++) {
        for (uint16_t i = (uint16_t)(i0 + j); i < n; i = (uint16_t)(i + COST_LANES)) {
            spvs_real e;
            if (hp_inlier(H, PT(s, i, 0), PT(s, i, 1), PT(s, i, 2), PT(s, i, 3), t2, &e)) {
                lane[j] += e;
            }
        }
    }
    return (lane[0] + lane[1]) + (lane[2] + lane[3]);
}

/* The linear fit and the Gauss-Newton refit on the first n_plane points,
 * on the column copy where there is one (same results, SIMD lanes). */
static int fit_linear(const spvs_t *s, const uint8_t *use, uint16_t n, spvs_real H[9])
{
#if SPVS_SIMD_COLUMNS
    const spvs_real *const cols[4] = {s->col[0], s->col[1], s->col[2], s->col[3]};
    return spvs_h_fit_linear_cols(cols, use, n, H);
#else
    return spvs_h_fit_linear((const spvs_real(*)[4])s->pts, use, n, H);
#endif
}

/* The final refit; with lin, its first step from the normal matrix of the
 * joint linear fit's sums on the same set (spvs_h_refit_lin). */
static int refit(const spvs_t *s, const uint8_t *use, uint16_t steps, const spvs_real *lin,
                 spvs_real H[9])
{
#if SPVS_SIMD_COLUMNS
    const spvs_real *const cols[4] = {s->col[0], s->col[1], s->col[2], s->col[3]};
    return lin ? spvs_h_refit_lin_cols(cols, use, s->n_plane, steps, lin, H)
               : spvs_h_refit_cols(cols, use, s->n_plane, steps, H);
#else
    const spvs_real(*pts)[4] = (const spvs_real(*)[4])s->pts;
    return lin ? spvs_h_refit_lin(pts, use, s->n_plane, steps, lin, H)
               : spvs_h_refit(pts, use, s->n_plane, steps, H);
#endif
}

/* The joint linear fit's sums over the points flagged in use, at the
 * weights of hw. */
static int lin_sums(const spvs_t *s, const uint8_t *use, const spvs_real hw[9],
                    spvs_real sums[SPVS_H_LIN_SUMS])
{
#if SPVS_SIMD_COLUMNS
    const spvs_real *const cols[4] = {s->col[0], s->col[1], s->col[2], s->col[3]};
    return spvs_h_lin_sums_cols(cols, use, s->n_plane, hw, sums);
#else
    return spvs_h_lin_sums((const spvs_real(*)[4])s->pts, use, s->n_plane, hw, sums);
#endif
}

/* Adds point i to the sums (to[i] set) or removes it; 0 when it could not
 * be added (w0 <= 0 under hw). */
static SPVS_ALWAYS_INLINE int lin_move(const spvs_t *s, const spvs_real hw[9], const uint8_t *to,
                                       uint16_t i, spvs_real sums[SPVS_H_LIN_SUMS])
{
    spvs_real buf[4];
    return spvs_h_lin_update(hw, point_row(s, i, buf), to[i] != 0, sums) == SPVS_OK;
}

/* Moves the sums from the set `from` to the set `to`: the points flagged in
 * one and not the other added or removed, in point order.  The flags (0 or
 * 1) are compared eight at a time and only the differing bytes of a word
 * visited (most words are equal).  Returns 0 when the sets are the same,
 * 1 when the sums moved, -1 when a point could not be added (w0 <= 0 under
 * hw: the sums are then no longer usable). */
static int lin_follow(const spvs_t *s, const spvs_real hw[9], const uint8_t *from,
                      const uint8_t *to, spvs_real sums[SPVS_H_LIN_SUMS])
{
    const uint16_t n = s->n_plane;
    int moved = 0;
    /* Bound: n / 8 words, each with at most 8 differing bytes, then fewer
     * than 8 points. */
    uint16_t i0 = 0;
    for (; i0 + 8u <= n; i0 = (uint16_t)(i0 + 8u)) {
        const uint64_t a = spvs_load_le64(from + i0);
        const uint64_t b = spvs_load_le64(to + i0);
        for (uint64_t d = a ^ b; d != 0u; d &= d - 1u) {
            if (!lin_move(s, hw, to, (uint16_t)(i0 + spvs_byte_of_lowest(d)), sums)) {
                return -1;
            }
            moved = 1;
        }
    }
    for (uint16_t i = i0; i < n; i++) {
        if (from[i] != to[i]) {
            if (!lin_move(s, hw, to, i, sums)) {
                return -1;
            }
            moved = 1;
        }
    }
    return moved;
}

/* LO step: polish a hypothesis with the weighted linear fit on its inliers
 * among the first SPVS_LO_POINTS points, then once more on the polished
 * model's own inliers among them.  The step only has to lift the count
 * that the stopping rule reads; the points are in spread order
 * (load_frame), so the first 96 stand for all of them.  A 3-point model's
 * inliers are those near its sample and it misses the others, so one fit
 * on them lifts the count only part of the way; the second pass takes the
 * best model's share at N = 200, 20 % mismatches, 1 px from 0.653 to 0.672
 * of the points, and the stopping rule needs 21.7 hypotheses instead of
 * 25.4 (docs/BENCHMARKS.md).  The final model is refitted on every inlier
 * (estimate()). */
static int est_refine(void *ctx, spvs_real *H, const uint8_t *mask)
{
    spvs_t *s = (spvs_t *)ctx;
    const uint16_t m = s->n_plane < SPVS_LO_POINTS ? s->n_plane : SPVS_LO_POINTS;
    const int rc = fit_linear(s, mask, m, H);
    if (rc != SPVS_OK) {
        return rc;
    }
    const spvs_real t = s->p.inlier_px / (spvs_real)SPVS_COORD_SCALE;
    (void)score_first(s, m, H, t * t, 0, s->lo_mask);
    /* On failure the fit leaves H as the first pass made it. */
    (void)fit_linear(s, s->lo_mask, m, H);
    return SPVS_OK;
}

/* ---- input validation and the estimation stage --------------------------- */

/* The first bad value of a frame, as a status: a non-finite coordinate,
 * one out of range, or a feature index out of range. */
static int frame_error(const spvs_match_t *m, uint16_t n)
{
    const spvs_real lim = (spvs_real)SPVS_MAX_COORD_PX;
    for (uint16_t i = 0; i < n; i++) {
        const spvs_real c[4] = {m[i].x_tgt, m[i].y_tgt, m[i].x_cur, m[i].y_cur};
        for (int j = 0; j < 4; j++) {
            if (!spvs_is_finite(c[j])) {
                return SPVS_E_NONFINITE;
            }
            if (SPVS_FABS(c[j]) > lim) {
                return SPVS_E_RANGE;
            }
        }
        if (m[i].feature >= SPVS_MAX_FEATURES) {
            return SPVS_E_RANGE;
        }
    }
    return SPVS_OK;
}

/* 1 when the off-plane memory holds feature f as off the plane.  An index
 * out of range reads feature 0's entry (load_frame refuses such a frame). */
static inline int known_offplane(const spvs_t *s, uint16_t f)
{
    return s->offplane[f < SPVS_MAX_FEATURES ? f : 0u] >= OFFPLANE_ON;
}

/* A stride for storing n matches in a spread order: near 0.618 n and
 * coprime with n, so that r -> (r * stride) mod n is a permutation that puts
 * neighbouring matches far apart.  Bound: SPREAD_TRIES candidates, each
 * tested by at most GCD_STEPS steps of Euclid's algorithm (enough for any
 * 16-bit pair); 1 (the input order) if none passes. */
#define SPREAD_TRIES 16
#define GCD_STEPS 32
static uint16_t spread_stride(uint16_t n)
{
    uint32_t p = ((uint32_t)n * 40503u) >> 16;
    for (int t = 0; t < SPREAD_TRIES && p > 1u; t++, p--) {
        uint32_t a = n;
        uint32_t b = p;
        for (int k = 0; k < GCD_STEPS && b != 0u; k++) {
            const uint32_t r = a % b;
            a = b;
            b = r;
        }
        if (a == 1u && b == 0u) {
            return (uint16_t)p;
        }
    }
    return 1u;
}

/* The input index of stored slot k (load_frame): the plane matches' slots
 * 0..n_plane take them in spread order, the position among them advancing by
 * `stride` (mod n_plane) from slot to slot; the other slots list the
 * off-plane matches (s->idx, filled by load_frame). */
static SPVS_ALWAYS_INLINE uint16_t slot_source(const spvs_t *s, uint16_t k, uint16_t n_plane,
                                               int all_plane, uint16_t stride, uint16_t *pos)
{
    if (k >= n_plane) {
        return s->idx[k];
    }
    const uint16_t p = *pos;
    const uint16_t q = (uint16_t)(p + stride);
    *pos = (uint16_t)(q >= n_plane ? q - n_plane : q);
    return all_plane ? p : s->idx[p];
}

/* load_frame's copy of the n matches into their slots; returns nonzero when
 * a value is out of range (all_plane is a constant where it is called, so
 * each case gets its own loop). */
static SPVS_ALWAYS_INLINE int32_t copy_slots(spvs_t *s, const spvs_match_t *m, uint16_t n,
                                             uint16_t n_plane, uint16_t stride, int all_plane)
{
    const spvs_real lim = (spvs_real)SPVS_MAX_COORD_PX;
    const spvs_real inv = SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE;
    uint16_t pos = 0;
    int32_t bad = 0;
    uint16_t k = 0;
#if SPVS_SIMD_COLUMNS
    /* -1 in a lane while every coordinate it has seen is in range. */
    spvs_v4i in_range = (spvs_v4i){0} - 1;
    /* Four slots at a time: the four coordinates of a match are one vector,
     * transposed with the three others into columns.  Bound: n /
     * SPVS_VLANES groups. */
    for (; k + SPVS_VLANES <= n; k = (uint16_t)(k + SPVS_VLANES)) {
        spvs_v4 r[SPVS_VLANES];
        for (uint16_t j = 0; j < SPVS_VLANES; j++) {
            const uint16_t i = slot_source(s, (uint16_t)(k + j), n_plane, all_plane, stride, &pos);
            const uint16_t f = m[i].feature;
            bad |= f >= SPVS_MAX_FEATURES;
            s->feat[k + j] = f;
            const spvs_v4 c = spvs_v4_load(&m[i].x_tgt);
            in_range &= spvs_v4_abs(c) <= lim;
            r[j] = c * inv;
        }
        /* (x y u v) rows to (x0 x1 x2 x3) ... columns. */
        const spvs_v4 t0 = SPVS_V4_SHUFFLE2(r[0], r[1], 0, 4, 1, 5);
        const spvs_v4 t1 = SPVS_V4_SHUFFLE2(r[0], r[1], 2, 6, 3, 7);
        const spvs_v4 t2 = SPVS_V4_SHUFFLE2(r[2], r[3], 0, 4, 1, 5);
        const spvs_v4 t3 = SPVS_V4_SHUFFLE2(r[2], r[3], 2, 6, 3, 7);
        *(spvs_v4u *)&s->col[0][k] = SPVS_V4_SHUFFLE2(t0, t2, 0, 1, 4, 5);
        *(spvs_v4u *)&s->col[1][k] = SPVS_V4_SHUFFLE2(t0, t2, 2, 3, 6, 7);
        *(spvs_v4u *)&s->col[2][k] = SPVS_V4_SHUFFLE2(t1, t3, 0, 1, 4, 5);
        *(spvs_v4u *)&s->col[3][k] = SPVS_V4_SHUFFLE2(t1, t3, 2, 3, 6, 7);
    }
    bad |= (in_range[0] & in_range[1] & in_range[2] & in_range[3]) == 0;
#endif
    /* One slot at a time (the rest, on SIMD lanes).  Bound: n slots. */
    for (; k < n; k++) {
        const uint16_t i = slot_source(s, k, n_plane, all_plane, stride, &pos);
        const uint16_t f = m[i].feature;
        bad |= f >= SPVS_MAX_FEATURES;
        s->feat[k] = f;
        const spvs_real c[4] = {m[i].x_tgt, m[i].y_tgt, m[i].x_cur, m[i].y_cur};
        for (int j = 0; j < 4; j++) {
            bad |= !(SPVS_FABS(c[j]) <= lim);
            PT(s, k, j) = c[j] * inv;
        }
    }
    return bad;
}

/* Checks the frame and copies it into the work buffers in scaled units, the
 * matches of features not known to be off the plane first (n_plane of them).
 * These are stored in a spread order: slot k holds the (k stride mod
 * n_plane)-th of them (spread_stride).  Matches often come sorted by image
 * position or by object, so outliers come in runs, and the inlier count's
 * bail-out test (est_score) needs every stretch of the stored order to look
 * like the whole.
 * The check is made without branches while copying: |c| <= lim fails for NaN
 * and infinities too (an index out of range: known_offplane).  Only a bad
 * frame is looked at again, for its status. */
static int load_frame(spvs_t *s, const spvs_match_t *m, uint16_t n)
{
    /* While the memory holds no off-plane feature every match is a plane
     * match; else s->idx lists the plane matches in input order, then the
     * others from the back. */
    const int all_plane = s->n_offplane_known == 0u;
    spvs_prefetch(m, (size_t)n * sizeof *m);
    uint16_t n_plane = n;
    if (!all_plane) {
        uint16_t back = n;
        n_plane = 0;
        for (uint16_t i = 0; i < n; i++) {
            if (known_offplane(s, m[i].feature)) {
                s->idx[--back] = i;
            } else {
                s->idx[n_plane++] = i;
            }
        }
    }
    const uint16_t stride = spread_stride(n_plane);
    const int32_t bad = all_plane ? copy_slots(s, m, n, n_plane, stride, 1)
                                  : copy_slots(s, m, n, n_plane, stride, 0);
    if (bad) {
        int rc = frame_error(m, n);
        return rc != SPVS_OK ? rc : SPVS_E_RANGE;
    }
    s->n_plane = n_plane;
    s->n_pts = n;
    return SPVS_OK;
}

static void clear_output(spvs_output_t *out, uint16_t n)
{
    out->v = SPVS_R(0.0);
    out->w = SPVS_R(0.0);
    for (int k = 0; k < 9; k++) {
        out->H[k] = SPVS_R(0.0);
    }
    out->e_x_px = SPVS_R(0.0);
    out->parallax_px = SPVS_R(-1.0);
    out->n_matches = n;
    out->n_inliers = 0;
    out->n_offplane = 0;
    out->ransac_iters = 0;
    out->status = SPVS_OK;
    out->step = 0;
    out->h_valid = 0;
    out->e_valid = 0;
    out->eq11 = 0;
    out->arrival_corner_px = SPVS_R(0.0);
    out->arrival_bound_px = SPVS_R(0.0);
    out->arrival_lateral_px = SPVS_R(0.0);
    out->arrival_depth_px = SPVS_R(0.0);
    out->arrival_h13_px = SPVS_R(0.0);
    out->arrival_frames = 0;
    out->arrival_reentries = 0;
    out->arrival_next = 0;
    out->arriving = 0;
}

/* Validate, RANSAC and refit.  On success s->H_sc holds H in scaled units and
 * s->mask the plane inliers among the first n_plane points. */
static int estimate(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_output_t *out)
{
    if (n > SPVS_MAX_MATCHES) {
        return SPVS_E_CAPACITY;
    }
    if (m == 0 && n > 0) {
        return SPVS_E_ARG;
    }
    if (n < 3u) {
        return SPVS_E_TOO_FEW;
    }
    int rc = load_frame(s, m, n);
    if (rc != SPVS_OK) {
        return rc;
    }
    if (s->n_plane < MIN_INLIERS) {
        return SPVS_E_TOO_FEW;
    }
    const spvs_real inv = SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE;
    spvs_real t = s->p.inlier_px * inv;
    spvs_estimator_t est = {3u, s->n_plane, s, est_fit, est_score, est_cost, est_refine};
    spvs_ransac_opts_t opts = {t * t, s->p.confidence, s->p.max_iters, MIN_INLIERS};
    spvs_ransac_stats_t st;
    spvs_real model[SPVS_MODEL_MAX];
    rc = spvs_ransac(&est, &opts, &s->rng, s->idx, model, s->mask, s->idx_mask, &st);
    out->ransac_iters = (uint16_t)(st.iters > 65535u ? 65535u : st.iters);
    if (rc != SPVS_OK) {
        return rc;
    }
    /* Re-select the inliers until the set stops changing (bound:
     * SPVS_REFIT_ROUNDS rounds): each round solves the joint linear fit on
     * the set in use and takes the inliers of its H as the next set.  The
     * fit's weights stay those of the RANSAC model, so its sums follow the
     * set by the points that enter or leave it (lin_follow) instead of
     * another pass.  Then one Gauss-Newton step on the final set, its
     * normal matrix taken from those sums (spvs_h_refit_lin). */
    uint16_t n_inl = st.n_inliers;
    /* The set in use and the next one, swapped each round. */
    uint8_t *cur = s->mask;
    uint8_t *next = s->idx_mask;
    spvs_real *const hw = s->lin_hw;
    spvs_real *const sums = s->lin_sums;
    for (int k = 0; k < 9; k++) {
        hw[k] = model[k];
    }
    int lin = lin_sums(s, cur, hw, sums) == SPVS_OK;
    for (int round = 0; lin && round < SPVS_REFIT_ROUNDS; round++) {
        spvs_real Hr[9];
        if (spvs_h_lin_solve(sums, hw, Hr) != SPVS_OK) {
            break;
        }
        const uint16_t n_new = est_score(s, Hr, opts.threshold2, 0, next);
        if (n_new < n_inl) {
            break;
        }
        for (int k = 0; k < 9; k++) {
            model[k] = Hr[k];
        }
        /* The model is now the fit on cur; the sums move to next. */
        const int moved = lin_follow(s, hw, cur, next, sums);
        if (moved < 0) {
            lin = 0;
            break;
        }
        uint8_t *const was = cur;
        cur = next;
        next = was;
        n_inl = n_new;
        if (moved == 0) {
            break;
        }
    }
    if (cur != s->mask) {
        memcpy(s->mask, cur, s->n_plane);
    }
    {
        spvs_real Hr[9];
        for (int k = 0; k < 9; k++) {
            Hr[k] = model[k];
        }
        if (refit(s, s->mask, FINAL_GN_STEPS, lin ? sums : 0, Hr) == SPVS_OK) {
            for (int k = 0; k < 9; k++) {
                model[k] = Hr[k];
            }
        }
    }
    for (int k = 0; k < 9; k++) {
        s->H_sc[k] = model[k];
        out->H[k] = model[k];
    }
    spvs_h_rescale(out->H, (spvs_real)SPVS_COORD_SCALE);
    out->n_inliers = n_inl;
    out->h_valid = 1;
    return SPVS_OK;
}

int spvs_estimate_h(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_output_t *out)
{
    if (s == 0 || out == 0) {
        return SPVS_E_ARG;
    }
    clear_output(out, n);
    int rc = estimate(s, m, n, out);
    out->status = (int16_t)rc;
    return rc;
}

/* ---- off-plane points, epipole and parallax ------------------------------ */

/* H^-1 normalised to h22 = 1 (the inverse of a planar-motion H has the same
 * form).  Returns 0 when H is singular. */
static int h_inverse(const spvs_real H[9], spvs_real Hi[9])
{
    /* Planar form: H = [[a b c] [0 1 0] [g h i]]. */
    const spvs_real a = H[0], b = H[1], c = H[2], g = H[6], h = H[7], i = H[8];
    spvs_real det = a * i - c * g;
    if (!(SPVS_FABS(det) > SPVS_R(1.0e-9))) {
        return 0;
    }
    spvs_real id = SPVS_R(1.0) / det;
    Hi[0] = i * id;
    Hi[1] = (c * h - b * i) * id;
    Hi[2] = -c * id;
    Hi[3] = SPVS_R(0.0);
    Hi[4] = SPVS_R(1.0);
    Hi[5] = SPVS_R(0.0);
    Hi[6] = -g * id;
    Hi[7] = (b * g - a * h) * id;
    Hi[8] = a * id;
    return 1;
}

/* Collects the off-plane candidates: matches of remembered off-plane features
 * first, then plane-set matches with a large transfer error.  Returns how many
 * of the candidates are remembered features. */
static uint16_t collect_candidates(spvs_t *s, uint16_t *n_cand)
{
    const spvs_real inv = SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE;
    const spvs_real off = s->p.offplane_px * inv;
    const spvs_real off2 = off * off;
    uint16_t nc = 0;
    for (uint16_t i = s->n_plane; i < s->n_pts && nc < SPVS_MAX_OFFPLANE; i++) {
        s->cand[nc++] = i;
    }
    uint16_t n_known = nc;
    /* Where H stretches the image (points seen at a grazing angle), a plane
     * point's noise is magnified in the current image and its forward error
     * is large; its error back in the target image is not.  An off-plane
     * point's parallax shows in both, so both must exceed the threshold. */
    spvs_real Hi[9];
    int have_inv = h_inverse(s->H_sc, Hi);
    for (uint16_t i = 0; i < s->n_plane && nc < SPVS_MAX_OFFPLANE; i++) {
        if (s->mask[i]) {
            continue;
        }
        spvs_real buf[4];
        const spvs_real *q = point_row(s, i, buf);
        spvs_real e2 = spvs_h_transfer_err2(s->H_sc, q);
        if (!(e2 > off2)) {
            continue;
        }
        if (have_inv) {
            const spvs_real back[4] = {q[2], q[3], q[0], q[1]};
            spvs_real b2 = spvs_h_transfer_err2(Hi, back);
            if (b2 >= SPVS_R(0.0) && !(b2 > off2)) {
                continue;
            }
        }
        s->cand[nc++] = i;
    }
#if SPVS_SIMD_COLUMNS
    for (uint16_t k = 0; k < nc; k++) {
        (void)point_row(s, s->cand[k], s->cand_pts[k]);
        s->cand_ord[k] = k;
    }
#endif
    *n_cand = nc;
    return n_known;
}

/* Candidate k's point as a row (collect_candidates). */
static inline const spvs_real *cand_row(const spvs_t *s, uint16_t k)
{
#if SPVS_SIMD_COLUMNS
    return s->cand_pts[k];
#else
    return s->pts[s->cand[k]];
#endif
}

/* Median transfer error (pixels) of the remembered off-plane features in this
 * frame; negative when none is in view.  Bound: SPVS_MAX_OFFPLANE values. */
static spvs_real known_parallax_px(spvs_t *s, uint16_t n_known)
{
    spvs_real *v = s->ework.n2;
    uint16_t nv = 0;
    for (uint16_t k = 0; k < n_known; k++) {
        spvs_real e2 = spvs_h_transfer_err2(s->H_sc, cand_row(s, k));
        if (e2 < SPVS_R(0.0)) {
            continue;
        }
        v[nv++] = e2;
    }
    if (nv == 0) {
        return SPVS_R(-1.0);
    }
    spvs_sort_small(v, nv);
    return (spvs_real)SPVS_COORD_SCALE * SPVS_SQRT(v[nv / 2]);
}

static void remember(spvs_t *s, uint16_t n_cand, int e_ok, spvs_real parallax_px)
{
    const spvs_real inv = SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE;
    const spvs_real off = s->p.offplane_px * inv;
    const spvs_real off2 = off * off;
    if (e_ok) {
        for (uint16_t k = 0; k < n_cand; k++) {
            uint16_t i = s->cand[k];
            int8_t *score = &s->offplane[s->feat[i]];
            if (s->support[k] && *score < OFFPLANE_MAX &&
                spvs_h_transfer_err2(s->H_sc, cand_row(s, k)) > off2) {
                (*score)++;
                s->n_offplane_known = (uint16_t)(s->n_offplane_known + (*score == OFFPLANE_ON));
            }
        }
    }
    /* A plane inlier while the scene shows clear parallax is a plane point. */
    if (parallax_px > SPVS_R(2.0) * s->p.offplane_px) {
        for (uint16_t i = 0; i < s->n_plane; i++) {
            int8_t *score = &s->offplane[s->feat[i]];
            if (s->mask[i] && *score > OFFPLANE_MIN) {
                s->n_offplane_known = (uint16_t)(s->n_offplane_known - (*score == OFFPLANE_ON));
                (*score)--;
            }
        }
    }
}

/* The epipole handed to the controller is the median of the last
 * SPVS_EPIPOLE_MEDIAN frames' estimates, and its side (ahead or behind) their
 * majority: one frame whose few off-plane points give a wild estimate must
 * not turn the robot (bound: SPVS_EPIPOLE_MEDIAN values). */
static void epipole_filter(spvs_t *s, const spvs_epipole_t *ep, spvs_control_input_t *in)
{
    s->ehist_x[s->i_ehist] = ep->e_x_px;
    s->ehist_z[s->i_ehist] = (int8_t)(ep->dir_z > SPVS_R(0.0) ? 1 : -1);
    s->i_ehist = (uint8_t)((s->i_ehist + 1u) % SPVS_EPIPOLE_MEDIAN);
    if (s->n_ehist < SPVS_EPIPOLE_MEDIAN) {
        s->n_ehist++;
    }
    spvs_real v[SPVS_EPIPOLE_MEDIAN];
    int votes = 0;
    for (uint8_t i = 0; i < s->n_ehist; i++) {
        v[i] = s->ehist_x[i];
        votes += s->ehist_z[i];
    }
    spvs_sort_small(v, s->n_ehist);
    in->e_x_px = v[s->n_ehist / 2];
    in->e_dir_x = ep->dir_x;
    in->e_dir_z = votes > 0 ? SPVS_R(1.0) : (votes < 0 ? SPVS_R(-1.0) : ep->dir_z);
}

int spvs_update(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                spvs_output_t *out)
{
    if (s == 0 || out == 0) {
        return SPVS_E_ARG;
    }
    clear_output(out, n);
    int rc = SPVS_OK;
    if (!spvs_is_finite(t_s)) {
        rc = SPVS_E_NONFINITE;
    } else if (s->has_last && !(t_s > s->last_t_s)) {
        /* A frame not after the last one is a duplicate or out of order:
         * its estimate would be stale. */
        rc = SPVS_E_STALE;
    }
    if (rc == SPVS_OK) {
        s->last_t_s = t_s;
        s->has_last = 1;
        rc = estimate(s, m, n, out);
    }
    if (rc != SPVS_OK) {
        /* The robot is told to stop: the controller's odometry must know. */
        s->ctl.last_v = SPVS_R(0.0);
        out->status = (int16_t)rc;
        out->step = (uint8_t)s->ctl.step;
        return rc;
    }
    /* A long gap since the last good frame: the step-end tests restart, as
     * their consecutive-frame counts no longer describe continuous motion. */
    if (s->has_good && t_s - s->last_good_t_s > s->p.max_frame_gap_s) {
        s->ctl.hold = 0;
        s->ctl.run_sign = 0;
        s->ctl.run_len = 0;
    }
    s->has_good = 1;
    s->last_good_t_s = t_s;

    uint16_t n_cand = 0;
    uint16_t n_known = collect_candidates(s, &n_cand);
    spvs_real parallax = known_parallax_px(s, n_known);
    spvs_epipole_t ep;
    const spvs_real sin_tol2 = s->p.epipole_sin_tol * s->p.epipole_sin_tol;
#if SPVS_SIMD_COLUMNS
    int erc = spvs_epipole_estimate(s->H_sc, (const spvs_real(*)[4])s->cand_pts, s->cand_ord,
                                    n_cand, sin_tol2, s->p.min_support, &ep, s->support,
                                    &s->ework);
#else
    int erc = spvs_epipole_estimate(s->H_sc, (const spvs_real(*)[4])s->pts, s->cand, n_cand,
                                    sin_tol2, s->p.min_support, &ep, s->support, &s->ework);
#endif
    int e_ok = (erc == SPVS_OK);
    if (parallax < SPVS_R(0.0) && e_ok) {
        parallax = ep.parallax_px;
    }
    remember(s, n_cand, e_ok, parallax);

    spvs_control_input_t in;
    for (int k = 0; k < 9; k++) {
        in.H[k] = out->H[k];
    }
    in.e_x_px = SPVS_R(0.0);
    in.e_dir_x = SPVS_R(0.0);
    in.e_dir_z = SPVS_R(0.0);
    if (e_ok) {
        epipole_filter(s, &ep, &in);
    }
    in.parallax_px = parallax;
    in.t_s = t_s;
    in.e_valid = (uint8_t)e_ok;
    in.n_inliers = out->n_inliers;

    spvs_real v, w;
    rc = spvs_control_step(&s->ctl, &s->p.ctl, &in, &v, &w);
    out->v = rc == SPVS_OK ? v : SPVS_R(0.0);
    out->w = rc == SPVS_OK ? w : SPVS_R(0.0);
    out->e_x_px = in.e_x_px;
    out->parallax_px = parallax;
    out->n_offplane = e_ok ? ep.n_support : 0u;
    out->e_valid = (uint8_t)e_ok;
    out->eq11 = s->ctl.use_eq11;
    out->status = (int16_t)rc;
    out->step = (uint8_t)s->ctl.step;
    out->arrival_corner_px = s->ctl.arrival_corner_px;
    out->arrival_bound_px = s->ctl.arrival_bound_px;
    out->arrival_lateral_px = s->ctl.arrival_lateral_px;
    out->arrival_depth_px = s->ctl.arrival_depth_px;
    out->arrival_h13_px = s->ctl.arrival_h13_px;
    out->arrival_frames = s->ctl.arrive_n;
    out->arrival_reentries = s->ctl.reentries;
    out->arrival_next = s->ctl.arrival_next;
    out->arriving = s->ctl.arriving;
    return rc;
}
