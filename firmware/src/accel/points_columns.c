/*
 * accel/points_columns.c - the frame's points in columns on SIMD lanes
 * (points.h), the accelerated layout of hosts with SSE2 or NEON, built
 * where SPVS_ACCEL is ON (firmware/CMakeLists.txt) in place of points.c's
 * rows.  Coordinate k of point i is v[k SPVS_MAX_MATCHES + i]; sums and
 * inlier counts read SPVS_VLANES points at a time (v4.h), and where the
 * processor has AVX2 (SPVS_AVX2, asked at run time) eight (v8.h).  Every
 * lane makes the scalar form's operations (h_point.inc) in the order of
 * points.inc's sum_rows, so the outputs are points.c's bit for bit
 * (tests/compare_layouts.sh, test_homography's store tests).
 *
 * h_point.inc is instantiated here for four lanes (hp_terms_v,
 * hp_inlier_v, hp_e2_v) and for eight (hp_terms_v8, hp_inlier_v8).
 */
#include "points.inc"

#include "v4.h"
#define HP_R spvs_v4
#define HP_M spvs_v4i
#define HP_SCALAR 0
#define HP_ANY(m) spvs_v4_any(m)
#define HP_JJT hp_jjt_v
#define HP_SAMPSON hp_sampson_v
#define HP_E2 hp_e2_v
#define HP_INLIER hp_inlier_v
#define HP_TERMS_LIN hp_terms_lin_v
#define HP_TERMS hp_terms_v
#include "h_point.inc"
#undef HP_ANY
_Static_assert(SPVS_VLANES == SUM_LANES, "a vector holds one row of lanes");

#if SPVS_AVX2
/* Eight lanes, two rows of four: the same text once more (v8.h).  Each term
 * is left for the caller, which adds the first row's into the four lanes'
 * sums before the second's, the order of the four-lane loops. */
#include "v8.h"
#define HP_R spvs_v8
#define HP_M spvs_v8i
#define HP_SCALAR 0
#define HP_ANY(m) spvs_v8_any(m)
#define HP_ADD(a, t) ((a) = (t))
#define HP_JJT hp_jjt_v8
#define HP_SAMPSON hp_sampson_v8
#define HP_E2 hp_e2_v8
#define HP_INLIER hp_inlier_v8
#define HP_TERMS_LIN hp_terms_lin_v8
#define HP_TERMS hp_terms_v8
#include "h_point.inc"
#undef HP_ANY
#endif
/* The loader reads a match's four coordinates as one vector. */
_Static_assert(offsetof(spvs_match_t, x_tgt) == 0 &&
                   offsetof(spvs_match_t, y_cur) == 3 * sizeof(spvs_real),
               "the coordinates of a match are contiguous");

#define COL(st, k) (&(st)->v[(size_t)(k) * SPVS_MAX_MATCHES])

static SPVS_ALWAYS_INLINE spvs_real at(const spvs_point_store_t *st, size_t i, int k)
{
    return st->v[(size_t)k * SPVS_MAX_MATCHES + i];
}

int spvs_pts_solve3(const spvs_point_store_t *st, const uint16_t idx[3], spvs_real H_out[9])
{
    const spvs_real *const c[4] = {COL(st, 0), COL(st, 1), COL(st, 2), COL(st, 3)};
    return spvs_h_solve3_strided(c, idx, 1u, H_out);
}

#if SPVS_AVX2
/* Rows 0 .. 2 floor(n_rows / 2) of sum_store (below), two at a time on
 * eight lanes: each point's terms are hp_terms_v's, and the first row's are
 * added into acc[] before the second's, so that every lane's sums are those
 * of sum_store's own loop, bit for bit.  *all_ok and *cnt as there.
 * Returns the rows done. */
