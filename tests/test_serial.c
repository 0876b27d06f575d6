/*
 * test_serial.c - the serial link's codec (serial/spvs_serial.h): CRC-32
 * check value, COBS round trips at the block edges, frames encoded and
 * decoded, every refusal of the decoder, the quantisation's rounding, and
 * the byte-count figures of docs/SERIAL.md.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "spvs_serial.h"

static uint8_t wire[SPVS_SERIAL_MAX_WIRE + 16];

static void test_crc_check_value(void **state)
{
    (void)state;
    assert_int_equal(spvs_serial_crc32((const uint8_t *)"123456789", 9), 0xCBF43926u);
    assert_int_equal(spvs_serial_crc32(NULL, 0), 0u);
}

static void test_cobs_round_trip(void **state)
{
    (void)state;
    static uint8_t in[1100], enc[1200], dec[1200];
    const size_t lens[] = { 1, 2, 253, 254, 255, 508, 509, 1000 };
    for (size_t k = 0; k < sizeof(lens) / sizeof(lens[0]); ++k) {
        for (int zeros = 0; zeros < 2; ++zeros) {
            for (size_t i = 0; i < lens[k]; ++i)
                in[i] = zeros ? (uint8_t)(i % 7) : (uint8_t)(1 + i % 255);
            size_t e = spvs_serial_cobs_encode(in, lens[k], enc, sizeof(enc));
            assert_true(e > lens[k]);
            assert_true(e <= lens[k] + 1 + lens[k] / 254);
            assert_null(memchr(enc, 0, e));
            int d = spvs_serial_cobs_decode(enc, e, dec, sizeof(dec));
            assert_int_equal(d, (int)lens[k]);
            assert_memory_equal(dec, in, lens[k]);
        }
    }
    /* Decoding refuses a zero inside and a block past the end. */
    uint8_t badz[3] = { 3, 0, 1 }, badlen[2] = { 5, 1 };
    assert_int_equal(spvs_serial_cobs_decode(badz, 3, dec, sizeof(dec)), SPVS_SERIAL_E_COBS);
    assert_int_equal(spvs_serial_cobs_decode(badlen, 2, dec, sizeof(dec)), SPVS_SERIAL_E_COBS);
    /* No room: encode says 0, not a partial frame. */
    assert_int_equal(spvs_serial_cobs_encode(in, 300, enc, 300), 0);
}

static uint16_t make_matches(spvs_match_t *m, uint16_t n)
{
    for (uint16_t i = 0; i < n; ++i) {
        m[i].feature = (uint16_t)(i * 3 % SPVS_MAX_FEATURES);
        m[i].x_tgt = (spvs_real)(-300.0 + 4.8125 * i);
        m[i].y_tgt = (spvs_real)(200.5 - 3.0625 * i);
        m[i].x_cur = (spvs_real)(1999.9375 - 16.0 * i);
        m[i].y_cur = (spvs_real)(-1999.9375 + 1.5 * i);
    }
    return n;
}

/* Feed a frame through the stream splitter and unpack it. */
static int receive(const uint8_t *p, int len, spvs_serial_rx_t *rx, spvs_serial_frame_t *f)
{
    int got = 0, st = SPVS_SERIAL_E_SHORT;
    for (int i = 0; i < len; ++i) {
        int r = spvs_serial_rx_push(rx, p[i]);
        if (r == 1) {
            got = 1;
            st = spvs_serial_unpack(rx->buf, rx->n, f);
        } else if (r < 0) {
            st = r;
        }
    }
    return got ? st : (st == SPVS_SERIAL_E_SHORT ? SPVS_SERIAL_E_SHORT : st);
}

static spvs_serial_rx_t rx;
static spvs_match_t m[SPVS_MAX_MATCHES], back[SPVS_MAX_MATCHES];

