#!/usr/bin/env python3
"""lcm2rosbag.py - an LCM log of spvs (lcm-logger's, e.g. the demo's
out/demo.lcmlog) as a rosbag2 folder with MCAP storage (docs/ROS2.md).

  lcm2rosbag.py [--lcm-types DIR] LOG OUT_DIR

The topics are those spvs-node --dds publishes, from the same messages:
  SPVS_MATCHES -> /spvs/matches  spvs_msgs/msg/Matches (the same fields)
  SPVS_CMD     -> /cmd_vel       geometry_msgs/msg/Twist (linear.x = v,
                                 angular.z = w, the rest zero), every
                                 command: answers and watchdog stops
               -> /spvs/state    spvs_msgs/msg/State: the command with the
                                 SPVS_STATE of the same seq logged before it,
                                 or the command alone (a rejected frame, a
                                 stop: seq -1)
Each message is stamped with its log event's time (microseconds since the
epoch, as lcm-logger writes it, in nanoseconds).  The message definitions
are spvs_msgs/ (Twist and Vector3 from spvs_msgs/external), embedded in the
bag.  Needs the venv's lcm and rosbags (scripts/setup_venv.sh).  --lcm-types:
the build's lcm_types/python (default: generated with lcm-gen).
Exit status: 0 done, 1 unreadable log or unwritable bag, 2 bad arguments.
"""
import argparse
import os
import sys
from pathlib import Path

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "spvs_msgs"))
sys.path.insert(0, os.path.join(ROOT, "sim_host", "zenoh"))

import lcm  # noqa: E402
from rosbags.interfaces import (Qos, QosDurability, QosHistory,  # noqa: E402
                                QosLiveliness, QosReliability, QosTime)
from rosbags.rosbag2 import StoragePlugin, Writer  # noqa: E402
from rosbags.typesys import Stores, get_typestore, get_types_from_msg  # noqa: E402

import msg2idl  # noqa: E402
from spvs_zenoh_common import load_lcm_types  # noqa: E402

MSGS = {
    "spvs_msgs/msg/Matches": "spvs_msgs/msg/Matches.msg",
    "spvs_msgs/msg/State": "spvs_msgs/msg/State.msg",
    "geometry_msgs/msg/Vector3": "spvs_msgs/external/geometry_msgs/msg/Vector3.msg",
    "geometry_msgs/msg/Twist": "spvs_msgs/external/geometry_msgs/msg/Twist.msg",
}
# What spvs-node --dds offers (docs/ROS2.md): reliable, volatile, keep last 10.
FOREVER = QosTime(sec=2147483647, nsec=4294967295)
QOS = [Qos(history=QosHistory.KEEP_LAST, depth=10,
           reliability=QosReliability.RELIABLE, durability=QosDurability.VOLATILE,
           deadline=FOREVER, lifespan=FOREVER, liveliness=QosLiveliness.AUTOMATIC,
           liveliness_lease_duration=FOREVER, avoid_ros_namespace_conventions=False)]


def typestore():
    store = get_typestore(Stores.EMPTY)
    types = {}
    for name, rel in MSGS.items():
        path = os.path.join(ROOT, rel)
        msg2idl.parse_msg(path)  # only the fields spvs_msgs allows
        types.update(get_types_from_msg(open(path, encoding="utf-8").read(), name))
    store.register(types)
    return store


