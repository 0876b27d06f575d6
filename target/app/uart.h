/*
 * uart.h - polled driver of the CMSDK APB UART0 of mps2-an386 (0x40004000).
 *
 * Receive is polled: the main loop reads the 1-byte receive register.  On
 * a real UART a byte that arrives while the register is still full is
 * lost and the overrun flag is set; uart_poll() reports that, so the
 * application can drop the frame in progress (its CRC would fail anyway)
 * and count it.  Under QEMU the model holds the socket's bytes back while
 * the register is full, so nothing is lost there.
 */
#ifndef TARGET_APP_UART_H
#define TARGET_APP_UART_H

#include <stddef.h>
#include <stdint.h>

/* Enable transmit and receive at `baud` on the board's 25 MHz APB clock
 * (BAUDDIV = 25 MHz / baud, at least 16). */
void uart_init(uint32_t baud);

/* One received byte, if there is one: returns 1 with *b set, 0 when the
 * receive register is empty.  *overrun is set to 1 when the receiver lost
 * a byte since the last call (the flag is then cleared), else 0. */
int uart_poll(uint8_t *b, int *overrun);

/* Send n bytes, waiting while the transmit register is full; each wait is
 * bounded (UART_TX_SPINS polls), so a stuck transmitter cannot hang the
 * loop.  Returns the bytes sent. */
size_t uart_write(const uint8_t *p, size_t n);

#endif /* TARGET_APP_UART_H */