static void test_matches_round_trip_and_size(void **state)
{
    (void)state;
    uint16_t n = make_matches(m, 125);
    spvs_serial_matches_hdr_t h = { 0xA5A5F00Du, 42u, 4200u, n }, hb;
    int len = spvs_serial_encode_matches(&h, m, wire, sizeof(wire));
    /* docs/SERIAL.md: 125 matches are 1,272 payload bytes, at most 1,279 on
     * the wire: 13.9 % of a 921,600 baud link at 10 Hz. */
    assert_int_equal(SPVS_SERIAL_PAYLOAD_BYTES(SPVS_SERIAL_MATCHES_BODY(125)), 1272);
    assert_int_equal(SPVS_SERIAL_WIRE_BYTES(SPVS_SERIAL_MATCHES_BODY(125)), 1279);
    assert_true(len > 1272 && len <= 1279);
    assert_true(len * 10 * 10 < 921600 / 5); /* under 20 % at 10 Hz */
    assert_int_equal(wire[len - 1], 0);
    spvs_serial_rx_init(&rx);
    spvs_serial_frame_t f;
    assert_int_equal(receive(wire, len, &rx, &f), SPVS_SERIAL_OK);
    assert_int_equal(spvs_serial_parse_matches(&f, &hb, back, SPVS_MAX_MATCHES), SPVS_SERIAL_OK);
    assert_int_equal(hb.run, h.run);
    assert_int_equal(hb.seq, 42);
    assert_int_equal(hb.t_ms, 4200);
    assert_int_equal(hb.count, 125);
    for (uint16_t i = 0; i < n; ++i) {
        spvs_match_t q;
        assert_int_equal(spvs_serial_quantize_match(&m[i], &q), SPVS_SERIAL_OK);
        assert_int_equal(back[i].feature, m[i].feature);
        assert_true(back[i].x_tgt == q.x_tgt && back[i].y_tgt == q.y_tgt);
        assert_true(back[i].x_cur == q.x_cur && back[i].y_cur == q.y_cur);
    }
}

static void test_decoder_refusals(void **state)
{
    (void)state;
    uint16_t n = make_matches(m, 20);
    spvs_serial_matches_hdr_t h = { 1u, 7u, 700u, n }, hb;
    int len = spvs_serial_encode_matches(&h, m, wire, sizeof(wire));
    spvs_serial_frame_t f;
    static uint8_t copy[SPVS_SERIAL_MAX_WIRE];
    /* Every single flipped bit of the frame (not the delimiter) is caught. */
    for (int i = 0; i < len - 1; ++i) {
        for (int b = 0; b < 8; ++b) {
            memcpy(copy, wire, (size_t)len);
            copy[i] ^= (uint8_t)(1u << b);
            spvs_serial_rx_init(&rx);
            int st = receive(copy, len, &rx, &f);
            assert_true(st != SPVS_SERIAL_OK);
        }
    }
    /* Truncated: the first half, then a delimiter. */
    memcpy(copy, wire, (size_t)len);
    copy[len / 2] = 0;
    spvs_serial_rx_init(&rx);
    int tst = receive(copy, len / 2 + 1, &rx, &f);
    assert_true(tst == SPVS_SERIAL_E_CRC || tst == SPVS_SERIAL_E_COBS);
    /* Oversize: more bytes than any frame before a delimiter. */
    spvs_serial_rx_init(&rx);
    int over = 0;
    for (unsigned i = 0; i < SPVS_SERIAL_MAX_WIRE + 10; ++i)
        assert_int_equal(spvs_serial_rx_push(&rx, 0x55), 0);
    over = spvs_serial_rx_push(&rx, 0);
    assert_int_equal(over, SPVS_SERIAL_E_OVERSIZE);
    /* A good frame right after is received. */
    assert_int_equal(receive(wire, len, &rx, &f), SPVS_SERIAL_OK);
    assert_int_equal(spvs_serial_parse_matches(&f, &hb, back, SPVS_MAX_MATCHES), SPVS_SERIAL_OK);
    /* Capacity: the receiver's cap below the count. */
    assert_int_equal(spvs_serial_parse_matches(&f, &hb, back, 19), SPVS_SERIAL_E_COUNT);
    /* A coordinate beyond +-2000 px cannot be sent. */
    m[3].x_cur = (spvs_real)2000.1;
    assert_int_equal(spvs_serial_encode_matches(&h, m, wire, sizeof(wire)), SPVS_SERIAL_E_RANGE);
    /* A feature index past the target's features cannot be sent either. */
    make_matches(m, 20);
    m[5].feature = SPVS_MAX_FEATURES;
    assert_int_equal(spvs_serial_encode_matches(&h, m, wire, sizeof(wire)), SPVS_SERIAL_E_RANGE);
    /* A result is not a matches frame. */
    spvs_serial_result_t r;
    memset(&r, 0, sizeof(r));
    len = spvs_serial_encode_result(&r, wire, sizeof(wire));
    spvs_serial_rx_init(&rx);
    assert_int_equal(receive(wire, len, &rx, &f), SPVS_SERIAL_OK);
    assert_int_equal(spvs_serial_parse_matches(&f, &hb, back, SPVS_MAX_MATCHES), SPVS_SERIAL_E_TYPE);
}

