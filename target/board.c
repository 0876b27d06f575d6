/*
 * board.c - SysTick tick counter and stack high-water mark.
 *
 * Under QEMU with -icount shift=S every guest instruction advances the
 * virtual clock by 2^S ns, and SysTick on the 25 MHz processor clock ticks
 * every 40 ns of that clock, so instructions = ticks * 40 / 2^S.  The
 * calibration loop in measure.c checks this on a loop of known length.
 */
#include "board.h"

extern uint32_t __stack_limit[], __stack_top[];

static volatile uint32_t wraps;

#define SYST_RELOAD 0x00FFFFFFu

void board_systick_handler(void)
{
    ++wraps;
}

void board_ticks_start(void)
{
    SYST_CSR = 0u;
    SYST_RVR = SYST_RELOAD;
    SYST_CVR = 0u;
    wraps = 0u;
    /* Processor clock, exception on wrap, enabled. */
    SYST_CSR = 0x7u;
}

uint64_t board_ticks(void)
{
    /* Read the wrap count on both sides of the counter, so a wrap between
     * the two reads cannot tear the value. */
    uint32_t w0, w1, cv;
    do {
        w0 = wraps;
        cv = SYST_CVR;
        w1 = wraps;
    } while (w0 != w1);
    return (uint64_t)w0 * (SYST_RELOAD + 1u) + (SYST_RELOAD - cv);
}

uint32_t board_stack_unused(void)
{
    const uint32_t *p = __stack_limit;
    while (p < __stack_top && *p == BOARD_STACK_PAINT) {
        ++p;
    }
    return (uint32_t)((uintptr_t)p - (uintptr_t)__stack_limit);
}

uint32_t board_stack_size(void)
{
    return (uint32_t)((uintptr_t)__stack_top - (uintptr_t)__stack_limit);
}

uintptr_t board_stack_paint(void)
{
    uint32_t *sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    /* Leave 64 words under this frame alone: this function is using them. */
    for (uint32_t *p = __stack_limit; p < sp - 64;) {
        *p++ = BOARD_STACK_PAINT;
    }
    return (uintptr_t)sp;
}

uint32_t board_stack_used_since(uintptr_t sp_at_paint)
{
    const uint32_t *p = __stack_limit;
    while ((uintptr_t)p < sp_at_paint && *p == BOARD_STACK_PAINT) {
        ++p;
    }
    return (uint32_t)(sp_at_paint - (uintptr_t)p);
}
