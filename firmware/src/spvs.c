/*
 * spvs.c - the update pipeline (spvs.h), one frame at a time in the paper's
 * order: check the frame, estimate the plane homography H (plane_h.h), find
 * the off-plane points, the epipole and the parallax (offplane.h,
 * epipole.h), and run the controller (control.h).
 */
#include <math.h>

#include "core_util.h"
#include "spvs/spvs.h"

spvs_real spvs_inlier_px(const spvs_params_t *p)
{
    return p->noise_px * SPVS_SQRT((spvs_real)SPVS_INLIER_CHI2_X100 / SPVS_R(100.0));
}

static int params_check(const spvs_params_t *p)
{
    int rc = spvs_control_params_check(&p->ctl);
    if (rc != SPVS_OK) {
        return rc;
    }
    if (!(p->noise_px > SPVS_R(0.0) && p->noise_px < SPVS_R(300.0)) ||
        !(p->confidence > SPVS_R(0.0) && p->confidence < SPVS_R(1.0)) ||
        p->max_iters < 1u || p->max_iters > SPVS_RANSAC_MAX_ITERS ||
        !(p->offplane_px >= spvs_inlier_px(p)) ||
        !(p->epipole_sin_tol > SPVS_R(0.0) && p->epipole_sin_tol < SPVS_R(1.0)) ||
        p->min_support < 1u ||
        !(p->max_frame_gap_s > SPVS_R(0.0))) {
        return SPVS_E_CONFIG;
    }
    return SPVS_OK;
}

int spvs_init(spvs_t *s, const spvs_params_t *p)
{
    if (s == 0 || p == 0) {
        return SPVS_E_ARG;
    }
    int rc = params_check(p);
    if (rc != SPVS_OK) {
        return rc;
    }
    s->p = *p;
    spvs_reset(s);
    return SPVS_OK;
}

void spvs_reset(spvs_t *s)
{
    SPVS_ASSERT(s != 0);
    spvs_control_reset(&s->ctl);
    spvs_rng_seed(&s->rng, s->p.seed);
    s->last_t_s = SPVS_R(0.0);
    s->last_good_t_s = SPVS_R(0.0);
    s->has_last = 0;
    s->has_good = 0;
    s->est.n_plane = 0;
    s->est.n_pts = 0;
    s->n_ehist = 0;
    s->i_ehist = 0;
    spvs_offplane_reset(&s->off);
}

static void clear_output(spvs_output_t *out, uint16_t n)
{
    out->v = SPVS_R(0.0);
    out->w = SPVS_R(0.0);
    for (int k = 0; k < 9; k++) {
        out->H[k] = SPVS_R(0.0);
    }
    out->e_x_px = SPVS_R(0.0);
    out->parallax_px = SPVS_R(-1.0);
    out->n_matches = n;
    out->n_inliers = 0;
    out->n_offplane = 0;
    out->ransac_iters = 0;
    out->status = SPVS_OK;
    out->step = 0;
    out->h_valid = 0;
    out->e_valid = 0;
    out->eq11 = 0;
    out->arrival_corner_px = SPVS_R(0.0);
    out->arrival_bound_px = SPVS_R(0.0);
    out->arrival_lateral_px = SPVS_R(0.0);
    out->arrival_depth_px = SPVS_R(0.0);
    out->arrival_h13_px = SPVS_R(0.0);
    out->arrival_parallax_px = SPVS_R(0.0);
    out->arrival_frames = 0;
    out->arrival_reentries = 0;
    out->arrival_next = 0;
    out->arriving = 0;
}

/* Check and load the frame, the matches of features known to be off the
 * plane kept out of the plane candidates, and estimate H (or take H_px,
 * pixels, when it is given).  On success s->est holds H in scaled units and
 * its inliers, and out->H the same in pixels. */
