/*
 * fuzz_node.c - libFuzzer target for the controller node's SPVS_MATCHES
 * path: raw bytes -> generated decoder (spvs_matches_t_decode) -> the node's
 * checks (spvs_wire_matches_check) -> the core -> SPVS_STATE and SPVS_CMD.
 * It calls spvs_node_on_bytes(), the function the node's LCM subscription
 * calls, on a node that publishes over LCM's in-process memq:// provider,
 * and reads back every command the node sends.
 *
 * One input is a sequence of up to MAX_MSGS messages to one fresh node, so
 * that duplicates, older frames and run changes are exercised.  Each
 * message is either raw bytes (the decoder's own robustness: wrong
 * fingerprints, short buffers, any field values) or a message built from
 * fields the input chooses and encoded with the generated encoder, then
 * optionally cut short or with one byte flipped (so that decoding succeeds
 * often enough for the checks and the core to be reached).
 *
 * Invariants (a violation aborts):
 *   - bytes that decode get exactly one SPVS_CMD, with their seq; bytes that
 *     do not decode get none and spvs_node_on_bytes() says SPVS_E_ARG;
 *   - every command is finite and within v_max, w_max, and every command
 *     with a non-zero status is a stop (v = w = 0);
 *   - a frame the checks reject (bad count, non-finite value, feature out of
 *     range) gets that status, and a frame older than the last gets
 *     SPVS_E_STALE.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lcm/lcm.h>

#include "fuzz_reader.h"
#include "node.h"

#define MAX_MSGS 6

/* What the SPVS_CMD subscription saw since the last reset. */
typedef struct {
    int n_cmd;
    spvs_cmd_t last;
    double v_max, w_max;
} cmd_log_t;

static void fail(const char *what, const spvs_cmd_t *c)
{
    if (c) {
        fprintf(stderr, "fuzz_node: invariant broken: %s (seq %lld, status "
                        "%d, v %g, w %g)\n",
                what, (long long)c->seq, c->status, c->v, c->w);
    } else {
        fprintf(stderr, "fuzz_node: invariant broken: %s\n", what);
    }
    abort();
}

static void on_cmd(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)channel;
    cmd_log_t *log = (cmd_log_t *)user;
    spvs_cmd_t c;
    if (spvs_cmd_t_decode(rbuf->data, 0, (int)rbuf->data_size, &c) < 0) {
        fail("the node published an undecodable SPVS_CMD", NULL);
    }
    if (!isfinite(c.v) || !isfinite(c.w) || fabs(c.v) > log->v_max ||
        fabs(c.w) > log->w_max) {
        fail("command not finite or past the limits", &c);
    }
    if (c.status != SPVS_OK && (c.v != 0.0 || c.w != 0.0)) {
        fail("an error status with a non-zero command", &c);
    }
    log->n_cmd++;
    log->last = c;
}

