/*
 * wire.c - core structs <-> LCM messages; see wire.h.
 */
#include "wire.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The .lcm files cannot name SPVS_MAX_MATCHES (lcm-gen 1.3.1 wants a literal
 * array size), so the two are tied together here instead. */
_Static_assert(SPVS_WIRE_MAX_MATCHES == SPVS_MAX_MATCHES,
               "lcm_types/matches_t.lcm array size must equal SPVS_MAX_MATCHES");
_Static_assert(sizeof(((spvs_matches_t *)0)->feature) / sizeof(int32_t) ==
                   SPVS_MAX_MATCHES,
               "matches_t.feature capacity must equal SPVS_MAX_MATCHES");

int spvs_wire_matches_from_core(spvs_matches_t *msg, int64_t seq,
                                int64_t utime, int64_t run_id,
                                const spvs_match_t *m, uint16_t n)
{
    if (n > SPVS_MAX_MATCHES)
        return SPVS_E_CAPACITY;
    memset(msg, 0, sizeof(*msg));
    msg->seq = seq;
    msg->utime = utime;
    msg->run_id = run_id;
    msg->count = (int16_t)n;
    for (uint16_t i = 0; i < n; i++) {
        msg->feature[i] = m[i].feature;
        msg->x_tgt[i] = (float)m[i].x_tgt;
        msg->y_tgt[i] = (float)m[i].y_tgt;
        msg->x_cur[i] = (float)m[i].x_cur;
        msg->y_cur[i] = (float)m[i].y_cur;
    }
    return SPVS_OK;
}

int spvs_wire_matches_check(const spvs_matches_t *msg, char *err,
                            unsigned err_len)
{
    if (msg->count < 0 || msg->count > SPVS_WIRE_MAX_MATCHES) {
        if (err_len)
            snprintf(err, err_len, "frame %lld: count %d outside 0..%d",
                     (long long)msg->seq, (int)msg->count,
                     SPVS_WIRE_MAX_MATCHES);
        return SPVS_E_CAPACITY;
    }
    for (int i = 0; i < msg->count; i++) {
        if (!isfinite(msg->x_tgt[i]) || !isfinite(msg->y_tgt[i]) ||
            !isfinite(msg->x_cur[i]) || !isfinite(msg->y_cur[i])) {
            if (err_len)
                snprintf(err, err_len,
                         "frame %lld: non-finite coordinate in match %d",
                         (long long)msg->seq, i);
            return SPVS_E_NONFINITE;
        }
        if (msg->feature[i] < 0 || msg->feature[i] >= SPVS_MAX_FEATURES) {
            if (err_len)
                snprintf(err, err_len,
                         "frame %lld: feature index %ld in match %d outside "
                         "0..%d",
                         (long long)msg->seq, (long)msg->feature[i], i,
                         SPVS_MAX_FEATURES - 1);
            return SPVS_E_RANGE;
        }
    }
    return SPVS_OK;
}

uint16_t spvs_wire_matches_to_core(const spvs_matches_t *msg, spvs_match_t *m)
{
    /* Callers checked the message; clamp anyway so a skipped check can never
     * read or write past either array. */
    int n = msg->count;
    if (n < 0)
        n = 0;
    if (n > SPVS_MAX_MATCHES)
        n = SPVS_MAX_MATCHES;
    for (int i = 0; i < n; i++) {
        m[i].x_tgt = (spvs_real)msg->x_tgt[i];
        m[i].y_tgt = (spvs_real)msg->y_tgt[i];
        m[i].x_cur = (spvs_real)msg->x_cur[i];
        m[i].y_cur = (spvs_real)msg->y_cur[i];
        m[i].feature = (uint16_t)msg->feature[i];
    }
    return (uint16_t)n;
}

void spvs_wire_cmd_from_output(spvs_cmd_t *cmd, int64_t seq, int64_t utime,
                               const spvs_output_t *out)
{
    memset(cmd, 0, sizeof(*cmd));
    cmd->seq = seq;
    cmd->utime = utime;
    cmd->v = (double)out->v;
    cmd->w = (double)out->w;
    cmd->step = (int8_t)out->step;
    cmd->status = out->status;
}

void spvs_wire_state_from_output(spvs_state_t *st, int64_t seq, int64_t utime,
                                 const spvs_output_t *out)
{
    memset(st, 0, sizeof(*st));
    st->seq = seq;
    st->utime = utime;
    for (int i = 0; i < 9; i++)
        st->H[i] = (double)out->H[i];
    st->h_valid = (int8_t)out->h_valid;
    st->n_matches = (int16_t)out->n_matches;
    st->n_inliers = (int16_t)out->n_inliers;
    st->n_offplane = (int16_t)out->n_offplane;
    st->e_x = (double)out->e_x_px;
    st->e_valid = (int8_t)out->e_valid;
    st->parallax = (double)out->parallax_px;
    st->eq11 = (int8_t)out->eq11;
    st->v = (double)out->v;
    st->w = (double)out->w;
    st->step = (int8_t)out->step;
    st->status = out->status;
    st->arrival_stat = (double)out->arrival_stat;
    st->arrival_threshold = (double)out->arrival_threshold;
    st->arrival_lateral_px = (double)out->arrival_lateral_px;
    st->arrival_lateral_sd_px = (double)out->arrival_lateral_sd_px;
    st->arrival_depth_px = (double)out->arrival_depth_px;
    st->arrival_depth_sd_px = (double)out->arrival_depth_sd_px;
    st->arrival_h13_px = (double)out->arrival_h13_px;
    st->arrival_h13_sd_px = (double)out->arrival_h13_sd_px;
    st->arrival_corner_px = (double)out->arrival_corner_px;
    st->arrival_parallax_px = (double)out->arrival_parallax_px;
    st->arrival_frames = (int16_t)out->arrival_frames;
    st->arrival_reentries = (int8_t)out->arrival_reentries;
    st->arrival_next = (int8_t)out->arrival_next;
    st->arriving = (int8_t)out->arriving;
}