static int estimate(spvs_t *s, const spvs_match_t *m, uint16_t n, const spvs_real *H_px,
                    spvs_output_t *out)
{
    int rc = spvs_plane_h_check(m, n);
    if (rc != SPVS_OK) {
        return rc;
    }
    const uint16_t *order = 0;
    uint16_t n_plane = n;
    if (s->off.n_known != 0u) {
        n_plane = spvs_offplane_split(&s->off, m, n, s->est.idx);
        order = s->est.idx;
    }
    rc = spvs_plane_h_load(&s->est, m, n, order, n_plane);
    if (rc != SPVS_OK) {
        return rc;
    }
    if (H_px != 0) {
        spvs_real H_sc[9];
        for (int k = 0; k < 9; k++) {
            H_sc[k] = H_px[k];
        }
        spvs_h_rescale(H_sc, SPVS_R(1.0) / (spvs_real)SPVS_COORD_SCALE);
        rc = spvs_plane_h_adopt(&s->est, H_sc, spvs_inlier_px(&s->p));
    } else {
        uint32_t iters = 0;
        rc = spvs_plane_h_estimate(&s->est, spvs_inlier_px(&s->p), s->p.confidence, s->p.max_iters,
                                   &s->rng, &iters);
        out->ransac_iters = (uint16_t)(iters > 65535u ? 65535u : iters);
    }
    if (rc != SPVS_OK) {
        return rc;
    }
    for (int k = 0; k < 9; k++) {
        out->H[k] = s->est.H_sc[k];
    }
    spvs_h_rescale(out->H, (spvs_real)SPVS_COORD_SCALE);
    out->n_inliers = s->est.n_inliers;
    out->h_valid = 1;
    return SPVS_OK;
}

int spvs_estimate_h(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_output_t *out)
{
    if (s == 0 || out == 0) {
        return SPVS_E_ARG;
    }
    clear_output(out, n);
    int rc = estimate(s, m, n, 0, out);
    out->status = (int16_t)rc;
    return rc;
}

/* The epipole handed to the controller is the median of the last
 * SPVS_EPIPOLE_MEDIAN frames' estimates, and its side (ahead or behind) their
 * majority: one frame whose few off-plane points give a wild estimate must
 * not turn the robot (bound: SPVS_EPIPOLE_MEDIAN values). */
static void epipole_filter(spvs_t *s, const spvs_epipole_t *ep, spvs_control_input_t *in)
{
    s->ehist_x[s->i_ehist] = ep->e_x_px;
    s->ehist_z[s->i_ehist] = (int8_t)(ep->dir_z > SPVS_R(0.0) ? 1 : -1);
    s->i_ehist = (uint8_t)((s->i_ehist + 1u) % SPVS_EPIPOLE_MEDIAN);
    if (s->n_ehist < SPVS_EPIPOLE_MEDIAN) {
        s->n_ehist++;
    }
    spvs_real v[SPVS_EPIPOLE_MEDIAN];
    int votes = 0;
    for (uint8_t i = 0; i < s->n_ehist; i++) {
        v[i] = s->ehist_x[i];
        votes += s->ehist_z[i];
    }
    spvs_sort_small(v, s->n_ehist);
    in->e_x_px = v[s->n_ehist / 2];
    in->e_dir_x = ep->dir_x;
    in->e_dir_z = votes > 0 ? SPVS_R(1.0) : (votes < 0 ? SPVS_R(-1.0) : ep->dir_z);
}

/* The frame's time and H (estimated, or H_px when given): SPVS_OK, or the
 * status that stops the robot. */
static int begin_frame(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                       const spvs_real *H_px, spvs_output_t *out)
{
    int rc = SPVS_OK;
    if (!spvs_is_finite(t_s)) {
        rc = SPVS_E_NONFINITE;
    } else if (s->has_last && !(t_s > s->last_t_s)) {
        /* A frame not after the last one is a duplicate or out of order:
         * its estimate would be stale. */
        rc = SPVS_E_STALE;
    }
    if (rc == SPVS_OK) {
        s->last_t_s = t_s;
        s->has_last = 1;
        rc = estimate(s, m, n, H_px, out);
    }
    if (rc != SPVS_OK) {
        return rc;
    }
    /* A long gap since the last good frame: the step-end tests restart, as
     * their consecutive-frame counts no longer describe continuous motion. */
    if (s->has_good && t_s - s->last_good_t_s > s->p.max_frame_gap_s) {
        s->ctl.hold = 0;
        s->ctl.run_sign = 0;
        s->ctl.run_len = 0;
    }
    s->has_good = 1;
    s->last_good_t_s = t_s;
    return SPVS_OK;
}

