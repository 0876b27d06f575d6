/*
 * spvs_serial.h - the serial link between a host and the controller on a
 * microcontroller: frame layout, COBS framing, CRC-32, and the encoders and
 * decoders of the three frame types (docs/SERIAL.md has the byte layout).
 *
 * One small library for both ends: the firmware application (target/app/)
 * and the host agent (sim_host/serial/) compile these same sources, and so
 * does the libFuzzer target of the decoder (tests/fuzz/fuzz_serial.c).
 * No heap, no stdio, no floating-point library call; every loop is bounded
 * by the length of its input or by SPVS_SERIAL_MAX_MATCHES.  With the
 * fixed-point core (SPVS_USE_FIXED) no floating-point arithmetic either: the
 * conversions between the wire's integers and the core's floats read and
 * build the floats through their bits, with the float arithmetic's values
 * bit for bit (docs/SERIAL.md).
 *
 * A frame on the wire is COBS(payload) followed by one 0x00 delimiter, and
 * the payload is
 *   version (1 byte) | type (1) | body length L (2, little-endian) |
 *   body (L bytes) | CRC-32 of the preceding 4 + L bytes (4, little-endian)
 * The CRC is CRC-32/ISO-HDLC (the Ethernet and zlib CRC: reflected
 * polynomial 0xEDB88320, initial value and final XOR 0xFFFFFFFF).
 */
#ifndef SPVS_SERIAL_H
#define SPVS_SERIAL_H

#include <stddef.h>
#include <stdint.h>

#include "spvs/spvs.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Version byte of this layout; a frame with another version is refused. */
#define SPVS_SERIAL_VERSION 1u

/* Frame types. */
#define SPVS_SERIAL_T_MATCHES 1u /* host -> MCU: one camera frame's matches */
#define SPVS_SERIAL_T_RESULT 2u  /* MCU -> host: command and short state    */
#define SPVS_SERIAL_T_STATUS 3u  /* MCU -> host: boot, watchdog, counters   */
#define SPVS_SERIAL_T_CONFIG 4u  /* host -> MCU: method, seed, focal length */

/* Most matches one frame carries: the core's capacity. */
#define SPVS_SERIAL_MAX_MATCHES SPVS_MAX_MATCHES

/* Coordinates travel as int16 in 1/SPVS_SERIAL_PX_SCALE pixel (centred
 * pixels, as the core takes them), limited to +-SPVS_SERIAL_Q_MAX, i.e.
 * +-2000 px: a decoder refuses anything outside. */
#define SPVS_SERIAL_PX_SCALE 16
#define SPVS_SERIAL_Q_MAX 32000

/* Sizes, bytes.  Payload = header 4 + body + CRC 4. */
#define SPVS_SERIAL_HDR_BYTES 4u
#define SPVS_SERIAL_CRC_BYTES 4u
#define SPVS_SERIAL_MATCHES_FIXED 14u /* run, seq, t_ms, count            */
#define SPVS_SERIAL_MATCH_BYTES 10u   /* feature + 4 coordinates           */
#define SPVS_SERIAL_RESULT_BODY 120u
#define SPVS_SERIAL_STATUS_BODY 68u
#define SPVS_SERIAL_CONFIG_BODY 16u
#define SPVS_SERIAL_PAYLOAD_BYTES(body) \
    (SPVS_SERIAL_HDR_BYTES + (body) + SPVS_SERIAL_CRC_BYTES)
/* COBS adds one byte per started block of 254, then the delimiter. */
#define SPVS_SERIAL_WIRE_BYTES(body)                                    \
    (SPVS_SERIAL_PAYLOAD_BYTES(body) + SPVS_SERIAL_PAYLOAD_BYTES(body) / 254u \
     + 1u + 1u)
#define SPVS_SERIAL_MATCHES_BODY(n) \
    (SPVS_SERIAL_MATCHES_FIXED + SPVS_SERIAL_MATCH_BYTES * (unsigned)(n))
/* The largest frame of any type, encoded, with its delimiter. */
#define SPVS_SERIAL_MAX_WIRE \
    SPVS_SERIAL_WIRE_BYTES(SPVS_SERIAL_MATCHES_BODY(SPVS_SERIAL_MAX_MATCHES))
#define SPVS_SERIAL_MAX_PAYLOAD \
    SPVS_SERIAL_PAYLOAD_BYTES(SPVS_SERIAL_MATCHES_BODY(SPVS_SERIAL_MAX_MATCHES))

/* What a decoder can say about a frame.  0 = good. */
typedef enum {
    SPVS_SERIAL_OK = 0,
    SPVS_SERIAL_E_COBS = -1,     /* not valid COBS (a zero inside, a block past the end) */
    SPVS_SERIAL_E_SHORT = -2,    /* fewer bytes than a header and a CRC                */
    SPVS_SERIAL_E_CRC = -3,      /* CRC mismatch                                       */
    SPVS_SERIAL_E_VERSION = -4,  /* another layout version                             */
    SPVS_SERIAL_E_LENGTH = -5,   /* body length disagrees with the bytes or the type   */
    SPVS_SERIAL_E_TYPE = -6,     /* unknown frame type, or not the one expected        */
    SPVS_SERIAL_E_COUNT = -7,    /* match count above the capacity                     */
    SPVS_SERIAL_E_RANGE = -8,    /* coordinate beyond +-SPVS_SERIAL_Q_MAX, feature
                                    index >= SPVS_MAX_FEATURES, or a value that cannot
                                    be sent                                            */
    SPVS_SERIAL_E_OVERSIZE = -9, /* more bytes before a delimiter than any frame has    */
    SPVS_SERIAL_E_ROOM = -10     /* output buffer too small (programmer error)         */
} spvs_serial_status_t;

