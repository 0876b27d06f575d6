/*
 * points.c - the frame's points in rows, read one point at a time: the
 * reference layout (points.h), which the Cortex-M images and every build
 * without accelerators (SPVS_ACCEL=OFF) use.  Point i of the store is
 * v[4 i .. 4 i + 3] = (x_tgt, y_tgt, x_cur, y_cur).  The loops that are the
 * same in every layout are points.inc; accel/points_columns.c is the layout
 * on SIMD lanes, which gives the same bits.
 */
#include "points.inc"

#define ROWS(st) ((const spvs_real(*)[4])(st)->v)

static SPVS_ALWAYS_INLINE spvs_real at(const spvs_point_store_t *st, size_t i, int k)
{
    return st->v[4u * i + (size_t)k];
}

int spvs_pts_solve3(const spvs_point_store_t *st, const uint16_t idx[3], spvs_real H_out[9])
{
    const spvs_real *const c[4] = {&st->v[0], &st->v[1], &st->v[2], &st->v[3]};
    return spvs_h_solve3_strided(c, idx, 4u, H_out);
}

static SPVS_ALWAYS_INLINE int32_t sum_store(int kind, int nt, int count, const spvs_real *H,
                                            const spvs_point_store_t *st, const uint8_t *use,
                                            uint16_t n, spvs_real *out)
{
    return sum_rows(kind, nt, count, H, ROWS(st), use, n, out);
}

static SPVS_ALWAYS_INLINE int32_t load(spvs_point_store_t *st, uint16_t *feat,
                                       const spvs_match_t *m, uint16_t n, uint16_t n_plane,
                                       const uint16_t *order, uint16_t stride)
{
    const spvs_real inv = SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE;
    spvs_real(*const rows)[4] = (spvs_real(*)[4])st->v;
    uint16_t pos = 0;
    int32_t bad = 0;
    /* The largest |x_cur| and |y_cur| so far. */
    spvs_real um = SPVS_R(0.0), vm = SPVS_R(0.0);
    /* Bound: n slots. */
    for (uint16_t k = 0; k < n; k++) {
        const uint16_t i = spvs_slot_source(k, n_plane, order, stride, &pos);
        bad |= load_one(&m[i], &feat[k], rows[k], &um, &vm);
    }
    st->cur_max[0] = um * inv;
    st->cur_max[1] = vm * inv;
    return bad;
}

/* One block of spvs_pts_score point by point, so `need` is tested at every
 * point, then the bail-out test. */
static SPVS_ALWAYS_INLINE int score_blockwise(const spvs_point_store_t *st, const spvs_real *h,
                                              size_t i, spvs_real t2, spvs_real c2,
                                              const score_stop_t *stop, uint8_t *mask,
                                              int32_t *inl, int wide)
{
    (void)wide;
    return score_points(st, h, i, i + SPVS_SCORE_BLOCK, t2, c2, stop->max_out, mask, inl) &&
           !bails(stop->p, stop->bail_var, i + SPVS_SCORE_BLOCK, *inl);
}

/* The points [i, n) after the last whole block, one at a time. */
static SPVS_ALWAYS_INLINE void score_tail(const spvs_point_store_t *st, const spvs_real *h,
                                          size_t i, size_t n, spvs_real t2, spvs_real c2,
                                          int32_t max_out, uint8_t *mask, int32_t *inl)
{
    (void)score_points(st, h, i, n, t2, c2, max_out, mask, inl);
}

static SPVS_ALWAYS_INLINE uint16_t score_count(const spvs_point_store_t *st, size_t n,
                                               const spvs_real H[9], spvs_real t2, spvs_real c2,
                                               const score_stop_t *stop, uint8_t *mask)
{
    return score_run(st, n, H, t2, c2, stop, mask, 0);
}

spvs_real spvs_pts_cost(const spvs_point_store_t *st, uint16_t n, const spvs_real H[9],
                        const uint8_t *mask)
{
    spvs_real lane[SUM_LANES] = {SPVS_R(0.0), SPVS_R(0.0), SPVS_R(0.0), SPVS_R(0.0)};
    /* Each lane in point order.  Bound: n points. */
    for (uint16_t j = 0; j < SUM_LANES; j++) {
        for (uint16_t i = j; i < n; i = (uint16_t)(i + SUM_LANES)) {
            if (mask[i]) {
                const spvs_real *p = ROWS(st)[i];
                spvs_real w, ex, ey;
                lane[j] += hp_e2(H, p[0], p[1], p[2], p[3], &w, &ex, &ey);
            }
        }
    }
    return (lane[0] + lane[1]) + (lane[2] + lane[3]);
}
