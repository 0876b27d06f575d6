/*
 * spvs_serial.c - COBS, CRC-32 and the frames of the serial link; see
 * spvs_serial.h and docs/SERIAL.md.
 */
#include "spvs_serial.h"

#include <string.h>

_Static_assert(SPVS_SERIAL_MAX_WIRE < 65536u, "rx length must fit uint16_t");
_Static_assert(SPVS_SERIAL_MATCHES_BODY(SPVS_SERIAL_MAX_MATCHES) < 65536u,
               "body length must fit its 16-bit field");

const char *spvs_serial_status_str(int st)
{
    switch (st) {
    case SPVS_SERIAL_OK: return "ok";
    case SPVS_SERIAL_E_COBS: return "cobs";
    case SPVS_SERIAL_E_SHORT: return "short";
    case SPVS_SERIAL_E_CRC: return "crc";
    case SPVS_SERIAL_E_VERSION: return "version";
    case SPVS_SERIAL_E_LENGTH: return "length";
    case SPVS_SERIAL_E_TYPE: return "type";
    case SPVS_SERIAL_E_COUNT: return "count";
    case SPVS_SERIAL_E_RANGE: return "range";
    case SPVS_SERIAL_E_OVERSIZE: return "oversize";
    case SPVS_SERIAL_E_ROOM: return "room";
    default: return "unknown";
    }
}

/* ---- CRC-32 -------------------------------------------------------------- */

/* Half-byte table of the reflected polynomial 0xEDB88320: two lookups per
 * byte, 64 bytes of flash instead of the 1 KiB byte table. */
static const uint32_t crc_nibble[16] = {
    0x00000000u, 0x1DB71064u, 0x3B6E20C8u, 0x26D930ACu,
    0x76DC4190u, 0x6B6B51F4u, 0x4DB26158u, 0x5005713Cu,
    0xEDB88320u, 0xF00F9344u, 0xD6D6A3E8u, 0xCB61B38Cu,
    0x9B64C2B0u, 0x86D3D2D4u, 0xA00AE278u, 0xBDBDF21Cu,
};

static uint32_t crc_update(uint32_t crc, const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; ++i) {
        crc ^= p[i];
        crc = (crc >> 4) ^ crc_nibble[crc & 0xFu];
        crc = (crc >> 4) ^ crc_nibble[crc & 0xFu];
    }
    return crc;
}

uint32_t spvs_serial_crc32(const uint8_t *p, size_t n)
{
    return crc_update(0xFFFFFFFFu, p, n) ^ 0xFFFFFFFFu;
}

/* ---- COBS ------------------------------------------------------------------ */

/* A streaming COBS encoder: bytes go in one at a time, so a frame is
 * encoded straight from its fields without a payload buffer. */
typedef struct {
    uint8_t *out;
    size_t cap;
    size_t pos;      /* next free byte                          */
    size_t code_pos; /* where the current block's code goes      */
    uint8_t code;    /* 1 + data bytes in the current block      */
    uint8_t full;    /* ran out of room                          */
    uint32_t crc;    /* running CRC of the payload bytes so far  */
} cobs_enc_t;

static void enc_start(cobs_enc_t *e, uint8_t *out, size_t cap)
{
    e->out = out;
    e->cap = cap;
    e->code_pos = 0u;
    e->pos = 1u;
    e->code = 1u;
    e->full = cap < 2u;
    e->crc = 0xFFFFFFFFu;
}

static void enc_raw(cobs_enc_t *e, uint8_t b)
{
    /* pos stays below cap, so the delimiter always has its byte. */
    if (e->full || e->pos + 1u >= e->cap) {
        e->full = 1u;
        return;
    }
    if (b == 0u) {
        e->out[e->code_pos] = e->code;
        e->code_pos = e->pos++;
        e->code = 1u;
        return;
    }
    e->out[e->pos++] = b;
    if (++e->code == 0xFFu) {
        if (e->pos + 1u >= e->cap) {
            e->full = 1u;
            return;
        }
        e->out[e->code_pos] = e->code;
        e->code_pos = e->pos++;
        e->code = 1u;
    }
}

