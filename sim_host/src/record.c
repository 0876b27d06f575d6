/* record.c - the binary recording (record.h, docs/RECORDING.md). */
#include "sim/record.h"

#include <string.h>

static void put_u16(uint8_t *b, uint16_t v)
{
    b[0] = (uint8_t)v;
    b[1] = (uint8_t)(v >> 8);
}

static void put_u32(uint8_t *b, uint32_t v)
{
    for (int i = 0; i < 4; ++i) {
        b[i] = (uint8_t)(v >> (8 * i));
    }
}

static void put_u64(uint8_t *b, uint64_t v)
{
    for (int i = 0; i < 8; ++i) {
        b[i] = (uint8_t)(v >> (8 * i));
    }
}

static void put_f32(uint8_t *b, double x)
{
    float f = (float)x;
    uint32_t u;
    memcpy(&u, &f, 4);
    put_u32(b, u);
}

static uint16_t get_u16(const uint8_t *b)
{
    return (uint16_t)(b[0] | (b[1] << 8));
}

static uint32_t get_u32(const uint8_t *b)
{
    return (uint32_t)b[0] | ((uint32_t)b[1] << 8) | ((uint32_t)b[2] << 16) |
           ((uint32_t)b[3] << 24);
}

static float get_f32(const uint8_t *b)
{
    uint32_t u = get_u32(b);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

int sim_record_write_header(FILE *f)
{
    return fwrite(SIM_RECORD_MAGIC, 1, 8, f) == 8 ? 0 : -1;
}

int sim_record_write_frame(FILE *f, uint32_t seq, double t_s,
                           const spvs_match_t *m, uint16_t n, double v_mps,
                           double w_radps, int16_t status, uint8_t step)
{
    uint8_t b[18];
    uint64_t tb;
    memcpy(&tb, &t_s, 8);
    put_u32(b, seq);
    put_u64(b + 4, tb);
    put_u16(b + 12, n);
    if (fwrite(b, 1, 14, f) != 14) {
        return -1;
    }
    for (uint16_t i = 0; i < n; ++i) {
        put_u16(b, m[i].feature);
        put_f32(b + 2, (double)m[i].x_tgt);
        put_f32(b + 6, (double)m[i].y_tgt);
        put_f32(b + 10, (double)m[i].x_cur);
        put_f32(b + 14, (double)m[i].y_cur);
        if (fwrite(b, 1, 18, f) != 18) {
            return -1;
        }
    }
    put_f32(b, v_mps);
    put_f32(b + 4, w_radps);
    put_u16(b + 8, (uint16_t)status);
    b[10] = step;
    return fwrite(b, 1, 11, f) == 11 ? 0 : -1;
}

int sim_record_read_header(FILE *f)
{
    char magic[8];
    if (fread(magic, 1, 8, f) != 8 || memcmp(magic, SIM_RECORD_MAGIC, 8) != 0) {
        return -1;
    }
    return 0;
}

int sim_record_read_frame(FILE *f, sim_record_frame_t *fr, spvs_match_t *m,
                          uint16_t cap)
{
    uint8_t b[18];
    size_t got = fread(b, 1, 14, f);
    if (got == 0 && feof(f)) {
        return 0;
    }
    if (got != 14) {
        return -1;
    }
    uint64_t tb = 0;
    for (int i = 7; i >= 0; --i) {
        tb = (tb << 8) | b[4 + i];
    }
    memset(fr, 0, sizeof(*fr));
    fr->seq = get_u32(b);
    memcpy(&fr->t_s, &tb, 8);
    fr->n = get_u16(b + 12);
    for (uint16_t i = 0; i < fr->n; ++i) {
        if (fread(b, 1, 18, f) != 18) {
            return -1;
        }
        if (i < cap) {
            m[i].feature = get_u16(b);
            m[i].x_tgt = (spvs_real)get_f32(b + 2);
            m[i].y_tgt = (spvs_real)get_f32(b + 6);
            m[i].x_cur = (spvs_real)get_f32(b + 10);
            m[i].y_cur = (spvs_real)get_f32(b + 14);
            fr->n_kept++;
        }
    }
    if (fread(b, 1, 11, f) != 11) {
        return -1;
    }
    fr->v_mps = get_f32(b);
    fr->w_radps = get_f32(b + 4);
    fr->status = (int16_t)get_u16(b + 8);
    fr->step = b[10];
    return 1;
}