static SPVS_ALWAYS_INLINE uint32_t sum_pairs(int kind, int nt, int count, const spvs_real *h,
                                             const spvs_real *const c[4], const uint8_t *use,
                                             uint32_t n_rows, spvs_v4 *acc, spvs_v4i *all_ok,
                                             spvs_v4i *cnt)
{
    /* The sums in locals: nothing the loop reads can alias them. */
    spvs_v4 a[TERMS_MAX];
    SPVS_UNROLL
    for (int k = 0; k < nt; k++) {
        a[k] = acc[k];
    }
    spvs_v8i ok = (spvs_v8i){0} - 1;
    spvs_v8i used = {0};
    const spvs_v8 one = (spvs_v8){0} + SPVS_R(1.0);
    const uint32_t end = n_rows & ~1u;
    /* Bound: n_rows / 2 pairs of rows. */
    for (uint32_t r = 0; r < end; r += 2) {
        const uint32_t i = r * SUM_LANES;
        const spvs_v8i on = spvs_v8_flags(use + i);
        spvs_v8 t[TERMS_MAX];
        ok &= hp_terms_v8(kind, h, spvs_v8_load(c[0] + i), spvs_v8_load(c[1] + i),
                          spvs_v8_load(c[2] + i), spvs_v8_load(c[3] + i),
                          (spvs_v8)((spvs_v8i)one & on), t);
        SPVS_UNROLL
        for (int k = 0; k < nt; k++) {
            a[k] += spvs_v8_lo(t[k]);
            a[k] += spvs_v8_hi(t[k]);
        }
        if (count) {
            used -= on;
        }
    }
    SPVS_UNROLL
    for (int k = 0; k < nt; k++) {
        acc[k] = a[k];
    }
    *all_ok &= spvs_v8i_lo(ok) & spvs_v8i_hi(ok);
    *cnt += spvs_v8i_lo(used) + spvs_v8i_hi(used);
    return end;
}

/* sum_pairs built for AVX2, one function per kind of terms. */
#define SUM_PAIRS_AVX2(name, kind, nt, count)                                                     \
    static SPVS_TARGET_AVX2 uint32_t name(const spvs_real *h, const spvs_real *const c[4],        \
                                          const uint8_t *use, uint32_t n_rows, spvs_v4 *acc,      \
                                          spvs_v4i *all_ok, spvs_v4i *cnt)                        \
    {                                                                                             \
        return sum_pairs(kind, nt, count, h, c, use, n_rows, acc, all_ok, cnt);                   \
    }
SUM_PAIRS_AVX2(pairs_fit_y, SPVS_T_FIT_Y, SPVS_NT_FIT, 1)
SUM_PAIRS_AVX2(pairs_fit_x, SPVS_T_FIT_X, SPVS_NT_FIT, 0)
SUM_PAIRS_AVX2(pairs_lin, SPVS_T_LIN, SPVS_H_LIN_SUMS, 1)
SUM_PAIRS_AVX2(pairs_sampson, SPVS_T_SAMPSON, SPVS_NT_SAMPSON, 0)

/* The pairs function of a kind (a constant where sum_store is inlined);
 * each takes the kind's term count and counting as spvs_pts_sum passes
 * them to sum_kind. */
static SPVS_ALWAYS_INLINE uint32_t sum_pairs_avx2(int kind, const spvs_real *h,
                                                  const spvs_real *const c[4], const uint8_t *use,
                                                  uint32_t n_rows, spvs_v4 *acc,
                                                  spvs_v4i *all_ok, spvs_v4i *cnt)
{
    switch (kind) {
    case SPVS_T_FIT_Y:
        return pairs_fit_y(h, c, use, n_rows, acc, all_ok, cnt);
    case SPVS_T_FIT_X:
        return pairs_fit_x(h, c, use, n_rows, acc, all_ok, cnt);
    case SPVS_T_LIN:
        return pairs_lin(h, c, use, n_rows, acc, all_ok, cnt);
    default:
        return pairs_sampson(h, c, use, n_rows, acc, all_ok, cnt);
    }
}
#endif