static void enc_u8(cobs_enc_t *e, uint8_t b)
{
    e->crc = crc_update(e->crc, &b, 1u);
    enc_raw(e, b);
}

static void enc_u16(cobs_enc_t *e, uint16_t v)
{
    enc_u8(e, (uint8_t)(v & 0xFFu));
    enc_u8(e, (uint8_t)(v >> 8));
}

static void enc_u32(cobs_enc_t *e, uint32_t v)
{
    for (int k = 0; k < 4; ++k) {
        enc_u8(e, (uint8_t)((v >> (8 * k)) & 0xFFu));
    }
}

static void enc_f32(cobs_enc_t *e, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof(u));
    enc_u32(e, u);
}

static void enc_header(cobs_enc_t *e, uint8_t type, uint16_t len)
{
    enc_u8(e, (uint8_t)SPVS_SERIAL_VERSION);
    enc_u8(e, type);
    enc_u16(e, len);
}

/* Append the CRC (not itself checksummed), close the last block and add
 * the delimiter.  Returns the frame's byte count or SPVS_SERIAL_E_ROOM. */
static int enc_finish(cobs_enc_t *e)
{
    uint32_t crc = e->crc ^ 0xFFFFFFFFu;
    for (int k = 0; k < 4; ++k) {
        enc_raw(e, (uint8_t)((crc >> (8 * k)) & 0xFFu));
    }
    if (e->full) {
        return SPVS_SERIAL_E_ROOM;
    }
    e->out[e->code_pos] = e->code;
    e->out[e->pos++] = 0u;
    return (int)e->pos;
}

size_t spvs_serial_cobs_encode(const uint8_t *in, size_t n, uint8_t *out,
                               size_t cap)
{
    cobs_enc_t e;
    enc_start(&e, out, cap + 1u); /* no delimiter: its byte is not needed */
    for (size_t i = 0; i < n; ++i) {
        enc_raw(&e, in[i]);
    }
    if (e.full) {
        return 0u;
    }
    e.out[e.code_pos] = e.code;
    return e.pos;
}

int spvs_serial_cobs_decode(const uint8_t *in, size_t n, uint8_t *out,
                            size_t cap)
{
    size_t i = 0u, o = 0u;
    /* Each pass consumes a code byte and the data bytes it names, so the
     * loop runs at most n times. */
    while (i < n) {
        uint8_t code = in[i++];
        if (code == 0u) {
            return SPVS_SERIAL_E_COBS;
        }
        size_t k = (size_t)code - 1u;
        if (k > n - i || o + k > cap) {
            return SPVS_SERIAL_E_COBS;
        }
        for (size_t j = 0; j < k; ++j) {
            uint8_t b = in[i++];
            if (b == 0u) {
                return SPVS_SERIAL_E_COBS;
            }
            out[o++] = b;
        }
        /* A block shorter than 254 bytes stood for a zero, except the
         * last block of the frame. */
        if (code != 0xFFu && i < n) {
            if (o >= cap) {
                return SPVS_SERIAL_E_COBS;
            }
            out[o++] = 0u;
        }
    }
    return (int)o;
}

/* ---- reading fields -------------------------------------------------------- */

static uint16_t rd_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

static uint32_t rd_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}

static int16_t rd_i16(const uint8_t *p)
{
    uint16_t u = rd_u16(p);
    int16_t v;
    memcpy(&v, &u, sizeof(v));
    return v;
}

static float rd_f32(const uint8_t *p)
{
    uint32_t u = rd_u32(p);
    float f;
    memcpy(&f, &u, sizeof(f));
    return f;
}

