/*
 * test_frontend_loop.c - the closed loop fed from rendered images: SIFT
 * matches of each current image against the target image (sim/frontend.h)
 * drive the in-process controller.  One run per ctest entry; the case is
 * given on the command line as METHOD X_M Z_M PHI_DEG [STATUS [POS_TOL_M]].
 *
 * Asserted: the run ends with STATUS, its documented outcome (converged
 * unless tests/frontend.cmake and docs/TESTING.md give not_at_target: the
 * verified arrival refusing a run that stands home), and the final pose
 * error is within POS_TOL_M (0.10 m unless the case's documented outcome
 * says more) in x and z and 1 deg in heading.
 * Reported: match counts and mismatch rates along the way (a mismatch is a
 * match more than 3 px from the true projection of its target feature's 3D
 * point), and the wall-clock time of the run.  The wall time is printed,
 * never asserted: it measures the host and its load, not the loop (the
 * figures for an unloaded machine are in docs/RESULTS_IMAGES.md; ctest's
 * TIMEOUT in tests/frontend.cmake allows a host three times slower).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sim/clock.h"
#include "sim/frontend.h"
#include "sim/link_inproc.h"
#include "sim/sim.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

/* The bounds of the image loop: 0.10 m and 1 deg. */
#define POS_TOL_M 0.10
#define PHI_TOL_DEG 1.0
/* Simulated time bound: the exact-point runs take 30..60 s. */
#define MAX_SIM_TIME_S 100.0

typedef struct {
    int method;
    double x_m, z_m, phi_deg;
    int expect_not_at_target; /* the documented outcome is not_at_target */
    double pos_tol_m;
} loop_case_t;

/* Per-step match statistics, gathered by the frame callback. */
typedef struct {
    uint32_t frames[4];
    uint64_t matches[4];
    uint64_t mismatches[4];
    uint16_t min_matches[4];
    uint64_t inliers[4];
} loop_stats_t;

static int watch(const sim_frame_t *f, void *user)
{
    loop_stats_t *s = user;
    int step = f->out->step;
    /* The frame belongs to the step the controller was in when it came,
     * i.e. the step it reports (steps 4, 5 are counted in step 3). */
    int k = step < 1 ? 1 : (step > 3 ? 3 : step);
    uint16_t bad = 0;
    for (uint16_t i = 0; i < f->n; ++i) {
        bad = (uint16_t)(bad + f->obs[i].mismatched);
    }
    if (s->frames[k] == 0 || f->n < s->min_matches[k]) {
        s->min_matches[k] = f->n;
    }
    s->frames[k]++;
    s->matches[k] += f->n;
    s->mismatches[k] += bad;
    s->inliers[k] += f->out->n_inliers;
    return 0;
}

