/*
 * fixed_scene.h - the random planar-motion scenes of the fixed-point tests
 * (test_fixed_q.c, test_fixed_fit.c): matches with noise in both images and
 * mismatches, loaded into the float store and the Q store in the same
 * spread order.  Included by one test source each, after unity.h (static
 * functions).
 */
#ifndef SPVS_TESTS_FIXED_SCENE_H
#define SPVS_TESTS_FIXED_SCENE_H

#include <math.h>
#include <stdint.h>

#include "fixed/points_q.h"
#include "spvs/homography.h"
#include "synth.h"

#ifndef S
#define S ((double)SPVS_COORD_SCALE)
#endif

#define NMAX 256
#define INLIER_PX 3.0348 /* sqrt(9.21) px: the default threshold, 1 px noise */

typedef struct {
    spvs_match_t m[NMAX];
    uint16_t n;
    spvs_point_store_t fst; /* float store */
    spvs_q_store_t qst;     /* Q store     */
    spvs_real Hs[9];        /* true H, scaled units */
} scene_t;

static inline void rescale_scaled(const double Hp[9], spvs_real Hs[9])
{
    for (int k = 0; k < 9; k++) {
        Hs[k] = (spvs_real)Hp[k];
    }
    spvs_h_rescale(Hs, (spvs_real)(1.0 / S));
}

/* A random planar-motion scene: n matches on the plane with sigma px of
 * noise in both images and a share `out` of them mismatched (the current
 * point anywhere in the image). */
static inline void make_scene(scene_t *sc, uint64_t *rng, int n, double sigma, double out)
{
    synth_pose_t p;
    synth_plane_t pl;
    p.x = -6 + 12 * synth_uniform(rng);
    p.z = -12 + 13 * synth_uniform(rng);
    p.phi = (-45 + 90 * synth_uniform(rng)) * SYNTH_PI / 180;
    synth_plane(&pl, -0.6 + 1.2 * synth_uniform(rng), -0.8 + 1.6 * synth_uniform(rng),
                -(0.3 + synth_uniform(rng)), 10 + 40 * synth_uniform(rng));
    sc->n = synth_frame(&p, &pl, 800, n, 0, sigma, rng, sc->m, NULL);
    for (uint16_t i = 0; i < sc->n; i++) {
        sc->m[i].x_tgt = (spvs_real)(sc->m[i].x_tgt + sigma * synth_gauss(rng));
        sc->m[i].y_tgt = (spvs_real)(sc->m[i].y_tgt + sigma * synth_gauss(rng));
        if (synth_uniform(rng) < out) {
            sc->m[i].x_cur = (spvs_real)((synth_uniform(rng) - 0.5) * 640);
            sc->m[i].y_cur = (spvs_real)((synth_uniform(rng) - 0.5) * 480);
        }
    }
    double Hp[9];
    synth_H(&p, &pl, 800, Hp);
    rescale_scaled(Hp, sc->Hs);
}

static inline void load_both(scene_t *sc)
{
    uint16_t f1[NMAX], f2[NMAX];
    const uint16_t stride = sc->n > 2 ? (uint16_t)(sc->n / 2 + 1) : 1;
    /* Any stride: the spread order must be the same in both stores. */
    uint16_t st = stride;
    while (sc->n > 1) {
        uint16_t a = st, b = sc->n;
        while (b) {
            const uint16_t t = (uint16_t)(a % b);
            a = b;
            b = t;
        }
        if (a == 1) {
            break;
        }
        st++;
    }
    TEST_ASSERT_EQUAL_INT64(0, spvs_pts_load(&sc->fst, f1, sc->m, sc->n, sc->n, NULL, st));
    TEST_ASSERT_EQUAL_INT64(0, spvs_q_pts_load(&sc->qst, f2, sc->m, sc->n, sc->n, NULL, st));
    TEST_ASSERT_EQUAL_MEMORY(f2, f1, sc->n * sizeof f1[0]);
    for (uint16_t i = 0; i < sc->n; i++) {
        spvs_real fr[4];
        int32_t qr[4];
        spvs_pts_row(&sc->fst, i, fr);
        spvs_q_pts_row(&sc->qst, i, qr);
        for (int k = 0; k < 4; k++) {
            /* Q26 rounding: within half a unit of 2^-26 scaled units. */
            TEST_ASSERT_TRUE(fabs(ldexp((double)qr[k], -SPVS_QC) - (double)fr[k]) <= 0x1p-27);
        }
    }
}

#endif /* SPVS_TESTS_FIXED_SCENE_H */
