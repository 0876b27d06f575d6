/*
 * offplane_q.h - the off-plane memory and the frame's off-plane candidates
 * in fixed point: offplane.h's stages on the Q estimator
 * (spvs_q_plane_h_t: the Q26 store, H in Q27, the inlier mask).  Private;
 * formats and ranges in docs/FIXED.md.
 *
 * The same memory (an int8 score per target feature, SPVS_OFFPLANE_MIN..
 * SPVS_OFFPLANE_MAX, off the plane at SPVS_OFFPLANE_ON), the same
 * candidates in the same order (the remembered features' matches, then the
 * rejected plane candidates whose transfer error exceeds offplane_px
 * forward and, where H has an inverse, back), the same updates.
 *
 * Formats: the candidates' rows Q26 scaled units (the store's); transfer
 * errors squared in Q52 scaled units^2 (uint64, below 2^63) from
 * spvs_q_transfer (epipole_q.h); pixel quantities (offplane_px, the
 * parallax) in Q16 pixels, int32 (below 32,768 px; offplane_px's square
 * in Q52, 4 offplane_q16^2, then fits a uint64).  The transfer's
 * components saturate at 16,384 px, so a threshold below that decides as
 * on exact values (a saturated error is above it).  The inverse of H for
 * the back test in Q27: its entries from spvs_qf_t (relative 2^-28); an
 * inverse with an entry outside (-16, 16) is not used (the forward test
 * alone decides, and hi_out_of_range counts the frames; float would use
 * it).
 *
 * Bounds: every loop runs over at most SPVS_MAX_MATCHES matches or
 * SPVS_MAX_OFFPLANE candidates.
 */
#ifndef SPVS_FIXED_OFFPLANE_Q_H
#define SPVS_FIXED_OFFPLANE_Q_H

#include "epipole_q.h"
#include "plane_h_q.h"
#include "spvs/offplane.h"

struct spvs_q_offplane {
    /* The memory, as spvs_offplane_t's. */
    int8_t score[SPVS_MAX_FEATURES];
    uint16_t n_known;
    /* This frame's candidates, as spvs_offplane_t's, the rows in Q26. */
    uint16_t n_cand;
    uint16_t n_cand_known;
    uint16_t cand[SPVS_MAX_OFFPLANE];
    int32_t cand_pts[SPVS_MAX_OFFPLANE][4];
    uint16_t cand_ord[SPVS_MAX_OFFPLANE];
    uint8_t support[SPVS_MAX_OFFPLANE];
    /* Frames whose H had an inverse (|det| > 1e-9) outside Q27's range:
     * collected on the forward test alone. */
    uint16_t hi_out_of_range;
    /* The H and the threshold of the last collect, whose forward tests
     * the memory's update then reuses (each tested candidate from
     * n_cand_known on passed it). */
    int32_t cand_H[9];
    int32_t cand_thr;
};

#endif /* SPVS_FIXED_OFFPLANE_Q_H */
