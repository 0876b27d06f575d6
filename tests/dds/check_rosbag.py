#!/usr/bin/env python3
"""check_rosbag.py [--log LCMLOG] BAG_DIR RECORDING [BAG_DIR2]

A rosbag2 written by spvs-sim --rosbag, read by two readers that are not
spvs's own, each decoding from the definitions the bag embeds:
  - mcap with mcap-ros2-support (CRCs checked, summary and chunk indexes);
  - rosbags (its rosbag2 Reader on metadata.yaml and MCAP storage).
Every frame of the run's recording (spvs-sim --record, docs/RECORDING.md)
must be in the bag: one /cmd_vel Twist with linear.x = v and angular.z = w
(the recording's float32 values) and the rest zero; one /spvs/state with
the same v, w, step and status and seq = the frame's; one /spvs/matches
with the frame's matches, all three stamped with the frame time.

With --log, a bag converted from that LCM log (tools/rosbag/lcm2rosbag.py):
the bag must hold exactly the log's messages (SPVS_MATCHES on
/spvs/matches, SPVS_CMD on /cmd_vel and /spvs/state, counted in the log by
LCM's own reader), the watchdog's stops (seq -1) must be zero Twists, and
every frame the log holds must equal the recording's frame of its seq: a
UDP log may miss datagrams of a run, which the figures printed show.  With BAG_DIR2 (the same run over another
transport) the two MCAP files must be equal byte for byte.
"""
import os
import struct
import sys
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore, get_types_from_msg


def recording(path):
    data = open(path, "rb").read()
    assert data[:8] == b"SPVSREC1", "not a recording"
    pos, out = 8, []
    while pos < len(data):
        seq, t, n = struct.unpack_from("<IdH", data, pos)
        pos += 14
        m = [struct.unpack_from("<Hffff", data, pos + 18 * i) for i in range(n)]
        pos += 18 * n
        v, w, status, step = struct.unpack_from("<ffhB", data, pos)
        pos += 11
        out.append(dict(seq=seq, t=t, m=m, v=v, w=w, status=status, step=step))
    return out


def by_mcap(bag):
    files = [f for f in os.listdir(bag) if f.endswith(".mcap")]
    assert len(files) == 1, files
    topics = {"/spvs/matches": [], "/cmd_vel": [], "/spvs/state": []}
    with open(os.path.join(bag, files[0]), "rb") as f:
        r = make_reader(f, decoder_factories=[DecoderFactory()], validate_crcs=True)
        summary = r.get_summary()
        for schema, ch, msg, dec in r.iter_decoded_messages(log_time_order=True):
            assert schema.encoding == "ros2msg" and ch.message_encoding == "cdr"
            topics[ch.topic].append((msg.log_time, dec))
    return topics, summary


def by_rosbags(bag):
    topics = {"/spvs/matches": [], "/cmd_vel": [], "/spvs/state": []}
    store = get_typestore(Stores.EMPTY)
    with Reader(Path(bag)) as r:
        types = {}
        for c in r.connections:
            types.update(get_types_from_msg(c.msgdef.data, c.msgtype))
        store.register(types)
        for c, t, raw in r.messages():
            topics[c.topic].append((t, store.deserialize_cdr(raw, c.msgtype)))
    return topics


def check_log(name, topics, rec, log_counts, bad):
    """A bag converted from an LCM log: the log's messages, each equal to
    the recording's frame of its seq."""
    want = {"/spvs/matches": log_counts.get("SPVS_MATCHES", 0),
            "/cmd_vel": log_counts.get("SPVS_CMD", 0),
            "/spvs/state": log_counts.get("SPVS_CMD", 0)}
    for topic, n in want.items():
        if len(topics[topic]) != n:
            bad.append("%s: %d messages on %s, the log has %d"
                       % (name, len(topics[topic]), topic, n))
            return
    by_seq = {fr["seq"]: fr for fr in rec}
    frames = set()
    for (tt, tw), (ts, st) in zip(topics["/cmd_vel"], topics["/spvs/state"]):
        twist = (tw.linear.x, tw.linear.y, tw.linear.z, tw.angular.x, tw.angular.y, tw.angular.z)
        if st.seq == -1:
            if twist != (0.0,) * 6:
                bad.append("%s: a watchdog stop with a moving Twist" % name)
            continue
        fr = by_seq.get(st.seq)
        if fr is None or tt != ts or twist != (fr["v"], 0.0, 0.0, 0.0, 0.0, fr["w"]) or \
                (st.v, st.w, st.step, st.status) != (fr["v"], fr["w"], fr["step"], fr["status"]):
            bad.append("%s: frame %d: /cmd_vel %s, /spvs/state v %r w %r step %d status %d"
                       % (name, st.seq, twist, st.v, st.w, st.step, st.status))
            return
        frames.add(st.seq)
    for t, mm in topics["/spvs/matches"]:
        fr = by_seq.get(mm.seq)
        got = [(mm.feature[i], mm.x_tgt[i], mm.y_tgt[i], mm.x_cur[i], mm.y_cur[i])
               for i in range(max(0, min(mm.count, 256)))]
        if fr is None or got != [tuple(x) for x in fr["m"]]:
            bad.append("%s: /spvs/matches of frame %d differ from the run's" % (name, mm.seq))
            return
    return frames


