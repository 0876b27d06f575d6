/*
 * synth_scene.h - the simulator's default scene for the core's unit tests
 * that drive a controller through frames (synth.h's geometry): 100 plane
 * points and 25 off-plane points 15..40 m deep, seen by the target camera
 * at random pixels, and the matches of a frame at a pose.
 */
#ifndef SPVS_TEST_SYNTH_SCENE_H
#define SPVS_TEST_SYNTH_SCENE_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "spvs/spvs.h"
#include "synth.h"

#define SYNTH_SCENE_PLANE 100
#define SYNTH_SCENE_OFF 25

typedef struct {
    double X[SYNTH_SCENE_PLANE + SYNTH_SCENE_OFF][3]; /* world, metres */
    double p_tgt[SYNTH_SCENE_PLANE + SYNTH_SCENE_OFF][2]; /* target image, centred px */
    int n;
} synth_scene_t;

/* The scene of plane pl (alpha = 800 px): each point drawn at a random
 * pixel of the 640 x 480 target image, at most 1000 tries a point.  With
 * sigma_tgt > 0 the target image gets that noise, drawn once; with 0 no
 * noise is drawn, so the generator's stream is the noise-free one. */
static inline void synth_scene_make(synth_scene_t *s, const synth_plane_t *pl, uint64_t *rng,
                                    double sigma_tgt)
{
    s->n = 0;
    for (int i = 0; i < SYNTH_SCENE_PLANE + SYNTH_SCENE_OFF; i++) {
        for (int tries = 0; tries < 1000; tries++) {
            const double u = (synth_uniform(rng) - 0.5) * 640;
            const double v = (synth_uniform(rng) - 0.5) * 480;
            double X[3];
            int ok;
            if (i < SYNTH_SCENE_PLANE) {
                ok = synth_plane_point(pl, 800, u, v, X);
            } else {
                const double z = 15 + 25 * synth_uniform(rng);
                X[0] = u / 800 * z;
                X[1] = v / 800 * z;
                X[2] = z;
                ok = pl->n[0] * X[0] + pl->n[1] * X[1] + pl->n[2] * X[2] > -pl->d;
            }
            if (ok) {
                memcpy(s->X[s->n], X, sizeof X);
                s->p_tgt[s->n][0] = u;
                s->p_tgt[s->n][1] = v;
                if (sigma_tgt > 0) {
                    s->p_tgt[s->n][0] += sigma_tgt * synth_gauss(rng);
                    s->p_tgt[s->n][1] += sigma_tgt * synth_gauss(rng);
                }
                s->n++;
                break;
            }
        }
    }
}

/* The matches of the frame at pose into m[]: noise sigma on the current
 * image, with mismatch > 0 that share of the matches replaced by a random
 * point of the image, and points at or beyond lim px left out (no
 * clipping at the image border, as in the simulator). */
static inline uint16_t synth_scene_frame(const synth_scene_t *s, const synth_pose_t *pose,
                                         double sigma, double mismatch, double lim,
                                         uint64_t *rng, spvs_match_t *m)
{
    uint16_t k = 0;
    for (int i = 0; i < s->n; i++) {
        double pc[2];
        if (!synth_project(pose, 800, s->X[i], pc)) {
            continue;
        }
        pc[0] += sigma * synth_gauss(rng);
        pc[1] += sigma * synth_gauss(rng);
        if (mismatch > 0 && synth_uniform(rng) < mismatch) {
            pc[0] = (synth_uniform(rng) - 0.5) * 640;
            pc[1] = (synth_uniform(rng) - 0.5) * 480;
        }
        if (!(fabs(pc[0]) < lim && fabs(pc[1]) < lim)) {
            continue;
        }
        m[k].x_tgt = (spvs_real)s->p_tgt[i][0];
        m[k].y_tgt = (spvs_real)s->p_tgt[i][1];
        m[k].x_cur = (spvs_real)pc[0];
        m[k].y_cur = (spvs_real)pc[1];
        m[k].feature = (uint16_t)i;
        k++;
    }
    return k;
}

#endif /* SPVS_TEST_SYNTH_SCENE_H */
