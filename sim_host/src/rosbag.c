/*
 * rosbag.c - rosbag2 (MCAP storage) of a simulator run; see sim/rosbag.h.
 *
 * MCAP (mcap.dev/spec): magic, Header, the data section (Schema and
 * Channel records, then Chunks each followed by the Message Index records
 * of its channels, then Data End), the summary section (Schemas, Channels,
 * Statistics, Chunk Indexes), the Summary Offset records, Footer, magic.
 * Every record is opcode (u8), content length (u64), content; integers
 * little endian; strings and byte arrays u32 length first, chunk records
 * u64 length first.
 *
 * ROS 2 CDR: a 4-byte encapsulation header (0x00 0x01 = CDR little endian,
 * options 0), then the fields in order, each aligned to its own size from
 * the end of that header; fixed-size arrays without a length.
 */
#define _POSIX_C_SOURCE 200809L

#include "sim/rosbag.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "spvs_msgdefs.h"
#include "wire.h"

/* A chunk is closed once its records pass this many bytes. */
#define CHUNK_BYTES (1u << 20)
#define N_CHANNELS 3
#define CH_MATCHES 1
#define CH_CMD_VEL 2
#define CH_STATE 3

enum {
    OP_HEADER = 0x01, OP_FOOTER = 0x02, OP_SCHEMA = 0x03, OP_CHANNEL = 0x04,
    OP_MESSAGE = 0x05, OP_CHUNK = 0x06, OP_MESSAGE_INDEX = 0x07,
    OP_CHUNK_INDEX = 0x08, OP_STATISTICS = 0x0B, OP_SUMMARY_OFFSET = 0x0E,
    OP_DATA_END = 0x0F
};

static const uint8_t MCAP_MAGIC[8] = { 0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n' };

/* What the topics offer, as rosbag2 records it (rmw enums: history 1 keep
 * last, reliability 1 reliable, durability 2 volatile, liveliness 1
 * automatic; infinite durations). */
#define QOS_YAML \
    "- history: 1\n  depth: 10\n  reliability: 1\n  durability: 2\n" \
    "  deadline:\n    sec: 2147483647\n    nsec: 4294967295\n" \
    "  lifespan:\n    sec: 2147483647\n    nsec: 4294967295\n" \
    "  liveliness: 1\n" \
    "  liveliness_lease_duration:\n    sec: 2147483647\n    nsec: 4294967295\n" \
    "  avoid_ros_namespace_conventions: false"

static const struct {
    const char *topic, *type, *def;
} k_channels[N_CHANNELS] = {
    { "/spvs/matches", SPVS_MSGTYPE_SPVS_MSGS_MATCHES, SPVS_MSGDEF_SPVS_MSGS_MATCHES },
    { "/cmd_vel", SPVS_MSGTYPE_GEOMETRY_MSGS_TWIST, SPVS_MSGDEF_GEOMETRY_MSGS_TWIST },
    { "/spvs/state", SPVS_MSGTYPE_SPVS_MSGS_STATE, SPVS_MSGDEF_SPVS_MSGS_STATE },
};

/* ---- growable byte buffer (edge code: the heap is fine here) ----------- */

typedef struct {
    uint8_t *p;
    size_t len, cap;
    int failed;
} buf_t;

static void put(buf_t *b, const void *d, size_t n)
{
    if (b->failed)
        return;
    if (b->len + n > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->len + n)
            cap *= 2;
        uint8_t *q = realloc(b->p, cap);
        if (!q) {
            b->failed = 1;
            return;
        }
        b->p = q;
        b->cap = cap;
    }
    memcpy(b->p + b->len, d, n);
    b->len += n;
}

static void put_le(buf_t *b, uint64_t v, int bytes)
{
    uint8_t t[8];
    for (int i = 0; i < bytes; i++)
        t[i] = (uint8_t)(v >> (8 * i));
    put(b, t, (size_t)bytes);
}
static void u8(buf_t *b, uint64_t v) { put_le(b, v, 1); }
static void u16(buf_t *b, uint64_t v) { put_le(b, v, 2); }
static void u32(buf_t *b, uint64_t v) { put_le(b, v, 4); }
static void u64(buf_t *b, uint64_t v) { put_le(b, v, 8); }
static void str(buf_t *b, const char *s)
{
    u32(b, strlen(s));
    put(b, s, strlen(s));
}