/* The sums of sum_rows on the columns c[0..3], SUM_LANES points at a time
 * in one vector (lane j holds points j, j + SUM_LANES, ...), branch free:
 * an unused point adds +-0, which leaves a lane's sum as it was (sums start
 * at +0 and so never become -0). */
static SPVS_ALWAYS_INLINE int32_t sum_store(int kind, int nt, int count, const spvs_real *H,
                                            const spvs_point_store_t *st, const uint8_t *use,
                                            uint16_t n, spvs_real *out)
{
    const spvs_real *const c[4] = {COL(st, 0), COL(st, 1), COL(st, 2), COL(st, 3)};
    spvs_v4 acc[TERMS_MAX];
    SPVS_UNROLL
    for (int k = 0; k < nt; k++) {
        acc[k] = (spvs_v4){0};
    }
    /* -1 in a lane while all its points have had w > SPVS_W_EPS. */
    spvs_v4i all_ok = (spvs_v4i){0} - 1;
    spvs_v4i cnt = {0};
    /* A local copy: nothing the loop stores can then alias it. */
    spvs_real h[9];
    for (int k = 0; k < 9; k++) {
        h[k] = H[k];
    }
    const spvs_v4 one = (spvs_v4){0} + SPVS_R(1.0);
    const uint32_t n_rows = (uint32_t)n / SUM_LANES;
    uint32_t r = 0;
#if SPVS_AVX2
    if (spvs_have_avx2()) {
        r = sum_pairs_avx2(kind, h, c, use, n_rows, acc, &all_ok, &cnt);
    }
#endif
    /* Bound: n / SUM_LANES rows of lanes. */
    for (; r < n_rows; r++) {
        const uint32_t i = r * SUM_LANES;
        const spvs_v4i on = spvs_v4_flags(use + i);
        all_ok &= hp_terms_v(kind, h, spvs_v4_load(c[0] + i), spvs_v4_load(c[1] + i),
                             spvs_v4_load(c[2] + i), spvs_v4_load(c[3] + i),
                             (spvs_v4)((spvs_v4i)one & on), acc);
        if (count) {
            cnt -= on;
        }
    }
    /* The rest, fewer than SUM_LANES points, as one more row padded with
     * unused points at the origin (an unused point adds +-0 and passes). */
    const uint32_t i0 = n_rows * SUM_LANES;
    if (i0 < n) {
        spvs_real t[4][SUM_LANES] = {{SPVS_R(0.0)}};
        uint8_t t_use[SUM_LANES] = {0};
        for (uint32_t i = i0; i < n; i++) {
            for (int k = 0; k < 4; k++) {
                t[k][i - i0] = c[k][i];
            }
            t_use[i - i0] = use[i];
        }
        const spvs_v4i on = spvs_v4_flags(t_use);
        all_ok &= hp_terms_v(kind, h, spvs_v4_load(t[0]), spvs_v4_load(t[1]),
                             spvs_v4_load(t[2]), spvs_v4_load(t[3]),
                             (spvs_v4)((spvs_v4i)one & on), acc);
        if (count) {
            cnt -= on;
        }
    }
    int32_t any_bad = 0;
    int32_t used = 0;
    for (int j = 0; j < SUM_LANES; j++) {
        any_bad |= all_ok[j] == 0;
        used += (int32_t)cnt[j];
    }
    if (any_bad) {
        return -1;
    }
    /* The lanes added as (0 + 1) + (2 + 3) (lanes_fold's order), four sums
     * at once: the pairs (0 + 1) and (2 + 3) of two sums side by side, then
     * those of four sums added across.  The rest one at a time. */
    int k = 0;
    SPVS_UNROLL
    for (; k + 4 <= nt; k += 4) {
        const spvs_v4 ab = SPVS_V4_SHUFFLE2(acc[k], acc[k + 1], 0, 2, 4, 6) +
                           SPVS_V4_SHUFFLE2(acc[k], acc[k + 1], 1, 3, 5, 7);
        const spvs_v4 cd = SPVS_V4_SHUFFLE2(acc[k + 2], acc[k + 3], 0, 2, 4, 6) +
                           SPVS_V4_SHUFFLE2(acc[k + 2], acc[k + 3], 1, 3, 5, 7);
        *(spvs_v4u *)(out + k) = SPVS_V4_SHUFFLE2(ab, cd, 0, 2, 4, 6) +
                                 SPVS_V4_SHUFFLE2(ab, cd, 1, 3, 5, 7);
    }
    SPVS_UNROLL
    for (; k < nt; k++) {
        const spvs_v4 p = acc[k] + SPVS_V4_SHUFFLE(acc[k], 1, 0, 3, 2);
        out[k] = (p + SPVS_V4_SHUFFLE(p, 2, 3, 0, 1))[0];
    }
    return used;
}

