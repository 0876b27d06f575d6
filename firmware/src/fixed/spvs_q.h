/*
 * spvs_q.h - the update pipeline in fixed point: spvs.h's spvs_update on
 * the Q stages, one call per frame, matches in and command out (private;
 * formats in docs/FIXED.md).
 *
 *   matches -> H: the Q estimator (plane_h_q.h: RANSAC, re-selection,
 *              refit on the Q26 store, H in Q27)
 *           -> off-plane candidates and memory (offplane_q.h)
 *           -> epipole and parallax (epipole_q.h), the epipole median
 *           -> step logic and control law (control_q.h) -> (v, w)
 *
 * The interface is the float core's: the parameters (spvs_params_t), the
 * matches (spvs_match_t) and the output (spvs_output_t) keep the core's
 * scalar, read and written through their bits with integer operations only
 * (q.h: spvs_q_ieee_f32 / f64 in, spvs_q_ieee_bits out), so a caller of
 * spvs_update can call spvs_q_update instead with nothing else changed, and
 * the simulator runs either core (spvs-sim --transport fixed).
 *
 * Where it differs from the float core (each a range of a Q format):
 *   - the frame time is Q16 seconds: |t_s| < 32768 s (9.1 hours), else
 *     SPVS_E_RANGE; two frames less than 2^-16 s (15 us) apart are one
 *     time, so the second is SPVS_E_STALE;
 *   - an H entry outside (-16, 16) in scaled units is no model (the
 *     estimator's range; docs/FIXED.md measures that no consensus is lost);
 *   - the parameters are checked on their bits by the float core's rules
 *     (pipeline.inc's and control_steps.inc's, written once) and by their
 *     Q conversions: a value beyond its Q format is SPVS_E_CONFIG.
 *   - spvs_q_update_with_h refuses an H entry outside that range
 *     (SPVS_E_RANGE), where the float core would score it.
 * Linked alone (firmware/src/fixed/, rng.c, common.c) it references no
 * floating-point helper, heap or stdio (docs/FIXED.md).
 */
#ifndef SPVS_FIXED_SPVS_Q_H
#define SPVS_FIXED_SPVS_Q_H

#include "control_q.h"
#include "epipole_q.h"
#include "offplane_q.h"
#include "plane_h_q.h"
#include "spvs/spvs.h"

typedef struct {
    spvs_q_ctl_params_t ctl_p;
    spvs_qf_t t2;             /* squared inlier threshold, scaled units^2  */
    uint32_t confidence_q32;  /* RANSAC's confidence 2^-32                 */
    uint32_t max_iters;
    int32_t offplane_q16;     /* pixels, Q16                              */
    int32_t sin_tol2_q30;     /* the epipole's support cone, sine^2, Q30  */
    uint16_t min_support;
    int32_t max_frame_gap_s;  /* seconds, Q16                             */
    uint32_t seed;
} spvs_q_params_t;

typedef struct spvs_q_s {
    spvs_q_params_t p;
    spvs_q_ctl_t ctl;
    spvs_rng_t rng;
    int32_t last_t_s;         /* s, Q16: the last update's time           */
    int32_t last_good_t_s;    /* s, Q16: the last frame with a valid H    */
    uint8_t has_last;
    uint8_t has_good;
    spvs_q_plane_h_t est;
    spvs_q_offplane_t off;
    spvs_q_epipole_work_t ework;
    int32_t scratch[SPVS_MAX_OFFPLANE];
    /* The last SPVS_EPIPOLE_MEDIAN epipole estimates (x, Q16 px; side). */
    int32_t ehist_x[SPVS_EPIPOLE_MEDIAN];
    int8_t ehist_z[SPVS_EPIPOLE_MEDIAN];
    uint8_t n_ehist;
    uint8_t i_ehist;
    int32_t lateral_q16;      /* the frame's horizontal and radial         */
    int32_t radial_q16;       /*   parallax, Q16 px, while arriving        */
} spvs_q_t;

/* spvs_init: p converted and checked (SPVS_E_ARG for NULL, SPVS_E_CONFIG
 * for a value out of range, spvs.c's rules and the Q formats'). */
SPVS_NODISCARD int spvs_q_init(spvs_q_t *s, const spvs_params_t *p);

/* spvs_reset. */
void spvs_q_reset(spvs_q_t *s);

/* spvs_update: the same contract and statuses (and SPVS_E_RANGE for a
 * time outside Q16's range, above). */
SPVS_NODISCARD int spvs_q_update(spvs_q_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                                 spvs_output_t *out);

/* spvs_update_with_h: H_px from the caller (H_cur_tgt in centred pixels,
 * planar form, h22 = 1; its middle row is taken as (0, 1, 0)) instead of
 * the estimate, read through its bits into Q27 scaled units (h13 in
 * pixels rounded to 2^-18 px, h31 and h32 per pixel to 2^-36, the others
 * to 2^-27).  The frame is checked and loaded as in spvs_q_update, the
 * plane candidates within the pipeline's inlier threshold of H (the Q
 * inlier count) are its inliers, and the rest of the pipeline (off-plane
 * memory, epipole, controller) runs unchanged; the PRNG is not drawn.
 * out->H is H_px as the pipeline holds it (rounded as above).
 * Returns spvs_q_update's statuses (SPVS_E_NO_CONSENSUS when fewer than
 * SPVS_MIN_INLIERS candidates are inliers of H_px), SPVS_E_ARG for H_px
 * NULL, SPVS_E_DEGENERATE for a NaN or infinite entry of rows 1 and 3 (as
 * the float core) and SPVS_E_RANGE for one outside (-16, 16) in scaled
 * units (|h11|, |h12|, |h33| >= 16, |h13| >= 8192 px, |h31|, |h32| >=
 * 1/32 per pixel); on every error (v, w) = (0, 0). */
SPVS_NODISCARD int spvs_q_update_with_h(spvs_q_t *s, const spvs_match_t *m, uint16_t n,
                                        spvs_real t_s, const spvs_real H_px[9],
                                        spvs_output_t *out);

/* spvs_inlier_px: noise_px sqrt(SPVS_INLIER_CHI2_X100 / 100), pixels, in
 * integers: in float32 the float core's value bit for bit (each of its
 * roundings made as the FPU makes it), in double within 2^-28.  The Q
 * pipeline's own threshold, spvs_q_params_t's t2, is made from noise_px
 * rounded to Q16 pixels. */
spvs_real spvs_q_inlier_px(const spvs_params_t *p);

/* spvs_estimate_h: the frame checked and loaded, the remembered off-plane
 * features kept out, H estimated (out->H in centred pixels, n_matches,
 * n_inliers, ransac_iters, h_valid, status; the command (0, 0)); the
 * off-plane memory and the controller are not touched. */
SPVS_NODISCARD int spvs_q_estimate_h(spvs_q_t *s, const spvs_match_t *m, uint16_t n,
                                     spvs_output_t *out);

#endif /* SPVS_FIXED_SPVS_Q_H */
