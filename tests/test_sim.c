/*
 * test_sim.c - the simulator's geometry, camera, noise and kinematics against
 * the paper's closed forms (eqs. (2), (3), (5), (7), (8), (9)) and
 * DESIGN.md section 1.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "sim/geometry.h"
#include "sim/kinematics.h"
#include "sim/record.h"
#include "sim/rng.h"
#include "sim/scene.h"
#include "sim/sim.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

/* The paper's default plane, n = (0.3, -0.6, -0.75) normalised, d = 45 m. */
static sim_plane_t default_plane(void)
{
    double n = sqrt(0.3 * 0.3 + 0.6 * 0.6 + 0.75 * 0.75);
    sim_plane_t pl = { { 0.3 / n, -0.6 / n, -0.75 / n }, 45.0 };
    return pl;
}

static sim_plane_t random_plane(sim_rng_t *r)
{
    sim_plane_t pl;
    double len;
    do {
        for (int i = 0; i < 3; ++i) {
            pl.n[i] = sim_rng_range(r, -1.0, 1.0);
        }
        len = sqrt(pl.n[0] * pl.n[0] + pl.n[1] * pl.n[1] + pl.n[2] * pl.n[2]);
    } while (len < 0.1);
    for (int i = 0; i < 3; ++i) {
        pl.n[i] /= len;
    }
    pl.d_m = sim_rng_range(r, 5.0, 100.0);
    return pl;
}

/* |a - b| within rel of the entry's natural scale (pixels for h13, 1/pixels
 * for h31 and h32, 1 for the rest) or of |b|, whichever is larger. */
static void assert_h_close(const double A[9], const double B[9], double alpha,
                           double rel)
{
    const double scale[9] = { 1, 1, alpha, 1, 1, 1, 1 / alpha, 1 / alpha, 1 };
    for (int i = 0; i < 9; ++i) {
        double tol = rel * fmax(scale[i], fabs(B[i]));
        if (!(fabs(A[i] - B[i]) <= tol)) {
            print_message("entry %d: %.17g vs %.17g (tol %.3g)\n", i, A[i],
                          B[i], tol);
            fail();
        }
    }
}

static void test_eq2_equals_eq5(void **state)
{
    (void)state;
    sim_rng_t r;
    sim_rng_seed(&r, 11, 0);
    for (int k = 0; k < 500; ++k) {
        sim_plane_t pl = random_plane(&r);
        sim_pose_t pose = { sim_rng_range(&r, -20, 20),
                            sim_rng_range(&r, -20, 20),
                            sim_rng_range(&r, -PI, PI) };
        /* Unequal focal lengths exercise the alpha_x / alpha_y of h12. */
        sim_camera_t cam = { 800.0, k % 2 ? 800.0 : 760.0, 0.0, 640, 480 };
        double H2[9], H5[9];
        sim_h_eq2(&cam, &pl, &pose, H2);
        sim_h_eq5(cam.alpha_x_px, cam.alpha_y_px, &pl, &pose, H5);
        /* eq. (5) has no normalisation; h22 = 1 there already. */
        assert_h_close(H2, H5, 800.0, 1e-9);
        assert_true(H2[3] == 0.0 && H2[5] == 0.0 && H2[4] == 1.0);
    }
}

static void test_form8_on_the_line(void **state)
{
    (void)state;
    const sim_plane_t pl = default_plane();
    const double a = 800.0;
    sim_camera_t cam = { a, a, 0.0, 640, 480 };
    const double phits[] = { -50 * DEG, -30 * DEG, 5 * DEG, 40 * DEG };
    const double zs[] = { -10.0, -3.0, 0.5, 4.0 };
    for (size_t i = 0; i < 4; ++i) {
        for (size_t j = 0; j < 4; ++j) {
            double ph = phits[i], z = zs[j];
            sim_pose_t pose = { -z * tan(ph), z, ph };
            double H[9], E[9];
            sim_h_eq2(&cam, &pl, &pose, H);
            double q = z / cos(ph) / pl.d_m;
            E[0] = cos(ph);
            E[1] = 0.0;
            E[2] = a * sin(ph);
            E[3] = 0.0;
            E[4] = 1.0;
            E[5] = 0.0;
            E[6] = (-sin(ph) + q * pl.n[0]) / a;
            E[7] = q * pl.n[1] / a;
            E[8] = cos(ph) + q * pl.n[2];
            assert_h_close(H, E, a, 1e-9);
        }
    }
}

