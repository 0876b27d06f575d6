/*
 * test_bench_cases.c - the benchmark's ground truth: the case generator
 * (tools/bench/hombench.c) and the HOMBENCH v1 reader and writer.
 *
 * Tolerances: the generator works in double, so geometric identities hold to
 * 1e-9 px (points) and 1e-12 (matrix entries) for these magnitudes.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "hombench.h"

#define DEG (3.14159265358979323846 / 180.0)

static void tmp_path(char *buf, size_t len, const char *tag)
{
    snprintf(buf, len, "/tmp/test_bench_cases_%ld_%s.bin", (long)getpid(), tag);
}

/* ---- generator --------------------------------------------------------- */

static void test_true_h_identity_at_target(void **state)
{
    (void)state;
    hb_scene_t sc;
    hb_scene_default(&sc);
    double H[9];
    hb_true_h(&sc, 0.0, 0.0, 0.0, H);
    for (int i = 0; i < 9; i++)
        assert_true(fabs(H[i] - ((i % 4 == 0) ? 1.0 : 0.0)) < 1e-12);
}

/* DESIGN.md section 1: det H = 1 + n^T c / d (h22 = 1 normalisation keeps it,
 * since h22 = 1 by construction under planar motion). */
static void test_true_h_determinant(void **state)
{
    (void)state;
    hb_scene_t sc;
    hb_scene_default(&sc);
    double H[9];
    const double x = -3.0, z = -10.0, phi = -30.0 * DEG;
    hb_true_h(&sc, x, z, phi, H);
    double det = H[0] * (H[4] * H[8] - H[5] * H[7]) - H[1] * (H[3] * H[8] - H[5] * H[6]) +
                 H[2] * (H[3] * H[7] - H[4] * H[6]);
    double expect = 1.0 + (sc.normal[0] * x + sc.normal[2] * z) / sc.d_m;
    assert_true(fabs(det - expect) < 1e-12);
    /* The planar form (eq. 4): second row (0, 1, 0). */
    assert_true(fabs(H[3]) < 1e-15 && fabs(H[4] - 1.0) < 1e-15 && fabs(H[5]) < 1e-15);
}

/* Noise-free inliers are the projections of plane points, so the true H
 * (eq. 2) must map each target point onto its current point. */
static void test_generated_inliers_follow_true_h(void **state)
{
    (void)state;
    hb_scene_t sc;
    hb_scene_default(&sc);
    hb_record_t rec;
    assert_int_equal(hb_record_alloc(&rec, 200), 0);
    assert_int_equal(hb_generate(&sc, 200, 0.0, 0.0, -2.0, -7.0, -16.7 * DEG, 42, &rec), 0);
    double worst = 0.0;
    for (uint32_t i = 0; i < rec.n; i++) {
        double x, y;
        assert_int_equal(hb_apply_h(rec.H, rec.pts[i][0], rec.pts[i][1], &x, &y), 0);
        worst = fmax(worst, hypot(x - rec.pts[i][2], y - rec.pts[i][3]));
        assert_true(fabs(rec.pts[i][0]) <= 320.0 && fabs(rec.pts[i][1]) <= 240.0);
    }
    assert_true(worst < 1e-9);
    assert_int_equal(rec.n_inliers, 200);
    free(rec.pts);
    free(rec.inlier);
}

