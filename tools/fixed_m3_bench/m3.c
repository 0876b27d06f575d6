/* The kernels' instruction counts on an emulated Cortex-M3 or M4F: one
 * frame (data.h, written by gen.c on the host) scored, costed and summed
 * by the float kernels (points.h) and the Q kernels (fixed/points_q.h);
 * SysTick ticks printed through semihosting (run.sh converts them). */
#include <string.h>
#include "fixed/points_q.h"
#include "spvs/homography.h"
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
static uint32_t now(void) { return 0x00FFFFFFu - SYST_CVR; }
static spvs_point_store_t fs;
static spvs_q_store_t qs;
static uint8_t mask[256], use[256];
int main(void);
int main(void)
{
    SYST_CSR = 0; SYST_RVR = 0x00FFFFFFu; SYST_CVR = 0; SYST_CSR = 5u;
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
    float sums[24]; spvs_q_sums_t qsum;
    t0 = now(); (void)spvs_pts_sum(SPVS_T_LIN, H, &in, use, N, sums); t1 = now();
    putu("lin_f ", t1 - t0);
    t0 = now(); (void)spvs_q_pts_sum(SPVS_T_LIN, hq, &qs, use, N, &qsum); t1 = now();
    putu("lin_q ", t1 - t0);
    t0 = now(); (void)spvs_pts_sum(SPVS_T_FIT_Y, H, &in, use, N, sums); t1 = now();
    putu("fity_f ", t1 - t0);
    t0 = now(); (void)spvs_q_pts_sum(SPVS_T_FIT_Y, hq, &qs, use, N, &qsum); t1 = now();
    putu("fity_q ", t1 - t0);
    uint32_t sat = 0;
    t0 = now(); (void)spvs_pts_cost(&fs, N, H, t2); t1 = now();
    putu("cost_f ", t1 - t0);
    t0 = now(); (void)spvs_q_pts_cost(&qs, N, hq, &thr, &sat); t1 = now();
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
__attribute__((section(".vectors"), used)) static const void *const vectors[2] = {&__stack_top, (void *)reset};
