/*
 * startup.c - reset and exception entry of the images for QEMU's MPS2
 * boards (mps2-an386 with a Cortex-M4F, mps2-an385 with a Cortex-M3):
 * vector table, FPU enable where there is one, .data copy, .bss clear, stack
 * painting, then main(); main's return value is the semihosting exit status.
 */
#include <stdint.h>

#include "board.h"
#include "fmt.h"
#include "semihost.h"

int main(void);
void spvs_reset_handler(void);

/* Symbols of mps2_an386.ld. */
extern uint32_t __data_load[], __data_start[], __data_end[];
extern uint32_t __bss_start[], __bss_end[];
extern uint32_t __stack_limit[], __stack_top[];

/* Every fault ends the run with a distinct status, so a crash in the core
 * fails the test instead of hanging it. */
__attribute__((noreturn)) static void fault(const char *what)
{
    out_str("FATAL: ");
    out_str(what);
    out_str("\n");
    sh_exit(BOARD_EXIT_FAULT);
}

static void nmi_handler(void) { fault("NMI"); }
static void hardfault_handler(void) { fault("HardFault"); }
static void memmanage_handler(void) { fault("MemManage"); }
static void busfault_handler(void) { fault("BusFault"); }
static void usagefault_handler(void) { fault("UsageFault"); }
static void unexpected_handler(void) { fault("unexpected exception"); }

typedef void (*vector_t)(void);

/* External interrupt 8 of mps2-an386 and mps2-an385 is the CMSDK timer 0.  An image that
 * enables it defines board_timer0_irq (the application's watchdog clock);
 * in the others it is never enabled and lands on the fault report. */
void board_timer0_irq(void) __attribute__((weak, alias("unexpected_handler")));

/* The 16 system entries of the ARMv7-M vector table and the external
 * interrupts up to timer 0 (IRQ 8); no image enables any other.  Entry 0 is
 * the initial stack pointer. */
__attribute__((section(".vectors"), used)) static const vector_t vectors[16 + 9] = {
    (vector_t)(uintptr_t)__stack_top,
    spvs_reset_handler,
    nmi_handler,
    hardfault_handler,
    memmanage_handler,
    busfault_handler,
    usagefault_handler,
    0, 0, 0, 0,
    unexpected_handler, /* SVCall   */
    unexpected_handler, /* DebugMon */
    0,
    unexpected_handler, /* PendSV   */
    board_systick_handler,
    /* IRQ 0..7: UARTs and GPIO, never enabled. */
    unexpected_handler, unexpected_handler, unexpected_handler, unexpected_handler,
    unexpected_handler, unexpected_handler, unexpected_handler, unexpected_handler,
    board_timer0_irq, /* IRQ 8: CMSDK timer 0 */
};

void spvs_reset_handler(void)
{
#if defined(__ARM_FP)
    /* Grant full access to CP10 and CP11 (the FPU) before any float
     * instruction; the barriers make the new CPACR take effect.  A build
     * without FPU instructions (the Cortex-M3's soft-float) leaves CPACR
     * alone: that core has none. */
    SCB_CPACR |= (0xFu << 20);
    __asm__ volatile("dsb\n\tisb" ::: "memory");
#endif

    for (uint32_t *src = __data_load, *dst = __data_start; dst < __data_end;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = __bss_start; dst < __bss_end;) {
        *dst++ = 0u;
    }
    /* Paint the unused stack (below the current frame) so the high-water
     * mark of the core can be read back after a run. */
    uint32_t *sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (uint32_t *p = __stack_limit; p < sp - 16;) {
        *p++ = BOARD_STACK_PAINT;
    }

    sh_exit(main());
}

/* newlib's assert() lands here (the core's SPVS_ASSERT hook defaults to
 * assert): report and stop, without newlib's fiprintf. */
__attribute__((noreturn)) void __assert_func(const char *file, int line,
                                             const char *func, const char *expr);
void __assert_func(const char *file, int line, const char *func, const char *expr)
{
    (void)func;
    out_str("ASSERT: ");
    out_str(expr);
    out_str(" at ");
    out_str(file);
    out_str(":");
    out_int(line);
    out_str("\n");
    sh_exit(BOARD_EXIT_FAULT);
}