static void test_form9_at_target_position(void **state)
{
    (void)state;
    sim_rng_t r;
    sim_rng_seed(&r, 12, 0);
    const double a = 800.0;
    sim_camera_t cam = { a, a, 0.0, 640, 480 };
    for (int k = 0; k < 100; ++k) {
        sim_plane_t pl = random_plane(&r);
        double ph = sim_rng_range(&r, -PI / 2 + 0.01, PI / 2 - 0.01);
        sim_pose_t pose = { 0.0, 0.0, ph };
        double H[9];
        sim_h_eq2(&cam, &pl, &pose, H);
        const double E[9] = { cos(ph), 0, a * sin(ph), 0, 1, 0,
                              -sin(ph) / a, 0, cos(ph) };
        assert_h_close(H, E, a, 1e-12);
        assert_true(fabs(sim_det3(H) - 1.0) < 1e-12);
    }
    /* At the target itself H is the identity (eq. 10). */
    sim_pose_t zero = { 0, 0, 0 };
    double H[9];
    sim_plane_t pl = default_plane();
    sim_h_eq2(&cam, &pl, &zero, H);
    const double I[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
    assert_h_close(H, I, a, 1e-15);
}

static void test_det_is_one_plus_nc_over_d(void **state)
{
    (void)state;
    sim_rng_t r;
    sim_rng_seed(&r, 13, 0);
    for (int k = 0; k < 500; ++k) {
        sim_plane_t pl = random_plane(&r);
        sim_pose_t pose = { sim_rng_range(&r, -20, 20),
                            sim_rng_range(&r, -20, 20),
                            sim_rng_range(&r, -PI, PI) };
        /* The principal point offset must not change det H (similarity). */
        sim_camera_t cam = { sim_rng_range(&r, 400, 1200), 0, 0, 640, 480 };
        cam.alpha_y_px = cam.alpha_x_px;
        cam.x0_px = sim_rng_range(&r, -30, 30);
        double H[9];
        sim_h_eq2(&cam, &pl, &pose, H);
        double expect = 1.0 + (pl.n[0] * pose.x_m + pl.n[2] * pose.z_m) / pl.d_m;
        assert_true(fabs(sim_det3(H) - expect) <= 1e-9 * fmax(1.0, fabs(expect)));
    }
}

/* Scene plane points imaged by the simulated camera obey p_cur ~ H p_tgt,
 * off-plane points do not, and the scene has the promised make-up. */
static void test_scene_and_transfer(void **state)
{
    (void)state;
    static sim_world_t w;
    char err[160];
    const sim_plane_t pl = default_plane();
    const sim_scene_spec_t spec = { 100, 25, 15.0, 40.0 };
    const double focals[] = { 6.0, 7.5, 4.5 };
    const double offsets[] = { 0.0, 12.0, -20.0 };
    sim_rng_t r;
    sim_rng_seed(&r, 14, 0);
    for (int c = 0; c < 3; ++c) {
        sim_camera_t cam;
        sim_camera_make(&cam, focals[c], 0.0075, offsets[c]);
        assert_int_equal(sim_world_init(&w, &cam, &pl, &spec, 0.0, 0.0, 0,
                                        (uint64_t)c, err, sizeof(err)), 0);
        const sim_scene_t *s = &w.scene;
        assert_int_equal(s->n, 125);
        int n_plane = 0;
        uint8_t seen[125] = { 0 };
        for (int i = 0; i < s->n; ++i) {
            assert_true(s->feature[i] < 125);
            assert_false(seen[s->feature[i]]);
            seen[s->feature[i]] = 1;
            double nX = pl.n[0] * s->X[i][0] + pl.n[1] * s->X[i][1] +
                        pl.n[2] * s->X[i][2];
            if (s->on_plane[i]) {
                ++n_plane;
                assert_true(fabs(nX + pl.d_m) < 1e-9 * pl.d_m);
                assert_true(s->X[i][2] > 0.0);
            } else {
                assert_true(nX > -pl.d_m);
                assert_true(s->X[i][2] >= 15.0 && s->X[i][2] < 40.0);
            }
            /* The stored target pixel is the projection from the origin. */
            sim_pose_t origin = { 0, 0, 0 };
            double p[2];
            assert_int_equal(sim_project(&cam, &origin, s->X[i], p, NULL), 0);
            assert_true(fabs(p[0] - s->p_tgt[i][0]) < 1e-9);
            assert_true(fabs(p[1] - s->p_tgt[i][1]) < 1e-9);
            assert_true(p[0] >= -320 && p[0] < 320 && p[1] >= -240 && p[1] < 240);
        }
        assert_int_equal(n_plane, 100);
        /* The permutation hides the plane: the first 100 features are not
         * exactly the plane points. */
        int plane_in_low = 0;
        for (int i = 0; i < s->n; ++i) {
            plane_in_low += s->on_plane[i] && s->feature[i] < 100;
        }
        assert_true(plane_in_low < 100);

        for (int k = 0; k < 50; ++k) {
            sim_pose_t pose = { sim_rng_range(&r, -6, 6),
                                sim_rng_range(&r, -12, 8),
                                sim_rng_range(&r, -60 * DEG, 60 * DEG) };
            double H[9];
            sim_h_eq2(&cam, &pl, &pose, H);
            double max_plane = 0.0, min_off = 1e30;
            for (int i = 0; i < s->n; ++i) {
                double p[2], q[2];
                if (sim_project(&cam, &pose, s->X[i], p, NULL) != 0) {
                    continue;
                }
                sim_h_apply(H, s->p_tgt[i][0], s->p_tgt[i][1], &q[0], &q[1]);
                double e = hypot(p[0] - q[0], p[1] - q[1]);
                if (s->on_plane[i]) {
                    max_plane = fmax(max_plane, e);
                } else {
                    min_off = fmin(min_off, e);
                }
            }
            assert_true(max_plane < 1e-6);
            /* Away from the target the off-plane points show parallax. */
            if (hypot(pose.x_m, pose.z_m) > 3.0) {
                assert_true(min_off > 1e-3);
            }
        }
    }
}

static void test_plane_out_of_view_is_an_error(void **state)
{
    (void)state;
    static sim_world_t w;
    char err[160] = "";
    sim_camera_t cam;
    sim_camera_make(&cam, 6.0, 0.0075, 0.0);
    /* n = (0, 0, 1), d = 10: the plane Z = -10 lies behind the camera. */
    const sim_plane_t behind = { { 0, 0, 1 }, 10.0 };
    const sim_scene_spec_t spec = { 100, 25, 15.0, 40.0 };
    assert_int_equal(sim_world_init(&w, &cam, &behind, &spec, 0, 0, 0, 0, err,
                                    sizeof(err)), -1);
    assert_non_null(strstr(err, "not in view"));
    assert_null(strchr(err, '\n'));
    assert_int_equal(sim_world_init(&w, &cam, &behind, &spec, -1.0, 0, 0, 0,
                                    err, sizeof(err)), -1);
    assert_int_equal(sim_world_init(&w, &cam, &behind, &spec, 0, 1.0, 0, 0,
                                    err, sizeof(err)), -1);
}

/* e_x = alpha_x tan(phi - phi_t) on the line x = -z tan(phi_t). */
static void test_epipole_on_the_line(void **state)
{
    (void)state;
    const double a = 800.0;
    sim_camera_t cam = { a, a, 0.0, 640, 480 };
    const double phits[] = { -40 * DEG, -10 * DEG, 25 * DEG };
    const double zs[] = { -10.0, -2.0, 3.0 };
    const double dphis[] = { -35 * DEG, -5 * DEG, 0.0, 1 * DEG, 30 * DEG };
    for (size_t i = 0; i < 3; ++i) {
        for (size_t j = 0; j < 3; ++j) {
            for (size_t k = 0; k < 5; ++k) {
                double ph_t = phits[i], z = zs[j];
                sim_pose_t pose = { -z * tan(ph_t), z, ph_t + dphis[k] };
                double e[3];
                sim_epipole(&cam, &pose, e);
                double ex = e[0] / e[2];
                double expect = a * tan(pose.phi_rad - ph_t);
                assert_true(fabs(ex - expect) < 1e-9 * fmax(1.0, fabs(expect)));
                /* The target is in front (e_z > 0) exactly when z < 0 on
                 * this line, i.e. the robot must drive forwards. */
                assert_true((e[2] > 0.0) == (z < 0.0));
                /* Where it is in front, it is the image of the origin. */
                if (e[2] > 0.0) {
                    const double O[3] = { 0, 0, 0 };
                    double p[2];
                    assert_int_equal(sim_project(&cam, &pose, O, p, NULL), 0);
                    assert_true(fabs(p[0] - ex) < 1e-9 * fmax(1.0, fabs(ex)));
                }
            }
        }
    }
}

static void test_kinematics_straight(void **state)
{
    (void)state;
    const double phis[] = { 0.0, 30 * DEG, -100 * DEG, 179 * DEG };
    for (size_t i = 0; i < 4; ++i) {
        sim_pose_t p = { 1.0, -2.0, phis[i] };
        sim_kin_step(&p, 0.5, 0.0, 4.0, 0.0);
        /* v t = 2 m along (-sin phi, cos phi). */
        assert_true(fabs(p.x_m - (1.0 - 2.0 * sin(phis[i]))) < 1e-12);
        assert_true(fabs(p.z_m - (-2.0 + 2.0 * cos(phis[i]))) < 1e-12);
        assert_true(fabs(p.phi_rad - phis[i]) < 1e-12);
        /* Backwards: the same distance the other way. */
        sim_pose_t q = { 0.0, 0.0, phis[i] };
        for (int k = 0; k < 40; ++k) {
            sim_kin_step(&q, -0.25, 0.0, 0.1, 0.0);
        }
        assert_true(fabs(q.x_m - sin(phis[i])) < 1e-12);
        assert_true(fabs(q.z_m + cos(phis[i])) < 1e-12);
    }
}

static void test_kinematics_circle(void **state)
{
    (void)state;
    /* w = 2 pi / 10 rad/s for 10 s: one full turn of radius v / w. */
    sim_pose_t p = { -3.0, 4.0, 20 * DEG };
    const double w = 2 * PI / 10.0, v = 1.5;
    double max_dist = 0.0;
    for (int k = 0; k < 100; ++k) {
        sim_kin_step(&p, v, w, 0.1, 0.0);
        max_dist = fmax(max_dist, hypot(p.x_m + 3.0, p.z_m - 4.0));
    }
    assert_true(fabs(p.x_m + 3.0) < 1e-9);
    assert_true(fabs(p.z_m - 4.0) < 1e-9);
    assert_true(fabs(sim_wrap_pi(p.phi_rad - 20 * DEG)) < 1e-9);
    /* Exact arcs: the farthest point is the diameter 2 v / w. */
    assert_true(fabs(max_dist - 2 * v / w) < 1e-9);
    /* A quarter turn from phi = 0: x = (v/w)(cos(pi/2) - 1), z = v/w. */
    sim_pose_t q = { 0, 0, 0 };
    sim_kin_step(&q, v, w, 2.5, 0.0);
    assert_true(fabs(q.x_m + v / w) < 1e-12 && fabs(q.z_m - v / w) < 1e-12);
}

static void test_kinematics_drift(void **state)
{
    (void)state;
    /* 1 deg/m: 0.4 m/s for 25 s is 10 m, so 10 deg, forwards or back. */
    const double vs[] = { 0.4, -0.4 };
    for (int i = 0; i < 2; ++i) {
        sim_pose_t p = { 0, 0, 0 };
        for (int k = 0; k < 250; ++k) {
            sim_kin_step(&p, vs[i], 0.0, 0.1, 1.0 * DEG);
        }
        assert_true(fabs(p.phi_rad - 10.0 * DEG) < 1e-12);
        /* The path is an arc of 10 m: chord 2 R sin(5 deg), R = 10 m / 10 deg. */
        double R = 10.0 / (10.0 * DEG);
        assert_true(fabs(hypot(p.x_m, p.z_m) - 2 * R * sin(5.0 * DEG)) < 1e-9);
    }
    /* Turning on the spot (v = 0) does not drift. */
    sim_pose_t p = { 0, 0, 0 };
    sim_kin_step(&p, 0.0, 0.2, 1.0, 1.0 * DEG);
    assert_true(fabs(p.phi_rad - 0.2) < 1e-12);
}

/* Requested sigma 2 px: the sample standard deviation of the current-image
 * noise, and of the once-per-run target-image noise, is within 2 %. */
static void test_noise_sigma(void **state)
{
    (void)state;
    static sim_world_t w;
    static sim_obs_t obs[SIM_MAX_POINTS], obs2[SIM_MAX_POINTS];
    char err[160];
    const double sigma = 2.0;
    sim_camera_t cam;
    sim_camera_make(&cam, 6.0, 0.0075, 0.0);
    const sim_plane_t pl = default_plane();
    const sim_scene_spec_t spec = { 100, 25, 15.0, 40.0 };
    assert_int_equal(sim_world_init(&w, &cam, &pl, &spec, sigma, 0.0, 0, 5,
                                    err, sizeof(err)), 0);
    const sim_pose_t pose = { -3.0, -10.0, -30 * DEG };
    double s1 = 0, s2 = 0;
    long cnt = 0;
    for (int f = 0; f < 400; ++f) {
        uint16_t n = sim_world_observe(&w, &pose, obs, SIM_MAX_POINTS);
        for (uint16_t i = 0; i < n; ++i) {
            /* Find the scene point of this feature. */
            int j = 0;
            while (w.scene.feature[j] != obs[i].feature) {
                ++j;
            }
            double p[2];
            assert_int_equal(sim_project(&cam, &pose, w.scene.X[j], p, NULL), 0);
            double dx = obs[i].x_cur - p[0], dy = obs[i].y_cur - p[1];
            s1 += dx + dy;
            s2 += dx * dx + dy * dy;
            cnt += 2;
        }
    }
    double mean = s1 / cnt, sd = sqrt(s2 / cnt - mean * mean);
    print_message("current-image noise: %ld samples, mean %.4f, sd %.4f px\n",
                  cnt, mean, sd);
    assert_true(cnt > 90000);
    assert_true(fabs(sd - sigma) < 0.02 * sigma);
    assert_true(fabs(mean) < 0.02 * sigma);

    /* Target noise is drawn once: two frames share x_tgt, not x_cur. */
    uint16_t n1 = sim_world_observe(&w, &pose, obs, SIM_MAX_POINTS);
    uint16_t n2 = sim_world_observe(&w, &pose, obs2, SIM_MAX_POINTS);
    assert_int_equal(n1, n2);
    assert_true(obs[0].x_tgt == obs2[0].x_tgt && obs[0].y_tgt == obs2[0].y_tgt);
    assert_true(obs[0].x_cur != obs2[0].x_cur);

    /* Its spread, over many runs (seeds). */
    s1 = s2 = 0;
    cnt = 0;
    for (uint64_t seed = 0; seed < 100; ++seed) {
        assert_int_equal(sim_world_init(&w, &cam, &pl, &spec, sigma, 0.0, 0,
                                        seed, err, sizeof(err)), 0);
        for (int i = 0; i < w.scene.n; ++i) {
            double dx = w.p_tgt_obs[i][0] - w.scene.p_tgt[i][0];
            double dy = w.p_tgt_obs[i][1] - w.scene.p_tgt[i][1];
            s1 += dx + dy;
            s2 += dx * dx + dy * dy;
            cnt += 2;
        }
    }
    mean = s1 / cnt;
    sd = sqrt(s2 / cnt - mean * mean);
    print_message("target-image noise: %ld samples, mean %.4f, sd %.4f px\n",
                  cnt, mean, sd);
    assert_true(fabs(sd - sigma) < 0.02 * sigma);
    assert_true(fabs(mean) < 0.05 * sigma);
}

/* Requested mismatch fraction 0.3: that share of each frame's matches lands
 * away from where the point really is, uniformly inside the image. */
static void test_mismatch_fraction(void **state)
{
    (void)state;
    static sim_world_t w;
    static sim_obs_t obs[SIM_MAX_POINTS];
    char err[160];
    const double frac = 0.3;
    sim_camera_t cam;
    sim_camera_make(&cam, 6.0, 0.0075, 0.0);
    const sim_plane_t pl = default_plane();
    const sim_scene_spec_t spec = { 100, 25, 15.0, 40.0 };
    assert_int_equal(sim_world_init(&w, &cam, &pl, &spec, 0.0, frac, 0, 9,
                                    err, sizeof(err)), 0);
    const sim_pose_t pose = { -1.0, -4.0, -10 * DEG };
    long moved = 0, total = 0, flagged = 0, plane_bad = 0;
    int min_frame = 1000, max_frame = 0;
    for (int f = 0; f < 200; ++f) {
        uint16_t n = sim_world_observe(&w, &pose, obs, SIM_MAX_POINTS);
        int bad = 0;
        for (uint16_t i = 0; i < n; ++i) {
            int j = 0;
            while (w.scene.feature[j] != obs[i].feature) {
                ++j;
            }
            double p[2];
            assert_int_equal(sim_project(&cam, &pose, w.scene.X[j], p, NULL), 0);
            /* A replacement point near the true one is not a mismatch that
             * matters; 2 px is the controller's scale of an inlier. */
            if (hypot(obs[i].x_cur - p[0], obs[i].y_cur - p[1]) > 2.0) {
                ++moved;
            }
            if (obs[i].mismatched) {
                ++bad;
                plane_bad += obs[i].on_plane;
                assert_true(obs[i].x_cur >= -320 && obs[i].x_cur < 320);
                assert_true(obs[i].y_cur >= -240 && obs[i].y_cur < 240);
            }
        }
        flagged += bad;
        total += n;
        min_frame = bad < min_frame ? bad : min_frame;
        max_frame = bad > max_frame ? bad : max_frame;
        /* Every frame carries round(0.3 n) mismatches. */
        assert_int_equal(bad, (int)floor(frac * n + 0.5));
    }
    double share = (double)moved / (double)total;
    print_message("mismatches: %ld of %ld matches displaced (%.4f)\n", moved,
                  total, share);
    assert_true(fabs(share - frac) < 0.01);
    /* Mismatches fall on plane and off-plane points alike (100 of 125). */
    double plane_share = (double)plane_bad / (double)flagged;
    assert_true(fabs(plane_share - 0.8) < 0.03);
}

static void test_seed_determinism(void **state)
{
    (void)state;
    static sim_world_t a, b;
    static sim_obs_t oa[SIM_MAX_POINTS], ob[SIM_MAX_POINTS];
    char err[160];
    sim_camera_t cam;
    sim_camera_make(&cam, 6.0, 0.0075, 0.0);
    const sim_plane_t pl = default_plane();
    const sim_scene_spec_t spec = { 100, 25, 15.0, 40.0 };
    const sim_pose_t pose = { -3.0, -10.0, -30 * DEG };
    assert_int_equal(sim_world_init(&a, &cam, &pl, &spec, 1.0, 0.1, 0, 3, err,
                                    sizeof(err)), 0);
    assert_int_equal(sim_world_init(&b, &cam, &pl, &spec, 1.0, 0.1, 0, 3, err,
                                    sizeof(err)), 0);
    uint16_t na = sim_world_observe(&a, &pose, oa, SIM_MAX_POINTS);
    uint16_t nb = sim_world_observe(&b, &pose, ob, SIM_MAX_POINTS);
    assert_int_equal(na, nb);
    assert_memory_equal(oa, ob, na * sizeof(sim_obs_t));
    /* Noise on or off leaves the scene itself unchanged. */
    assert_int_equal(sim_world_init(&b, &cam, &pl, &spec, 0.0, 0.0, 0, 3, err,
                                    sizeof(err)), 0);
    assert_memory_equal(a.scene.X, b.scene.X, sizeof(a.scene.X));
    /* Another seed, another scene. */
    assert_int_equal(sim_world_init(&b, &cam, &pl, &spec, 1.0, 0.1, 0, 4, err,
                                    sizeof(err)), 0);
    assert_true(memcmp(a.scene.X, b.scene.X, sizeof(a.scene.X)) != 0);
}

static void test_clip_keeps_points_in_frame(void **state)
{
    (void)state;
    static sim_world_t w;
    static sim_obs_t obs[SIM_MAX_POINTS];
    char err[160];
    sim_camera_t cam;
    sim_camera_make(&cam, 6.0, 0.0075, 0.0);
    const sim_plane_t pl = default_plane();
    const sim_scene_spec_t spec = { 100, 25, 15.0, 40.0 };
    /* Turned 60 deg away from the scene, part of it leaves the frame. */
    const sim_pose_t pose = { 2.0, -5.0, 35 * DEG };
    assert_int_equal(sim_world_init(&w, &cam, &pl, &spec, 0.0, 0.0, 0, 1, err,
                                    sizeof(err)), 0);
    uint16_t n_all = sim_world_observe(&w, &pose, obs, SIM_MAX_POINTS);
    assert_int_equal(sim_world_init(&w, &cam, &pl, &spec, 0.0, 0.0, 1, 1, err,
                                    sizeof(err)), 0);
    uint16_t n_in = sim_world_observe(&w, &pose, obs, SIM_MAX_POINTS);
    int inside = 0;
    for (int i = 0; i < w.scene.n; ++i) {
        double p[2];
        if (sim_project(&cam, &pose, w.scene.X[i], p, NULL) == 0 &&
            p[0] >= -320 && p[0] < 320 && p[1] >= -240 && p[1] < 240) {
            ++inside;
        }
    }
    assert_int_equal(n_all, 125);
    assert_int_equal(n_in, inside);
    assert_true(n_in < n_all && n_in > 0);
    for (uint16_t i = 0; i < n_in; ++i) {
        assert_true(fabs(obs[i].x_cur) <= 320 && fabs(obs[i].y_cur) <= 240);
    }
}

static void test_record_round_trip(void **state)
{
    (void)state;
    FILE *f = tmpfile();
    assert_non_null(f);
    spvs_match_t m[3] = { { 1.5f, -2.25f, 300.125f, -239.5f, 7 },
                          { 0, 0, 0, 0, 124 },
                          { -320, 240, 1e3f, -1e3f, 65535 } };
    assert_int_equal(sim_record_write_header(f), 0);
    assert_int_equal(sim_record_write_frame(f, 0, 0.0, m, 3, 0.25, -0.5, 0, 1), 0);
    assert_int_equal(sim_record_write_frame(f, 1, 0.1, m, 0, 0, 0, -9, 5), 0);
    /* 8 + (14 + 3 * 18 + 11) + (14 + 11) bytes, no padding. */
    assert_int_equal(ftell(f), 8 + 79 + 25);
    rewind(f);
    assert_int_equal(sim_record_read_header(f), 0);
    sim_record_frame_t fr;
    spvs_match_t back[3];
    assert_int_equal(sim_record_read_frame(f, &fr, back, 3), 1);
    assert_int_equal(fr.seq, 0);
    assert_int_equal(fr.n, 3);
    assert_true(fr.v_mps == 0.25f && fr.w_radps == -0.5f);
    assert_int_equal(fr.step, 1);
    for (int i = 0; i < 3; ++i) {
        assert_int_equal(back[i].feature, m[i].feature);
        assert_true(back[i].x_tgt == m[i].x_tgt && back[i].y_cur == m[i].y_cur);
    }
    assert_int_equal(sim_record_read_frame(f, &fr, back, 3), 1);
    assert_true(fr.seq == 1 && fr.t_s == 0.1 && fr.n == 0);
    assert_int_equal(fr.status, -9);
    assert_int_equal(fr.step, 5);
    assert_int_equal(sim_record_read_frame(f, &fr, back, 3), 0);
    fclose(f);
    /* The first bytes are the magic, little-endian fields after it. */
    f = tmpfile();
    assert_int_equal(sim_record_write_header(f), 0);
    assert_int_equal(sim_record_write_frame(f, 0x01020304u, 1.0, m, 0, 0, 0, 0, 0), 0);
    rewind(f);
    unsigned char b[12];
    assert_int_equal(fread(b, 1, 12, f), 12);
    assert_memory_equal(b, "SPVSREC1", 8);
    assert_true(b[8] == 4 && b[9] == 3 && b[10] == 2 && b[11] == 1);
    fclose(f);
}

static void test_config_check(void **state)
{
    (void)state;
    sim_config_t c;
    char err[160];
    sim_config_default(&c);
    assert_int_equal(sim_config_check(&c, err, sizeof(err)), 0);
    assert_int_equal(c.method, 3);
    assert_true(c.start.x_m == -3.0 && c.start.z_m == -10.0);
    assert_true(fabs(c.start.phi_rad + 30 * DEG) < 1e-15);
    assert_true(c.distance_m == 45.0 && c.dt_s == 0.1 && c.max_time_s == 300.0);
    sim_config_t bad = c;
    bad.method = 4;
    assert_int_equal(sim_config_check(&bad, err, sizeof(err)), -1);
    bad = c;
    bad.distance_m = 0.0;
    assert_int_equal(sim_config_check(&bad, err, sizeof(err)), -1);
    bad = c;
    bad.normal[0] = bad.normal[1] = bad.normal[2] = 0.0;
    assert_int_equal(sim_config_check(&bad, err, sizeof(err)), -1);
    bad = c;
    bad.outliers = 1.0;
    assert_int_equal(sim_config_check(&bad, err, sizeof(err)), -1);
    bad = c;
    bad.noise_px = -0.1;
    assert_int_equal(sim_config_check(&bad, err, sizeof(err)), -1);
    bad = c;
    bad.focal_true_mm = 0.0;
    assert_int_equal(sim_config_check(&bad, err, sizeof(err)), -1);
    bad = c;
    bad.dt_s = 0.0 / (c.dt_s - c.dt_s); /* NaN made at run time */
    assert_int_equal(sim_config_check(&bad, err, sizeof(err)), -1);
    assert_null(strchr(err, '\n'));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_eq2_equals_eq5),
        cmocka_unit_test(test_form8_on_the_line),
        cmocka_unit_test(test_form9_at_target_position),
        cmocka_unit_test(test_det_is_one_plus_nc_over_d),
        cmocka_unit_test(test_scene_and_transfer),
        cmocka_unit_test(test_plane_out_of_view_is_an_error),
        cmocka_unit_test(test_epipole_on_the_line),
        cmocka_unit_test(test_kinematics_straight),
        cmocka_unit_test(test_kinematics_circle),
        cmocka_unit_test(test_kinematics_drift),
        cmocka_unit_test(test_noise_sigma),
        cmocka_unit_test(test_mismatch_fraction),
        cmocka_unit_test(test_seed_determinism),
        cmocka_unit_test(test_clip_keeps_points_in_frame),
        cmocka_unit_test(test_record_round_trip),
        cmocka_unit_test(test_config_check),
    };
    return cmocka_run_group_tests_name("sim", tests, NULL, NULL);
}