def check(name, topics, rec, bad):
    for topic in topics:
        if len(topics[topic]) != len(rec):
            bad.append("%s: %d messages on %s for %d frames"
                       % (name, len(topics[topic]), topic, len(rec)))
            return
    for k, fr in enumerate(rec):
        t_ns = round(fr["t"] * 1e9)
        (tt, tw), (ts, st), (tm, mm) = (topics["/cmd_vel"][k], topics["/spvs/state"][k],
                                        topics["/spvs/matches"][k])
        twist = (tw.linear.x, tw.linear.y, tw.linear.z, tw.angular.x, tw.angular.y, tw.angular.z)
        want = (fr["v"], 0.0, 0.0, 0.0, 0.0, fr["w"])
        if twist != want:
            bad.append("%s: frame %d: /cmd_vel %s, the run's (v, w) %s" % (name, k, twist, want))
            return
        if (st.seq, st.v, st.w, st.step, st.status) != (fr["seq"], fr["v"], fr["w"],
                                                         fr["step"], fr["status"]):
            bad.append("%s: frame %d: /spvs/state seq %d v %r w %r step %d status %d"
                       % (name, k, st.seq, st.v, st.w, st.step, st.status))
            return
        n = len(fr["m"])
        got = [(mm.feature[i], mm.x_tgt[i], mm.y_tgt[i], mm.x_cur[i], mm.y_cur[i])
               for i in range(mm.count)]
        if mm.seq != fr["seq"] or mm.count != n or got != [tuple(x) for x in fr["m"]]:
            bad.append("%s: frame %d: /spvs/matches differ from the run's %d matches"
                       % (name, k, n))
            return
        if not (tt == ts == tm == t_ns):
            bad.append("%s: frame %d: stamps %d %d %d, frame time %d ns"
                       % (name, k, tt, ts, tm, t_ns))
            return


def main():
    args = sys.argv[1:]
    log = None
    if len(args) >= 2 and args[0] == "--log":
        log, args = args[1], args[2:]
    if len(args) not in (2, 3):
        print(__doc__)
        return 2
    bag, rec = args[0], recording(args[1])
    bad = []
    topics, summary = by_mcap(bag)
    print("mcap: %d messages, %d chunks, per channel %s; the run: %d frames"
          % (summary.statistics.message_count, len(summary.chunk_indexes),
             dict(summary.statistics.channel_message_counts), len(rec)))
    other = by_rosbags(bag)
    if log:
        import lcm
        counts = {}
        for ev in lcm.EventLog(log, "r"):
            counts[ev.channel] = counts.get(ev.channel, 0) + 1
        frames = check_log("mcap-ros2-support", topics, rec, counts, bad)
        check_log("rosbags", other, rec, counts, bad)
        print("the LCM log: %s; its answers cover %d of the run's %d frames"
              % (counts, len(frames or ()), len(rec)))
        if not frames:
            bad.append("no frame of the run in the bag")
    else:
        check("mcap-ros2-support", topics, rec, bad)
        check("rosbags", other, rec, bad)
    if not log:
        left = sum(1 for fr in rec if fr["w"] > 0)
        print("/cmd_vel: %d Twists equal to the run's (v, w) in both readers "
              "(%d turning left, angular.z > 0)" % (len(rec), left))
    if len(args) == 3:
        mc = lambda d: open(os.path.join(d, [f for f in os.listdir(d)
                                             if f.endswith(".mcap")][0]), "rb").read()
        a, b = mc(bag), mc(args[2])
        print("the other transport's bag: %d bytes, this one %d bytes" % (len(b), len(a)))
        if a != b:
            bad.append("the bag of the other transport's run differs")
    if bad:
        print("FAIL:\n  " + "\n  ".join(bad))
        return 1
    print("rosbag: decoded by mcap-ros2-support and rosbags, equal to the run")
    return 0


if __name__ == "__main__":
    sys.exit(main())