static void test_mismatch_count_and_noise(void **state)
{
    (void)state;
    hb_scene_t sc;
    hb_scene_default(&sc);
    hb_record_t a, b;
    assert_int_equal(hb_record_alloc(&a, 500), 0);
    assert_int_equal(hb_record_alloc(&b, 500), 0);
    assert_int_equal(hb_generate(&sc, 500, 0.2, 0.0, -3.0, -10.0, -30.0 * DEG, 7, &a), 0);
    assert_int_equal(hb_generate(&sc, 500, 0.2, 1.0, -3.0, -10.0, -30.0 * DEG, 7, &b), 0);
    uint32_t flagged = 0;
    for (uint32_t i = 0; i < 500; i++)
        flagged += a.inlier[i];
    assert_int_equal(flagged, 400);
    assert_int_equal(a.n_inliers, 400);
    /* Same seed: same points and mismatches; sigma = 1 only adds noise, whose
     * sample standard deviation over 2000 coordinates is within 10 % of 1. */
    double s2 = 0.0;
    for (uint32_t i = 0; i < 500; i++) {
        assert_int_equal(a.inlier[i], b.inlier[i]);
        for (int j = 0; j < 4; j++) {
            double d = b.pts[i][j] - a.pts[i][j];
            s2 += d * d;
        }
    }
    double sd = sqrt(s2 / 2000.0);
    assert_true(sd > 0.9 && sd < 1.1);
    /* Mismatched current points are in the frame. */
    for (uint32_t i = 0; i < 500; i++)
        if (!a.inlier[i])
            assert_true(fabs(a.pts[i][2]) <= 320.0 && fabs(a.pts[i][3]) <= 240.0);
    assert_int_equal(hb_generate(&sc, 500, 1.5, 0.0, 0, 0, 0, 7, &a), -1);
    assert_int_equal(hb_generate(&sc, 500, 0.2, -1.0, 0, 0, 0, 7, &a), -1);
    free(a.pts);
    free(a.inlier);
    free(b.pts);
    free(b.inlier);
}

static void test_corner_error(void **state)
{
    (void)state;
    hb_scene_t sc;
    hb_scene_default(&sc);
    double H[9], G[9];
    hb_true_h(&sc, -1.0, -5.0, -10.0 * DEG, H);
    assert_true(hb_corner_err(&sc, H, H) < 1e-12);
    /* A common scale, even a negative one, is no error. */
    for (int i = 0; i < 9; i++)
        G[i] = -2.5 * H[i];
    assert_true(hb_corner_err(&sc, H, G) < 1e-9);
    /* Identity against a pure 3 px shift in x and 4 px in y: 5 px at every corner. */
    double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, T[9] = {1, 0, 3, 0, 1, 4, 0, 0, 1};
    assert_true(fabs(hb_corner_err(&sc, I, T) - 5.0) < 1e-12);
    T[0] = NAN;
    assert_true(isinf(hb_corner_err(&sc, I, T)));
}

static void test_homing_pose(void **state)
{
    (void)state;
    double x, z, phi;
    hb_homing_pose(-3.0, -10.0, -30.0 * DEG, 0.0, &x, &z, &phi);
    assert_true(x == -3.0 && z == -10.0 && fabs(phi + 30.0 * DEG) < 1e-15);
    hb_homing_pose(-3.0, -10.0, -30.0 * DEG, 1.0, &x, &z, &phi);
    assert_true(x == 0.0 && z == 0.0 && fabs(phi) < 1e-12);
    /* Mid-way along the straight line, heading (-sin phi, cos phi) points at
     * the target: the cross product with (-x, -z) vanishes. */
    hb_homing_pose(-3.0, -10.0, -30.0 * DEG, 0.5, &x, &z, &phi);
    assert_true(fabs(x + 1.5) < 1e-12 && fabs(z + 5.0) < 1e-12);
    assert_true(fabs(-sin(phi) * (-z) - cos(phi) * (-x)) < 1e-12);
    assert_true(-sin(phi) * (-x) + cos(phi) * (-z) > 0.0);
}


/* The controller drives backwards onto the line when the target is behind
 * (tools/experiments.py's Figure 5: (-6, 4, 20) and (6, 8, 10)), and from
 * the grazing start (5, 2, -50) too: the line's heading is the one nearer
 * the start heading. */
static void test_homing_pose_backwards(void **state)
{
    (void)state;
    double x, z, phi;
    hb_homing_pose(-6.0, 4.0, 20.0 * DEG, 0.5, &x, &z, &phi);
    assert_true(fabs(phi - atan2(6.0, 4.0)) < 1e-12); /* 56.31 deg */
    /* Backwards: the heading points away from the target. */
    assert_true(-sin(phi) * (-x) + cos(phi) * (-z) < 0.0);
    hb_homing_pose(5.0, 2.0, -50.0 * DEG, 0.5, &x, &z, &phi);
    assert_true(fabs(phi / DEG + 68.198590513648) < 1e-9);
    hb_homing_pose(6.0, 8.0, 10.0 * DEG, 0.5, &x, &z, &phi);
    assert_true(fabs(phi / DEG + 36.869897645844) < 1e-9);
    /* The first rotation takes the short way: half-way through it from
     * (5, 2, -50) the heading is the mean of -50 and -68.2 deg. */
    hb_homing_pose(5.0, 2.0, -50.0 * DEG, 0.1, &x, &z, &phi);
    assert_true(fabs(phi / DEG + 59.099295256824) < 1e-9);
    /* The last rotation ends at phi = 0. */
    hb_homing_pose(5.0, 2.0, -50.0 * DEG, 1.0, &x, &z, &phi);
    assert_true(fabs(phi) < 1e-12 && x == 0.0 && z == 0.0);
}