/* CRC-32 (IEEE, as zlib), bitwise: a few MB per run. */
static uint32_t crc32_update(uint32_t crc, const uint8_t *p, size_t n)
{
    crc = ~crc;
    for (size_t i = 0; i < n; i++) {
        crc ^= p[i];
        for (int k = 0; k < 8; k++)
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

/* ---- CDR ---------------------------------------------------------------- */

static void cdr_begin(buf_t *b)
{
    b->len = 0;
    const uint8_t hdr[4] = { 0x00, 0x01, 0x00, 0x00 };
    put(b, hdr, 4);
}
static void cdr_align(buf_t *b, size_t a)
{
    static const uint8_t zero[8];
    size_t off = (b->len - 4) % a;
    if (off)
        put(b, zero, a - off);
}
static void c_i16(buf_t *b, int16_t v) { cdr_align(b, 2); u16(b, (uint16_t)v); }
static void c_i32(buf_t *b, int32_t v) { cdr_align(b, 4); u32(b, (uint32_t)v); }
static void c_i64(buf_t *b, int64_t v) { cdr_align(b, 8); u64(b, (uint64_t)v); }
static void c_u8(buf_t *b, unsigned v) { u8(b, v & 0xFFu); }
static void c_f32(buf_t *b, float v)
{
    uint32_t x;
    memcpy(&x, &v, 4);
    cdr_align(b, 4);
    u32(b, x);
}
static void c_f64(buf_t *b, double v)
{
    uint64_t x;
    memcpy(&x, &v, 8);
    cdr_align(b, 8);
    u64(b, x);
}

/* spvs_msgs/msg/Matches, field by field as Matches.msg. */
static void cdr_matches(buf_t *b, const spvs_matches_t *m)
{
    cdr_begin(b);
    c_i64(b, m->seq);
    c_i64(b, m->utime);
    c_i64(b, m->run_id);
    c_i16(b, m->count);
    for (int i = 0; i < SPVS_WIRE_MAX_MATCHES; i++)
        c_i32(b, m->feature[i]);
    const float *arr[4] = { m->x_tgt, m->y_tgt, m->x_cur, m->y_cur };
    for (int a = 0; a < 4; a++)
        for (int i = 0; i < SPVS_WIRE_MAX_MATCHES; i++)
            c_f32(b, arr[a][i]);
}

/* geometry_msgs/msg/Twist: linear (x, y, z), angular (x, y, z). */
static void cdr_twist(buf_t *b, const spvs_cmd_t *c)
{
    cdr_begin(b);
    const double f[6] = { c->v, 0.0, 0.0, 0.0, 0.0, c->w };
    for (int i = 0; i < 6; i++)
        c_f64(b, f[i]);
}

/* spvs_msgs/msg/State, field by field as State.msg. */
static void cdr_state(buf_t *b, const spvs_state_t *s, const spvs_cmd_t *c)
{
    cdr_begin(b);
    c_i64(b, c->seq);
    c_i64(b, c->utime);
    for (int i = 0; i < 9; i++)
        c_f64(b, s->H[i]);
    c_u8(b, s->h_valid != 0);
    c_i16(b, s->n_matches);
    c_i16(b, s->n_inliers);
    c_i16(b, s->n_offplane);
    c_f64(b, s->e_x);
    c_u8(b, s->e_valid != 0);
    c_f64(b, s->parallax);
    c_u8(b, s->eq11 != 0);
    c_f64(b, c->v);
    c_f64(b, c->w);
    c_u8(b, (unsigned)c->step);
    c_i16(b, c->status);
    c_f64(b, s->arrival_stat);
    c_f64(b, s->arrival_threshold);
    c_f64(b, s->arrival_lateral_px);
    c_f64(b, s->arrival_lateral_sd_px);
    c_f64(b, s->arrival_depth_px);
    c_f64(b, s->arrival_depth_sd_px);
    c_f64(b, s->arrival_h13_px);
    c_f64(b, s->arrival_h13_sd_px);
    c_f64(b, s->arrival_corner_px);
    c_f64(b, s->arrival_parallax_px);
    c_i16(b, s->arrival_frames);
    c_u8(b, (unsigned)s->arrival_reentries);
    c_u8(b, (unsigned)s->arrival_next);
    c_u8(b, s->arriving != 0);
}

/* ---- the MCAP writer ---------------------------------------------------- */

typedef struct {
    uint64_t start, end, offset, length;
    uint64_t mi_offset[N_CHANNELS], mi_length;
    uint64_t size;
} chunk_info_t;

struct sim_rosbag {
    char dir[512];
    char file[128];            /* the MCAP file's name inside dir            */
    FILE *f;
    uint64_t pos;              /* bytes written to f                          */
    buf_t rec, chunk, msg;
    buf_t index[N_CHANNELS];   /* this chunk's (time, offset) per channel     */
    uint64_t chunk_start, chunk_end;
    chunk_info_t *chunks;
    size_t n_chunks, cap_chunks;
    uint64_t count[N_CHANNELS], total, t_first, t_last;
    uint32_t seq[N_CHANNELS];
    int64_t run_id;
    int failed;
    spvs_matches_t lcm_m;
};

static void out_bytes(sim_rosbag_t *b, const void *p, size_t n)
{
    if (!b->failed && fwrite(p, 1, n, b->f) != n)
        b->failed = 1;
    b->pos += n;
}

/* One record: opcode, length, the content in b->rec. */
static void out_record(sim_rosbag_t *b, int op, const buf_t *content)
{
    buf_t h = { 0 };
    u8(&h, (unsigned)op);
    u64(&h, content->len);
    out_bytes(b, h.p, h.len);
    out_bytes(b, content->p, content->len);
    b->failed |= h.failed | content->failed;
    free(h.p);
}

static void rec_schema(buf_t *r, int id)
{
    r->len = 0;
    u16(r, (unsigned)id);
    str(r, k_channels[id - 1].type);
    str(r, "ros2msg");
    str(r, k_channels[id - 1].def);
}

static void rec_channel(buf_t *r, int id)
{
    static const char key[] = "offered_qos_profiles";
    r->len = 0;
    u16(r, (unsigned)id);
    u16(r, (unsigned)id); /* one schema per channel, the same id */
    str(r, k_channels[id - 1].topic);
    str(r, "cdr");
    u32(r, 4 + strlen(key) + 4 + strlen(QOS_YAML));
    str(r, key);
    str(r, QOS_YAML);
}

static void flush_chunk(sim_rosbag_t *b)
{
    if (b->chunk.len == 0)
        return;
    if (b->n_chunks == b->cap_chunks) {
        size_t cap = b->cap_chunks ? 2 * b->cap_chunks : 16;
        chunk_info_t *c = realloc(b->chunks, cap * sizeof(*c));
        if (!c) {
            b->failed = 1;
            return;
        }
        b->chunks = c;
        b->cap_chunks = cap;
    }
    chunk_info_t *ci = &b->chunks[b->n_chunks++];
    memset(ci, 0, sizeof(*ci));
    ci->start = b->chunk_start;
    ci->end = b->chunk_end;
    ci->offset = b->pos;
    ci->size = b->chunk.len;

    buf_t *r = &b->rec;
    r->len = 0;
    u64(r, b->chunk_start);
    u64(r, b->chunk_end);
    u64(r, b->chunk.len);
    u32(r, crc32_update(0, b->chunk.p, b->chunk.len));
    str(r, "");
    u64(r, b->chunk.len);
    put(r, b->chunk.p, b->chunk.len);
    out_record(b, OP_CHUNK, r);
    ci->length = b->pos - ci->offset;

    uint64_t mi_start = b->pos;
    for (int c = 0; c < N_CHANNELS; c++) {
        if (b->index[c].len == 0)
            continue;
        ci->mi_offset[c] = b->pos;
        r->len = 0;
        u16(r, (unsigned)(c + 1));
        u32(r, b->index[c].len);
        put(r, b->index[c].p, b->index[c].len);
        out_record(b, OP_MESSAGE_INDEX, r);
        b->index[c].len = 0;
    }
    ci->mi_length = b->pos - mi_start;
    b->chunk.len = 0;
}

/* A message of channel ch (1..3) with CDR data in b->msg at time t_ns. */
static void add_message(sim_rosbag_t *b, int ch, uint64_t t_ns)
{
    if (b->chunk.len == 0)
        b->chunk_start = t_ns;
    b->chunk_end = t_ns;
    u64(&b->index[ch - 1], t_ns);
    u64(&b->index[ch - 1], b->chunk.len);
    u8(&b->chunk, OP_MESSAGE);
    u64(&b->chunk, 2 + 4 + 8 + 8 + b->msg.len);
    u16(&b->chunk, (unsigned)ch);
    u32(&b->chunk, b->seq[ch - 1]++);
    u64(&b->chunk, t_ns);
    u64(&b->chunk, t_ns);
    put(&b->chunk, b->msg.p, b->msg.len);
    b->count[ch - 1]++;
    if (b->total++ == 0)
        b->t_first = t_ns;
    b->t_last = t_ns;
    if (b->chunk.len >= CHUNK_BYTES)
        flush_chunk(b);
}

sim_rosbag_t *sim_rosbag_open(const char *dir, char *err, unsigned err_len)
{
    const char *base = strrchr(dir, '/');
    base = base && base[1] ? base + 1 : dir;
    if (strlen(dir) == 0 || strlen(dir) >= sizeof(((sim_rosbag_t *)0)->dir) ||
        strlen(base) > 100) {
        snprintf(err, err_len, "--rosbag: folder name empty or too long");
        return NULL;
    }
    if (mkdir(dir, 0777) != 0) {
        snprintf(err, err_len, "--rosbag: cannot create folder '%s': %s%s",
                 dir, strerror(errno),
                 errno == EEXIST ? " (ros2 bag record refuses it too)" : "");
        return NULL;
    }
    sim_rosbag_t *b = calloc(1, sizeof(*b));
    if (!b) {
        snprintf(err, err_len, "--rosbag: out of memory");
        return NULL;
    }
    snprintf(b->dir, sizeof(b->dir), "%s", dir);
    snprintf(b->file, sizeof(b->file), "%s_0.mcap", base);
    char path[700];
    snprintf(path, sizeof(path), "%s/%s", b->dir, b->file);
    b->f = fopen(path, "wb");
    if (!b->f) {
        snprintf(err, err_len, "--rosbag: cannot create '%s': %s", path,
                 strerror(errno));
        free(b);
        return NULL;
    }
    b->run_id = 1;
    out_bytes(b, MCAP_MAGIC, sizeof(MCAP_MAGIC));
    buf_t *r = &b->rec;
    r->len = 0;
    str(r, "ros2");
    str(r, "spvs-sim");
    out_record(b, OP_HEADER, r);
    for (int id = 1; id <= N_CHANNELS; id++) {
        rec_schema(r, id);
        out_record(b, OP_SCHEMA, r);
    }
    for (int id = 1; id <= N_CHANNELS; id++) {
        rec_channel(r, id);
        out_record(b, OP_CHANNEL, r);
    }
    return b;
}

int sim_rosbag_frame(sim_rosbag_t *b, uint32_t seq, double t_s,
                     const spvs_match_t *m, uint16_t n,
                     const spvs_output_t *out, char *err, unsigned err_len)
{
    if (!(t_s >= 0.0) || !(t_s < 9e9)) {
        snprintf(err, err_len, "--rosbag: frame time %g s out of range", t_s);
        return -1;
    }
    uint64_t t_ns = (uint64_t)llround(t_s * 1e9);
    if (spvs_wire_frame_from_sim(&b->lcm_m, seq, t_s, b->run_id, m, n,
                                 "--rosbag", err, err_len) != 0)
        return -1;
    spvs_cmd_t cmd;
    spvs_state_t st;
    spvs_wire_cmd_from_output(&cmd, b->lcm_m.seq, b->lcm_m.utime, out);
    spvs_wire_state_from_output(&st, b->lcm_m.seq, b->lcm_m.utime, out);
    cdr_matches(&b->msg, &b->lcm_m);
    add_message(b, CH_MATCHES, t_ns);
    cdr_twist(&b->msg, &cmd);
    add_message(b, CH_CMD_VEL, t_ns);
    cdr_state(&b->msg, &st, &cmd);
    add_message(b, CH_STATE, t_ns);
    if (b->failed || b->msg.failed || b->chunk.failed) {
        snprintf(err, err_len, "--rosbag: cannot write '%s/%s'", b->dir,
                 b->file);
        return -1;
    }
    return 0;
}

/* Summary, summary offsets, footer, closing magic. */
static void finish_mcap(sim_rosbag_t *b)
{
    buf_t *r = &b->rec;
    flush_chunk(b);
    r->len = 0;
    u32(r, 0); /* data section CRC: not computed */
    out_record(b, OP_DATA_END, r);

    uint64_t summary_start = b->pos;
    uint64_t group_start[4], group_len[4];
    const int group_op[4] = { OP_SCHEMA, OP_CHANNEL, OP_STATISTICS, OP_CHUNK_INDEX };
    group_start[0] = b->pos;
    for (int id = 1; id <= N_CHANNELS; id++) {
        rec_schema(r, id);
        out_record(b, OP_SCHEMA, r);
    }
    group_len[0] = b->pos - group_start[0];
    group_start[1] = b->pos;
    for (int id = 1; id <= N_CHANNELS; id++) {
        rec_channel(r, id);
        out_record(b, OP_CHANNEL, r);
    }
    group_len[1] = b->pos - group_start[1];

    group_start[2] = b->pos;
    r->len = 0;
    u64(r, b->total);
    u16(r, N_CHANNELS);      /* schemas */
    u32(r, N_CHANNELS);      /* channels */
    u32(r, 0);               /* attachments */
    u32(r, 0);               /* metadata */
    u32(r, b->n_chunks);
    u64(r, b->t_first);
    u64(r, b->t_last);
    u32(r, N_CHANNELS * (2 + 8));
    for (int c = 0; c < N_CHANNELS; c++) {
        u16(r, (unsigned)(c + 1));
        u64(r, b->count[c]);
    }
    out_record(b, OP_STATISTICS, r);
    group_len[2] = b->pos - group_start[2];

    group_start[3] = b->pos;
    for (size_t k = 0; k < b->n_chunks; k++) {
        const chunk_info_t *ci = &b->chunks[k];
        int used = 0;
        for (int c = 0; c < N_CHANNELS; c++)
            used += ci->mi_offset[c] != 0;
        r->len = 0;
        u64(r, ci->start);
        u64(r, ci->end);
        u64(r, ci->offset);
        u64(r, ci->length);
        u32(r, (uint64_t)used * (2 + 8));
        for (int c = 0; c < N_CHANNELS; c++) {
            if (ci->mi_offset[c] == 0)
                continue;
            u16(r, (unsigned)(c + 1));
            u64(r, ci->mi_offset[c]);
        }
        u64(r, ci->mi_length);
        str(r, "");
        u64(r, ci->size);
        u64(r, ci->size);
        out_record(b, OP_CHUNK_INDEX, r);
    }
    group_len[3] = b->pos - group_start[3];

    uint64_t offsets_start = b->pos;
    for (int g = 0; g < 4; g++) {
        if (group_len[g] == 0)
            continue;
        r->len = 0;
        u8(r, (unsigned)group_op[g]);
        u64(r, group_start[g]);
        u64(r, group_len[g]);
        out_record(b, OP_SUMMARY_OFFSET, r);
    }
    r->len = 0;
    u64(r, summary_start);
    u64(r, offsets_start);
    u32(r, 0); /* summary CRC: not computed */
    out_record(b, OP_FOOTER, r);
    out_bytes(b, MCAP_MAGIC, sizeof(MCAP_MAGIC));
}

static int write_metadata(const sim_rosbag_t *b)
{
    char path[700];
    snprintf(path, sizeof(path), "%s/metadata.yaml", b->dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    unsigned long long start = b->total ? b->t_first : 0;
    unsigned long long dur = b->total ? b->t_last - b->t_first : 0;
    fprintf(f,
            "rosbag2_bagfile_information:\n"
            "  version: 5\n"
            "  storage_identifier: mcap\n"
            "  duration:\n    nanoseconds: %llu\n"
            "  starting_time:\n    nanoseconds_since_epoch: %llu\n"
            "  message_count: %llu\n"
            "  topics_with_message_count:\n",
            dur, start, (unsigned long long)b->total);
    for (int c = 0; c < N_CHANNELS; c++) {
        fprintf(f, "    - topic_metadata:\n"
                   "        name: %s\n"
                   "        type: %s\n"
                   "        serialization_format: cdr\n"
                   "        offered_qos_profiles: \"",
                k_channels[c].topic, k_channels[c].type);
        for (const char *p = QOS_YAML; *p; p++) {
            if (*p == '\n')
                fputs("\\n", f);
            else
                fputc(*p, f);
        }
        fprintf(f, "\"\n      message_count: %llu\n",
                (unsigned long long)b->count[c]);
    }
    fprintf(f,
            "  compression_format: \"\"\n"
            "  compression_mode: \"\"\n"
            "  relative_file_paths:\n    - %s\n"
            "  files:\n"
            "    - path: %s\n"
            "      starting_time:\n        nanoseconds_since_epoch: %llu\n"
            "      duration:\n        nanoseconds: %llu\n"
            "      message_count: %llu\n",
            b->file, b->file, start, dur, (unsigned long long)b->total);
    return fclose(f) == 0 ? 0 : -1;
}

int sim_rosbag_close(sim_rosbag_t *b, char *err, unsigned err_len)
{
    if (!b)
        return 0;
    finish_mcap(b);
    int bad = b->failed || b->rec.failed;
    if (fclose(b->f) != 0)
        bad = 1;
    if (!bad && write_metadata(b) != 0)
        bad = 1;
    if (bad)
        snprintf(err, err_len, "--rosbag: cannot write the bag in '%s'",
                 b->dir);
    free(b->rec.p);
    free(b->chunk.p);
    free(b->msg.p);
    for (int c = 0; c < N_CHANNELS; c++)
        free(b->index[c].p);
    free(b->chunks);
    free(b);
    return bad ? -1 : 0;
}