/* The match of slot k (spvs_slot_source's, whose position *pos it keeps
 * when `order` is given).  Without `order` the plane matches are walked by
 * a byte offset *off instead, the same sequence without the 16-bit
 * position's arithmetic and the scaling of an index per match. */
static SPVS_ALWAYS_INLINE const spvs_match_t *slot_match(const spvs_match_t *m, uint16_t k,
                                                         uint16_t n_plane, const uint16_t *order,
                                                         uint16_t stride, uint16_t *pos,
                                                         size_t *off)
{
    if (order != 0) {
        return &m[spvs_slot_source(k, n_plane, order, stride, pos)];
    }
    const spvs_match_t *const at_off = (const spvs_match_t *)(const void *)((const char *)m + *off);
    const size_t next = *off + (size_t)stride * sizeof *m;
    const size_t end = (size_t)n_plane * sizeof *m;
    *off = next >= end ? next - end : next;
    return at_off;
}

/* Asks the data cache for the `bytes` bytes at p, a line (64 bytes) at a
 * time: the loader reads the matches in the spread order, a gather the
 * hardware prefetcher cannot follow.  Bound: bytes / 64 + 1 hints. */
static inline void prefetch(const void *p, size_t bytes)
{
    const char *c = (const char *)p;
    for (size_t b = 0; b < bytes; b += 64u) {
        __builtin_prefetch(c + b);
    }
}

/* The loader's copy (spvs_pts_load); `order` is NULL or not where it is
 * called, so each case gets its own loop. */