/* The families: record counts, pose ids, the Figure 5 starts, and the
 * grazing family's off-axis angles (60 .. 100 deg, right then left). */
static void test_families(void **state)
{
    (void)state;
    hb_scene_t sc;
    hb_scene_default(&sc);
    assert_int_equal(hb_family_poses(HB_FAMILY_HOMING, 8), 8);
    assert_int_equal(hb_family_poses(HB_FAMILY_FIG5, 8), 48);
    assert_int_equal(hb_family_poses(HB_FAMILY_GRAZING, 8), 48);
    assert_string_equal(hb_family_name(HB_FAMILY_GRAZING), "grazing");
    assert_null(hb_family_name(HB_FAMILIES));
    double x, z, phi;
    uint32_t id;
    /* fig5 pose 5 * 8: the sixth start itself. */
    assert_int_equal(hb_family_pose(&sc, HB_FAMILY_FIG5, 40, 8, &x, &z, &phi, &id), 0);
    assert_true(x == 5.0 && z == 2.0 && fabs(phi + 50.0 * DEG) < 1e-12);
    assert_int_equal(id, 5 * HB_POSE_STRIDE);
    /* (5, 2, -50) sees the goal image's centre 54.9 deg left of its axis. */
    assert_true(fabs(hb_off_axis(&sc, x, z, phi) / DEG + 54.89) < 0.01);
    for (uint32_t k = 0; k < 48; k++) {
        assert_int_equal(hb_family_pose(&sc, HB_FAMILY_GRAZING, k, 8, &x, &z, &phi, &id), 0);
        double x0, z0, phi0;
        assert_int_equal(hb_fig5_start(k / 8, &x0, &z0, &phi0), 0);
        assert_true(x == x0 && z == z0);
        assert_int_equal(id, (k / 8) * HB_POSE_STRIDE + k % 8);
        double want = (60.0 + 40.0 * (double)(k % 8) / 7.0) * ((k % 2) ? -1.0 : 1.0);
        assert_true(fabs(hb_off_axis(&sc, x, z, phi) / DEG - want) < 1e-9);
    }
    assert_int_equal(hb_family_pose(&sc, HB_FAMILY_GRAZING, 48, 8, &x, &z, &phi, &id), -1);
    assert_int_equal(hb_family_pose(&sc, HB_FAMILIES, 0, 8, &x, &z, &phi, &id), -1);
    assert_int_equal(hb_family_pose(&sc, HB_FAMILY_FIG5, 0, HB_POSE_STRIDE, &x, &z, &phi, &id), -1);
}

/* (x, y) of the target image maps in front of the current camera within
 * HB_VIEW_PX (+ 1e-6 px: a corner on the bound may round past it). */
static int seen(const double H[9], double x, double y)
{
    double w = H[6] * x + H[7] * y + H[8], xo, yo;
    if (!(w > 0.0) || hb_apply_h(H, x, y, &xo, &yo) != 0)
        return 0;
    return fabs(xo) <= HB_VIEW_PX + 1e-6 && fabs(yo) <= HB_VIEW_PX + 1e-6;
}

/* The seen rectangle: the whole image on the homing run; at a grazing view
 * a strip whose corners map in front within HB_VIEW_PX, with nothing
 * seen 2 px beyond the edge that bounds it. */