static void test_result_status_config(void **state)
{
    (void)state;
    spvs_serial_result_t r, rb;
    memset(&r, 0, sizeof(r));
    r.run = 9; r.seq = 11; r.t_ms = 1100; r.flags = SPVS_SERIAL_F_H_VALID | SPVS_SERIAL_F_EQ11;
    r.out.v = (spvs_real)0.123456789; r.out.w = (spvs_real)-0.0625; r.out.status = SPVS_E_NO_PARALLAX;
    r.out.step = 2; r.out.n_matches = 125; r.out.n_inliers = 90; r.out.n_offplane = 20;
    for (int k = 0; k < 9; ++k) r.out.H[k] = (spvs_real)(0.1 * k - 0.3);
    r.out.arrival_corner_px = (spvs_real)0.75; r.out.arrival_stat = (spvs_real)3.4375;
    r.out.arrival_lateral_px = (spvs_real)0.5; r.out.arrival_depth_px = (spvs_real)-0.25;
    r.out.arrival_h13_px = (spvs_real)-0.125; r.out.arrival_parallax_px = (spvs_real)2.9;
    r.out.arrival_frames = 21; r.out.arrival_reentries = 2; r.out.arrival_next = 1;
    r.out.arrival_threshold = (spvs_real)4.0; r.out.arrival_lateral_sd_px = (spvs_real)0.1875;
    r.out.arrival_depth_sd_px = (spvs_real)0.0625; r.out.arrival_h13_sd_px = (spvs_real)0.046875;
    int len = spvs_serial_encode_result(&r, wire, sizeof(wire));
    assert_int_equal(len, 1 + 128 + 1); /* 120-byte body: 130 B on the wire, no zeros to spare */
    assert_int_equal(len, SPVS_SERIAL_WIRE_BYTES(SPVS_SERIAL_RESULT_BODY));
    spvs_serial_frame_t f;
    spvs_serial_rx_init(&rx);
    assert_int_equal(receive(wire, len, &rx, &f), SPVS_SERIAL_OK);
    assert_int_equal(f.len, SPVS_SERIAL_RESULT_BODY);
    assert_int_equal(f.len, 120);
    assert_int_equal(spvs_serial_parse_result(&f, &rb), SPVS_SERIAL_OK);
    /* The arrival check's figures, float32 at 76..99 and 104..119
     * (docs/SERIAL.md). */
    assert_true((float)rb.out.arrival_corner_px == 0.75f);
    assert_true((float)rb.out.arrival_stat == 3.4375f);
    assert_true((float)rb.out.arrival_lateral_px == 0.5f);
    assert_true((float)rb.out.arrival_depth_px == -0.25f);
    assert_true((float)rb.out.arrival_h13_px == -0.125f);
    assert_true((float)rb.out.arrival_parallax_px == (float)r.out.arrival_parallax_px);
    assert_true((float)rb.out.arrival_threshold == 4.0f);
    assert_true((float)rb.out.arrival_lateral_sd_px == 0.1875f);
    assert_true((float)rb.out.arrival_depth_sd_px == 0.0625f);
    assert_true((float)rb.out.arrival_h13_sd_px == 0.046875f);
    /* Where docs/SERIAL.md puts them, little-endian: the statistic at body
     * offset 80, the parallax at 96, the threshold at 104 and the three
     * standard deviations at 108, 112, 116. */
    static const struct { unsigned off; float want; } at[] = {
        {80u, 3.4375f}, {96u, 2.9f}, {104u, 4.0f},
        {108u, 0.1875f}, {112u, 0.0625f}, {116u, 0.046875f}};
    for (size_t i = 0; i < sizeof at / sizeof at[0]; ++i) {
        const uint8_t *b = f.body + at[i].off;
        const uint32_t bits = (uint32_t)b[0] | (uint32_t)b[1] << 8 |
                              (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
        float v;
        memcpy(&v, &bits, sizeof(v));
        assert_true(v == at[i].want);
    }
    assert_int_equal(rb.out.arrival_frames, 21);
    assert_int_equal(rb.out.arrival_reentries, 2);
    assert_int_equal(rb.out.arrival_next, 1);
    /* No off-plane point seen over the hold: -1 goes through as it is. */
    r.out.arrival_parallax_px = (spvs_real)-1.0;
    len = spvs_serial_encode_result(&r, wire, sizeof(wire));
    spvs_serial_rx_init(&rx);
    assert_int_equal(receive(wire, len, &rx, &f), SPVS_SERIAL_OK);
    assert_int_equal(spvs_serial_parse_result(&f, &rb), SPVS_SERIAL_OK);
    assert_true((float)rb.out.arrival_parallax_px == -1.0f);
    assert_int_equal(rb.out.arrival_frames, 21);
    assert_true((float)rb.out.v == (float)r.out.v && (float)rb.out.w == (float)r.out.w);
    assert_int_equal(rb.out.status, SPVS_E_NO_PARALLAX);
    assert_int_equal(rb.out.step, 2);
    assert_int_equal(rb.out.h_valid, 1);
    assert_int_equal(rb.out.eq11, 1);
    assert_int_equal(rb.out.e_valid, 0);
    assert_true((float)rb.out.H[8] == (float)r.out.H[8]);

    spvs_serial_status_frame_t s, sb;
    memset(&s, 0, sizeof(s));
    s.reason = SPVS_SERIAL_S_WATCHDOG; s.method = 2; s.seed = 77; s.alpha_px = 800.0f;
    s.age_ms = 300; s.watchdog_stops = 5; s.crc_errors = 3;
    len = spvs_serial_encode_status(&s, wire, sizeof(wire));
    spvs_serial_rx_init(&rx);
    assert_int_equal(receive(wire, len, &rx, &f), SPVS_SERIAL_OK);
    assert_int_equal(spvs_serial_parse_status(&f, &sb), SPVS_SERIAL_OK);
    assert_int_equal(sb.reason, SPVS_SERIAL_S_WATCHDOG);
    assert_int_equal(sb.method, 2);
    assert_int_equal(sb.seed, 77);
    assert_int_equal(sb.age_ms, 300);
    assert_int_equal(sb.watchdog_stops, 5);
    assert_int_equal(sb.crc_errors, 3);

    spvs_serial_config_t c = { 1, 4000000000u, 400.0f, 0u }, cb;
    len = spvs_serial_encode_config(&c, wire, sizeof(wire));
    spvs_serial_rx_init(&rx);
    assert_int_equal(receive(wire, len, &rx, &f), SPVS_SERIAL_OK);
    assert_int_equal(spvs_serial_parse_config(&f, &cb), SPVS_SERIAL_OK);
    assert_int_equal(cb.method, 1);
    assert_int_equal(cb.seed, 4000000000u);
    assert_int_equal(cb.watchdog_ms, 0); /* 0: the MCU's default */
    /* The watchdog time travels in bytes 2..3; 0 or 50..10000 ms. */
    const uint16_t wd_ok[] = { SPVS_SERIAL_WATCHDOG_MIN_MS, 300u, SPVS_SERIAL_WATCHDOG_MAX_MS };
    for (size_t i = 0; i < sizeof(wd_ok) / sizeof(wd_ok[0]); ++i) {
        c.watchdog_ms = wd_ok[i];
        len = spvs_serial_encode_config(&c, wire, sizeof(wire));
        spvs_serial_rx_init(&rx);
        assert_int_equal(receive(wire, len, &rx, &f), SPVS_SERIAL_OK);
        assert_int_equal(spvs_serial_parse_config(&f, &cb), SPVS_SERIAL_OK);
        assert_int_equal(cb.watchdog_ms, wd_ok[i]);
        assert_int_equal(f.body[2] | (f.body[3] << 8), wd_ok[i]);
    }
    const uint16_t wd_bad[] = { 1u, SPVS_SERIAL_WATCHDOG_MIN_MS - 1u,
                                SPVS_SERIAL_WATCHDOG_MAX_MS + 1u, 65535u };
    for (size_t i = 0; i < sizeof(wd_bad) / sizeof(wd_bad[0]); ++i) {
        c.watchdog_ms = wd_bad[i];
        len = spvs_serial_encode_config(&c, wire, sizeof(wire));
        spvs_serial_rx_init(&rx);
        assert_int_equal(receive(wire, len, &rx, &f), SPVS_SERIAL_OK);
        assert_int_equal(spvs_serial_parse_config(&f, &cb), SPVS_SERIAL_E_RANGE);
    }
    c.watchdog_ms = 0u;
    c.method = 4;
    len = spvs_serial_encode_config(&c, wire, sizeof(wire));
    spvs_serial_rx_init(&rx);
    assert_int_equal(receive(wire, len, &rx, &f), SPVS_SERIAL_OK);
    assert_int_equal(spvs_serial_parse_config(&f, &cb), SPVS_SERIAL_E_RANGE);
}

static void test_quantisation(void **state)
{
    (void)state;
    int16_t q = 0;
    assert_int_equal(spvs_serial_q_from_px((spvs_real)1.03125, &q), SPVS_SERIAL_OK);
    assert_int_equal(q, 17); /* 16.5 rounds away from zero */
    assert_int_equal(spvs_serial_q_from_px((spvs_real)-1.03125, &q), SPVS_SERIAL_OK);
    assert_int_equal(q, -17);
    assert_int_equal(spvs_serial_q_from_px((spvs_real)0.0312, &q), SPVS_SERIAL_OK);
    assert_int_equal(q, 0);
    assert_int_equal(spvs_serial_q_from_px((spvs_real)2000.0, &q), SPVS_SERIAL_OK);
    assert_int_equal(q, 32000);
    assert_int_equal(spvs_serial_q_from_px((spvs_real)2000.01, &q), SPVS_SERIAL_E_RANGE);
    spvs_real zero = 0;
    assert_int_equal(spvs_serial_q_from_px(zero / zero, &q), SPVS_SERIAL_E_RANGE);
    uint32_t ms = 0;
    assert_int_equal(spvs_serial_ms_from_utime(1499, &ms), SPVS_SERIAL_OK);
    assert_int_equal(ms, 1);
    assert_int_equal(spvs_serial_ms_from_utime(1500, &ms), SPVS_SERIAL_OK);
    assert_int_equal(ms, 2);
    assert_int_equal(spvs_serial_ms_from_utime(-1, &ms), SPVS_SERIAL_E_RANGE);
    assert_true(spvs_serial_s_from_ms(300) == 0.3f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crc_check_value),
        cmocka_unit_test(test_cobs_round_trip),
        cmocka_unit_test(test_matches_round_trip_and_size),
        cmocka_unit_test(test_decoder_refusals),
        cmocka_unit_test(test_result_status_config),
        cmocka_unit_test(test_quantisation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