static SPVS_ALWAYS_INLINE int32_t load(spvs_point_store_t *st, uint16_t *feat,
                                       const spvs_match_t *m, uint16_t n, uint16_t n_plane,
                                       const uint16_t *order, uint16_t stride)
{
    const spvs_real lim = (spvs_real)SPVS_MAX_COORD_PX;
    const spvs_real inv = SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE;
    spvs_real *const c0 = COL(st, 0), *const c1 = COL(st, 1);
    spvs_real *const c2 = COL(st, 2), *const c3 = COL(st, 3);
    prefetch(m, (size_t)n * sizeof *m);
    uint16_t pos = 0;
    size_t off = 0;
    int32_t bad = 0;
    uint16_t k = 0;
    /* Each coordinate's largest magnitude so far, and the coordinates' sum:
     * the sum is NaN once a coordinate is NaN, and without a NaN the
     * largest magnitudes are exact (an infinity among them), so the range
     * test at the end (every largest magnitude within lim, no sum NaN)
     * fails exactly when a coordinate is not finite or out of range,
     * although spvs_v4_max may drop a NaN. */
    spvs_v4 amax = {0};
    spvs_v4 csum = {0};
    /* Four slots at a time: the four coordinates of a match are one vector,
     * transposed with the three others into columns.  Bound: n /
     * SPVS_VLANES groups. */
    for (; k + SPVS_VLANES <= n; k = (uint16_t)(k + SPVS_VLANES)) {
        spvs_v4 r[SPVS_VLANES];
        for (uint16_t j = 0; j < SPVS_VLANES; j++) {
            const spvs_match_t *const mi =
                slot_match(m, (uint16_t)(k + j), n_plane, order, stride, &pos, &off);
            const uint16_t f = mi->feature;
            bad |= f >= SPVS_MAX_FEATURES;
            feat[k + j] = f;
            const spvs_v4 c = spvs_v4_load(&mi->x_tgt);
            amax = spvs_v4_max(amax, spvs_v4_abs(c));
            csum += c;
            r[j] = c * inv;
        }
        /* (x y u v) rows to (x0 x1 x2 x3) ... columns. */
        const spvs_v4 t0 = SPVS_V4_SHUFFLE2(r[0], r[1], 0, 4, 1, 5);
        const spvs_v4 t1 = SPVS_V4_SHUFFLE2(r[0], r[1], 2, 6, 3, 7);
        const spvs_v4 t2 = SPVS_V4_SHUFFLE2(r[2], r[3], 0, 4, 1, 5);
        const spvs_v4 t3 = SPVS_V4_SHUFFLE2(r[2], r[3], 2, 6, 3, 7);
        *(spvs_v4u *)&c0[k] = SPVS_V4_SHUFFLE2(t0, t2, 0, 1, 4, 5);
        *(spvs_v4u *)&c1[k] = SPVS_V4_SHUFFLE2(t0, t2, 2, 3, 6, 7);
        *(spvs_v4u *)&c2[k] = SPVS_V4_SHUFFLE2(t1, t3, 0, 1, 4, 5);
        *(spvs_v4u *)&c3[k] = SPVS_V4_SHUFFLE2(t1, t3, 2, 3, 6, 7);
    }
    bad |= spvs_v4_any(~((amax <= lim) & (csum == csum)));
    spvs_real um = amax[2], vm = amax[3];
    /* The rest one slot at a time.  Bound: fewer than SPVS_VLANES slots. */
    for (; k < n; k++) {
        const spvs_match_t *const mi = slot_match(m, k, n_plane, order, stride, &pos, &off);
        spvs_real c[4];
        bad |= load_one(mi, &feat[k], c, &um, &vm);
        for (int j = 0; j < 4; j++) {
            COL(st, j)[k] = c[j];
        }
    }
    st->cur_max[0] = um * inv;
    st->cur_max[1] = vm * inv;
    return bad;
}

/* The inlier flags of H for points r..r + SPVS_VLANES (-1 or 0 lanes). */
static SPVS_ALWAYS_INLINE spvs_v4i score_row(const spvs_real *h, const spvs_point_store_t *st,
                                             size_t r, spvs_real t2, spvs_real c2)
{
    return hp_inlier_v(h, spvs_v4_load(&COL(st, 0)[r]), spvs_v4_load(&COL(st, 1)[r]),
                       spvs_v4_load(&COL(st, 2)[r]), spvs_v4_load(&COL(st, 3)[r]), t2, c2);
}

/* cnt plus the inliers of H among points r..end, a row of lanes at a time
 * (marked in mask[r..] when with_mask): what a block's groups leave. */
static SPVS_ALWAYS_INLINE spvs_v4i score_rows(const spvs_real *h, const spvs_point_store_t *st,
                                              size_t r, size_t end, spvs_real t2, spvs_real c2,
                                              uint8_t *mask, int with_mask, spvs_v4i cnt)
{
    SPVS_UNROLL
    for (; r < end; r += SPVS_VLANES) {
        const spvs_v4i in = score_row(h, st, r, t2, c2);
        cnt -= in;
        if (with_mask) {
            spvs_v4_store_flags(in, mask + r);
        }
    }
    return cnt;
}

/* Rows of lanes whose flags are stored together (spvs_v4_store_flags4). */
#define FLAG_ROWS 4
_Static_assert(FLAG_ROWS == 4, "spvs_v4_store_flags4 takes four rows");

/* The inliers of H among points i..i + SPVS_SCORE_BLOCK, marked in
 * mask[i..] when with_mask; returns their count.  The flags of FLAG_ROWS
 * rows go out in one store, the rows a group leaves over one at a time. */