static void test_view_region(void **state)
{
    (void)state;
    hb_scene_t sc;
    hb_scene_default(&sc);
    double H[9], r[4], x, z, phi;
    uint32_t id;
    hb_true_h(&sc, -3.0, -10.0, -30.0 * DEG, H);
    assert_int_equal(hb_view_region(&sc, H, r), 0);
    assert_true(r[0] == -320.0 && r[1] == 320.0 && r[2] == -240.0 && r[3] == 240.0);
    /* Grazing, 100 deg left of the axis at (0, -8): pose 1 * 8 + 7. */
    assert_int_equal(hb_family_pose(&sc, HB_FAMILY_GRAZING, 15, 8, &x, &z, &phi, &id), 0);
    hb_true_h(&sc, x, z, phi, H);
    assert_int_equal(hb_view_region(&sc, H, r), 0);
    assert_true(r[1] - r[0] >= 1.0 && r[1] - r[0] < 200.0);
    const double cx[4] = {r[0], r[1], r[1], r[0]}, cy[4] = {r[2], r[2], r[3], r[3]};
    for (int k = 0; k < 4; k++)
        assert_true(seen(H, cx[k], cy[k]));
    /* The strip lies at one side of the image; 2 px past its inner edge the
     * top or the bottom corner is no longer seen. */
    const int left = r[0] == -320.0;
    const double beyond = left ? r[1] + 2.0 : r[0] - 2.0;
    assert_true(left ? r[1] < 320.0 : r[0] > -320.0);
    assert_false(seen(H, beyond, r[2]) && seen(H, beyond, r[3]));
    /* Past 90 deg the goal image's centre is behind the camera (h33 < 0);
     * the true H, at any scale of either sign, still scores 0. */
    assert_true(H[8] < 0.0);
    double G[9];
    for (int i = 0; i < 9; i++)
        G[i] = -3.0 * H[i];
    assert_true(hb_corner_err(&sc, H, H) < 1e-9 && hb_corner_err(&sc, H, G) < 1e-9);
    assert_true(hb_corner_err_tgt(&sc, H, G) < 1e-9);
    /* Facing away from the plane, nothing is seen. */
    hb_true_h(&sc, 0.0, 0.0, 180.0 * DEG, H);
    assert_int_equal(hb_view_region(&sc, H, r), -1);
}

/* A grazing record: the target points in the seen strip, every current
 * point imaged within HB_VIEW_PX, the true H exact on noise-free inliers,
 * and noise of sigma on the target image too (as a real goal image has),
 * which H magnifies: most true inliers then lie over 3 px from H p_tgt. */
static void test_grazing_record(void **state)
{
    (void)state;
    hb_scene_t sc;
    hb_scene_default(&sc);
    double x, z, phi, r[4];
    uint32_t id;
    assert_int_equal(hb_family_pose(&sc, HB_FAMILY_GRAZING, 4, 8, &x, &z, &phi, &id), 0);
    hb_record_t a, b;
    assert_int_equal(hb_record_alloc(&a, 400), 0);
    assert_int_equal(hb_record_alloc(&b, 400), 0);
    assert_int_equal(hb_generate(&sc, 400, 0.0, 0.0, x, z, phi, 11, &a), 0);
    assert_int_equal(hb_generate(&sc, 400, 0.0, 1.0, x, z, phi, 11, &b), 0);
    assert_int_equal(hb_view_region(&sc, a.H, r), 0);
    double worst = 0.0, s2_tgt = 0.0, s2_cur = 0.0;
    for (uint32_t i = 0; i < 400; i++) {
        assert_true(a.pts[i][0] >= r[0] && a.pts[i][0] <= r[1]);
        assert_true(a.pts[i][1] >= r[2] && a.pts[i][1] <= r[3]);
        assert_true(fabs(a.pts[i][2]) <= HB_VIEW_PX && fabs(a.pts[i][3]) <= HB_VIEW_PX);
        double xo, yo;
        assert_int_equal(hb_apply_h(a.H, a.pts[i][0], a.pts[i][1], &xo, &yo), 0);
        worst = fmax(worst, hypot(xo - a.pts[i][2], yo - a.pts[i][3]));
        for (int j = 0; j < 2; j++) {
            s2_tgt += pow(b.pts[i][j] - a.pts[i][j], 2);
            s2_cur += pow(b.pts[i][2 + j] - a.pts[i][2 + j], 2);
        }
    }
    assert_true(worst < 1e-6);
    assert_true(fabs(sqrt(s2_tgt / 800.0) - 1.0) < 0.1);
    assert_true(fabs(sqrt(s2_cur / 800.0) - 1.0) < 0.1);
    assert_true(hb_inliers_over(&a, 3.0) == 0.0);
    assert_true(hb_inliers_over(&b, 3.0) > 0.5);
    /* The first-order error that weighs both images' noise keeps them: at
     * the chi-square 0.99 quantile about 1 % are cut, not over half. */
    assert_true(hb_inliers_over_sampson(&a, 0.0, 9.21) == 0.0);
    assert_true(hb_inliers_over_sampson(&b, 1.0, 9.21) < 0.04);
    free(a.pts);
    free(a.inlier);
    free(b.pts);
    free(b.inlier);
}

