/*
 * main.c - the controller application on mps2-an386: CMSDK UART0 at
 * 921,600 baud, the millisecond clock on CMSDK timer 0, and the main loop
 * around app.c.  No heap, no stdio; the loop runs forever, every pass
 * bounded (at most MAIN_RX_BURST bytes, then the watchdog).
 */
#include "app.h"
#include "clock.h"
#include "uart.h"

#define MAIN_BAUD 921600u
/* Bytes taken per pass before the watchdog is looked at again. */
#define MAIN_RX_BURST 64u

/* In .bss: about 16 KiB with the core's instance. */
static app_t app;

static size_t uart_sink(void *ctx, const uint8_t *p, size_t n)
{
    (void)ctx;
    return uart_write(p, n);
}

int main(void)
{
    uart_init(MAIN_BAUD);
    clock_start();
    __asm__ volatile("cpsie i" ::: "memory");
    app_init(&app, uart_sink, 0, clock_ms());
    for (;;) {
        for (uint32_t k = 0; k < MAIN_RX_BURST; ++k) {
            uint8_t b = 0u;
            int overrun;
            int got = uart_poll(&b, &overrun);
            if (overrun) {
                app_on_overrun(&app);
            }
            if (!got) {
                break;
            }
            app_on_byte(&app, b, clock_ms());
        }
        app_tick(&app, clock_ms());
    }
}
