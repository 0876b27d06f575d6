/*
 * clock.h - a millisecond clock on the CMSDK APB timer 0 of mps2-an386
 * (0x40000000, IRQ 8): the timer reloads every millisecond of the 25 MHz
 * APB clock and its interrupt counts.  The watchdog of the application
 * reads it.
 */
#ifndef TARGET_APP_CLOCK_H
#define TARGET_APP_CLOCK_H

#include <stdint.h>

/* Start the timer and its interrupt. */
void clock_start(void);

/* Milliseconds since clock_start (wraps after 49.7 days; differences of
 * two readings are right across the wrap). */
uint32_t clock_ms(void);

#endif /* TARGET_APP_CLOCK_H */
