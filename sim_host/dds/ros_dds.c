/*
 * ros_dds.c - see ros_dds.h.
 */
#define _POSIX_C_SOURCE 200809L

#include "ros_dds.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

_Static_assert(sizeof(((spvs_dds_matches_t *)0)->x_tgt) ==
                   sizeof(((spvs_matches_t *)0)->x_tgt),
               "spvs_msgs/msg/Matches.msg and lcm_types/matches_t.lcm must "
               "have the same capacity");
_Static_assert(sizeof(((spvs_dds_state_t *)0)->h) ==
                   sizeof(((spvs_state_t *)0)->H),
               "State.h holds the 9 entries of H");

int spvs_dds_domain(uint32_t *domain, char *err, unsigned err_len)
{
    const char *s = getenv("ROS_DOMAIN_ID");
    *domain = 0;
    if (!s || !*s)
        return 0;
    char *end = NULL;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno != 0 || end == s || *end != '\0' || v < 0 ||
        v > SPVS_DDS_DOMAIN_MAX) {
        snprintf(err, err_len, "ROS_DOMAIN_ID '%s' is not an integer 0..%d",
                 s, SPVS_DDS_DOMAIN_MAX);
        return -1;
    }
    *domain = (uint32_t)v;
    return 0;
}

dds_entity_t spvs_dds_participant(uint32_t domain, char *err,
                                  unsigned err_len)
{
    dds_entity_t pp = dds_create_participant((dds_domainid_t)domain, NULL,
                                             NULL);
    if (pp < 0)
        snprintf(err, err_len,
                 "cannot join DDS domain %u: %s (check CYCLONEDDS_URI)",
                 (unsigned)domain, dds_strretcode(pp));
    return pp;
}

dds_qos_t *spvs_dds_qos(void)
{
    dds_qos_t *q = dds_create_qos();
    if (!q)
        return NULL;
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, SPVS_DDS_DEPTH);
    return q;
}

void spvs_dds_matches_from_lcm(spvs_dds_matches_t *out,
                               const spvs_matches_t *in)
{
    out->seq = in->seq;
    out->utime = in->utime;
    out->run_id = in->run_id;
    out->count = in->count;
    memcpy(out->feature, in->feature, sizeof(out->feature));
    memcpy(out->x_tgt, in->x_tgt, sizeof(out->x_tgt));
    memcpy(out->y_tgt, in->y_tgt, sizeof(out->y_tgt));
    memcpy(out->x_cur, in->x_cur, sizeof(out->x_cur));
    memcpy(out->y_cur, in->y_cur, sizeof(out->y_cur));
}

void spvs_dds_matches_to_lcm(spvs_matches_t *out,
                             const spvs_dds_matches_t *in)
{
    out->seq = in->seq;
    out->utime = in->utime;
    out->run_id = in->run_id;
    out->count = in->count;
    memcpy(out->feature, in->feature, sizeof(out->feature));
    memcpy(out->x_tgt, in->x_tgt, sizeof(out->x_tgt));
    memcpy(out->y_tgt, in->y_tgt, sizeof(out->y_tgt));
    memcpy(out->x_cur, in->x_cur, sizeof(out->x_cur));
    memcpy(out->y_cur, in->y_cur, sizeof(out->y_cur));
}

void spvs_dds_twist_from_cmd(spvs_dds_twist_t *out, const spvs_cmd_t *cmd)
{
    memset(out, 0, sizeof(*out));
    out->linear.x = cmd->v;
    out->angular.z = cmd->w;
}

void spvs_dds_state_from_lcm(spvs_dds_state_t *out, const spvs_state_t *st,
                             const spvs_cmd_t *cmd)
{
    memset(out, 0, sizeof(*out));
    if (st) {
        memcpy(out->h, st->H, sizeof(out->h));
        out->h_valid = st->h_valid != 0;
        out->n_matches = st->n_matches;
        out->n_inliers = st->n_inliers;
        out->n_offplane = st->n_offplane;
        out->e_x = st->e_x;
        out->e_valid = st->e_valid != 0;
        out->parallax = st->parallax;
        out->eq11 = st->eq11 != 0;
        out->arrival_stat = st->arrival_stat;
        out->arrival_threshold = st->arrival_threshold;
        out->arrival_lateral_px = st->arrival_lateral_px;
        out->arrival_lateral_sd_px = st->arrival_lateral_sd_px;
        out->arrival_depth_px = st->arrival_depth_px;
        out->arrival_depth_sd_px = st->arrival_depth_sd_px;
        out->arrival_h13_px = st->arrival_h13_px;
        out->arrival_h13_sd_px = st->arrival_h13_sd_px;
        out->arrival_corner_px = st->arrival_corner_px;
        out->arrival_parallax_px = st->arrival_parallax_px;
        out->arrival_frames = st->arrival_frames;
        out->arrival_reentries = (uint8_t)st->arrival_reentries;
        out->arrival_next = (uint8_t)st->arrival_next;
        out->arriving = st->arriving != 0;
    }
    /* The command decides what the robot does; the state repeats it. */
    out->seq = cmd->seq;
    out->utime = cmd->utime;
    out->v = cmd->v;
    out->w = cmd->w;
    out->step = (uint8_t)cmd->step;
    out->status = cmd->status;
}

void spvs_dds_state_to_lcm(spvs_state_t *st, spvs_cmd_t *cmd,
                           const spvs_dds_state_t *in)
{
    memset(st, 0, sizeof(*st));
    st->seq = in->seq;
    st->utime = in->utime;
    memcpy(st->H, in->h, sizeof(st->H));
    st->h_valid = in->h_valid ? 1 : 0;
    st->n_matches = in->n_matches;
    st->n_inliers = in->n_inliers;
    st->n_offplane = in->n_offplane;
    st->e_x = in->e_x;
    st->e_valid = in->e_valid ? 1 : 0;
    st->parallax = in->parallax;
    st->eq11 = in->eq11 ? 1 : 0;
    st->v = in->v;
    st->w = in->w;
    st->step = (int8_t)in->step;
    st->status = in->status;
    st->arrival_stat = in->arrival_stat;
    st->arrival_threshold = in->arrival_threshold;
    st->arrival_lateral_px = in->arrival_lateral_px;
    st->arrival_lateral_sd_px = in->arrival_lateral_sd_px;
    st->arrival_depth_px = in->arrival_depth_px;
    st->arrival_depth_sd_px = in->arrival_depth_sd_px;
    st->arrival_h13_px = in->arrival_h13_px;
    st->arrival_h13_sd_px = in->arrival_h13_sd_px;
    st->arrival_corner_px = in->arrival_corner_px;
    st->arrival_parallax_px = in->arrival_parallax_px;
    st->arrival_frames = in->arrival_frames;
    st->arrival_reentries = (int8_t)in->arrival_reentries;
    st->arrival_next = (int8_t)in->arrival_next;
    st->arriving = in->arriving ? 1 : 0;

    memset(cmd, 0, sizeof(*cmd));
    cmd->seq = in->seq;
    cmd->utime = in->utime;
    cmd->v = in->v;
    cmd->w = in->w;
    cmd->step = (int8_t)in->step;
    cmd->status = in->status;
}