def convert(log_path, out_dir, spvs):
    store = typestore()
    T = {name: store.types[name] for name in MSGS}
    V3 = T["geometry_msgs/msg/Vector3"]
    import numpy as np

    counts = {"/spvs/matches": 0, "/cmd_vel": 0, "/spvs/state": 0}
    pending = None  # the last SPVS_STATE, waiting for its SPVS_CMD
    log = lcm.EventLog(log_path, "r")
    with Writer(Path(out_dir), version=8, storage_plugin=StoragePlugin.MCAP) as w:
        conn = {
            "/spvs/matches": w.add_connection("/spvs/matches", "spvs_msgs/msg/Matches",
                                              typestore=store, offered_qos_profiles=QOS),
            "/cmd_vel": w.add_connection("/cmd_vel", "geometry_msgs/msg/Twist",
                                         typestore=store, offered_qos_profiles=QOS),
            "/spvs/state": w.add_connection("/spvs/state", "spvs_msgs/msg/State",
                                            typestore=store, offered_qos_profiles=QOS),
        }

        def put(topic, msg, t_ns):
            w.write(conn[topic], t_ns, store.serialize_cdr(msg, msg.__msgtype__))
            counts[topic] += 1

        for ev in log:
            t_ns = ev.timestamp * 1000
            if ev.channel == "SPVS_MATCHES":
                m = spvs.matches_t.decode(ev.data)
                put("/spvs/matches", T["spvs_msgs/msg/Matches"](
                    seq=m.seq, utime=m.utime, run_id=m.run_id, count=m.count,
                    feature=np.array(m.feature, dtype=np.int32),
                    x_tgt=np.array(m.x_tgt, dtype=np.float32),
                    y_tgt=np.array(m.y_tgt, dtype=np.float32),
                    x_cur=np.array(m.x_cur, dtype=np.float32),
                    y_cur=np.array(m.y_cur, dtype=np.float32)), t_ns)
            elif ev.channel == "SPVS_STATE":
                pending = spvs.state_t.decode(ev.data)
            elif ev.channel == "SPVS_CMD":
                c = spvs.cmd_t.decode(ev.data)
                put("/cmd_vel", T["geometry_msgs/msg/Twist"](
                    linear=V3(x=c.v, y=0.0, z=0.0),
                    angular=V3(x=0.0, y=0.0, z=c.w)), t_ns)
                s = pending if pending is not None and pending.seq == c.seq else None
                pending = None
                z = 0.0
                put("/spvs/state", T["spvs_msgs/msg/State"](
                    seq=c.seq, utime=c.utime,
                    h=np.array(s.H if s else [0.0] * 9, dtype=np.float64),
                    h_valid=bool(s and s.h_valid),
                    n_matches=s.n_matches if s else 0,
                    n_inliers=s.n_inliers if s else 0,
                    n_offplane=s.n_offplane if s else 0,
                    e_x=s.e_x if s else z, e_valid=bool(s and s.e_valid),
                    parallax=s.parallax if s else z, eq11=bool(s and s.eq11),
                    v=c.v, w=c.w, step=c.step & 0xFF, status=c.status,
                    arrival_stat=s.arrival_stat if s else z,
                    arrival_threshold=s.arrival_threshold if s else z,
                    arrival_lateral_px=s.arrival_lateral_px if s else z,
                    arrival_lateral_sd_px=s.arrival_lateral_sd_px if s else z,
                    arrival_depth_px=s.arrival_depth_px if s else z,
                    arrival_depth_sd_px=s.arrival_depth_sd_px if s else z,
                    arrival_h13_px=s.arrival_h13_px if s else z,
                    arrival_h13_sd_px=s.arrival_h13_sd_px if s else z,
                    arrival_corner_px=s.arrival_corner_px if s else z,
                    arrival_parallax_px=s.arrival_parallax_px if s else z,
                    arrival_frames=s.arrival_frames if s else 0,
                    arrival_reentries=(s.arrival_reentries & 0xFF) if s else 0,
                    arrival_next=(s.arrival_next & 0xFF) if s else 0,
                    arriving=bool(s and s.arriving)), t_ns)
    log.close()
    return counts


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("log", help="LCM log (lcm-logger)")
    ap.add_argument("out", help="rosbag2 folder to create (must not exist)")
    ap.add_argument("--lcm-types", help="the build's lcm_types/python")
    a = ap.parse_args()
    if os.path.exists(a.out):
        print("lcm2rosbag.py: %s exists already (a rosbag2 folder is made new)"
              % a.out, file=sys.stderr)
        return 2
    if not os.path.isfile(a.log):
        print("lcm2rosbag.py: no LCM log '%s'" % a.log, file=sys.stderr)
        return 1
    try:
        spvs = load_lcm_types(a.lcm_types)
        counts = convert(a.log, a.out, spvs)
    except (OSError, IOError, ValueError, RuntimeError) as e:
        print("lcm2rosbag.py: %s" % e, file=sys.stderr)
        return 1
    print("%s: %s" % (a.out, ", ".join("%s %d" % kv for kv in counts.items())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