int spvs_serial_unpack(uint8_t *enc, size_t n, spvs_serial_frame_t *f)
{
    if (n > SPVS_SERIAL_MAX_WIRE) {
        return SPVS_SERIAL_E_OVERSIZE;
    }
    int len = spvs_serial_cobs_decode(enc, n, enc, n);
    if (len < 0) {
        return len;
    }
    size_t m = (size_t)len;
    if (m < SPVS_SERIAL_HDR_BYTES + SPVS_SERIAL_CRC_BYTES) {
        return SPVS_SERIAL_E_SHORT;
    }
    /* The CRC first: a damaged header says nothing reliable. */
    uint32_t crc = spvs_serial_crc32(enc, m - SPVS_SERIAL_CRC_BYTES);
    if (crc != rd_u32(enc + m - SPVS_SERIAL_CRC_BYTES)) {
        return SPVS_SERIAL_E_CRC;
    }
    if (enc[0] != SPVS_SERIAL_VERSION) {
        return SPVS_SERIAL_E_VERSION;
    }
    uint16_t body = rd_u16(enc + 2);
    if ((size_t)body != m - SPVS_SERIAL_HDR_BYTES - SPVS_SERIAL_CRC_BYTES) {
        return SPVS_SERIAL_E_LENGTH;
    }
    f->type = enc[1];
    f->body = enc + SPVS_SERIAL_HDR_BYTES;
    f->len = body;
    return SPVS_SERIAL_OK;
}

/* ---- quantisation ---------------------------------------------------------- */

/* The conversions between the wire's integers and the core's floats.  With
 * the fixed-point core (SPVS_USE_FIXED) an MCU without FPU runs this codec,
 * and a float operation there is a soft-float library call: the floats are
 * then read and built through their IEEE-754 bits with integer operations
 * only.  Otherwise in float arithmetic, which an FPU does in an
 * instruction.  Both give the same values, bit for bit (test_serial_bits
 * compiles this file with SPVS_SERIAL_INT_CONV=1 and checks them against
 * the float arithmetic), so a host of either build and an MCU of either
 * build agree on every frame. */
#ifndef SPVS_SERIAL_INT_CONV
#define SPVS_SERIAL_INT_CONV SPVS_USE_FIXED
#endif

#if SPVS_SERIAL_INT_CONV

/* The core's scalar's IEEE-754 layout: stored mantissa bits, exponent
 * field mask and bias. */
#if SPVS_USE_DOUBLE
typedef uint64_t real_bits_t;
#define REAL_MANT 52
#define REAL_EXP_MASK 0x7ffu
#define REAL_BIAS 1023
#else
typedef uint32_t real_bits_t;
#define REAL_MANT 23
#define REAL_EXP_MASK 0xffu
#define REAL_BIAS 127
#endif
#define REAL_SIGN ((real_bits_t)1 << (sizeof(real_bits_t) * 8u - 1u))
_Static_assert(SPVS_SERIAL_PX_SCALE == 16, "the conversions take 2^4 wire units a pixel");

/* Bits in x > 0 (1..32).  GCC and Clang, the compilers of both ends, have
 * the builtin; on the Cortex-M3 it is one CLZ instruction. */
static int bitlen32(uint32_t x)
{
    return 32 - __builtin_clz(x);
}

static int bitlen64(uint64_t x)
{
    const uint32_t hi = (uint32_t)(x >> 32);
    return hi != 0u ? 32 + bitlen32(hi) : bitlen32((uint32_t)x);
}

int spvs_serial_q_from_px(spvs_real px, int16_t *q)
{
    real_bits_t b;
    memcpy(&b, &px, sizeof(b));
    const uint32_t ex = (uint32_t)(b >> REAL_MANT) & REAL_EXP_MASK;
    if (ex == REAL_EXP_MASK) {
        return SPVS_SERIAL_E_RANGE; /* NaN or infinity */
    }
    real_bits_t mant = b & (((real_bits_t)1 << REAL_MANT) - 1u);
    if (ex != 0u) {
        mant |= (real_bits_t)1 << REAL_MANT;
    }
    /* |px| * 16 = mant 2^e exactly; rounded to an integer t, halves away
     * from zero.  |px| <= 2000 px is |px| * 16 <= 32000, tested on the
     * exact value (integer part and remainder), as the float path tests
     * px against the limit before rounding. */
    const int e = (ex == 0u ? 1 : (int)ex) - REAL_BIAS - REAL_MANT + 4;
    uint32_t t;
    if (mant == 0u) {
        t = 0u;
    } else if (e >= 0) {
        /* A normal number (a subnormal has e < 0): at least its mantissa,
         * 2^REAL_MANT, far beyond the limit. */
        return SPVS_SERIAL_E_RANGE;
    } else if (-e > REAL_MANT + 1) {
        /* mant < 2^(REAL_MANT + 1): the value is below 1/2. */
        t = 0u;
    } else {
        const int r = -e;
        const real_bits_t ip = mant >> r;
        const real_bits_t rem = mant - (ip << r);
        if (ip > (real_bits_t)SPVS_SERIAL_Q_MAX ||
            (ip == (real_bits_t)SPVS_SERIAL_Q_MAX && rem != 0u)) {
            return SPVS_SERIAL_E_RANGE;
        }
        t = (uint32_t)ip + (rem >= ((real_bits_t)1 << (r - 1)) ? 1u : 0u);
    }
    *q = (b & REAL_SIGN) != 0u ? (int16_t)(0 - (int32_t)t) : (int16_t)t;
    return SPVS_SERIAL_OK;
}

