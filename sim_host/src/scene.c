/* scene.c - random scene, target image and per-frame matches (scene.h). */
#include "sim/scene.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "spvs/spvs_config.h"

/* Streams of one seed (see sim_rng_seed). */
enum { STREAM_SCENE = 1, STREAM_TGT_NOISE = 2, STREAM_FRAME = 3,
       STREAM_MISMATCH = 4 };

/* Direction of the ray through centred pixel (x, y) of camera cam, Z = 1. */
static void pixel_ray(const sim_camera_t *cam, double x, double y,
                      double dir[3])
{
    dir[0] = (x - cam->x0_px) / cam->alpha_x_px;
    dir[1] = y / cam->alpha_y_px;
    dir[2] = 1.0;
}

static void random_pixel(const sim_camera_t *cam, sim_rng_t *rng, double p[2])
{
    p[0] = sim_rng_range(rng, -0.5 * cam->width_px, 0.5 * cam->width_px);
    p[1] = sim_rng_range(rng, -0.5 * cam->height_px, 0.5 * cam->height_px);
}

int sim_scene_make(sim_scene_t *s, const sim_camera_t *cam,
                   const sim_plane_t *pl, const sim_scene_spec_t *spec,
                   sim_rng_t *rng, char *err, unsigned err_len)
{
    unsigned total = (unsigned)spec->n_plane + spec->n_off;
    memset(s, 0, sizeof(*s));
    if (total < 1 || total > SIM_MAX_POINTS) {
        snprintf(err, err_len, "scene needs 1..%d points, got %u",
                 SIM_MAX_POINTS, total);
        return -1;
    }
    if (spec->n_off > 0 &&
        !(spec->off_zmin_m > SIM_MIN_DEPTH_M &&
          spec->off_zmax_m > spec->off_zmin_m)) {
        snprintf(err, err_len, "off-plane depth range %g..%g m is empty",
                 spec->off_zmin_m, spec->off_zmax_m);
        return -1;
    }
    uint16_t k = 0;
    for (unsigned i = 0; i < spec->n_plane; ++i) {
        int placed = 0;
        for (int tries = 0; tries < SIM_SCENE_MAX_TRIES && !placed; ++tries) {
            double p[2], dir[3];
            random_pixel(cam, rng, p);
            pixel_ray(cam, p[0], p[1], dir);
            double nd = pl->n[0] * dir[0] + pl->n[1] * dir[1] + pl->n[2] * dir[2];
            /* n^T (t dir) = -d has t > 0 only when n^T dir < 0; very grazing
             * rays put points absurdly far away, so keep t bounded too. */
            if (!(nd < 0.0)) {
                continue;
            }
            double t = -pl->d_m / nd;
            if (!(t > SIM_MIN_DEPTH_M) || t > 1000.0 * pl->d_m) {
                continue;
            }
            for (int j = 0; j < 3; ++j) {
                s->X[k][j] = t * dir[j];
            }
            s->p_tgt[k][0] = p[0];
            s->p_tgt[k][1] = p[1];
            s->on_plane[k] = 1;
            placed = 1;
        }
        if (!placed) {
            snprintf(err, err_len,
                     "the plane is not in view of the target camera "
                     "(no plane point after %d tries)", SIM_SCENE_MAX_TRIES);
            return -1;
        }
        ++k;
    }
    for (unsigned i = 0; i < spec->n_off; ++i) {
        int placed = 0;
        for (int tries = 0; tries < SIM_SCENE_MAX_TRIES && !placed; ++tries) {
            double p[2], dir[3];
            random_pixel(cam, rng, p);
            pixel_ray(cam, p[0], p[1], dir);
            double z = sim_rng_range(rng, spec->off_zmin_m, spec->off_zmax_m);
            double X[3] = { z * dir[0], z * dir[1], z };
            double nX = pl->n[0] * X[0] + pl->n[1] * X[1] + pl->n[2] * X[2];
            if (!(nX > -pl->d_m)) {
                continue;
            }
            memcpy(s->X[k], X, sizeof(X));
            s->p_tgt[k][0] = p[0];
            s->p_tgt[k][1] = p[1];
            s->on_plane[k] = 0;
            placed = 1;
        }
        if (!placed) {
            snprintf(err, err_len,
                     "no off-plane point fits between the camera and the "
                     "plane at %g..%g m (%d tries)",
                     spec->off_zmin_m, spec->off_zmax_m, SIM_SCENE_MAX_TRIES);
            return -1;
        }
        ++k;
    }
    s->n = k;
    /* Feature indices: a Fisher-Yates permutation of 0..n-1. */
    for (uint16_t i = 0; i < k; ++i) {
        s->feature[i] = i;
    }
    for (uint16_t i = k; i > 1; --i) {
        uint32_t j = sim_rng_below(rng, i);
        uint16_t tmp = s->feature[i - 1];
        s->feature[i - 1] = s->feature[j];
        s->feature[j] = tmp;
    }
    return 0;
}

