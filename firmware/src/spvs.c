/*
 * spvs.c - the update pipeline (spvs.h), one frame at a time in the paper's
 * order: check the frame, estimate the plane homography H (plane_h.h), find
 * the off-plane points, the epipole and the parallax (offplane.h,
 * epipole.h), and run the controller (control.h).  The flow and its
 * rules are pipeline.inc's, written once for this core and the
 * fixed-point one (fixed/spvs_q.c); this file gives it the float stages.
 *
 * Stage to file (float core; the fixed-point side of each is in fixed/):
 *   frame check              common.c (spvs_match_list_check, both cores)
 *   loader                   plane_h.c, plane_h.inc, points.c (accel:
 *                            accel/points_columns.c)
 *   RANSAC, LO, refit        ransac.c, ransac.inc, homography.c, h_point.inc
 *   Sampson inlier test      h_point.inc (hp_inlier)
 *   off-plane memory         offplane.c, offplane.inc
 *   epipole                  epipole.c, epipole.inc
 *   controller, arrival      control.c, control_steps.inc
 *   the flow of one frame    pipeline.inc
 * A .inc is written once for both cores.  Where it defines an entry point
 * or calls one of two functions that take the same arguments, it names
 * both, SPVS_CORE_NAME(float name, fixed-point name), so that grep finds
 * every function under its own name; the including file picks one.
 */
#include <math.h>
#include <string.h>

#include "core_util.h"
#include "spvs/instance.h"

spvs_real spvs_inlier_px(const spvs_params_t *p)
{
    return p->noise_px * SPVS_SQRT((spvs_real)SPVS_INLIER_CHI2_X100 / SPVS_R(100.0));
}

/* ---- the float core's side of pipeline.inc ----------------------------- */

typedef spvs_state_t pl_t;
typedef spvs_control_input_t pl_input_t;
typedef spvs_epipole_t pl_epipole_t;
typedef spvs_real pl_time_t;
typedef spvs_real pl_wide_t;
typedef spvs_real pl_ex_t;
typedef spvs_real pl_par_t;
typedef spvs_real pl_cmd_t;
#define SPVS_CORE_NAME(float_name, fixed_name) float_name
#define PL_INLINE

