/*
 * load_q.c - the fixed-point loader, the reference path (points_q.h:
 * spvs_q_pts_load): every coordinate by the general IEEE conversion
 * (q.h's spvs_q_from_ieee).  Built where SPVS_ACCEL is OFF;
 * accel/load_fast_q.c converts a float32 in 32-bit operations with the
 * same results.
 */
#include "load_q.h"

/* One coordinate c in Q26 scaled units, its flags into *bad, its doubled
 * magnitude into *mag2 (load_umag2). */
static int32_t load_coord(spvs_real c, uint32_t *bad, uint32_t *mag2)
{
    uint32_t f = 0;
    int below = 0;
    const int32_t q = spvs_q_from_ieee(spvs_q_real_parts(c), LOAD_PX_FRAC, &f, &below);
    *bad |= load_flags(q, f, below, LOAD_LIM);
    *mag2 = load_umag2(q);
    return q;
}

uint32_t spvs_q_pts_load(spvs_q_store_t *st, uint16_t *feat, const spvs_match_t *m, uint16_t n,
                         uint16_t n_plane, const uint16_t *order, uint16_t stride)
{
    uint32_t bad = 0;
    load_max_t mx = {0u, 0u, 0u, 0u};
    uint16_t pos = 0;
    /* Bound: n slots. */
    for (uint16_t k = 0; k < n; k++) {
        const spvs_match_t *mi = &m[spvs_slot_source(k, n_plane, order, stride, &pos)];
        feat[k] = mi->feature;
        bad |= mi->feature >= SPVS_MAX_FEATURES ? SPVS_Q_SAT : 0u;
        int32_t *const r = &st->v[4u * k];
        uint32_t ax, ay, au, av;
        r[0] = load_coord(mi->x_tgt, &bad, &ax);
        r[1] = load_coord(mi->y_tgt, &bad, &ay);
        r[2] = load_coord(mi->x_cur, &bad, &au);
        r[3] = load_coord(mi->y_cur, &bad, &av);
        load_max(&mx, ax, ay, au, av);
    }
    load_finish(st, &mx);
    return bad;
}
