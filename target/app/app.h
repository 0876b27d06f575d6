/*
 * app.h - the controller application of the MCU: frames in from the serial
 * link, the core, commands out, and the watchdog.  Written against a byte
 * sink and a millisecond clock only, so the same logic runs on the board
 * (main.c: CMSDK UART and timer) and in host tests.
 *
 * What it does with each frame (docs/SERIAL.md):
 *   - not decodable (COBS, CRC, version, length): counted, dropped, never
 *     answered (nothing in it can be trusted, not even its seq);
 *   - CONFIG: the controller is (re)initialised when the set-up differs;
 *   - MATCHES refused (count above capacity, a coordinate or feature out of
 *     range, no CONFIG yet): a stop for its seq, flagged REJECTED, with
 *     SPVS_E_CAPACITY, SPVS_E_RANGE or SPVS_E_CONFIG; the core is not run;
 *   - a new run tag: the controller is reset first;
 *   - the seq of the last update again: its answer again (REPEAT), the core
 *     is not run twice;
 *   - an older seq: a stop with SPVS_E_STALE (REJECTED);
 *   - otherwise spvs_update() at t = t_ms / 1000 s, and its RESULT.
 * Watchdog: while no MATCHES frame has been accepted for the watchdog time
 * (the CONFIG frame's, or APP_WATCHDOG_MS when it names none), a STATUS
 * frame with reason WATCHDOG, which commands a stop, goes out once per
 * watchdog time.  A STATUS with the counters goes out every
 * APP_STATUS_PERIOD_MS, and one with reason BOOT at start.
 */
#ifndef TARGET_APP_APP_H
#define TARGET_APP_APP_H

#include <stddef.h>
#include <stdint.h>

#include "spvs/spvs.h"
#include "spvs_serial.h"

/* The default watchdog time: three control periods of a 10 Hz camera.  A
 * CONFIG frame may choose another (SPVS_SERIAL_WATCHDOG_MIN_MS ..
 * _MAX_MS); a reset brings this one back. */
#ifndef APP_WATCHDOG_MS
#define APP_WATCHDOG_MS 300u
#endif
#if APP_WATCHDOG_MS < SPVS_SERIAL_WATCHDOG_MIN_MS || APP_WATCHDOG_MS > SPVS_SERIAL_WATCHDOG_MAX_MS
#error "APP_WATCHDOG_MS must lie in SPVS_SERIAL_WATCHDOG_MIN_MS .. _MAX_MS"
#endif
#ifndef APP_STATUS_PERIOD_MS
#define APP_STATUS_PERIOD_MS 1000u
#endif

/* Where encoded frames go: returns the bytes taken. */
typedef size_t (*app_write_fn)(void *ctx, const uint8_t *p, size_t n);

typedef struct {
    app_write_fn write;
    void *write_ctx;

    spvs_t core;
    spvs_match_t m[SPVS_MAX_MATCHES];
    spvs_serial_rx_t rx;
    /* The larger of a RESULT and a STATUS frame. */
    uint8_t tx[(SPVS_SERIAL_RESULT_BODY > SPVS_SERIAL_STATUS_BODY
                    ? SPVS_SERIAL_WIRE_BYTES(SPVS_SERIAL_RESULT_BODY)
                    : SPVS_SERIAL_WIRE_BYTES(SPVS_SERIAL_STATUS_BODY)) + 8u];

    uint8_t configured;
    spvs_serial_config_t cfg;
    uint8_t has_run;
    uint8_t has_last;
    uint32_t run;
    uint32_t last_seq;
    spvs_serial_result_t last; /* answer of the last update                 */

    uint32_t watchdog_ms;       /* the watchdog time in force               */
    uint8_t has_valid;
    uint32_t boot_ms;
    uint32_t last_valid_ms;     /* last accepted MATCHES frame              */
    uint32_t last_stop_ms;      /* last watchdog stop                       */
    uint32_t last_status_ms;    /* last periodic STATUS                     */
    spvs_serial_status_frame_t st; /* counters, as the STATUS frame sends them */
} app_t;

/* Set up at time now_ms (no controller until a CONFIG frame) and send the
 * BOOT status. */
void app_init(app_t *a, app_write_fn write, void *write_ctx, uint32_t now_ms);

/* One received byte. */
void app_on_byte(app_t *a, uint8_t b, uint32_t now_ms);

/* The UART lost a byte: the frame being received is dropped. */
void app_on_overrun(app_t *a);

/* Watchdog and periodic status; call every pass of the main loop. */
void app_tick(app_t *a, uint32_t now_ms);

#endif /* TARGET_APP_APP_H */
