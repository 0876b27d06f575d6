/*
 * offplane.h - the points off the dominant plane: the memory of which
 * target features are off it, and the frame's off-plane candidates for the
 * epipole and the parallax (DESIGN.md section 2).
 *
 * Candidates: the matches of remembered off-plane features first, then the
 * plane candidates that H rejects with a transfer error above offplane_px
 * both forward (in the current image) and back (in the target image).
 *
 * Memory: a candidate with a large transfer error that also agrees with the
 * epipole raises its target feature's score; at SPVS_OFFPLANE_ON the
 * feature is off the plane and stays out of the homography estimate until
 * spvs_offplane_reset, so that near the target, where its parallax shrinks
 * under the inlier threshold, it cannot bias H.  A plane inlier seen while
 * the scene shows clear parallax (above SPVS_PARALLAX_CLEAR x offplane_px)
 * lowers its score.  Scores stay within SPVS_OFFPLANE_MIN..SPVS_OFFPLANE_MAX.
 *
 * Bounds: every loop runs over at most SPVS_MAX_MATCHES matches or
 * SPVS_MAX_OFFPLANE candidates.
 */
#ifndef SPVS_OFFPLANE_H
#define SPVS_OFFPLANE_H

#include "spvs/common.h"
#include "spvs/plane_h.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    /* The memory: a score per target feature, and how many features are
     * off the plane now (score >= SPVS_OFFPLANE_ON). */
    int8_t score[SPVS_MAX_FEATURES];
    uint16_t n_known;
    /* This frame's candidates: n_cand of them, the first n_cand_known the
     * remembered features; point index in the estimator, the point as a
     * row (scaled units), the epipole's order over them (0..n_cand) and
     * whether each supports the epipole. */
    uint16_t n_cand;
    uint16_t n_cand_known;
    uint16_t cand[SPVS_MAX_OFFPLANE];
    spvs_real cand_pts[SPVS_MAX_OFFPLANE][4];
    uint16_t cand_ord[SPVS_MAX_OFFPLANE];
    uint8_t support[SPVS_MAX_OFFPLANE];
} spvs_offplane_t;

/* The fixed-point core's memory (fixed/offplane_q.h): each entry point
 * below is written once (offplane.inc) and declared for both cores, the
 * float one first.  The Q one takes H in Q27 scaled units, rows in Q26 and
 * pixel quantities in Q16 pixels (int32; docs/FIXED.md). */
typedef struct spvs_q_offplane spvs_q_offplane_t;

/* Forget every feature. */
void spvs_offplane_reset(spvs_offplane_t *o);
void spvs_q_offplane_reset(spvs_q_offplane_t *o);

/* Splits the matches m[0..n) (n <= SPVS_MAX_MATCHES) for
 * spvs_plane_h_load: order[] gets the indices of the matches whose feature
 * is not known to be off the plane, in input order, then the others from
 * the back.  Returns the number of the former. */
uint16_t spvs_offplane_split(const spvs_offplane_t *o, const spvs_match_t *m, uint16_t n,
                             uint16_t order[SPVS_MAX_MATCHES]);
uint16_t spvs_q_offplane_split(const spvs_q_offplane_t *o, const spvs_match_t *m, uint16_t n,
                               uint16_t order[SPVS_MAX_MATCHES]);

/* Collects this frame's candidates from the estimate e (its points, H and
 * inlier mask); offplane_px is the transfer error, pixels, above which a
 * rejected plane candidate is one (in Q16, negative is taken as 0).  At
 * most SPVS_MAX_OFFPLANE. */
void spvs_offplane_collect(spvs_offplane_t *o, const spvs_plane_h_t *e, spvs_real offplane_px);
void spvs_q_offplane_collect(spvs_q_offplane_t *o, const spvs_q_plane_h_t *e,
                             int32_t offplane_q16);

/* Median transfer error, pixels, of the remembered features' candidates
 * under H_sc (scaled units); negative when none is in view (-1 px in Q16;
 * the Q error's relative error is 2^-27 plus 1/2 unit, saturated below
 * 2^15 px).  scratch: SPVS_MAX_OFFPLANE values. */
spvs_real spvs_offplane_known_parallax_px(const spvs_offplane_t *o, const spvs_real H_sc[9],
                                          spvs_real *scratch);
int32_t spvs_q_offplane_known_parallax_q16(const spvs_q_offplane_t *o, const int32_t H[9],
                                           int32_t *scratch);

/* The median of one component of the same candidates' transfer errors,
 * signed, pixels (current minus transferred goal point; 0 when none is in
 * view): with lateral NULL the horizontal one, the arrival check's
 * sideways residual; else the one along the current point's radius of the
 * error less *lateral horizontally, its residual along the optical axis.
 * scratch: SPVS_MAX_OFFPLANE values. */
spvs_real spvs_offplane_known_direction_px(const spvs_offplane_t *o, const spvs_real H_sc[9],
                                           const spvs_real *lateral, spvs_real *scratch);
int32_t spvs_q_offplane_known_direction_q16(const spvs_q_offplane_t *o, const int32_t H[9],
                                            const int32_t *lateral, int32_t *scratch);

/* Updates the memory after the epipole: e_ok says whether it was found
 * (o->support then holds its supporters), parallax_px is the frame's
 * parallax.  The Q core's collect notes its H and threshold: where they
 * are e's and offplane_q16, the candidates it tested (from n_cand_known
 * on) are above the threshold forward without a second test. */
void spvs_offplane_remember(spvs_offplane_t *o, const spvs_plane_h_t *e, int e_ok,
                            spvs_real parallax_px, spvs_real offplane_px);
void spvs_q_offplane_remember(spvs_q_offplane_t *o, const spvs_q_plane_h_t *e, int e_ok,
                              int32_t parallax_q16, int32_t offplane_q16);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_OFFPLANE_H */
