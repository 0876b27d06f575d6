/*
 * ros_dds.h - spvs on DDS with ROS 2's names (docs/ROS2.md), shared by
 * spvs-node --dds and spvs-sim --transport dds: topic names, the QoS, the
 * domain from ROS_DOMAIN_ID, and the conversions between the DDS samples
 * (types made by Cyclone DDS's idlc from spvs_msgs/) and the LCM messages
 * that the node's logic and the lock-step exchange already speak.
 *
 * ROS 2 maps a topic /x to the DDS topic rt/x and a type pkg/msg/T to the
 * IDL struct pkg::msg::dds_::T_; samples are CDR (XCDR1, little endian).
 */
#ifndef SPVS_ROS_DDS_H
#define SPVS_ROS_DDS_H

#include <stdint.h>

#include <dds/dds.h>

#include "geometry_msgs/msg/Twist.h"
#include "lcmtypes/spvs_cmd_t.h"
#include "lcmtypes/spvs_matches_t.h"
#include "lcmtypes/spvs_state_t.h"
#include "spvs_msgs/msg/Matches.h"
#include "spvs_msgs/msg/State.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef spvs_msgs_msg_dds__Matches_ spvs_dds_matches_t;
typedef spvs_msgs_msg_dds__State_ spvs_dds_state_t;
typedef geometry_msgs_msg_dds__Twist_ spvs_dds_twist_t;

/* DDS topics of /spvs/matches, /cmd_vel and /spvs/state. */
#define SPVS_DDS_TOPIC_MATCHES "rt/spvs/matches"
#define SPVS_DDS_TOPIC_CMD_VEL "rt/cmd_vel"
#define SPVS_DDS_TOPIC_STATE "rt/spvs/state"

/* Every reader and writer: reliable, volatile, keep last this many samples
 * (ROS 2's default profile, rmw_qos_profile_default). */
#define SPVS_DDS_DEPTH 10

/* Largest domain id accepted from ROS_DOMAIN_ID (Cyclone DDS's default port
 * mapping reaches 232; ROS 2 advises 0..101). */
#define SPVS_DDS_DOMAIN_MAX 232

/* The domain: ROS_DOMAIN_ID when set and not empty, else 0.  Returns 0, or
 * -1 with a one-line reason in err when it is not an integer 0..232. */
int spvs_dds_domain(uint32_t *domain, char *err, unsigned err_len);

/* A participant on domain (CYCLONEDDS_URI configures it, as Cyclone DDS
 * always reads it).  Returns the entity (> 0) or a negative DDS return code
 * with a one-line reason in err. */
dds_entity_t spvs_dds_participant(uint32_t domain, char *err,
                                  unsigned err_len);

/* The QoS above (dds_delete_qos it after use); NULL when out of memory. */
dds_qos_t *spvs_dds_qos(void);

/* Matches sample <-> LCM matches message: the same fields and units.  The
 * count is copied as it is, so a bad count reaches the node's check. */
void spvs_dds_matches_from_lcm(spvs_dds_matches_t *out,
                               const spvs_matches_t *in);
void spvs_dds_matches_to_lcm(spvs_matches_t *out,
                             const spvs_dds_matches_t *in);

/* The Twist of a command: linear.x = v (m/s, forward), angular.z = w
 * (rad/s).  w is phidot of the kinematics (docs/SIM.md, eq. 7), and a
 * positive phidot turns the heading (-sin phi, cos phi) from +Z towards -X,
 * the robot's left: REP 103's positive yaw, so no sign changes. */
void spvs_dds_twist_from_cmd(spvs_dds_twist_t *out, const spvs_cmd_t *cmd);

/* State sample of a command and its telemetry (st NULL: none, as for a
 * rejected frame or a watchdog stop; then only seq, utime, v, w, step and
 * status are set). */
void spvs_dds_state_from_lcm(spvs_dds_state_t *out, const spvs_state_t *st,
                             const spvs_cmd_t *cmd);

/* Back: the telemetry and the command that a State sample carries. */
void spvs_dds_state_to_lcm(spvs_state_t *st, spvs_cmd_t *cmd,
                           const spvs_dds_state_t *in);

#ifdef __cplusplus
}
#endif

#endif /* SPVS_ROS_DDS_H */
