/*
 * uart.c - CMSDK APB UART0, polled; see uart.h.
 */
#include "uart.h"

#define UART0_BASE 0x40004000u
#define UART_DATA (*(volatile uint32_t *)(UART0_BASE + 0x00u))
#define UART_STATE (*(volatile uint32_t *)(UART0_BASE + 0x04u))
#define UART_CTRL (*(volatile uint32_t *)(UART0_BASE + 0x08u))
#define UART_BAUDDIV (*(volatile uint32_t *)(UART0_BASE + 0x10u))

#define STATE_TX_FULL 0x1u
#define STATE_RX_FULL 0x2u
#define STATE_TX_OVERRUN 0x4u
#define STATE_RX_OVERRUN 0x8u
#define CTRL_TX_EN 0x1u
#define CTRL_RX_EN 0x2u

#define APB_HZ 25000000u
/* Polls of a full transmit register before a byte is given up: far more
 * than one byte time (about 270 APB cycles at 921,600 baud). */
#define UART_TX_SPINS 100000u

void uart_init(uint32_t baud)
{
    uint32_t div = baud ? APB_HZ / baud : 16u;
    UART_CTRL = 0u;
    UART_BAUDDIV = div < 16u ? 16u : div;
    /* Clear any stale overrun flags (write one to clear). */
    UART_STATE = STATE_TX_OVERRUN | STATE_RX_OVERRUN;
    UART_CTRL = CTRL_TX_EN | CTRL_RX_EN;
}

int uart_poll(uint8_t *b, int *overrun)
{
    uint32_t st = UART_STATE;
    *overrun = 0;
    if (st & STATE_RX_OVERRUN) {
        UART_STATE = STATE_RX_OVERRUN;
        *overrun = 1;
    }
    if (st & STATE_RX_FULL) {
        *b = (uint8_t)(UART_DATA & 0xFFu);
        return 1;
    }
    return 0;
}
size_t uart_write(const uint8_t *p, size_t n)
{
    size_t sent = 0u;
    for (; sent < n; ++sent) {
        uint32_t spins = 0u;
        while ((UART_STATE & STATE_TX_FULL) && spins < UART_TX_SPINS) {
            ++spins;
        }
        if (spins >= UART_TX_SPINS) {
            break;
        }
        UART_DATA = p[sent];
    }
    return sent;
}
