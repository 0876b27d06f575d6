/*
 * h_refit.h - a test oracle: the least-squares refit of a planar-motion H
 * on the forward transfer error, by plain Gauss-Newton on rows of points.
 * The core estimates H by the Sampson-weighted linear fit (plane_h.c); this
 * refit is what the tests hold it and the golden vectors against.  It
 * computes in spvs_real, so the Cortex-M images run it as the host does.
 */
#ifndef SPVS_TEST_H_REFIT_H
#define SPVS_TEST_H_REFIT_H

#include <stdint.h>

#include "spvs/spvs.h"

/* Most Gauss-Newton steps h_refit takes. */
#define H_REFIT_MAX_ITERS 5

/* Least-squares refit of H on the points flagged in `use`, minimising the
 * sum over them of |p_cur - dehom(H p_tgt)|^2 (the transfer error in the
 * current image) over theta = (h11 h12 h13 h31 h32 h33), by Gauss-Newton
 * from the H given.  Each step rebuilds the normal equations; a step that
 * raises the cost is undone and ends the refit, and so does one that gains
 * under 1e-4 of the cost.
 * pts: n rows (x_tgt, y_tgt, x_cur, y_cur) in scaled units (pixels /
 *      SPVS_COORD_SCALE); use: n flags; H: start value in, result out.
 * max_iters: steps at most, clamped to 1..H_REFIT_MAX_ITERS.
 * Returns SPVS_OK, SPVS_E_TOO_FEW (fewer than 3 flagged points) or
 * SPVS_E_DEGENERATE (a flagged point behind the camera at the start, or
 * singular normal equations at the start); on error H is unchanged. */
int h_refit(const spvs_real (*pts)[4], const uint8_t *use, uint16_t n, uint16_t max_iters,
            spvs_real H[9]);

#endif /* SPVS_TEST_H_REFIT_H */
