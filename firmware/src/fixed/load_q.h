/*
 * load_q.h - what the fixed-point loaders share (private to the core):
 * the reference loader (load_q.c) and the accelerated one
 * (accel/load_fast_q.c) round every coordinate the same way and keep the
 * same bounds of the frame.
 */
#ifndef SPVS_FIXED_LOAD_Q_H
#define SPVS_FIXED_LOAD_Q_H

#include "../core_util.h"
#include "point_q.h"

/* A pixel coordinate as Q26 scaled units: pixels in Q(26 - log2 scale) are
 * the same integers.  Flags a coordinate above SPVS_MAX_COORD_PX (compared
 * before rounding: a value just above the limit that rounds down to it is
 * still out) with SPVS_Q_SAT, NaN or infinity with SPVS_Q_NONFINITE. */

/* The loader's constants for SPVS_COORD_SCALE and SPVS_MAX_COORD_PX: the
 * pixels' fraction bits px_frac (pixels in Q(px_frac) are scaled units in
 * Q26), the limit lim (SPVS_MAX_COORD_PX in Q(px_frac), <= 2^30) and the
 * largest s of load_coord_mag's fixed-position rounding whose magnitudes
 * (at most 2^(24 + s)) stay below lim: 2^(24 + s) <= 2^(floor(log2 lim) -
 * 1), at most 7 (the shift 7 - s). */
#define LOAD_PX_FRAC (SPVS_QC - (31 - spvs_q_clz32((uint32_t)SPVS_COORD_SCALE)))
#define LOAD_LIM ((int32_t)(((int64_t)SPVS_MAX_COORD_PX << SPVS_QC) / SPVS_COORD_SCALE))
#define LOAD_S_LG (31 - spvs_q_clz32((uint32_t)LOAD_LIM) - 25)
#define LOAD_S_MAX (LOAD_S_LG > 7 ? 7 : LOAD_S_LG)

/* |q|, with INT32_MIN (a clamped value) as INT32_MAX. */
static inline int32_t q_abs_clamp(int32_t q)
{
    return q < 0 ? (q == SPVS_Q_I32_MIN ? SPVS_Q_I32_MAX : -q) : q;
}

/* 2 |q| for the loaders' maxima, |q| taken at most to COORD_LIM + 1 (the
 * store's bound is COORD_LIM beyond that): below 2^32. */
static inline uint32_t load_umag2(int32_t q)
{
    const uint32_t sg = (uint32_t)(q >> 31);
    const uint32_t a = ((uint32_t)q ^ sg) - sg;
    return 2u * (a > (uint32_t)COORD_LIM ? (uint32_t)COORD_LIM + 1u : a);
}

/* The frame's largest magnitudes while it loads, doubled (load_umag2). */
typedef struct {
    uint32_t xm, ym, um, vm;
} load_max_t;

/* The store's bound from a doubled maximum: at most COORD_LIM. */
static inline int32_t load_bound(uint32_t m2)
{
    const uint32_t a = m2 >> 1;
    return a > (uint32_t)COORD_LIM ? COORD_LIM : (int32_t)a;
}

/* The store's bounds from the loader's maxima mx.  On a bad frame the
 * clamped values are not in range: the bounds stay meaningful anyway. */
static inline void load_finish(spvs_q_store_t *st, const load_max_t *mx)
{
    st->cur_max[0] = load_bound(mx->um);
    st->cur_max[1] = load_bound(mx->vm);
    st->tgt_max[0] = load_bound(mx->xm);
    st->tgt_max[1] = load_bound(mx->ym);
}

/* The flags of coordinate q as the conversion left it (f its flags, below
 * nonzero where it rounded a magnitude just above the limit down to it):
 * SPVS_Q_NONFINITE, and SPVS_Q_SAT beyond lim (SPVS_MAX_COORD_PX in Q26
 * scaled units, LOAD_LIM), compared before rounding. */
static inline uint32_t load_flags(int32_t q, uint32_t f, int below, int32_t lim)
{
    const int32_t a = q_abs_clamp(q);
    return (f & SPVS_Q_NONFINITE) | ((a > lim || (a == lim && below)) ? SPVS_Q_SAT : 0u);
}

/* The maxima mx with a match's four doubled magnitudes. */
static inline void load_max(load_max_t *mx, uint32_t ax, uint32_t ay, uint32_t au, uint32_t av)
{
    mx->xm = ax > mx->xm ? ax : mx->xm;
    mx->ym = ay > mx->ym ? ay : mx->ym;
    mx->um = au > mx->um ? au : mx->um;
    mx->vm = av > mx->vm ? av : mx->vm;
}

#endif /* SPVS_FIXED_LOAD_Q_H */