void spvs_wire_cmd_stop(spvs_cmd_t *cmd, int64_t seq, int64_t utime,
                        int status, int step)
{
    memset(cmd, 0, sizeof(*cmd));
    cmd->seq = seq;
    cmd->utime = utime;
    cmd->v = 0.0;
    cmd->w = 0.0;
    cmd->step = (int8_t)step;
    cmd->status = (int16_t)status;
}

void spvs_wire_output_from_msgs(spvs_output_t *out, const spvs_cmd_t *cmd,
                                const spvs_state_t *st)
{
    memset(out, 0, sizeof(*out));
    out->v = (spvs_real)cmd->v;
    out->w = (spvs_real)cmd->w;
    out->step = (uint8_t)cmd->step;
    out->status = cmd->status;
    if (!st)
        return;
    for (int i = 0; i < 9; i++)
        out->H[i] = (spvs_real)st->H[i];
    out->h_valid = (uint8_t)st->h_valid;
    out->n_matches = (uint16_t)st->n_matches;
    out->n_inliers = (uint16_t)st->n_inliers;
    out->n_offplane = (uint16_t)st->n_offplane;
    out->e_x_px = (spvs_real)st->e_x;
    out->e_valid = (uint8_t)st->e_valid;
    out->parallax_px = (spvs_real)st->parallax;
    out->eq11 = (uint8_t)st->eq11;
    out->arrival_stat = (spvs_real)st->arrival_stat;
    out->arrival_threshold = (spvs_real)st->arrival_threshold;
    out->arrival_lateral_px = (spvs_real)st->arrival_lateral_px;
    out->arrival_lateral_sd_px = (spvs_real)st->arrival_lateral_sd_px;
    out->arrival_depth_px = (spvs_real)st->arrival_depth_px;
    out->arrival_depth_sd_px = (spvs_real)st->arrival_depth_sd_px;
    out->arrival_h13_px = (spvs_real)st->arrival_h13_px;
    out->arrival_h13_sd_px = (spvs_real)st->arrival_h13_sd_px;
    out->arrival_corner_px = (spvs_real)st->arrival_corner_px;
    out->arrival_parallax_px = (spvs_real)st->arrival_parallax_px;
    out->arrival_frames = (uint16_t)st->arrival_frames;
    out->arrival_reentries = (uint8_t)st->arrival_reentries;
    out->arrival_next = (uint8_t)st->arrival_next;
    out->arriving = (uint8_t)st->arriving;
}

int spvs_wire_publish_matches(lcm_t *lcm, const spvs_matches_t *msg)
{
    uint8_t buf[SPVS_WIRE_MATCHES_BYTES];
    int len = spvs_matches_t_encode(buf, 0, (int)sizeof(buf), msg);
    if (len < 0)
        return -1;
    return lcm_publish(lcm, SPVS_CH_MATCHES, buf, (unsigned)len) < 0 ? -1 : 0;
}

int spvs_wire_publish_cmd(lcm_t *lcm, const spvs_cmd_t *cmd)
{
    uint8_t buf[128];
    int len = spvs_cmd_t_encode(buf, 0, (int)sizeof(buf), cmd);
    if (len < 0)
        return -1;
    return lcm_publish(lcm, SPVS_CH_CMD, buf, (unsigned)len) < 0 ? -1 : 0;
}

int spvs_wire_publish_state(lcm_t *lcm, const spvs_state_t *st)
{
    uint8_t buf[256];
    int len = spvs_state_t_encode(buf, 0, (int)sizeof(buf), st);
    if (len < 0)
        return -1;
    return lcm_publish(lcm, SPVS_CH_STATE, buf, (unsigned)len) < 0 ? -1 : 0;
}

int spvs_wire_frame_from_sim(spvs_matches_t *msg, uint32_t seq, double t_s,
                             int64_t run_id, const spvs_match_t *m, uint16_t n,
                             const char *who, char *err, unsigned err_len)
{
    if (!isfinite(t_s) || t_s < 0.0 || t_s > 9.0e12) {
        snprintf(err, err_len, "%s: frame %u has a bad time %g s", who,
                 (unsigned)seq, t_s);
        return -1;
    }
    int64_t utime = (int64_t)llround(t_s * 1e6);
    if (spvs_wire_matches_from_core(msg, seq, utime, run_id, m, n) != SPVS_OK) {
        snprintf(err, err_len, "%s: frame %u has %u matches, more than the "
                 "message capacity %d", who, (unsigned)seq, (unsigned)n,
                 SPVS_MAX_MATCHES);
        return -1;
    }
    return 0;
}
