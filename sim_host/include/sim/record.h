/*
 * record.h - binary recording of a run: every frame's matches and the
 * command that answered it.  Format in docs/RECORDING.md: the magic
 * "SPVSREC1", then per frame
 *   uint32 seq, float64 t, uint16 n,
 *   n x { uint16 feature, float32 x_tgt, y_tgt, x_cur, y_cur },
 *   float32 v, float32 w, int16 status, uint8 step,
 * all little-endian, no padding.
 */
#ifndef SIM_RECORD_H
#define SIM_RECORD_H

#include <stdint.h>
#include <stdio.h>

#include "spvs/spvs.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SIM_RECORD_MAGIC "SPVSREC1"
#define SIM_RECORD_MAX_MATCHES 65535

/* Append the magic to an open file.  Returns 0 or -1 on a write error. */
int sim_record_write_header(FILE *f);

/* Append one frame.  v in m/s, w in rad/s.  Returns 0 or -1 on a write
 * error. */
int sim_record_write_frame(FILE *f, uint32_t seq, double t_s,
                           const spvs_match_t *m, uint16_t n, double v_mps,
                           double w_radps, int16_t status, uint8_t step);

/* One frame read back. */
typedef struct {
    uint32_t seq;
    double t_s;
    uint16_t n;        /* matches in the file for this frame               */
    uint16_t n_kept;   /* of which stored in m (at most the caller's cap)  */
    float v_mps;
    float w_radps;
    int16_t status;
    uint8_t step;
} sim_record_frame_t;

/* Check the magic.  Returns 0, or -1 when the file is not a recording. */
int sim_record_read_header(FILE *f);

/* Read the next frame; up to cap matches go to m (the rest are skipped).
 * Returns 1 for a frame, 0 at a clean end of file, -1 when the file ends
 * inside a frame. */
int sim_record_read_frame(FILE *f, sim_record_frame_t *fr, spvs_match_t *m,
                          uint16_t cap);

#ifdef __cplusplus
}
#endif

#endif /* SIM_RECORD_H */