/* H_px (pixels) in scaled units as the loaded frame's estimate. */
static int adopt_h(spvs_state_t *s, const spvs_real *H_px)
{
    spvs_real H_sc[9];
    for (int k = 0; k < 9; k++) {
        H_sc[k] = H_px[k];
    }
    spvs_h_rescale(H_sc, SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
    return spvs_plane_h_adopt(&s->est, H_sc, spvs_inlier_px(&s->p));
}

static int plane_estimate(spvs_state_t *s, uint32_t *iters)
{
    return spvs_plane_h_estimate(&s->est, spvs_inlier_px(&s->p), s->p.confidence,
                                 s->p.max_iters, &s->rng, iters);
}

static void h_to_output(const spvs_state_t *s, spvs_output_t *out)
{
    for (int k = 0; k < 9; k++) {
        out->H[k] = s->est.H_sc[k];
    }
    spvs_h_rescale(out->H, (spvs_real)SPVS_COORD_SCALE);
}

static int time_in(spvs_real t_s, spvs_real *t)
{
    *t = t_s;
    return spvs_is_finite(t_s) ? SPVS_OK : SPVS_E_NONFINITE;
}

static int frame_epipole(spvs_state_t *s, spvs_epipole_t *ep, spvs_real *parallax)
{
    spvs_offplane_t *const o = &s->off;
    spvs_offplane_collect(o, &s->est, s->p.offplane_px);
    *parallax = spvs_offplane_known_parallax_px(o, s->est.H_sc, s->ework.n2);
    /* The parallax's direction, for the arrival check only. */
    const int dir = s->ctl.arriving && *parallax >= SPVS_R(0.0);
    s->lateral_px = dir ? spvs_offplane_known_direction_px(o, s->est.H_sc, 0, s->ework.n2)
                        : SPVS_R(0.0);
    s->radial_px =
        dir ? spvs_offplane_known_direction_px(o, s->est.H_sc, &s->lateral_px, s->ework.n2)
            : SPVS_R(0.0);
    const spvs_real sin_tol2 = s->p.epipole_sin_tol * s->p.epipole_sin_tol;
    return spvs_epipole_estimate(s->est.H_sc, (const spvs_real(*)[4])o->cand_pts,
                                 o->cand_ord, o->n_cand, sin_tol2, s->p.min_support, ep,
                                 o->support, &s->ework) == SPVS_OK;
}

static spvs_real ep_x(const spvs_epipole_t *ep)
{
    return ep->e_x_px;
}

static spvs_real ep_parallax(const spvs_epipole_t *ep)
{
    return ep->parallax_px;
}

static void offplane_learn(spvs_state_t *s, int e_ok, spvs_real parallax)
{
    spvs_offplane_remember(&s->off, &s->est, e_ok, parallax, s->p.offplane_px);
}

static void sort_ex(spvs_real *v, uint16_t n)
{
    spvs_sort_small(v, n);
}

/* The controller reads only the sign of e_dir_z (control.h). */
static void input_epipole(spvs_control_input_t *in, spvs_real x, int8_t side,
                          const spvs_epipole_t *ep)
{
    in->e_x_px = x;
    in->e_dir_x = ep->dir_x;
    in->e_dir_z = (spvs_real)side;
}

/* The controller's input but for the epipole: H in pixels (out->H). */
static void control_input(const spvs_state_t *s, spvs_control_input_t *in, spvs_real t_s, int e_ok,
                          spvs_real parallax, const spvs_output_t *out)
{
    for (int k = 0; k < 9; k++) {
        in->H[k] = out->H[k];
    }
    in->e_x_px = SPVS_R(0.0);
    in->e_dir_x = SPVS_R(0.0);
    in->e_dir_z = SPVS_R(0.0);
    in->parallax_px = parallax;
    in->parallax_x_px = s->lateral_px;
    in->parallax_r_px = s->radial_px;
    in->t_s = t_s;
    in->e_valid = (uint8_t)e_ok;
    in->n_inliers = out->n_inliers;
}

static spvs_real input_ex(const spvs_control_input_t *in)
{
    return in->e_x_px;
}

static int control_step(spvs_state_t *s, const spvs_control_input_t *in, spvs_real *v, spvs_real *w)
{
    return spvs_control_step(&s->ctl, &s->p.ctl, in, v, w);
}

static spvs_real cmd_out(spvs_real x)
{
    return x;
}

static spvs_real px_out(spvs_real x)
{
    return x;
}

static spvs_real stat_out(spvs_real x)
{
    return x;
}

static spvs_real threshold_out(const spvs_state_t *s)
{
    return s->p.ctl.arrival_k;
}

#include "pipeline.inc"

int spvs_init(spvs_t *inst, const spvs_params_t *p)
{
    if (inst == 0 || p == 0) {
        return SPVS_E_ARG;
    }
    int rc = pipeline_rules(p);
    if (rc != SPVS_OK) {
        return rc;
    }
    spvs_state_t *s = spvs_state(inst);
    s->p = *p;
    spvs_reset(inst);
    return SPVS_OK;
}

void spvs_reset(spvs_t *inst)
{
    SPVS_ASSERT(inst != 0);
    spvs_state_t *s = spvs_state(inst);
    spvs_control_reset(&s->ctl);
    spvs_rng_seed(&s->rng, s->p.seed);
    reset_frames(s);
    spvs_offplane_reset(&s->off);
}

int spvs_estimate_h(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_output_t *out)
{
    return estimate_only(spvs_state(s), m, n, out);
}

int spvs_update(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                spvs_output_t *out)
{
    return update(spvs_state(s), m, n, t_s, 0, out);
}

int spvs_update_with_h(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                       const spvs_real H_px[9], spvs_output_t *out)
{
    return update_with_h(spvs_state(s), m, n, t_s, H_px, out);
}

spvs_step_t spvs_step(const spvs_t *s)
{
    return spvs_state_c(s)->ctl.step;
}
