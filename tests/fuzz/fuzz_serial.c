/*
 * fuzz_serial.c - libFuzzer target of the serial link's receive path, the
 * same sources as the MCU application runs: the input is a byte stream fed
 * byte by byte to the application (target/app/app.c: the stream splitter,
 * COBS, CRC, the frame parsers, the controller on accepted frames, the
 * watchdog), with the clock advancing 7 ms every 64 bytes; then each
 * delimited piece of the input goes to spvs_serial_unpack() and every
 * parser directly.  Any crash, hang or sanitizer report is a finding.  The
 * frames the application writes back must themselves decode.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "app.h"
#include "spvs_serial.h"

static app_t app;
static spvs_serial_rx_t back;
static uint8_t piece[SPVS_SERIAL_MAX_WIRE];
static spvs_match_t m[SPVS_MAX_MATCHES];

/* Everything the application sends must be a good frame. */
static size_t sink(void *ctx, const uint8_t *p, size_t n)
{
    (void)ctx;
    for (size_t i = 0; i < n; ++i) {
        if (spvs_serial_rx_push(&back, p[i]) == 1) {
            spvs_serial_frame_t f;
            if (spvs_serial_unpack(back.buf, back.n, &f) != SPVS_SERIAL_OK) {
                abort();
            }
        }
    }
    return n;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    spvs_serial_rx_init(&back);
    uint32_t now = 0;
    app_init(&app, sink, NULL, now);
    for (size_t i = 0; i < size; ++i) {
        if (i % 64 == 0) {
            now += 7u;
            app_tick(&app, now);
        }
        app_on_byte(&app, data[i], now);
    }
    app_tick(&app, now + 1000u);

    size_t start = 0;
    for (size_t i = 0; i <= size; ++i) {
        if (i < size && data[i] != 0) {
            continue;
        }
        size_t n = i - start;
        if (n > 0 && n <= sizeof(piece)) {
            memcpy(piece, data + start, n);
            spvs_serial_frame_t f;
            if (spvs_serial_unpack(piece, n, &f) == SPVS_SERIAL_OK) {
                spvs_serial_matches_hdr_t h;
                spvs_serial_result_t r;
                spvs_serial_status_frame_t s;
                spvs_serial_config_t c;
                (void)spvs_serial_parse_matches(&f, &h, m, SPVS_MAX_MATCHES);
                (void)spvs_serial_parse_result(&f, &r);
                (void)spvs_serial_parse_status(&f, &s);
                (void)spvs_serial_parse_config(&f, &c);
            }
        }
        start = i + 1;
    }
    return 0;
}