spvs_real spvs_serial_px_from_q(int16_t q)
{
    /* q / 16 is exact: |q| <= 2^15 as a normal number 1.f 2^(len - 1 - 4). */
    real_bits_t b = 0u;
    if (q != 0) {
        const uint32_t a = (uint32_t)(q < 0 ? -(int32_t)q : (int32_t)q);
        const int len = bitlen32(a);
        const real_bits_t field = (real_bits_t)(len - 1 - 4 + REAL_BIAS);
        const real_bits_t frac =
            ((real_bits_t)a << (REAL_MANT - (len - 1))) & (((real_bits_t)1 << REAL_MANT) - 1u);
        b = (q < 0 ? REAL_SIGN : 0u) | (field << REAL_MANT) | frac;
    }
    spvs_real px;
    memcpy(&px, &b, sizeof(px));
    return px;
}

/* m / 2^d rounded to nearest, ties to even.  sticky nonzero: the value is
 * a little above m (by less than a unit of m, bits dropped before), so a
 * remainder of exactly half rounds up.  d in 1..63. */
static uint64_t round_even(uint64_t m, int d, int sticky)
{
    const uint64_t keep = m >> d;
    const uint64_t rem = m - (keep << d);
    const uint64_t half = (uint64_t)1 << (d - 1);
    const int up = rem > half || (rem == half && (sticky || (keep & 1u) != 0u));
    return keep + (up ? 1u : 0u);
}

float spvs_serial_s_from_ms(uint32_t t_ms)
{
    uint32_t b = 0u;
    if (t_ms != 0u) {
        /* (float)t_ms: m 2^e, m rounded to 24 bits, ties to even (exact
         * below 2^24). */
        uint64_t m = t_ms;
        int e = 0;
        const int len = bitlen32(t_ms);
        if (len > 24) {
            e = len - 24;
            m = round_even(m, e, 0);
        }
        /* m < 2^25, so m 2^39 < 2^64; the quotient by 1000 has at least
         * 29 bits, of which the top 24 (and a sticky remainder) give the
         * float quotient rounded as the FPU rounds it. */
        const uint64_t num = m << 39;
        const uint64_t quo = num / 1000u;
        const int sticky = num - quo * 1000u != 0u;
        int d = bitlen64(quo) - 24;
        uint64_t f = round_even(quo, d, sticky);
        if (f >> 24 != 0u) {
            f >>= 1;
            d++;
        }
        /* The value is f 2^(d + e - 39) with f in [2^23, 2^24): 0.001 s
         * to 4.3e6 s, normal floats. */
        const uint32_t field = (uint32_t)(23 + d + e - 39 + 127);
        b = (field << 23) | ((uint32_t)f & 0x7fffffu);
    }
    float s;
    memcpy(&s, &b, sizeof(s));
    return s;
}

#else /* float arithmetic */

int spvs_serial_q_from_px(spvs_real px, int16_t *q)
{
    const spvs_real lim = (spvs_real)SPVS_SERIAL_Q_MAX / (spvs_real)SPVS_SERIAL_PX_SCALE;
    /* The negated test is false for NaN too. */
    if (!(px >= -lim && px <= lim)) {
        return SPVS_SERIAL_E_RANGE;
    }
    /* s is exact (a power-of-two scale), its integer part too, and so is
     * the fraction below 2^15: the rounding is exact, halves away from 0. */
    spvs_real s = px * (spvs_real)SPVS_SERIAL_PX_SCALE;
    int32_t t = (int32_t)s;
    spvs_real frac = s - (spvs_real)t;
    if (frac >= SPVS_R(0.5)) {
        ++t;
    } else if (frac <= SPVS_R(-0.5)) {
        --t;
    }
    if (t > SPVS_SERIAL_Q_MAX || t < -SPVS_SERIAL_Q_MAX) {
        return SPVS_SERIAL_E_RANGE;
    }
    *q = (int16_t)t;
    return SPVS_SERIAL_OK;
}