static SPVS_ALWAYS_INLINE int32_t score_block(const spvs_real *h, const spvs_point_store_t *st,
                                              size_t i, spvs_real t2, spvs_real c2, uint8_t *mask,
                                              int with_mask)
{
    const size_t group = FLAG_ROWS * SPVS_VLANES;
    const size_t end = i + SPVS_SCORE_BLOCK;
    const size_t end_groups = i + SPVS_SCORE_BLOCK / group * group;
    spvs_v4i cnt = {0};
    size_t r = i;
    SPVS_UNROLL
    for (; r < end_groups; r += group) {
        spvs_v4i in[FLAG_ROWS];
        SPVS_UNROLL
        for (int q = 0; q < FLAG_ROWS; q++) {
            in[q] = score_row(h, st, r + (size_t)q * SPVS_VLANES, t2, c2);
            cnt -= in[q];
        }
        if (with_mask) {
            spvs_v4_store_flags4(in[0], in[1], in[2], in[3], mask + r);
        }
    }
    return (int32_t)spvs_v4i_sum(score_rows(h, st, r, end, t2, c2, mask, with_mask, cnt));
}

#if SPVS_AVX2
/* The inlier flags of H for points r..r + 8 (score_row's, two rows). */
static SPVS_ALWAYS_INLINE spvs_v8i score_row8(const spvs_real *h, const spvs_point_store_t *st,
                                              size_t r, spvs_real t2, spvs_real c2)
{
    return hp_inlier_v8(h, spvs_v8_load(&COL(st, 0)[r]), spvs_v8_load(&COL(st, 1)[r]),
                        spvs_v8_load(&COL(st, 2)[r]), spvs_v8_load(&COL(st, 3)[r]), t2, c2);
}

/* score_block on eight lanes: the same flags (each lane's test is
 * score_row's) and the same count. */
static SPVS_ALWAYS_INLINE int32_t score_block8(const spvs_real *h, const spvs_point_store_t *st,
                                               size_t i, spvs_real t2, spvs_real c2,
                                               uint8_t *mask, int with_mask)
{
    const size_t end = i + SPVS_SCORE_BLOCK;
    spvs_v4i cnt = {0};
    size_t r = i;
    SPVS_UNROLL
    for (; r + 16u <= end; r += 16u) {
        const spvs_v8i a = score_row8(h, st, r, t2, c2);
        const spvs_v8i b = score_row8(h, st, r + 8u, t2, c2);
        cnt -= (spvs_v8i_lo(a) + spvs_v8i_hi(a)) + (spvs_v8i_lo(b) + spvs_v8i_hi(b));
        if (with_mask) {
            spvs_v4_store_flags4(spvs_v8i_lo(a), spvs_v8i_hi(a), spvs_v8i_lo(b), spvs_v8i_hi(b),
                                 mask + r);
        }
    }
    return (int32_t)spvs_v4i_sum(score_rows(h, st, r, end, t2, c2, mask, with_mask, cnt));
}
#endif

/* One block of spvs_pts_score, the whole block counted on SIMD lanes;
 * returns 0 when the count stops: `need` can no longer be reached, or the
 * bail-out test fails (both tested once per block).  With need = 0
 * neither can happen (every count reaches 0, and none falls below a share
 * of 0), so neither is tested. */
static SPVS_ALWAYS_INLINE int score_blockwise(const spvs_point_store_t *st, const spvs_real *h,
                                              size_t i, spvs_real t2, spvs_real c2,
                                              const score_stop_t *stop, uint8_t *mask,
                                              int32_t *inl, int wide)
{
    (void)wide;
#if SPVS_AVX2
    if (wide) {
        *inl += mask ? score_block8(h, st, i, t2, c2, mask, 1)
                     : score_block8(h, st, i, t2, c2, mask, 0);
    } else
#endif
    {
        *inl += mask ? score_block(h, st, i, t2, c2, mask, 1)
                     : score_block(h, st, i, t2, c2, mask, 0);
    }
    return stop->need == 0u || keeps_on(stop, i + SPVS_SCORE_BLOCK, *inl);
}

