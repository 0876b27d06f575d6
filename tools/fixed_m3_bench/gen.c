/* gen.c - host side of run.sh: one synthetic frame (the default scene of
 * DESIGN.md section 5, start pose (-3, -10, -30 deg), 0.5 px noise on the
 * current image, a share of mismatches), its matches, its float store
 * (rows) and Q store, H and t2, written as a C header for m3.c.
 *   gen N MISMATCH_SHARE > data.h */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fixed/points_q.h"
#include "spvs/homography.h"
#include "synth.h"
static spvs_match_t m[256];
static spvs_point_store_t fs;
static spvs_q_store_t qs;
int main(int argc, char **argv)
{
    int N = argc > 1 ? atoi(argv[1]) : 256;
    double out = argc > 2 ? atof(argv[2]) : 0.2;
    uint64_t rng = 1;
    synth_pose_t p = {-3, -10, -30 * SYNTH_PI / 180};
    synth_plane_t pl;
    synth_plane(&pl, 0.3, -0.6, -0.75, 45);
    uint16_t n = synth_frame(&p, &pl, 800, N, 0, 0.5, &rng, m, NULL);
    for (uint16_t i = 0; i < n; i++) {
        if (synth_uniform(&rng) < out) {
            m[i].x_cur = (float)((synth_uniform(&rng) - 0.5) * 640);
            m[i].y_cur = (float)((synth_uniform(&rng) - 0.5) * 480);
        }
    }
    uint16_t f[256];
    if (spvs_pts_load(&fs, f, m, n, n, NULL, 1) || spvs_q_pts_load(&qs, f, m, n, n, NULL, 1)) return 1;
    double Hp[9];
    synth_H(&p, &pl, 800, Hp);
    float Hs[9];
    for (int k = 0; k < 9; k++) Hs[k] = (float)Hp[k];
    spvs_h_rescale(Hs, 1.0f / 512);
    int32_t Hq[9];
    if (spvs_q_h_from_real(Hs, Hq)) return 2;
    float t = 3.0348f / 512; float t2 = t * t;
    uint32_t sat = 0;
    spvs_qf_t qt2 = spvs_q_t2_from_real(t2, &sat);
    const spvs_q_thr_t thr = spvs_q_thr(qt2);
    uint8_t mask[256];
    printf("#define N %u\n", n);
    printf("static const uint32_t fbits[] = {");
    for (unsigned i = 0; i < n; i++) { float r[4]; spvs_pts_row(&fs, (uint16_t)i, r); for (int k = 0; k < 4; k++) { uint32_t b; memcpy(&b, &r[k], 4); printf("%uu,", b); } }
    printf("};\nstatic const uint32_t fmax_bits[2] = {");
    for (int i = 0; i < 2; i++) { uint32_t b; memcpy(&b, &fs.cur_max[i], 4); printf("%uu,", b); }
    printf("};\nstatic const int32_t qv[] = {");
    for (unsigned i = 0; i < 4u * n; i++) printf("%d,", qs.v[i]);
    printf("};\nstatic const int32_t qmax[2] = {%d,%d};\nstatic const int32_t tmax[2] = {%d,%d};\n", qs.cur_max[0], qs.cur_max[1], qs.tgt_max[0], qs.tgt_max[1]);
    printf("static const uint32_t hbits[9] = {");
    for (int k = 0; k < 9; k++) { uint32_t b; memcpy(&b, &Hs[k], 4); printf("%uu,", b); }
    printf("};\nstatic const int32_t hq[9] = {");
    for (int k = 0; k < 9; k++) printf("%d,", Hq[k]);
    uint32_t tb; memcpy(&tb, &t2, 4);
    printf("};\nstatic const uint32_t t2bits = %uu;\nstatic const int32_t qt2m = %d, qt2e = %d;\n", tb, qt2.m, qt2.e);
    /* The frame's matches as given to spvs_update (bits of x_tgt, y_tgt,
     * x_cur, y_cur; the feature is the index). */
    printf("static const uint32_t mbits[] = {");
    for (unsigned i = 0; i < n; i++) {
        const float c[4] = {m[i].x_tgt, m[i].y_tgt, m[i].x_cur, m[i].y_cur};
        for (int k = 0; k < 4; k++) { uint32_t b; memcpy(&b, &c[k], 4); printf("%uu,", b); }
    }
    printf("};\n");
    /* A second frame with off-plane points for the off-plane stage and
     * the epipole (keys o*): 200 plane points, 20 % of them mismatched,
     * and 40 off the plane, from the same pose. */
    static spvs_match_t mo[240];
    uint64_t rng2 = 2;
    uint16_t no = synth_frame(&p, &pl, 800, 200, 40, 0.5, &rng2, mo, NULL);
    for (uint16_t i = 0; i < 200 && i < no; i++) {
        if (synth_uniform(&rng2) < 0.2) {
            mo[i].x_cur = (float)((synth_uniform(&rng2) - 0.5) * 640);
            mo[i].y_cur = (float)((synth_uniform(&rng2) - 0.5) * 480);
        }
    }
    printf("#define NO %u\nstatic const uint32_t obits[] = {", no);
    for (unsigned i = 0; i < no; i++) {
        const float c[4] = {mo[i].x_tgt, mo[i].y_tgt, mo[i].x_cur, mo[i].y_cur};
        for (int k = 0; k < 4; k++) { uint32_t b; memcpy(&b, &c[k], 4); printf("%uu,", b); }
    }
    printf("};\n");
    printf("#define EXPECT_F %u\n#define EXPECT_Q %u\n", spvs_pts_score(&fs, n, Hs, t2, 0, mask), spvs_q_pts_score(&qs, n, Hq, &thr, 0, mask));
    return 0;
}