/* Short name of a status ("crc", "cobs", ...), for logs. */
const char *spvs_serial_status_str(int st);

/* CRC-32/ISO-HDLC of n bytes (check value of "123456789": 0xCBF43926). */
uint32_t spvs_serial_crc32(const uint8_t *p, size_t n);

/* COBS-encode n bytes into out (cap bytes), no delimiter.  Returns the
 * encoded length (n + 1 + n / 254 at most), or 0 when it does not fit. */
size_t spvs_serial_cobs_encode(const uint8_t *in, size_t n, uint8_t *out,
                               size_t cap);

/* COBS-decode n bytes (no delimiter) into out (cap bytes); out may equal
 * in (decoding in place).  Returns the decoded length, or
 * SPVS_SERIAL_E_COBS (a zero byte, a block past the end, no room). */
int spvs_serial_cobs_decode(const uint8_t *in, size_t n, uint8_t *out,
                            size_t cap);

/* ---- frames ------------------------------------------------------------ */

/* Header of a matches frame. */
typedef struct {
    uint32_t run;   /* run tag: a new value starts a new run (core reset)  */
    uint32_t seq;   /* frame number, increasing within a run               */
    uint32_t t_ms;  /* frame time, milliseconds                            */
    uint16_t count; /* matches that follow                                 */
} spvs_serial_matches_hdr_t;

/* A result: the command and short state of one update. */
#define SPVS_SERIAL_F_H_VALID 0x01u
#define SPVS_SERIAL_F_E_VALID 0x02u
#define SPVS_SERIAL_F_EQ11 0x04u
#define SPVS_SERIAL_F_REJECTED 0x08u  /* frame refused: the core did not run */
#define SPVS_SERIAL_F_REPEAT 0x10u    /* answer to a repeated seq, resent    */
typedef struct {
    uint32_t run, seq, t_ms;
    uint8_t flags;
    spvs_output_t out; /* v, w, status, step, counts, e_x, parallax, H */
} spvs_serial_result_t;

/* Why a status frame was sent. */
#define SPVS_SERIAL_S_BOOT 0u     /* the application started             */
#define SPVS_SERIAL_S_WATCHDOG 1u /* watchdog: stop commanded            */
#define SPVS_SERIAL_S_PERIODIC 2u /* counters, sent every second         */

/* The MCU's link and controller counters. */
typedef struct {
    uint8_t reason;          /* SPVS_SERIAL_S_*                               */
    uint8_t step;            /* the controller's step                         */
    int16_t status;          /* status of the last update                     */
    uint8_t method;          /* configured method 1..3, 0: not configured     */
    uint32_t seed;           /* configured PRNG seed                          */
    float alpha_px;          /* configured focal length, pixels               */
    uint32_t run;            /* run tag in force                              */
    uint32_t last_seq;       /* last frame run through the core               */
    uint32_t age_ms;         /* since the last valid frame (0xFFFFFFFF: none) */
    uint32_t uptime_ms;      /* since the application started                */
    uint32_t watchdog_ms;    /* the watchdog time                             */
    uint32_t updates;        /* frames run through the core                   */
    uint32_t repeats;        /* repeated seq, answered again                  */
    uint32_t stale;          /* older seq, answered with a stop               */
    uint32_t rejected;       /* decoded but refused (count, range, type)      */
    uint32_t crc_errors;     /* CRC mismatch                                  */
    uint32_t framing_errors; /* COBS, length, version, oversize               */
    uint32_t overruns;       /* UART receive overruns                         */
    uint32_t watchdog_stops; /* stops commanded by the watchdog               */
} spvs_serial_status_frame_t;

/* The watchdog time a CONFIG frame may choose, milliseconds: 0 means the
 * MCU's own default (APP_WATCHDOG_MS, 300 ms); anything else must lie in
 * this range (more than a frame's link time at capacity, 28 ms, plus an
 * update; at most 10 s of silence before the robot is stopped). */
#define SPVS_SERIAL_WATCHDOG_MIN_MS 50u
#define SPVS_SERIAL_WATCHDOG_MAX_MS 10000u

/* The controller's set-up, sent by the host before the first frame and
 * after every boot of the MCU.  A set-up whose method, seed or focal
 * length differs from the one in force re-initialises the controller; the
 * watchdog time alone does not. */
typedef struct {
    uint8_t method;   /* 1, 2 or 3                                 */
    uint32_t seed;    /* RANSAC seed                               */
    float alpha_px;   /* assumed focal length, pixels (x and y)    */
    uint16_t watchdog_ms; /* 0: the MCU's default, else 50..10000  */
} spvs_serial_config_t;

