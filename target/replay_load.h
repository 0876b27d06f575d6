/*
 * replay_load.h - one recorded frame of replay_frames.h as the core's
 * matches: the target point from the feature table, the current point from
 * the frame (shared by replay.c and replay_q.c).  Include replay_frames.h
 * first.
 */
#ifndef TARGET_REPLAY_LOAD_H
#define TARGET_REPLAY_LOAD_H

#include "fmt.h"
#include "spvs/spvs.h"

/* The frame's matches into m (at most SPVS_MAX_MATCHES: a longer frame the
 * host refused too, and the core refuses it again by its count). */
static inline void replay_load(const spvs_replay_frame_t *fr, spvs_match_t *m)
{
    uint16_t n = fr->n;
    if (n > SPVS_MAX_MATCHES) {
        n = SPVS_MAX_MATCHES;
    }
    for (uint16_t i = 0; i < n; ++i) {
        const spvs_replay_match_t *rm = &spvs_replay_matches[fr->first + i];
        m[i].feature = rm->feature;
        m[i].x_tgt = spvs_replay_tgt[rm->feature][0];
        m[i].y_tgt = spvs_replay_tgt[rm->feature][1];
        m[i].x_cur = rm->x_cur;
        m[i].y_cur = rm->y_cur;
    }
}

/* The start of a replay's failure line: the frame, and the status and step
 * against the host's; the caller adds its command figures and "\n". */
static inline void replay_fail_head(const spvs_replay_frame_t *fr, int st, uint8_t step)
{
    out_str("FAIL replay frame ");
    out_u32(fr->seq);
    out_str(": status ");
    out_int(st);
    out_str(" (host ");
    out_int(fr->status);
    out_str("), step ");
    out_u32(step);
    out_str(" (host ");
    out_u32(fr->step);
    out_str(")");
}

#endif /* TARGET_REPLAY_LOAD_H */