spvs_real spvs_serial_px_from_q(int16_t q)
{
    return (spvs_real)q * (SPVS_R(1.0) / (spvs_real)SPVS_SERIAL_PX_SCALE);
}

float spvs_serial_s_from_ms(uint32_t t_ms)
{
    return (float)t_ms / 1000.0f;
}

#endif

int spvs_serial_ms_from_utime(int64_t utime, uint32_t *t_ms)
{
    if (utime < 0 || utime > (int64_t)UINT32_MAX * 1000 + 499) {
        return SPVS_SERIAL_E_RANGE;
    }
    *t_ms = (uint32_t)((utime + 500) / 1000);
    return SPVS_SERIAL_OK;
}

int spvs_serial_quantize_match(const spvs_match_t *in, spvs_match_t *out)
{
    int16_t q[4];
    if (in->feature >= SPVS_MAX_FEATURES ||
        spvs_serial_q_from_px(in->x_tgt, &q[0]) != SPVS_SERIAL_OK ||
        spvs_serial_q_from_px(in->y_tgt, &q[1]) != SPVS_SERIAL_OK ||
        spvs_serial_q_from_px(in->x_cur, &q[2]) != SPVS_SERIAL_OK ||
        spvs_serial_q_from_px(in->y_cur, &q[3]) != SPVS_SERIAL_OK) {
        return SPVS_SERIAL_E_RANGE;
    }
    out->feature = in->feature;
    out->x_tgt = spvs_serial_px_from_q(q[0]);
    out->y_tgt = spvs_serial_px_from_q(q[1]);
    out->x_cur = spvs_serial_px_from_q(q[2]);
    out->y_cur = spvs_serial_px_from_q(q[3]);
    return SPVS_SERIAL_OK;
}

/* ---- matches ----------------------------------------------------------------- */

int spvs_serial_encode_matches(const spvs_serial_matches_hdr_t *h,
                               const spvs_match_t *m, uint8_t *out,
                               size_t cap)
{
    if (h->count > SPVS_SERIAL_MAX_MATCHES) {
        return SPVS_SERIAL_E_COUNT;
    }
    cobs_enc_t e;
    enc_start(&e, out, cap);
    enc_header(&e, (uint8_t)SPVS_SERIAL_T_MATCHES,
               (uint16_t)SPVS_SERIAL_MATCHES_BODY(h->count));
    enc_u32(&e, h->run);
    enc_u32(&e, h->seq);
    enc_u32(&e, h->t_ms);
    enc_u16(&e, h->count);
    for (uint16_t i = 0; i < h->count; ++i) {
        int16_t q[4];
        if (m[i].feature >= SPVS_MAX_FEATURES ||
            spvs_serial_q_from_px(m[i].x_tgt, &q[0]) != SPVS_SERIAL_OK ||
            spvs_serial_q_from_px(m[i].y_tgt, &q[1]) != SPVS_SERIAL_OK ||
            spvs_serial_q_from_px(m[i].x_cur, &q[2]) != SPVS_SERIAL_OK ||
            spvs_serial_q_from_px(m[i].y_cur, &q[3]) != SPVS_SERIAL_OK) {
            return SPVS_SERIAL_E_RANGE;
        }
        enc_u16(&e, m[i].feature);
        for (int k = 0; k < 4; ++k) {
            enc_u16(&e, (uint16_t)q[k]);
        }
    }
    return enc_finish(&e);
}

