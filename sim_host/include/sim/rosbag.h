/*
 * rosbag.h - a rosbag2 folder of a simulator run (spvs-sim --rosbag DIR,
 * docs/ROS2.md): DIR/metadata.yaml and DIR/DIR_0.mcap, MCAP storage with
 * ROS 2 CDR messages and their definitions embedded (schema encoding
 * ros2msg), so ros2 bag, Foxglove and rosbags read it without spvs.
 *
 * Each frame gives three messages, all stamped with the frame time
 * (nanoseconds from the run's start, log and publish time alike):
 *   /spvs/matches  spvs_msgs/msg/Matches   the frame the controller got
 *   /cmd_vel       geometry_msgs/msg/Twist linear.x = v, angular.z = w
 *   /spvs/state    spvs_msgs/msg/State     the command and the telemetry
 * The fields are those the DDS topics carry (spvs_msgs/msg/Matches.msg, State.msg), filled
 * by the node's conversions (sim_host/node/wire.h).  MCAP: uncompressed
 * chunks of about 1 MiB with message indexes, and a summary (schemas,
 * channels, statistics, chunk indexes) with its offsets.
 */
#ifndef SIM_ROSBAG_H
#define SIM_ROSBAG_H

#include <stdint.h>

#include "spvs/spvs.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sim_rosbag sim_rosbag_t;

/* Create the folder dir (it must not exist yet, as for ros2 bag record)
 * and start its MCAP file.  Returns the writer, or NULL with a one-line
 * reason in err. */
sim_rosbag_t *sim_rosbag_open(const char *dir, char *err, unsigned err_len);

/* One answered frame: seq, time t_s (seconds, >= 0), its n matches, and the
 * controller's output.  Returns 0, or -1 with a reason in err. */
int sim_rosbag_frame(sim_rosbag_t *b, uint32_t seq, double t_s,
                     const spvs_match_t *m, uint16_t n,
                     const spvs_output_t *out, char *err, unsigned err_len);

/* Finish the MCAP file (summary, footer), write metadata.yaml and free b.
 * Returns 0, or -1 with a reason in err (b is freed in every case). */
int sim_rosbag_close(sim_rosbag_t *b, char *err, unsigned err_len);

#ifdef __cplusplus
}
#endif

#endif /* SIM_ROSBAG_H */
