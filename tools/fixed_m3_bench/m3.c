/* The kernels' instruction counts on an emulated Cortex-M3 or M4F: one
 * frame (data.h, written by gen.c on the host) scored, costed and summed
 * by the float kernels (points.h) and the Q kernels (fixed/points_q.h);
 * SysTick ticks printed through semihosting (run.sh converts them). */
#include <math.h>
#include <string.h>
#include "fixed/points_q.h"
#include "fixed/fit_q.h"
#include "fixed/plane_h_q.h"
#include "fixed/spvs_q.h"
#include "spvs/spvs.h"
#include "spvs/plane_h.h"
#include "h_fit.h"
#include "spvs/homography.h"
#include "spvs/control.h"
#include "spvs/offplane.h"
#include "spvs/epipole.h"
#include "spvs/instance.h"
#include "fixed/control_q.h"
#include "data.h"
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
static int semi(int op, const void *arg)
{
    register int r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}
static void puts_(const char *s) { semi(4, s); }
static void putu(const char *k, uint32_t v)
{
    char b[16]; int i = 15; b[i] = 0;
    do { b[--i] = (char)('0' + v % 10u); v /= 10u; } while (v);
    puts_(k); puts_(b + i); puts_("\n");
}
/* SysTick's 24 bits wrap after 16.7 M ticks (10.5 M instructions); its
 * interrupt counts the wraps, so a soft-float update is timed whole. */
static volatile uint32_t g_wraps;
void systick(void);
void systick(void) { g_wraps++; }
static uint32_t now(void)
{
    uint32_t w, c;
    do {
        w = g_wraps;
        c = SYST_CVR;
    } while (w != g_wraps);
    return w * 0x01000000u + (0x00FFFFFFu - c);
}
static void putk(const char *pre, const char *k, uint32_t v)
{
    /* run.sh prints keys that begin with cnt unconverted: the prefix
     * goes after it. */
    char b[32]; int i = 0;
    if (k[0] == 'c' && k[1] == 'n' && k[2] == 't' && k[3] == '_') {
        while (i < 4) b[i++] = *k++;
    }
    while (*pre && i < 12) b[i++] = *pre++;
    while (*k && i < 30) b[i++] = *k++;
    b[i] = 0;
    putu(b, v);
}
static void stages_f(spvs_state_t *s, const char *pre)
{
    spvs_offplane_t *const o = &s->off;
    uint32_t t0 = now();
    spvs_offplane_collect(o, &s->est, s->p.offplane_px);
    uint32_t t1 = now();
    putk(pre, "collect_f ", t1 - t0); putk(pre, "cnt_cand_f ", o->n_cand);
    spvs_epipole_t ep;
    const float sin_tol2 = s->p.epipole_sin_tol * s->p.epipole_sin_tol;
    t0 = now();
    const int rc = spvs_epipole_estimate(s->est.H_sc, (const float(*)[4])o->cand_pts, o->cand_ord,
                                         o->n_cand, sin_tol2, s->p.min_support, &ep, o->support,
                                         &s->ework);
    t1 = now();
    putk(pre, "epipole_f ", t1 - t0); putk(pre, "cnt_epipole_f_st ", (uint32_t)(rc + 100));
}
static void stages_q(spvs_q_t *s, const char *pre)
{
    spvs_q_offplane_t *const o = &s->off;
    uint32_t t0 = now();
    spvs_q_offplane_collect(o, &s->est, s->p.offplane_q16);
    uint32_t t1 = now();
    putk(pre, "collect_q ", t1 - t0); putk(pre, "cnt_cand_q ", o->n_cand);
    t0 = now();
    const int32_t par = spvs_q_offplane_known_parallax_q16(o, s->est.H, s->scratch);
    t1 = now();
    putk(pre, "known_q ", t1 - t0);
    spvs_q_epipole_t ep;
    t0 = now();
    const int rc = spvs_q_epipole_estimate(s->est.H, (const int32_t(*)[4])o->cand_pts, o->cand_ord,
                                           o->n_cand, s->p.sin_tol2_q30, s->p.min_support, &ep,
                                           o->support, &s->ework);
    t1 = now();
    putk(pre, "epipole_q ", t1 - t0); putk(pre, "cnt_epipole_q_st ", (uint32_t)(rc + 100));
    putk(pre, "cnt_support_q ", ep.n_support);
    t0 = now();
    spvs_q_offplane_remember(o, &s->est, rc == SPVS_OK, par < 0 && rc == SPVS_OK ? ep.parallax_q16 : par,
                             s->p.offplane_q16);
    t1 = now();
    putk(pre, "remember_q ", t1 - t0);
}
/* The arrival check: a controller standing still after step 3 on H near
 * the identity, frame after frame until it decides; the deciding frame's
 * count (the check's means, standard deviations and statistic). */
