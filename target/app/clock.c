/*
 * clock.c - millisecond clock on CMSDK timer 0; see clock.h.
 */
#include "clock.h"

#define TIMER0_BASE 0x40000000u
#define TIMER_CTRL (*(volatile uint32_t *)(TIMER0_BASE + 0x00u))
#define TIMER_VALUE (*(volatile uint32_t *)(TIMER0_BASE + 0x04u))
#define TIMER_RELOAD (*(volatile uint32_t *)(TIMER0_BASE + 0x08u))
#define TIMER_INTCLEAR (*(volatile uint32_t *)(TIMER0_BASE + 0x0Cu))
#define TIMER_CTRL_EN 0x1u
#define TIMER_CTRL_IRQ_EN 0x8u

#define NVIC_ISER0 (*(volatile uint32_t *)0xE000E100u)
#define TIMER0_IRQ 8u
#define APB_HZ 25000000u

static volatile uint32_t ms_count;

void board_timer0_irq(void);
void board_timer0_irq(void)
{
    TIMER_INTCLEAR = 1u;
    ++ms_count;
}

void clock_start(void)
{
    TIMER_CTRL = 0u;
    ms_count = 0u;
    TIMER_RELOAD = APB_HZ / 1000u - 1u;
    TIMER_VALUE = APB_HZ / 1000u - 1u;
    TIMER_INTCLEAR = 1u;
    NVIC_ISER0 = 1u << TIMER0_IRQ;
    TIMER_CTRL = TIMER_CTRL_EN | TIMER_CTRL_IRQ_EN;
}

uint32_t clock_ms(void)
{
    return ms_count;
}
