/*
 * spvs-consumer: a program outside the spvs tree that uses the installed
 * core (docs/INSTALL.md).  It builds one synthetic frame, runs the Method III
 * controller on it for four frames and checks the command against the
 * geometry (exit status 0 when every check holds, 1 otherwise).
 *
 * The scene is that of the paper's Figure 5: the robot at x = -3 m,
 * z = -10 m, heading phi = -30 deg, the target at the origin; a plane
 * n = (0.3, -0.6, -0.75), d = 45 m, with 100 points on it and 25 points off
 * it (15-40 m deep); a 640x480 camera with a focal length of 800 pixels.
 * Image points are pixels centred on the principal point.
 *
 * Expected: step 1 (turn on the spot): v = 0; w = 0 for the first two frames
 * (the step logic waits for the start frames), then w > 0 (turning towards
 * the target, which lies to the left); all 100 plane points are the
 * homography's inliers, the others support the epipole, whose x is
 * alpha tan(phi - phi_t) with phi_t = -atan(3/10), and w = k_w |e_x|
 * (eq. 22, step 1).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include <spvs/spvs.h>

#define PI 3.14159265358979323846
#define ALPHA_PX 800.0
#define N_PLANE 100
#define N_OFF 25

static const double pose_x = -3.0, pose_z = -10.0, pose_phi = -30.0 * PI / 180.0;
static const double plane_n[3] = {0.3, -0.6, -0.75}, plane_d = 45.0;

/* A fixed pseudo-random sequence (xorshift64*), uniform in [0, 1). */
static double uniform(uint64_t *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

/* World point X (target camera frame) to pixels in the current camera:
 * X_c = R(phi) (X - c), c = (x, 0, z).  Returns 0 when behind the camera. */
static int project(const double X[3], double px[2])
{
    double c = cos(pose_phi), s = sin(pose_phi);
    double dx = X[0] - pose_x, dz = X[2] - pose_z;
    double xc = c * dx + s * dz, yc = X[1], zc = -s * dx + c * dz;
    if (zc < 0.1) {
        return 0;
    }
    px[0] = ALPHA_PX * xc / zc;
    px[1] = ALPHA_PX * yc / zc;
    return 1;
}

/* The frame: plane points first (features 0..99), then off-plane points. */
static uint16_t make_frame(spvs_match_t *m)
{
    double l = sqrt(plane_n[0] * plane_n[0] + plane_n[1] * plane_n[1] + plane_n[2] * plane_n[2]);
    uint64_t rng = 1;
    uint16_t k = 0;
    for (int i = 0; i < N_PLANE + N_OFF; i++) {
        for (int tries = 0; tries < 1000; tries++) {
            double u = (uniform(&rng) - 0.5) * 640, v = (uniform(&rng) - 0.5) * 480;
            double r[3] = {u / ALPHA_PX, v / ALPHA_PX, 1.0}, X[3], px[2];
            double nr = (plane_n[0] * r[0] + plane_n[1] * r[1] + plane_n[2] * r[2]) / l;
            double depth;
            if (i < N_PLANE) {
                if (!(nr < -1e-9)) {
                    continue;
                }
                depth = -plane_d / nr;
            } else {
                depth = 15 + 25 * uniform(&rng);
                if (!(depth * nr > -plane_d)) {
                    continue;
                }
            }
            X[0] = depth * r[0];
            X[1] = depth * r[1];
            X[2] = depth;
            if (project(X, px) && fabs(px[0]) < 4000 && fabs(px[1]) < 4000) {
                m[k].x_tgt = (spvs_real)u;
                m[k].y_tgt = (spvs_real)v;
                m[k].x_cur = (spvs_real)px[0];
                m[k].y_cur = (spvs_real)px[1];
                m[k].feature = (uint16_t)i;
                k++;
                break;
            }
        }
    }
    return k;
}

static int failures;

static void check(int ok, const char *what)
{
    if (!ok) {
        fprintf(stderr, "spvs-consumer: FAIL: %s\n", what);
        failures++;
    }
}

int main(void)
{
    static spvs_t ctl; /* caller-owned, sizeof(spvs_t) bytes, no heap */
    static spvs_match_t m[N_PLANE + N_OFF];
    spvs_params_t p;
    spvs_output_t out = {0};

    spvs_params_default(&p, SPVS_METHOD_III);
    p.ctl.alpha_x = p.ctl.alpha_y = (spvs_real)ALPHA_PX;
    if (spvs_init(&ctl, &p) != SPVS_OK) {
        fprintf(stderr, "spvs-consumer: spvs_init rejected the default parameters\n");
        return 1;
    }
    uint16_t n = make_frame(m);
    check(n == N_PLANE + N_OFF, "the frame has 125 matches");

    for (int k = 0; k < 4; k++) {
        int st = spvs_update(&ctl, m, n, (spvs_real)(0.1 * k), &out);
        check(st == SPVS_OK, "spvs_update returns SPVS_OK");
        check(out.step == SPVS_STEP_ROTATE, "step 1 (rotate)");
        check(out.v == 0, "v = 0 while turning on the spot");
        check(k < 2 ? out.w == 0 : out.w > 0, "w = 0 on the start frames, then w > 0");
    }
    double ex_expected = ALPHA_PX * tan(pose_phi + atan(0.3));
    check(out.h_valid && out.n_inliers == N_PLANE, "the 100 plane points are H's inliers");
    check(out.e_valid && out.n_offplane >= 20 && out.n_offplane <= N_OFF,
          "at least 20 of the 25 off-plane points support the epipole");
    check(fabs((double)out.e_x_px - ex_expected) < 0.05, "e_x within 0.05 px of alpha tan(phi - phi_t)");
    /* Step 1 of Method III: w = -k_w e_x, the gain's sign chosen so that the
     * robot turns towards the target (eq. 22), under the w_max saturation. */
    double w_expected = fmin((double)p.ctl.k_w * fabs(ex_expected), (double)p.ctl.w_max);
    check(fabs((double)out.w - w_expected) < 1e-3 * w_expected, "w = k_w |e_x| to 0.1 %");

    printf("version %s\n", SPVS_VERSION_STRING);
    printf("scalar %s%s\n", SPVS_USE_FIXED ? "fixed_" : "", SPVS_USE_DOUBLE ? "double" : "float");
    printf("sizeof_spvs_t %u\n", (unsigned)sizeof(spvs_t));
    printf("matches %u\n", (unsigned)out.n_matches);
    printf("inliers %u\n", (unsigned)out.n_inliers);
    printf("offplane %u\n", (unsigned)out.n_offplane);
    printf("e_x_px %.4f\n", (double)out.e_x_px);
    printf("e_x_expected_px %.4f\n", ex_expected);
    printf("w_expected_rad_s %.6f\n", w_expected);
    printf("step %u\n", (unsigned)out.step);
    printf("v_m_s %.6f\n", (double)out.v);
    printf("w_rad_s %.6f\n", (double)out.w);
    printf("result %s\n", failures == 0 ? "ok" : "FAIL");
    return failures == 0 ? 0 : 1;
}