/* A decoded frame: its type and body, pointing into the caller's buffer. */
typedef struct {
    uint8_t type;
    const uint8_t *body;
    uint16_t len;
} spvs_serial_frame_t;

/* Decode one received frame: enc holds the bytes between two delimiters
 * (n bytes, no 0x00), decoded in place.  Checks COBS, size, CRC, version
 * and that the body length matches.  Returns SPVS_SERIAL_OK with *f
 * pointing into enc, or a negative spvs_serial_status_t. */
int spvs_serial_unpack(uint8_t *enc, size_t n, spvs_serial_frame_t *f);

/* Parse a matches body into header h and core matches m (cap entries).
 * Checks: type, count <= min(cap, SPVS_SERIAL_MAX_MATCHES) (else
 * SPVS_SERIAL_E_COUNT), length == SPVS_SERIAL_MATCHES_BODY(count),
 * every coordinate within +-SPVS_SERIAL_Q_MAX and every feature index below
 * SPVS_MAX_FEATURES (else SPVS_SERIAL_E_RANGE).  On an error h holds what
 * the fixed part said (when it was there) and m is partly written. */
int spvs_serial_parse_matches(const spvs_serial_frame_t *f,
                              spvs_serial_matches_hdr_t *h, spvs_match_t *m,
                              uint16_t cap);
int spvs_serial_parse_result(const spvs_serial_frame_t *f,
                             spvs_serial_result_t *r);
int spvs_serial_parse_status(const spvs_serial_frame_t *f,
                             spvs_serial_status_frame_t *s);
/* Checks the method (1..3), the focal length (finite, 1..1e5 px) and the
 * watchdog time (0, or SPVS_SERIAL_WATCHDOG_MIN_MS .. _MAX_MS):
 * SPVS_SERIAL_E_RANGE otherwise. */
int spvs_serial_parse_config(const spvs_serial_frame_t *f,
                             spvs_serial_config_t *c);

/* Encode a frame into out (cap bytes), COBS and the trailing delimiter
 * included.  Return the byte count, or a negative status: SPVS_SERIAL_E_ROOM,
 * SPVS_SERIAL_E_COUNT, SPVS_SERIAL_E_RANGE (a coordinate or feature that
 * cannot be sent: see spvs_serial_q_from_px). */
int spvs_serial_encode_matches(const spvs_serial_matches_hdr_t *h,
                               const spvs_match_t *m, uint8_t *out,
                               size_t cap);
int spvs_serial_encode_result(const spvs_serial_result_t *r, uint8_t *out,
                              size_t cap);
int spvs_serial_encode_status(const spvs_serial_status_frame_t *s,
                              uint8_t *out, size_t cap);
int spvs_serial_encode_config(const spvs_serial_config_t *c, uint8_t *out,
                              size_t cap);

/* ---- quantisation -------------------------------------------------------- */

/* Pixels -> wire units: round(px * 16), halves away from zero.  Returns
 * SPVS_SERIAL_OK, or SPVS_SERIAL_E_RANGE for a non-finite value or one
 * beyond +-SPVS_SERIAL_Q_MAX / 16 px (q untouched). */
int spvs_serial_q_from_px(spvs_real px, int16_t *q);
/* Wire units -> pixels (exact). */
spvs_real spvs_serial_px_from_q(int16_t q);

/* Frame time milliseconds -> the core's seconds: (float)t_ms / 1000, in
 * float32 on both ends (in integers with the fixed-point core: the same
 * value). */
float spvs_serial_s_from_ms(uint32_t t_ms);

/* An LCM frame time (microseconds, spvs-sim's llround(t * 1e6)) -> the
 * wire's milliseconds, rounded half up.  Returns SPVS_SERIAL_E_RANGE for a
 * negative time or one past 2^32 - 1 ms. */
int spvs_serial_ms_from_utime(int64_t utime, uint32_t *t_ms);

/* A match as it arrives on the MCU: coordinates through the wire's units.
 * Returns SPVS_SERIAL_OK or SPVS_SERIAL_E_RANGE. */
int spvs_serial_quantize_match(const spvs_match_t *in, spvs_match_t *out);

/* ---- receiving a byte stream --------------------------------------------- */

/* Splits a byte stream at the delimiters.  Bytes of a frame longer than
 * SPVS_SERIAL_MAX_WIRE are dropped up to the next delimiter. */
typedef struct {
    uint8_t buf[SPVS_SERIAL_MAX_WIRE];
    uint16_t n;
    uint8_t overflow;
    uint8_t done; /* buf holds a finished frame */
} spvs_serial_rx_t;

void spvs_serial_rx_init(spvs_serial_rx_t *rx);
/* Take one byte.  Returns 1 when it completed a frame (rx->buf, rx->n
 * bytes, valid until the next call), SPVS_SERIAL_E_OVERSIZE when it ended
 * an oversized frame (dropped), 0 otherwise.  Empty frames (two
 * delimiters in a row) are skipped. */
int spvs_serial_rx_push(spvs_serial_rx_t *rx, uint8_t byte);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_SERIAL_H */