static void closed_loop_from_images(void **state)
{
    const loop_case_t *lc = *state;
    sim_config_t c;
    sim_config_default(&c);
    c.method = lc->method;
    c.start.x_m = lc->x_m;
    c.start.z_m = lc->z_m;
    c.start.phi_rad = lc->phi_deg * DEG;
    c.max_time_s = MAX_SIM_TIME_S;
    /* The front end's wide camera, and the controller told so. */
    c.focal_true_mm = SIM_FRONTEND_FOCAL_MM;
    c.focal_assumed_mm = SIM_FRONTEND_FOCAL_MM;
    c.arrival_sigma_px = SIM_FRONTEND_ARRIVAL_SIGMA_PX;

    static sim_world_t world;
    char err[200];
    assert_int_equal(sim_config_world(&c, &world, err, sizeof(err)), 0);
    sim_frontend_params_t fp;
    sim_frontend_params_default(&fp);
    fp.seed = c.seed;
    double t0 = sim_clock_now_s();
    sim_frontend_t *fe = sim_frontend_create(&fp, &world.cam, &world.plane,
                                             err, sizeof(err));
    if (fe == NULL) {
        print_message("front end: %s\n", err);
    }
    assert_non_null(fe);
    c.observe = sim_frontend_observe_cb;
    c.observe_user = fe;

    loop_stats_t st;
    memset(&st, 0, sizeof(st));
    sim_result_t r;
    int rc = sim_run_inproc(&c, &r, watch, &st, err, sizeof(err));
    double wall = sim_clock_now_s() - t0;
    sim_frontend_totals_t tot;
    sim_frontend_totals(fe, &tot);
    sim_frontend_destroy(fe);
    assert_int_equal(rc, 0);

    print_message("method %d from (%g m, %g m, %g deg): %s%s%s after %.1f s "
                  "simulated (%u frames), final error x %+.4f m, z %+.4f m, "
                  "phi %+.3f deg; wall %.1f s (render %.1f s, features %.1f s)\n",
                  lc->method, lc->x_m, lc->z_m, lc->phi_deg,
                  sim_status_str(r.status), r.reason[0] ? ": " : "", r.reason,
                  r.time_s, (unsigned)r.frames, r.err_x_m, r.err_z_m,
                  r.err_phi_deg, wall, tot.render_ms / 1000.0,
                  tot.match_ms / 1000.0);
    print_message("  matches per frame: mean %.1f, min %u, max %u; mismatch "
                  "rate %.1f %% overall, worst frame %.1f %%\n",
                  tot.frames ? (double)tot.matches / tot.frames : 0.0,
                  (unsigned)tot.min_matches, (unsigned)tot.max_matches,
                  tot.matches ? 100.0 * (double)tot.mismatches /
                                    (double)tot.matches
                              : 0.0,
                  100.0 * tot.max_mismatch_rate);
    for (int k = 1; k <= 3; ++k) {
        if (st.frames[k] == 0) {
            continue;
        }
        print_message("  step %d: %u frames, matches mean %.1f (min %u), "
                      "plane inliers mean %.1f, mismatch rate %.1f %%\n",
                      k, (unsigned)st.frames[k],
                      (double)st.matches[k] / st.frames[k],
                      (unsigned)st.min_matches[k],
                      (double)st.inliers[k] / st.frames[k],
                      st.matches[k] ? 100.0 * (double)st.mismatches[k] /
                                          (double)st.matches[k]
                                    : 0.0);
    }

    /* Home within the limits, with the case's documented status: converged,
     * or not_at_target where the verified arrival (docs/CONTROL.md) saw the
     * residual offset of the image matches and its re-entries could not
     * remove it. */
    if (lc->expect_not_at_target) {
        assert_true(r.status != SIM_CONVERGED && r.core_status == SPVS_E_NOT_AT_TARGET);
    } else {
        assert_true(r.status == SIM_CONVERGED);
    }
    assert_true(fabs(r.err_x_m) <= lc->pos_tol_m);
    assert_true(fabs(r.err_z_m) <= lc->pos_tol_m);
    assert_true(fabs(r.err_phi_deg) <= PHI_TOL_DEG);
}

int main(int argc, char **argv)
{
    static loop_case_t lc = { 3, -3.0, -10.0, -30.0, 0, POS_TOL_M };
    if (argc >= 5 && argc <= 7) {
        lc.method = atoi(argv[1]);
        lc.x_m = atof(argv[2]);
        lc.z_m = atof(argv[3]);
        lc.phi_deg = atof(argv[4]);
        if (argc >= 6) {
            if (strcmp(argv[5], "not_at_target") == 0) {
                lc.expect_not_at_target = 1;
            } else if (strcmp(argv[5], "converged") != 0) {
                fprintf(stderr, "%s: STATUS must be converged or not_at_target\n", argv[0]);
                return 2;
            }
        }
        if (argc == 7) {
            lc.pos_tol_m = atof(argv[6]);
            if (!(lc.pos_tol_m > 0.0)) {
                fprintf(stderr, "%s: POS_TOL_M must be a positive number\n", argv[0]);
                return 2;
            }
        }
    } else if (argc != 1) {
        fprintf(stderr, "usage: %s [METHOD X_M Z_M PHI_DEG [STATUS [POS_TOL_M]]]\n", argv[0]);
        return 2;
    }
    if (lc.method < 1 || lc.method > 3) {
        fprintf(stderr, "%s: method must be 1, 2 or 3\n", argv[0]);
        return 2;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_prestate(closed_loop_from_images, &lc),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