/* The pipeline after H: the off-plane points, the epipole and the
 * controller's command. */
static int after_h(spvs_t *s, spvs_real t_s, spvs_output_t *out)
{
    int rc;
    /* The off-plane points, the parallax of the remembered ones, the
     * epipole from all of them, and what the memory learns from it. */
    spvs_offplane_t *const o = &s->off;
    spvs_offplane_collect(o, &s->est, s->p.offplane_px);
    spvs_real parallax = spvs_offplane_known_parallax_px(o, s->est.H_sc, s->ework.n2);
    spvs_epipole_t ep;
    const spvs_real sin_tol2 = s->p.epipole_sin_tol * s->p.epipole_sin_tol;
    const int e_ok = spvs_epipole_estimate(s->est.H_sc, (const spvs_real(*)[4])o->cand_pts,
                                           o->cand_ord, o->n_cand, sin_tol2, s->p.min_support,
                                           &ep, o->support, &s->ework) == SPVS_OK;
    if (parallax < SPVS_R(0.0) && e_ok) {
        parallax = ep.parallax_px;
    }
    spvs_offplane_remember(o, &s->est, e_ok, parallax, s->p.offplane_px);

    spvs_control_input_t in;
    for (int k = 0; k < 9; k++) {
        in.H[k] = out->H[k];
    }
    in.e_x_px = SPVS_R(0.0);
    in.e_dir_x = SPVS_R(0.0);
    in.e_dir_z = SPVS_R(0.0);
    if (e_ok) {
        epipole_filter(s, &ep, &in);
    }
    in.parallax_px = parallax;
    in.t_s = t_s;
    in.e_valid = (uint8_t)e_ok;
    in.n_inliers = out->n_inliers;

    spvs_real v, w;
    rc = spvs_control_step(&s->ctl, &s->p.ctl, &in, &v, &w);
    out->v = rc == SPVS_OK ? v : SPVS_R(0.0);
    out->w = rc == SPVS_OK ? w : SPVS_R(0.0);
    out->e_x_px = in.e_x_px;
    out->parallax_px = parallax;
    out->n_offplane = e_ok ? ep.n_support : 0u;
    out->e_valid = (uint8_t)e_ok;
    out->eq11 = s->ctl.use_eq11;
    out->status = (int16_t)rc;
    out->step = (uint8_t)s->ctl.step;
    out->arrival_corner_px = s->ctl.arrival_corner_px;
    out->arrival_bound_px = s->ctl.arrival_bound_px;
    out->arrival_lateral_px = s->ctl.arrival_lateral_px;
    out->arrival_depth_px = s->ctl.arrival_depth_px;
    out->arrival_h13_px = s->ctl.arrival_h13_px;
    out->arrival_parallax_px = s->ctl.arrival_parallax_px;
    out->arrival_frames = s->ctl.arrive_n;
    out->arrival_reentries = s->ctl.reentries;
    out->arrival_next = s->ctl.arrival_next;
    out->arriving = s->ctl.arriving;
    return rc;
}

/* spvs_update and spvs_update_with_h. */
static int update(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                  const spvs_real *H_px, spvs_output_t *out)
{
    if (s == 0 || out == 0) {
        return SPVS_E_ARG;
    }
    clear_output(out, n);
    const int rc = begin_frame(s, m, n, t_s, H_px, out);
    if (rc != SPVS_OK) {
        /* The robot is told to stop: the controller's odometry must know. */
        s->ctl.last_v = SPVS_R(0.0);
        out->status = (int16_t)rc;
        out->step = (uint8_t)s->ctl.step;
        return rc;
    }
    return after_h(s, t_s, out);
}

int spvs_update(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                spvs_output_t *out)
{
    return update(s, m, n, t_s, 0, out);
}

int spvs_update_with_h(spvs_t *s, const spvs_match_t *m, uint16_t n, spvs_real t_s,
                       const spvs_real H_px[9], spvs_output_t *out)
{
    if (H_px == 0) {
        if (out != 0) {
            clear_output(out, n);
            out->status = SPVS_E_ARG;
        }
        return SPVS_E_ARG;
    }
    return update(s, m, n, t_s, H_px, out);
}