/* The points [i, n) after the last whole block: rows of lanes, each
 * followed by the test of score_blockwise (a count stopped there is below
 * `need` all the same), then the last few points one at a time. */
static SPVS_ALWAYS_INLINE void score_tail(const spvs_point_store_t *st, const spvs_real *h,
                                          size_t i, size_t n, spvs_real t2, spvs_real c2,
                                          int32_t max_out, uint8_t *mask, int32_t *inl)
{
    /* Bound: fewer than SPVS_SCORE_BLOCK / SPVS_VLANES rows. */
    for (; i + SPVS_VLANES <= n; i += SPVS_VLANES) {
        const spvs_v4i in = score_row(h, st, i, t2, c2);
        if (mask) {
            spvs_v4_store_flags(in, mask + i);
        }
        *inl -= (int32_t)spvs_v4i_sum(in);
        if ((int32_t)(i + SPVS_VLANES) - *inl > max_out) {
            return;
        }
    }
    (void)score_points(st, h, i, n, t2, c2, max_out, mask, inl);
}

spvs_real spvs_pts_cost(const spvs_point_store_t *st, uint16_t n, const spvs_real H[9],
                        const uint8_t *mask)
{
    spvs_real lane[SUM_LANES] = {SPVS_R(0.0), SPVS_R(0.0), SPVS_R(0.0), SPVS_R(0.0)};
    /* A point not flagged adds +0, which leaves a lane's sum (never -0) as
     * it was. */
    spvs_v4 acc = {0};
    uint16_t i0 = 0;
    /* Bound: n / SUM_LANES rows. */
    for (; i0 + SUM_LANES <= n; i0 = (uint16_t)(i0 + SUM_LANES)) {
        spvs_v4 w, ex, ey;
        const spvs_v4 e =
            hp_e2_v(H, spvs_v4_load(&COL(st, 0)[i0]), spvs_v4_load(&COL(st, 1)[i0]),
                    spvs_v4_load(&COL(st, 2)[i0]), spvs_v4_load(&COL(st, 3)[i0]), &w, &ex, &ey);
        const spvs_v4i in = spvs_v4_flags(mask + i0);
        acc += (spvs_v4)((spvs_v4i)e & in);
    }
    for (int j = 0; j < SUM_LANES; j++) {
        lane[j] = acc[j];
    }
    /* The rest of each lane, in point order.  Bound: fewer than SUM_LANES. */
    for (uint16_t j = 0; j < SUM_LANES; j++) {
        for (uint16_t i = (uint16_t)(i0 + j); i < n; i = (uint16_t)(i + SUM_LANES)) {
            if (mask[i]) {
                spvs_real w, ex, ey;
                lane[j] += hp_e2(H, at(st, i, 0), at(st, i, 1), at(st, i, 2), at(st, i, 3), &w,
                                 &ex, &ey);
            }
        }
    }
    return (lane[0] + lane[1]) + (lane[2] + lane[3]);
}

#if SPVS_AVX2
static SPVS_TARGET_AVX2 uint16_t score_avx2(const spvs_point_store_t *st, size_t n,
                                            const spvs_real H[9], spvs_real t2, spvs_real c2,
                                            const score_stop_t *stop, uint8_t *mask)
{
    return score_run(st, n, H, t2, c2, stop, mask, 1);
}
#endif

static SPVS_ALWAYS_INLINE uint16_t score_count(const spvs_point_store_t *st, size_t n,
                                               const spvs_real H[9], spvs_real t2, spvs_real c2,
                                               const score_stop_t *stop, uint8_t *mask)
{
#if SPVS_AVX2
    if (spvs_have_avx2()) {
        return score_avx2(st, n, H, t2, c2, stop, mask);
    }
#endif
    return score_run(st, n, H, t2, c2, stop, mask, 0);
}