#define ARR_H11 1.0004f
#define ARR_H13 0.3f
#define ARR_H33 0.9997f
static void arrive_f(const spvs_control_params_t *p)
{
    static spvs_control_t c;
    spvs_control_reset(&c);
    c.step = SPVS_STEP_ALIGN; c.checked_plane = 1; c.arriving = 1;
    spvs_control_input_t in = {.H = {ARR_H11, 0.0f, ARR_H13, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, ARR_H33},
                               .e_dir_z = 1.0f, .parallax_px = 0.2f, .parallax_x_px = 0.0f, .parallax_r_px = 0.0f,
                               .t_s = 0.0f, .e_valid = 1, .n_inliers = 100};
    uint32_t last = 0; int k = 0, rc = 0;
    while (c.arriving && k < 1000) {
        in.t_s = 0.125f * (float)k++;
        float v, w;
        const uint32_t t0 = now(); rc = spvs_control_step(&c, p, &in, &v, &w); last = now() - t0;
    }
    putu("ctl_arrive_f ", last); putu("cnt_arrive_f_frames ", (uint32_t)k); putu("cnt_arrive_f_step ", (uint32_t)c.step); putu("cnt_arrive_f_st ", (uint32_t)(rc + 100));
}
static void arrive_q(const spvs_q_ctl_params_t *p)
{
    static spvs_q_ctl_t c;
    spvs_q_ctl_reset(&c);
    c.step = SPVS_STEP_ALIGN; c.checked_plane = 1; c.arriving = 1;
    const float hf[9] = {ARR_H11, 0.0f, ARR_H13, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, ARR_H33};
    spvs_control_input_t fin = {.e_dir_z = 1.0f, .parallax_px = 0.2f, .parallax_x_px = 0.0f, .parallax_r_px = 0.0f,
                                .t_s = 0.0f, .e_valid = 1, .n_inliers = 100};
    memcpy(fin.H, hf, sizeof hf);
    spvs_q_ctl_input_t in;
    const int rin = spvs_q_ctl_input_from_real(&in, &fin);
    putu("cnt_arrive_q_in ", (uint32_t)(rin + 100));
    uint32_t last = 0; int k = 0, rc = 0;
    while (c.arriving && k < 1000) {
        in.t = 8192 * k++; /* 0.125 s in Q16 */
        int32_t v, w;
        const uint32_t t0 = now(); rc = spvs_q_ctl_step(&c, p, &in, &v, &w); last = now() - t0;
    }
    putu("ctl_arrive_q ", last); putu("cnt_arrive_q_frames ", (uint32_t)k); putu("cnt_arrive_q_step ", (uint32_t)c.step); putu("cnt_arrive_q_st ", (uint32_t)(rc + 100));
}
static spvs_point_store_t fs;
static spvs_q_store_t qs;
static uint8_t mask[256], use[256];
int main(void);
int main(void)
{
    SYST_CSR = 0; SYST_RVR = 0x00FFFFFFu; SYST_CVR = 0; SYST_CSR = 7u;
    memcpy(fs.v, fbits, sizeof fbits); memcpy(fs.cur_max, fmax_bits, sizeof fmax_bits);
    memcpy(qs.v, qv, sizeof qv); qs.cur_max[0] = qmax[0]; qs.cur_max[1] = qmax[1]; qs.tgt_max[0] = tmax[0]; qs.tgt_max[1] = tmax[1];
    float H[9], t2; memcpy(H, hbits, sizeof H); memcpy(&t2, &t2bits, 4);
    spvs_qf_t qt2 = {qt2m, qt2e};
    const spvs_q_thr_t thr = spvs_q_thr(qt2);
    uint32_t t0, t1;
    t0 = now(); uint16_t cf = spvs_pts_score(&fs, N, H, t2, 0, mask); t1 = now();
    putu("score_f ", t1 - t0); putu("cnt_f ", cf);
    t0 = now(); uint16_t cq = spvs_q_pts_score(&qs, N, hq, &thr, 0, mask); t1 = now();
    putu("score_q ", t1 - t0); putu("cnt_q ", cq);
    for (int i = 0; i < N; i++) use[i] = mask[i];
    const spvs_pts_in_t in = {0, &fs};
    float sums[SPVS_H_LIN_SUMS]; spvs_q_sums_t qsum;
    t0 = now(); (void)spvs_pts_sum(SPVS_T_LIN, H, &in, use, N, sums); t1 = now();
    putu("lin_f ", t1 - t0);
    t0 = now(); (void)spvs_q_pts_sum(SPVS_T_LIN, hq, &qs, use, N, &qsum); t1 = now();
    putu("lin_q ", t1 - t0);
    t0 = now(); (void)spvs_pts_sum(SPVS_T_FIT_Y, H, &in, use, N, sums); t1 = now();
    putu("fity_f ", t1 - t0);
    t0 = now(); (void)spvs_q_pts_sum(SPVS_T_FIT_Y, hq, &qs, use, N, &qsum); t1 = now();
    putu("fity_q ", t1 - t0);
    uint32_t sat = 0;
    t0 = now(); (void)spvs_pts_cost(&fs, N, H, mask); t1 = now();
    putu("cost_f ", t1 - t0);
    t0 = now(); (void)spvs_q_pts_cost(&qs, N, hq, mask, &sat); t1 = now();
    putu("cost_q ", t1 - t0);
    /* The 3-point solver on the first triple (i, i + N/3, i + 2N/3) that
     * both solvers solve (found untimed), as RANSAC's solvable samples
     * (neighbouring points of the synthetic frame lie on a line). */
    uint16_t idx[3] = {0, 1, 2};
    float pf[3][4], Hf[9];
    int32_t Hs3[9];
    for (uint16_t i = 0; i + 2 < N; i++) {
        for (int k = 0; k < 3; k++) { idx[k] = (uint16_t)((i + k * (N / 3)) % N); spvs_pts_row(&fs, idx[k], pf[k]); }
        if (spvs_h_solve3(pf, Hf) == 0 && spvs_q_solve3(&qs, idx, Hs3) == 0) break;
    }
    t0 = now(); const int rf = spvs_h_solve3(pf, Hf); t1 = now();
    putu("solve_f ", t1 - t0); putu("cnt_solve_f_ok ", rf == 0);
    t0 = now(); const int rq = spvs_q_solve3(&qs, idx, Hs3); t1 = now();
    putu("solve_q ", t1 - t0); putu("cnt_solve_q_ok ", rq == 0);
    /* The linear fits on the frame's inliers: the two-stage fit from H's
     * weights (its two sums and two 3 x 3 solves), the Q 3 x 3 solve
     * alone, and the joint fit's 6 x 6 solve of the SPVS_T_LIN sums at H
     * (made untimed). */
    float Hl[9]; memcpy(Hl, H, sizeof Hl);
    t0 = now(); const int rfl = spvs_hf_fit_linear(&in, use, N, Hl); t1 = now();
    putu("fitlin_f ", t1 - t0); putu("cnt_fitlin_f_ok ", rfl == 0);
    int32_t Hql[9]; memcpy(Hql, hq, sizeof Hql);
    t0 = now(); const int rql = spvs_q_fit_linear(&qs, use, N, Hql); t1 = now();
    putu("fitlin_q ", t1 - t0); putu("cnt_fitlin_q_ok ", rql == 0);
    static spvs_q_sums_t fq;
    (void)spvs_q_pts_sum(SPVS_T_FIT_Y, hq, &qs, use, N, &fq);
    int32_t h3q[3];
    t0 = now(); const int rfs = spvs_q_fit_solve(&fq, h3q); t1 = now();
    putu("fitsolve_q ", t1 - t0); putu("cnt_fitsolve_q_ok ", rfs == 0);
    static float lsums[SPVS_H_LIN_SUMS]; static spvs_q_sums_t lq;
    (void)spvs_pts_sum(SPVS_T_LIN, H, &in, use, N, lsums);
    (void)spvs_q_pts_sum(SPVS_T_LIN, hq, &qs, use, N, &lq);
    float Hls[9]; int32_t Hqs[9];
    t0 = now(); const int rls = spvs_hf_lin_solve(lsums, H, Hls); t1 = now();
    putu("linsolve_f ", t1 - t0); putu("cnt_linsolve_f_ok ", rls == 0);
    t0 = now(); const int rlq = spvs_q_lin_solve(&lq, hq, Hqs); t1 = now();
    putu("linsolve_q ", t1 - t0); putu("cnt_linsolve_q_ok ", rlq == 0);
    /* The whole robust estimate on the frame, float and Q, from the same
     * seed: RANSAC with its LO step, the re-selection and the final
     * refit (spvs_plane_h_estimate, spvs_q_plane_h_estimate). */
    static spvs_plane_h_t ef;
    static spvs_q_plane_h_t eq;
    memcpy(&ef.pts, &fs, sizeof fs);
    ef.n_plane = ef.n_pts = N;
    memcpy(&eq.pts, &qs, sizeof qs);
    eq.n_plane = eq.n_pts = N;
    const float inlier_px = sqrtf(t2) * (float)SPVS_COORD_SCALE;
    spvs_rng_t rng;
    uint32_t it_f = 0, it_q = 0;
    spvs_rng_seed(&rng, 1u);
    t0 = now(); const int ref = spvs_plane_h_estimate(&ef, inlier_px, 0.99f, 200u, &rng, &it_f); t1 = now();
    putu("est_f ", t1 - t0); putu("cnt_est_f_ok ", ref == 0); putu("cnt_est_f_inl ", ef.n_inliers); putu("cnt_est_f_it ", it_f);
    spvs_rng_seed(&rng, 1u);
    const uint32_t conf_q32 = 4252017623u; /* 0.99 2^32, rounded down */
    t0 = now(); const int req = spvs_q_plane_h_estimate(&eq, qt2, conf_q32, 200u, &rng, &it_q); t1 = now();
    putu("est_q ", t1 - t0); putu("cnt_est_q_ok ", req == 0); putu("cnt_est_q_inl ", eq.n_inliers); putu("cnt_est_q_it ", it_q);
    /* One whole update (spvs_update, spvs_q_update) of a fresh Method III
     * controller on the frame's matches: the estimate, the off-plane stage
     * and the epipole (the frame has no off-plane point, so it finds no
     * parallax and the controller waits), the control step. */
    static spvs_match_t mm[N];
    for (int i = 0; i < N; i++) {
        memcpy(&mm[i].x_tgt, &mbits[4 * i], 4); memcpy(&mm[i].y_tgt, &mbits[4 * i + 1], 4);
        memcpy(&mm[i].x_cur, &mbits[4 * i + 2], 4); memcpy(&mm[i].y_cur, &mbits[4 * i + 3], 4);
        mm[i].feature = (uint16_t)i;
    }
    static spvs_t sf;
    static spvs_q_t sq;
    static spvs_output_t out;
    spvs_params_t pp;
    spvs_params_default(&pp, SPVS_METHOD_III);
    pp.seed = 1u;
    const int if_ = spvs_init(&sf, &pp), iq_ = spvs_q_init(&sq, &pp);
    t0 = now(); const int uf = spvs_update(&sf, mm, N, 0.1f, &out); t1 = now();
    putu("update_f ", t1 - t0); putu("cnt_update_f_init ", (uint32_t)if_); putu("cnt_update_f_st ", (uint32_t)(uf + 100)); putu("cnt_update_f_inl ", out.n_inliers);
    t0 = now(); const int uq = spvs_q_update(&sq, mm, N, 0.1f, &out); t1 = now();
    putu("update_q ", t1 - t0); putu("cnt_update_q_init ", (uint32_t)iq_); putu("cnt_update_q_st ", (uint32_t)(uq + 100)); putu("cnt_update_q_inl ", out.n_inliers);
    /* The stages after H, replayed on the update's own state (the same
     * estimate, so the same candidates): the off-plane collect, the
     * epipole, the memory's update; then the same on a frame with
     * off-plane points (keys o*), and the arrival check's decision. */
    stages_f(spvs_state(&sf), "");
    stages_q(&sq, "");
    static spvs_match_t mo[NO];
    for (int i = 0; i < NO; i++) {
        memcpy(&mo[i].x_tgt, &obits[4 * i], 4); memcpy(&mo[i].y_tgt, &obits[4 * i + 1], 4);
        memcpy(&mo[i].x_cur, &obits[4 * i + 2], 4); memcpy(&mo[i].y_cur, &obits[4 * i + 3], 4);
        mo[i].feature = (uint16_t)i;
    }
    const int oif = spvs_init(&sf, &pp), oiq = spvs_q_init(&sq, &pp);
    putu("cnt_oinit ", (uint32_t)(oif | oiq));
    t0 = now(); const int ouf = spvs_update(&sf, mo, NO, 0.1f, &out); t1 = now();
    putu("oupdate_f ", t1 - t0); putu("cnt_oupdate_f_st ", (uint32_t)(ouf + 100));
    t0 = now(); const int ouq = spvs_q_update(&sq, mo, NO, 0.1f, &out); t1 = now();
    putu("oupdate_q ", t1 - t0); putu("cnt_oupdate_q_st ", (uint32_t)(ouq + 100));
    stages_f(spvs_state(&sf), "o");
    stages_q(&sq, "o");
    arrive_f(&pp.ctl);
    arrive_q(&sq.p.ctl_p);
    static const int exit_args[2] = {0x20026, 0};
    semi(0x18, exit_args);
    for (;;) {}
}
extern uint32_t __stack_top;
void reset(void);
void reset(void)
{
#if ENABLE_FPU
    /* CPACR: full access to CP10 and CP11 (the Cortex-M4F's FPU). */
    *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb");
#endif
    main();
}
__attribute__((section(".vectors"), used)) static const void *const vectors[16] = {
    &__stack_top, (void *)reset, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, (void *)systick};