/* The corner error in target-image pixels: equal to the current-image one
 * where H is the identity, smaller by the local magnification at a grazing
 * view. */
static void test_corner_error_tgt(void **state)
{
    (void)state;
    hb_scene_t sc;
    hb_scene_default(&sc);
    double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, T[9] = {1, 0, 3, 0, 1, 4, 0, 0, 1};
    assert_true(fabs(hb_corner_err_tgt(&sc, I, T) - 5.0) < 1e-12);
    double H[9], G[9], x, z, phi;
    uint32_t id;
    assert_int_equal(hb_family_pose(&sc, HB_FAMILY_GRAZING, 4, 8, &x, &z, &phi, &id), 0);
    hb_true_h(&sc, x, z, phi, H);
    assert_true(hb_corner_err_tgt(&sc, H, H) < 1e-9);
    /* The estimate off by 1 px along x in the target image: G = H T1. */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            G[3 * i + j] = H[3 * i + j] + (j == 2 ? H[3 * i] : 0.0);
    assert_true(fabs(hb_corner_err_tgt(&sc, H, G) - 1.0) < 1e-6);
    assert_true(hb_corner_err(&sc, H, G) > 5.0);
}

/* ---- file format ------------------------------------------------------- */

static int make_set(hb_set_t *set, uint32_t count)
{
    memset(set, 0, sizeof *set);
    hb_scene_default(&set->scene);
    set->rec = calloc(count, sizeof *set->rec);
    if (!set->rec)
        return -1;
    for (uint32_t r = 0; r < count; r++) {
        uint32_t n = 5 + 3 * r; /* odd sizes exercise the padding */
        if (hb_record_alloc(&set->rec[r], n) != 0)
            return -1;
        set->count = r + 1;
        if (hb_generate(&set->scene, n, 0.4, 1.0, -0.5 * r, -4.0, -0.1 * r, 100 + r, &set->rec[r]))
            return -1;
        set->rec[r].case_id = r / 2;
        set->rec[r].instance = r % 2;
        set->rec[r].pose = r;
    }
    return 0;
}

static long file_size(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    fseek(f, 0, SEEK_END);
    long s = ftell(f);
    fclose(f);
    return s;
}

static void test_round_trip(void **state)
{
    (void)state;
    char path[256], err[256];
    tmp_path(path, sizeof path, "rt");
    hb_set_t a, b;
    assert_int_equal(make_set(&a, 5), 0);
    assert_int_equal(hb_write(path, &a, err, sizeof err), 0);
    /* 80-byte header, then per record 144 + 33 N bytes rounded up to 8. */
    long expect = 80;
    for (uint32_t r = 0; r < a.count; r++)
        expect += (144 + 33 * (long)a.rec[r].n + 7) / 8 * 8;
    assert_int_equal(file_size(path), expect);
    assert_int_equal(hb_read(path, &b, err, sizeof err), 0);
    assert_int_equal(b.count, a.count);
    assert_memory_equal(&b.scene, &a.scene, sizeof a.scene);
    for (uint32_t r = 0; r < a.count; r++) {
        const hb_record_t *x = &a.rec[r], *y = &b.rec[r];
        assert_int_equal(y->case_id, x->case_id);
        assert_int_equal(y->instance, x->instance);
        assert_int_equal(y->pose, x->pose);
        assert_int_equal(y->n, x->n);
        assert_int_equal(y->n_inliers, x->n_inliers);
        assert_true(y->seed == x->seed);
        assert_true(y->mismatch == x->mismatch && y->sigma_px == x->sigma_px);
        assert_true(y->x_m == x->x_m && y->z_m == x->z_m && y->phi_rad == x->phi_rad);
        assert_memory_equal(y->H, x->H, sizeof x->H);
        assert_memory_equal(y->pts, x->pts, 32 * (size_t)x->n);
        assert_memory_equal(y->inlier, x->inlier, x->n);
    }
    hb_set_free(&a);
    hb_set_free(&b);
    remove(path);
}

