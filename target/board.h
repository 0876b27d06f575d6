/*
 * board.h - what the image knows of the mps2-an386 / mps2-an385 boards and
 * the ARMv7-M system registers: CPACR (Cortex-M4F only), SysTick, the stack
 * bounds, exit statuses.
 */
#ifndef TARGET_BOARD_H
#define TARGET_BOARD_H

#include <stdint.h>

/* The CPU's name in the images' banners (cmake/cpu/<cpu>.cmake). */
#ifndef SPVS_TARGET_CPU_NAME
#define SPVS_TARGET_CPU_NAME "Cortex-M4F"
#endif

#define SCB_CPACR (*(volatile uint32_t *)0xE000ED88u)
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

/* The board's processor clock, which SysTick counts with CLKSOURCE = 1. */
#define BOARD_CPU_HZ 25000000u

/* Exit statuses: 0 all checks passed, 1..BOARD_EXIT_MAX_FAILS the number of
 * failed checks (capped), BOARD_EXIT_FAULT a fault or a failed assertion. */
#define BOARD_EXIT_MAX_FAILS 100
#define BOARD_EXIT_FAULT 120

/* Word written over the free stack at reset. */
#define BOARD_STACK_PAINT 0xC0FFEE55u

/* SysTick as a 64-bit tick counter: 24-bit down-counter plus a wrap count
 * kept by the SysTick exception. */
void board_ticks_start(void);
uint64_t board_ticks(void);
void board_systick_handler(void);

/* Paint the free stack below the caller's frame (keeping a margin for
 * this call) and return the stack pointer at that moment. */
uintptr_t board_stack_paint(void);
/* Deepest stack use since the last board_stack_paint(), bytes below the
 * stack pointer it returned. */
uint32_t board_stack_used_since(uintptr_t sp_at_paint);

/* Bytes of stack never written since reset (from the painted pattern). */
uint32_t board_stack_unused(void);
/* Total stack bytes. */
uint32_t board_stack_size(void);

#endif /* TARGET_BOARD_H */