int sim_world_init(sim_world_t *w, const sim_camera_t *cam_true,
                   const sim_plane_t *pl, const sim_scene_spec_t *spec,
                   double noise_px, double outliers, int clip, uint64_t seed,
                   char *err, unsigned err_len)
{
    memset(w, 0, sizeof(*w));
    if (!(noise_px >= 0.0) || !isfinite(noise_px)) {
        snprintf(err, err_len, "noise must be finite and >= 0, got %g",
                 noise_px);
        return -1;
    }
    if (!(outliers >= 0.0 && outliers < 1.0)) {
        snprintf(err, err_len, "outlier fraction must be in [0, 1), got %g",
                 outliers);
        return -1;
    }
    w->cam = *cam_true;
    w->plane = *pl;
    w->noise_px = noise_px;
    w->outliers = outliers;
    w->clip = clip;
    sim_rng_t rng_scene, rng_tgt;
    sim_rng_seed(&rng_scene, seed, STREAM_SCENE);
    if (sim_scene_make(&w->scene, cam_true, pl, spec, &rng_scene, err,
                       err_len) != 0) {
        return -1;
    }
    /* The target image is taken once, so its noise is drawn once. */
    sim_rng_seed(&rng_tgt, seed, STREAM_TGT_NOISE);
    for (uint16_t i = 0; i < w->scene.n; ++i) {
        double nx = sim_rng_gauss(&rng_tgt), ny = sim_rng_gauss(&rng_tgt);
        w->p_tgt_obs[i][0] = w->scene.p_tgt[i][0] + noise_px * nx;
        w->p_tgt_obs[i][1] = w->scene.p_tgt[i][1] + noise_px * ny;
    }
    sim_rng_seed(&w->rng_frame, seed, STREAM_FRAME);
    sim_rng_seed(&w->rng_mismatch, seed, STREAM_MISMATCH);
    return 0;
}

static int in_frame(const sim_camera_t *cam, double x, double y)
{
    return x >= -0.5 * cam->width_px && x < 0.5 * cam->width_px &&
           y >= -0.5 * cam->height_px && y < 0.5 * cam->height_px;
}

uint16_t sim_world_observe(sim_world_t *w, const sim_pose_t *pose,
                           sim_obs_t *obs, uint16_t cap)
{
    const double lim = (double)SPVS_MAX_COORD_PX;
    uint16_t n = 0;
    for (uint16_t i = 0; i < w->scene.n && n < cap; ++i) {
        double p[2];
        if (sim_project(&w->cam, pose, w->scene.X[i], p, NULL) != 0) {
            continue;
        }
        if (w->clip && !in_frame(&w->cam, p[0], p[1])) {
            continue;
        }
        /* Noise is drawn for every imaged point before the range test, so a
         * point leaving the range does not shift the noise of the others. */
        double nx = sim_rng_gauss(&w->rng_frame);
        double ny = sim_rng_gauss(&w->rng_frame);
        double xc = p[0] + w->noise_px * nx, yc = p[1] + w->noise_px * ny;
        if (!(fabs(xc) < lim && fabs(yc) < lim)) {
            continue;
        }
        sim_obs_t *o = &obs[n++];
        o->feature = w->scene.feature[i];
        o->x_tgt = w->p_tgt_obs[i][0];
        o->y_tgt = w->p_tgt_obs[i][1];
        o->x_cur = xc;
        o->y_cur = yc;
        o->on_plane = w->scene.on_plane[i];
        o->mismatched = 0;
    }
    /* Mismatches: a random subset of exactly round(outliers * n) matches,
     * chosen by a partial Fisher-Yates over the match indices. */
    uint16_t n_bad = (uint16_t)floor(w->outliers * n + 0.5);
    if (n_bad > 0) {
        uint16_t order[SIM_MAX_POINTS];
        for (uint16_t i = 0; i < n; ++i) {
            order[i] = i;
        }
        for (uint16_t i = 0; i < n_bad; ++i) {
            uint16_t j = (uint16_t)(i + sim_rng_below(&w->rng_mismatch,
                                                      (uint32_t)(n - i)));
            uint16_t tmp = order[i];
            order[i] = order[j];
            order[j] = tmp;
            sim_obs_t *o = &obs[order[i]];
            o->x_cur = sim_rng_range(&w->rng_mismatch, -0.5 * w->cam.width_px,
                                     0.5 * w->cam.width_px);
            o->y_cur = sim_rng_range(&w->rng_mismatch, -0.5 * w->cam.height_px,
                                     0.5 * w->cam.height_px);
            o->mismatched = 1;
        }
    }
    return n;
}

void sim_obs_to_matches(const sim_obs_t *obs, uint16_t n, spvs_match_t *m)
{
    for (uint16_t i = 0; i < n; ++i) {
        m[i].x_tgt = (spvs_real)obs[i].x_tgt;
        m[i].y_tgt = (spvs_real)obs[i].y_tgt;
        m[i].x_cur = (spvs_real)obs[i].x_cur;
        m[i].y_cur = (spvs_real)obs[i].y_cur;
        m[i].feature = obs[i].feature;
    }
}