int spvs_serial_parse_matches(const spvs_serial_frame_t *f,
                              spvs_serial_matches_hdr_t *h, spvs_match_t *m,
                              uint16_t cap)
{
    if (f->type != SPVS_SERIAL_T_MATCHES) {
        return SPVS_SERIAL_E_TYPE;
    }
    if (f->len < SPVS_SERIAL_MATCHES_FIXED) {
        return SPVS_SERIAL_E_LENGTH;
    }
    const uint8_t *p = f->body;
    h->run = rd_u32(p);
    h->seq = rd_u32(p + 4);
    h->t_ms = rd_u32(p + 8);
    h->count = rd_u16(p + 12);
    if (h->count > SPVS_SERIAL_MAX_MATCHES || h->count > cap) {
        return SPVS_SERIAL_E_COUNT;
    }
    if (f->len != SPVS_SERIAL_MATCHES_BODY(h->count)) {
        return SPVS_SERIAL_E_LENGTH;
    }
    p += SPVS_SERIAL_MATCHES_FIXED;
    for (uint16_t i = 0; i < h->count; ++i, p += SPVS_SERIAL_MATCH_BYTES) {
        uint16_t feature = rd_u16(p);
        int16_t q[4];
        for (int k = 0; k < 4; ++k) {
            q[k] = rd_i16(p + 2 + 2 * k);
            if (q[k] > SPVS_SERIAL_Q_MAX || q[k] < -SPVS_SERIAL_Q_MAX) {
                return SPVS_SERIAL_E_RANGE;
            }
        }
        if (feature >= SPVS_MAX_FEATURES) {
            return SPVS_SERIAL_E_RANGE;
        }
        m[i].feature = feature;
        m[i].x_tgt = spvs_serial_px_from_q(q[0]);
        m[i].y_tgt = spvs_serial_px_from_q(q[1]);
        m[i].x_cur = spvs_serial_px_from_q(q[2]);
        m[i].y_cur = spvs_serial_px_from_q(q[3]);
    }
    return SPVS_SERIAL_OK;
}

/* ---- result -------------------------------------------------------------------- */

int spvs_serial_encode_result(const spvs_serial_result_t *r, uint8_t *out,
                              size_t cap)
{
    const spvs_output_t *o = &r->out;
    cobs_enc_t e;
    enc_start(&e, out, cap);
    enc_header(&e, (uint8_t)SPVS_SERIAL_T_RESULT, (uint16_t)SPVS_SERIAL_RESULT_BODY);
    enc_u32(&e, r->run);
    enc_u32(&e, r->seq);
    enc_u32(&e, r->t_ms);
    enc_f32(&e, (float)o->v);
    enc_f32(&e, (float)o->w);
    enc_u16(&e, (uint16_t)o->status);
    enc_u8(&e, o->step);
    enc_u8(&e, r->flags);
    enc_u16(&e, o->n_matches);
    enc_u16(&e, o->n_inliers);
    enc_u16(&e, o->n_offplane);
    enc_u16(&e, o->ransac_iters);
    enc_f32(&e, (float)o->e_x_px);
    enc_f32(&e, (float)o->parallax_px);
    for (int k = 0; k < 9; ++k) {
        enc_f32(&e, (float)o->H[k]);
    }
    enc_f32(&e, (float)o->arrival_corner_px);
    enc_f32(&e, (float)o->arrival_stat);
    enc_f32(&e, (float)o->arrival_lateral_px);
    enc_f32(&e, (float)o->arrival_depth_px);
    enc_f32(&e, (float)o->arrival_h13_px);
    enc_f32(&e, (float)o->arrival_parallax_px);
    enc_u16(&e, o->arrival_frames);
    enc_u8(&e, o->arrival_reentries);
    enc_u8(&e, o->arrival_next);
    enc_f32(&e, (float)o->arrival_threshold);
    enc_f32(&e, (float)o->arrival_lateral_sd_px);
    enc_f32(&e, (float)o->arrival_depth_sd_px);
    enc_f32(&e, (float)o->arrival_h13_sd_px);
    return enc_finish(&e);
}