/* A message from fields the input picks.  Returns the encoded length. */
static int build_message(reader_t *r, uint8_t *buf, int cap, int64_t *seq,
                         int64_t *utime)
{
    static spvs_matches_t msg;
    memset(&msg, 0, sizeof(msg));
    /* Mostly increasing seq and time, sometimes repeated or backwards. */
    int8_t dseq = (int8_t)rd_u8(r);
    *seq += dseq;
    int8_t dt = (int8_t)rd_u8(r);
    *utime += (int64_t)dt * 10000;
    msg.seq = *seq;
    msg.utime = *utime;
    msg.run_id = rd_u8(r) % 3u;
    uint8_t cnt_code = rd_u8(r);
    if (cnt_code >= 0xF0u) {
        msg.count = (int16_t)(rd_u8(r) << 8 | rd_u8(r)); /* any int16 */
    } else {
        msg.count = (int16_t)(cnt_code % 120u);
    }
    const int n = msg.count < 0 ? 0 : msg.count > 256 ? 256 : msg.count;
    /* A consistent pure-rotation frame (H = identity + shift), damaged per
     * match by one code byte. */
    const float shift = (float)((int8_t)rd_u8(r));
    for (int i = 0; i < n; i++) {
        float x = (float)((i * 37) % 600 - 300);
        float y = (float)((i * 53) % 440 - 220);
        msg.feature[i] = i;
        msg.x_tgt[i] = x;
        msg.y_tgt[i] = y;
        msg.x_cur[i] = x + shift;
        msg.y_cur[i] = y;
        uint8_t code = rd_u8(r);
        switch (code) {
        case 1: msg.x_cur[i] = rd_float_bits(r); break;
        case 2: msg.y_tgt[i] = NAN; break;
        case 3: msg.x_tgt[i] = -INFINITY; break;
        case 4: msg.feature[i] = (int32_t)rd_u32(r); break;
        case 5: msg.y_cur[i] = 3.0e38f; break;
        default: break;
        }
    }
    return spvs_matches_t_encode(buf, 0, cap, &msg);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static lcm_t *lcm;
    static cmd_log_t log;
    static spvs_node_t node;
    static uint8_t buf[SPVS_WIRE_MATCHES_BYTES + 64];

    if (!lcm) {
        lcm = lcm_create("memq://");
        if (!lcm || !lcm_subscribe(lcm, SPVS_CH_CMD, on_cmd, &log)) {
            fail("cannot open memq:// LCM", NULL);
        }
    }
    reader_t r = {data, size, 0};
    const uint8_t head = rd_u8(&r);

    spvs_params_t p;
    spvs_params_default(&p, (spvs_method_t)(1 + head % 3u));
    log.v_max = (double)p.ctl.v_max * (1.0 + 1e-6);
    log.w_max = (double)p.ctl.w_max * (1.0 + 1e-6);
    node.log_level = 0;
    node.progress_every = 0;
    node.progress = stderr;
    if (spvs_node_init(&node, lcm, &p, 0.5, 0.0) != SPVS_OK) {
        fail("node rejected default parameters", NULL);
    }

    const int msgs = 1 + (head >> 2) % MAX_MSGS;
    int64_t seq = 0, utime = 0, last_seq = 0;
    int has_last = 0;
    for (int k = 0; k < msgs && r.at < r.n; k++) {
        const uint8_t mode = rd_u8(&r);
        const uint8_t *bytes;
        int len;
        if (mode & 1u) {
            /* Raw: the rest of this message's bytes, length from the input. */
            size_t want = (size_t)(rd_u8(&r) << 8 | rd_u8(&r));
            size_t left = r.n - (r.at < r.n ? r.at : r.n);
            len = (int)(want < left ? want : left);
            bytes = r.p + (r.at < r.n ? r.at : r.n);
            r.at += (size_t)len;
        } else {
            len = build_message(&r, buf, (int)sizeof(buf), &seq, &utime);
            if (len < 0) {
                fail("the generated encoder failed on a valid message", NULL);
            }
            if (mode & 2u) {
                len -= rd_u8(&r) % 16; /* cut short */
            }
            if (mode & 4u) {
                unsigned at = (unsigned)(rd_u8(&r) << 8 | rd_u8(&r)) % (unsigned)len;
                buf[at] ^= rd_u8(&r);
            }
            bytes = buf;
        }

        /* What the node will see, decoded independently. */
        static spvs_matches_t ref;
        const int decodes = spvs_matches_t_decode(bytes, 0, len, &ref) >= 0;
        const int new_run = decodes && (!node.has_run || ref.run_id != node.run_id);

        log.n_cmd = 0;
        int st = spvs_node_on_bytes(&node, bytes, len, 1.0 + 0.1 * k);
        while (lcm_handle_timeout(lcm, 0) > 0) {
        }

        if (!decodes) {
            if (st != SPVS_E_ARG || log.n_cmd != 0) {
                fail("undecodable bytes were answered", NULL);
            }
            continue;
        }
        if (log.n_cmd != 1 || log.last.seq != ref.seq) {
            fail("a decodable frame did not get exactly one answer", &log.last);
        }
        if (log.last.status != st) {
            fail("returned status differs from the published one", &log.last);
        }
        if (new_run) {
            has_last = 0;
        }
        char err[8];
        int check = spvs_wire_matches_check(&ref, err, 0);
        if (check != SPVS_OK) {
            if (st != check) {
                fail("a rejected frame got another status", &log.last);
            }
            continue;
        }
        if (has_last && ref.seq < last_seq && st != SPVS_E_STALE) {
            fail("an older frame was not answered as stale", &log.last);
        }
        if (!has_last || ref.seq > last_seq) {
            has_last = 1;
            last_seq = ref.seq;
        }
    }
    spvs_node_close(&node);
    while (lcm_handle_timeout(lcm, 0) > 0) {
    }
    return 0;
}
