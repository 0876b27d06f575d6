/*
 * fuzz_reader.h - a reader over the fuzz bytes, shared by the fuzz targets:
 * past the end it returns zeros, so every input, however short, is a
 * complete description.
 */
#ifndef SPVS_FUZZ_READER_H
#define SPVS_FUZZ_READER_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

typedef struct {
    const uint8_t *p;
    size_t n;
    size_t at;
} reader_t;

static inline uint8_t rd_u8(reader_t *r)
{
    return r->at < r->n ? r->p[r->at++] : 0u;
}

static inline uint16_t rd_u16(reader_t *r)
{
    uint16_t hi = rd_u8(r);
    return (uint16_t)((hi << 8) | rd_u8(r));
}

static inline uint32_t rd_u32(reader_t *r)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; i++) {
        v = (v << 8) | rd_u8(r);
    }
    return v;
}

/* Raw float bits: NaN payloads, infinities, denormals all reachable. */
static inline float rd_float_bits(reader_t *r)
{
    uint32_t u = rd_u32(r);
    float f;
    memcpy(&f, &u, sizeof(f));
    return f;
}

/* A value in [lo, hi] from one byte. */
static inline double rd_range(reader_t *r, double lo, double hi)
{
    return lo + (hi - lo) * (double)rd_u8(r) / 255.0;
}

#endif /* SPVS_FUZZ_READER_H */