int spvs_serial_parse_result(const spvs_serial_frame_t *f,
                             spvs_serial_result_t *r)
{
    if (f->type != SPVS_SERIAL_T_RESULT) {
        return SPVS_SERIAL_E_TYPE;
    }
    if (f->len != SPVS_SERIAL_RESULT_BODY) {
        return SPVS_SERIAL_E_LENGTH;
    }
    const uint8_t *p = f->body;
    spvs_output_t *o = &r->out;
    memset(o, 0, sizeof(*o));
    r->run = rd_u32(p);
    r->seq = rd_u32(p + 4);
    r->t_ms = rd_u32(p + 8);
    o->v = (spvs_real)rd_f32(p + 12);
    o->w = (spvs_real)rd_f32(p + 16);
    o->status = rd_i16(p + 20);
    o->step = p[22];
    r->flags = p[23];
    o->n_matches = rd_u16(p + 24);
    o->n_inliers = rd_u16(p + 26);
    o->n_offplane = rd_u16(p + 28);
    o->ransac_iters = rd_u16(p + 30);
    o->e_x_px = (spvs_real)rd_f32(p + 32);
    o->parallax_px = (spvs_real)rd_f32(p + 36);
    for (int k = 0; k < 9; ++k) {
        o->H[k] = (spvs_real)rd_f32(p + 40 + 4 * k);
    }
    o->arrival_corner_px = (spvs_real)rd_f32(p + 76);
    o->arrival_stat = (spvs_real)rd_f32(p + 80);
    o->arrival_lateral_px = (spvs_real)rd_f32(p + 84);
    o->arrival_depth_px = (spvs_real)rd_f32(p + 88);
    o->arrival_h13_px = (spvs_real)rd_f32(p + 92);
    o->arrival_parallax_px = (spvs_real)rd_f32(p + 96);
    o->arrival_frames = rd_u16(p + 100);
    o->arrival_reentries = p[102];
    o->arrival_next = p[103];
    o->arrival_threshold = (spvs_real)rd_f32(p + 104);
    o->arrival_lateral_sd_px = (spvs_real)rd_f32(p + 108);
    o->arrival_depth_sd_px = (spvs_real)rd_f32(p + 112);
    o->arrival_h13_sd_px = (spvs_real)rd_f32(p + 116);
    o->h_valid = (r->flags & SPVS_SERIAL_F_H_VALID) ? 1u : 0u;
    o->e_valid = (r->flags & SPVS_SERIAL_F_E_VALID) ? 1u : 0u;
    o->eq11 = (r->flags & SPVS_SERIAL_F_EQ11) ? 1u : 0u;
    return SPVS_SERIAL_OK;
}

/* ---- status ---------------------------------------------------------------------- */

int spvs_serial_encode_status(const spvs_serial_status_frame_t *s,
                              uint8_t *out, size_t cap)
{
    cobs_enc_t e;
    enc_start(&e, out, cap);
    enc_header(&e, (uint8_t)SPVS_SERIAL_T_STATUS, (uint16_t)SPVS_SERIAL_STATUS_BODY);
    enc_u8(&e, s->reason);
    enc_u8(&e, s->step);
    enc_u16(&e, (uint16_t)s->status);
    enc_u8(&e, s->method);
    enc_u8(&e, 0u);
    enc_u16(&e, 0u);
    enc_u32(&e, s->seed);
    enc_f32(&e, s->alpha_px);
    const uint32_t w[13] = { s->run, s->last_seq, s->age_ms, s->uptime_ms,
                             s->watchdog_ms, s->updates, s->repeats, s->stale,
                             s->rejected, s->crc_errors, s->framing_errors,
                             s->overruns, s->watchdog_stops };
    for (int k = 0; k < 13; ++k) {
        enc_u32(&e, w[k]);
    }
    return enc_finish(&e);
}

int spvs_serial_parse_status(const spvs_serial_frame_t *f,
                             spvs_serial_status_frame_t *s)
{
    if (f->type != SPVS_SERIAL_T_STATUS) {
        return SPVS_SERIAL_E_TYPE;
    }
    if (f->len != SPVS_SERIAL_STATUS_BODY) {
        return SPVS_SERIAL_E_LENGTH;
    }
    const uint8_t *p = f->body;
    s->reason = p[0];
    s->step = p[1];
    s->status = rd_i16(p + 2);
    s->method = p[4];
    s->seed = rd_u32(p + 8);
    s->alpha_px = rd_f32(p + 12);
    p += 12;
    uint32_t *w[13] = { &s->run, &s->last_seq, &s->age_ms, &s->uptime_ms,
                        &s->watchdog_ms, &s->updates, &s->repeats, &s->stale,
                        &s->rejected, &s->crc_errors, &s->framing_errors,
                        &s->overruns, &s->watchdog_stops };
    for (int k = 0; k < 13; ++k) {
        *w[k] = rd_u32(p + 4 + 4 * k);
    }
    return SPVS_SERIAL_OK;
}