/* Write a valid file, damage one byte range, and expect a clean refusal. */
static void expect_rejected(const char *tag, long offset, const void *bytes, size_t len,
                            long truncate_to, const char *needle)
{
    char path[256], err[256] = "";
    tmp_path(path, sizeof path, tag);
    hb_set_t a, b;
    assert_int_equal(make_set(&a, 3), 0);
    assert_int_equal(hb_write(path, &a, err, sizeof err), 0);
    hb_set_free(&a);
    long size = file_size(path);
    unsigned char *buf = malloc((size_t)size + 16);
    assert_non_null(buf);
    FILE *f = fopen(path, "rb");
    assert_int_equal(fread(buf, 1, (size_t)size, f), (size_t)size);
    fclose(f);
    if (bytes)
        memcpy(buf + offset, bytes, len);
    long out = truncate_to >= 0 ? truncate_to : size;
    if (truncate_to > size) {
        memset(buf + size, 0, (size_t)(truncate_to - size));
    }
    f = fopen(path, "wb");
    assert_int_equal(fwrite(buf, 1, (size_t)out, f), (size_t)out);
    fclose(f);
    free(buf);
    b.count = 99;
    assert_int_equal(hb_read(path, &b, err, sizeof err), -1);
    assert_int_equal(b.count, 0);
    assert_null(b.rec);
    assert_non_null(strstr(err, needle));
    assert_null(strchr(err, '\n'));
    remove(path);
}

static void test_bad_files_rejected(void **state)
{
    (void)state;
    const uint32_t v2 = 2, zero = 0, huge = 0xFFFFFFFFu;
    const unsigned char flag = 7;
    uint64_t nan_bits;
    double nan_v = NAN;
    memcpy(&nan_bits, &nan_v, 8);
    expect_rejected("magic", 0, "HOMBENCX", 8, -1, "magic");
    expect_rejected("version", 8, &v2, 4, -1, "version");
    expect_rejected("count0", 12, &zero, 4, -1, "record count");
    expect_rejected("short", 0, NULL, 0, 40, "header");
    expect_rejected("trunc", 0, NULL, 0, 300, "past the end");
    /* Record 0 starts at byte 80: N at +12, a point value at +144, flags at
     * +144 + 32 N (N = 5 for record 0). */
    expect_rejected("hugeN", 80 + 12, &huge, 4, -1, "N=");
    expect_rejected("nan", 80 + 144, &nan_bits, 8, -1, "non-finite");
    expect_rejected("flag", 80 + 144 + 160, &flag, 1, -1, "flag");
    /* Records of N = 5, 8, 11 take 312, 408 and 512 bytes: 1312 in all. */
    expect_rejected("trailing", 0, NULL, 0, 1312 + 8, "trailing");
    char err[128];
    hb_set_t s;
    assert_int_equal(hb_read("/nonexistent/dir/x.bin", &s, err, sizeof err), -1);
    assert_non_null(strstr(err, "cannot open"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_true_h_identity_at_target),
        cmocka_unit_test(test_true_h_determinant),
        cmocka_unit_test(test_generated_inliers_follow_true_h),
        cmocka_unit_test(test_mismatch_count_and_noise),
        cmocka_unit_test(test_corner_error),
        cmocka_unit_test(test_homing_pose),
        cmocka_unit_test(test_homing_pose_backwards),
        cmocka_unit_test(test_families),
        cmocka_unit_test(test_view_region),
        cmocka_unit_test(test_grazing_record),
        cmocka_unit_test(test_corner_error_tgt),
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_bad_files_rejected),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
