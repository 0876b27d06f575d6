/*
 * fp_helpers.h - where the float core's time goes on a CPU without FPU:
 * counts and times every call to the soft-float helpers and the libm
 * functions the core calls, in spvs_measure_fp.elf only.
 *
 * The image is linked with ld's --wrap for each routine of fp_helpers.c
 * (target/CMakeLists.txt), so a call from the core (or from libm) to, e.g.,
 * __aeabi_fmul lands in __wrap___aeabi_fmul, which reads the SysTick
 * counter around the real routine.  What a timed call costs by itself (the
 * two reads, the argument moves, the call) is measured at fp_helpers_start
 * on a routine of one instruction (its return) through the same timed path,
 * and taken off every call; so the instructions executed inside a routine,
 * its return included, are to_instructions(ticks) + calls.  That is good to
 * about one instruction per call (a one-argument routine moves one argument
 * fewer than the two-argument calibration).  Calls made inside a timed call
 * (the helpers that sqrtf and logf call) belong to the outer one and are
 * not counted again.
 */
#ifndef TARGET_FP_HELPERS_H
#define TARGET_FP_HELPERS_H

#include <stdint.h>

typedef struct {
    const char *name; /* the routine's symbol */
    uint32_t calls;   /* calls since fp_helpers_start */
    uint64_t ticks;   /* SysTick ticks in them less the cost of a timed call
                         of a one-instruction routine, per call */
} fp_helper_stat_t;

/* Zero the counters, measure the timing's own cost, count from now on. */
void fp_helpers_start(void);
/* Stop counting (the counters keep their values). */
void fp_helpers_stop(void);
/* Number of routines wrapped; fp_helpers_stat(i) for i below it. */
uint32_t fp_helpers_count(void);
const fp_helper_stat_t *fp_helpers_stat(uint32_t i);

#endif /* TARGET_FP_HELPERS_H */