/* ---- config ---------------------------------------------------------------------- */

int spvs_serial_encode_config(const spvs_serial_config_t *c, uint8_t *out,
                              size_t cap)
{
    cobs_enc_t e;
    enc_start(&e, out, cap);
    enc_header(&e, (uint8_t)SPVS_SERIAL_T_CONFIG, (uint16_t)SPVS_SERIAL_CONFIG_BODY);
    enc_u8(&e, c->method);
    enc_u8(&e, 0u);
    enc_u16(&e, c->watchdog_ms);
    enc_u32(&e, c->seed);
    enc_f32(&e, c->alpha_px);
    enc_f32(&e, c->alpha_px);
    return enc_finish(&e);
}

/* The focal lengths' check: alpha_x in [1, 1e5] px and alpha_y equal to
 * it.  With integer conversions on their bits: a positive float's bits
 * sort as its value, and every NaN's and negative value's lie above
 * 1e5f's; within the range, equal floats are equal bits. */
static int alpha_ok(uint32_t ax_bits, uint32_t ay_bits)
{
#if SPVS_SERIAL_INT_CONV
    return ax_bits >= 0x3F800000u /* 1.0f */ && ax_bits <= 0x47C35000u /* 1e5f */ &&
           ay_bits == ax_bits;
#else
    float ax, ay;
    memcpy(&ax, &ax_bits, sizeof(ax));
    memcpy(&ay, &ay_bits, sizeof(ay));
    return ax >= 1.0f && ax <= 1.0e5f && ay == ax;
#endif
}

int spvs_serial_parse_config(const spvs_serial_frame_t *f,
                             spvs_serial_config_t *c)
{
    if (f->type != SPVS_SERIAL_T_CONFIG) {
        return SPVS_SERIAL_E_TYPE;
    }
    if (f->len != SPVS_SERIAL_CONFIG_BODY) {
        return SPVS_SERIAL_E_LENGTH;
    }
    const uint8_t *p = f->body;
    c->method = p[0];
    c->watchdog_ms = rd_u16(p + 2);
    c->seed = rd_u32(p + 4);
    c->alpha_px = rd_f32(p + 8);
    /* x and y focal lengths travel apart for a later non-square camera;
     * this version takes square pixels only. */
    if (c->method < 1u || c->method > 3u || !alpha_ok(rd_u32(p + 8), rd_u32(p + 12)) ||
        (c->watchdog_ms != 0u && (c->watchdog_ms < SPVS_SERIAL_WATCHDOG_MIN_MS ||
                                  c->watchdog_ms > SPVS_SERIAL_WATCHDOG_MAX_MS))) {
        return SPVS_SERIAL_E_RANGE;
    }
    return SPVS_SERIAL_OK;
}

/* ---- byte stream ----------------------------------------------------------------- */

void spvs_serial_rx_init(spvs_serial_rx_t *rx)
{
    rx->n = 0u;
    rx->overflow = 0u;
    rx->done = 0u;
}

int spvs_serial_rx_push(spvs_serial_rx_t *rx, uint8_t byte)
{
    if (rx->done) {
        /* The frame handed out by the last call is finished with. */
        rx->n = 0u;
        rx->done = 0u;
    }
    if (byte == 0u) {
        int over = rx->overflow;
        rx->overflow = 0u;
        if (over) {
            rx->n = 0u;
            return SPVS_SERIAL_E_OVERSIZE;
        }
        if (rx->n == 0u) {
            return 0;
        }
        rx->done = 1u;
        return 1;
    }
    if (rx->overflow) {
        return 0;
    }
    if (rx->n >= sizeof(rx->buf)) {
        rx->overflow = 1u;
        return 0;
    }
    rx->buf[rx->n++] = byte;
    return 0;
}
