/*
 * params.c - the default parameters of docs/CONTROL.md: the control law's
 * (control.h) and the pipeline's (spvs.h).  Constants only, in a file of
 * their own, so that the fixed-point build (docs/FIXED.md), whose images
 * link no floating-point helper, takes the same defaults without linking
 * the float control law or pipeline.
 */
#include "spvs/common.h"
#include "spvs/control.h"

void spvs_control_params_default(spvs_control_params_t *p, spvs_method_t m)
{
    SPVS_ASSERT(p != 0);
    p->method = m;
    p->alpha_x = SPVS_R(800.0);
    p->alpha_y = SPVS_R(800.0);
    p->k_w3 = SPVS_R(0.002);
    p->k_w11 = SPVS_R(3.0);
    p->v_max = SPVS_R(0.5);
    p->w_max = SPVS_R(0.5);
    p->w_min_escape = SPVS_R(0.05);
    p->tol_h13_px = SPVS_R(0.5);
    p->lock_ex_px = SPVS_R(28.0); /* alpha_x tan(2 deg) */
    p->switch_parallax_px = SPVS_R(5.0);
    p->tol_det = SPVS_R(0.015);
    p->hold_heading_ratio = SPVS_R(0.1);
    p->min_signal_ratio = SPVS_R(0.1);
    p->step_timeout_s = SPVS_R(120.0);
    p->hold_frames = 3;
    p->fit_min_frames = 10;
    p->fit_min_span_m = SPVS_R(0.5);
    p->arrival_sigma_px = SPVS_R(1.0);
    p->arrival_k = SPVS_R(3.0);
    p->arrival_corner_x_px = SPVS_R(320.0);
    p->arrival_corner_y_px = SPVS_R(240.0);
    p->arrival_frames = 20;
    p->arrival_resolution_px = SPVS_R(0.5);
    switch (m) {
    case SPVS_METHOD_I:
        /* f of eq. (19) changes by about 2 (r/d) |n_x cos phi + n_z sin phi|
         * per radian: ~0.3 at r = 10 m, d = 45 m. */
        p->k_w = SPVS_R(5.0);
        p->k_v = SPVS_R(30.0);
        p->tol_align = SPVS_R(1.0e-4);
        p->tol_translate = SPVS_R(1.5e-4);
        break;
    case SPVS_METHOD_II:
        /* h12 changes by about (r/d) n_y per radian; alpha_y h32 by n_y / d
         * per metre. */
        p->k_w = SPVS_R(30.0);
        p->k_v = SPVS_R(40.0);
        p->tol_align = SPVS_R(1.0e-4);
        p->tol_translate = SPVS_R(1.5e-4);
        break;
    case SPVS_METHOD_III:
    default:
        /* e_x changes by alpha_x per radian. */
        p->k_w = SPVS_R(0.002);
        p->k_v = SPVS_R(30.0);
        p->tol_align = SPVS_R(0.5);
        p->tol_translate = SPVS_R(1.5e-4);
        break;
    }
}

void spvs_params_default(spvs_params_t *p, spvs_method_t method)
{
    SPVS_ASSERT(p != 0);
    spvs_control_params_default(&p->ctl, method);
    p->noise_px = SPVS_R(1.0);
    p->confidence = SPVS_R(0.99);
    p->max_iters = SPVS_RANSAC_MAX_ITERS;
    p->offplane_px = SPVS_R(8.0);
    p->epipole_sin_tol = SPVS_R(0.1);
    p->min_support = 3;
    p->max_frame_gap_s = SPVS_R(1.0);
    p->seed = 0;
}
