#!/usr/bin/env python3
"""check_zenoh_ros2.py BUILD ROOT DOMAIN

/cmd_vel on Zenoh with rmw_zenoh's key (spvs-zenoh-bridge --ros2-cmd-vel,
docs/ROS2.md), run inside a loopback-only namespace (tests/zenoh/netns.sh):
spvs-sim --transport zenoh drives spvs-node through the bridge while a
plain Zenoh subscriber listens on
    DOMAIN/cmd_vel/geometry_msgs::msg::dds_::Twist_/RIHS01_9c45...
and on the liveliness tokens under @ros2_lv/DOMAIN.  Each payload is decoded
as CDR by rosbags' ROS 2 Jazzy type store (not spvs's code); the Twists must
be one per frame, equal to the in-process run's (v, w); the attachments
decode with Zenoh's deserializer as sequence numbers 1, 2, ..., source
times and one 16-byte gid; the publisher's token names the topic, type,
hash and the default QoS; and the hash is the one rosbags computes from
spvs_msgs' Twist.msg.
"""
import os
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time

build, root, domain = sys.argv[1], sys.argv[2], int(sys.argv[3])
sys.path.insert(0, os.path.join(root, "sim_host", "zenoh"))
sys.path.insert(0, os.path.join(root, "spvs_msgs"))
import zenoh  # noqa: E402
import zenoh.ext as zext  # noqa: E402
from rosbags.typesys import Stores, get_typestore, get_types_from_msg  # noqa: E402

import ros2_keys  # noqa: E402
import spvs_zenoh_common as common  # noqa: E402

SIM = os.path.join(build, "sim_host", "spvs-sim")
NODE = os.path.join(build, "sim_host", "node", "spvs-node")
BRIDGE = os.path.join(root, "sim_host", "zenoh", "spvs-zenoh-bridge")
TYPES = os.path.join(build, "lcm_types", "python")
LCM_URL = "udpm://239.255.76.67:%d?ttl=0" % (20000 + os.getpid() % 20000)
ARGS = ["--method", "3", "--seed", "0"]
bad = []


def recording(path):
    data = open(path, "rb").read()
    pos, out = 8, []
    while pos < len(data):
        _, _, n = struct.unpack_from("<IdH", data, pos)
        pos += 14 + 18 * n
        v, w, _, _ = struct.unpack_from("<ffhB", data, pos)
        pos += 11
        out.append((v, w))
    return out


def main():
    tmp = tempfile.mkdtemp(prefix="spvs-zenoh-ros2-")
    try:
        run(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def run(tmp):
    rec_path = os.path.join(tmp, "run.rec")
    subprocess.run([SIM] + ARGS + ["--quiet", "--record", rec_path],
                   check=True, timeout=120)
    rec = recording(rec_path)

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    ep = "tcp/127.0.0.1:%d" % port
    env = dict(os.environ, LCM_DEFAULT_URL=LCM_URL, ROS_DOMAIN_ID=str(domain))
    logs = {n: open(os.path.join(tmp, n + ".err"), "w") for n in ("node", "bridge", "sim")}
    node = subprocess.Popen([NODE, "--method", "3", "--seed", "0", "--watchdog", "30",
                             "--lcm-url", LCM_URL], stderr=logs["node"], env=env)
    bridge = subprocess.Popen([BRIDGE, "--listen", ep, "--lcm-url", LCM_URL,
                               "--lcm-types", TYPES, "--ros2-cmd-vel", "--log-level", "2"],
                              stderr=logs["bridge"], env=env)
    procs = [node, bridge]
    try:
        cfg = common.zenoh_config(zenoh, "peer", [], [ep], False)
        session = zenoh.open(cfg)
        twists, tokens = [], set()
        key = ros2_keys.data_key(domain, "/cmd_vel", ros2_keys.TWIST_TYPE,
                                 ros2_keys.TWIST_HASH)
        sub = session.declare_subscriber(key, lambda s: twists.append(
            (bytes(s.payload.to_bytes()),
             bytes(s.attachment.to_bytes()) if s.attachment is not None else None)))
        lsub = session.liveliness().declare_subscriber(
            "@ros2_lv/%d/**" % domain, lambda s: tokens.add(str(s.key_expr)),
            history=True)
        end = time.monotonic() + 20
        while not any("/MP/" in t for t in tokens) and time.monotonic() < end:
            time.sleep(0.05)
        if not any("/MP/" in t for t in tokens):
            bad.append("no publisher token under @ros2_lv/%d within 20 s" % domain)
            return
        sim = subprocess.run([SIM] + ARGS + ["--transport", "zenoh", "--zenoh-endpoint", ep,
                                             "--timeout", "10", "--quiet", "--json"],
                             stdout=subprocess.PIPE, stderr=logs["sim"], timeout=150, env=env)
        if sim.returncode != 0:
            bad.append("spvs-sim over Zenoh exited %d" % sim.returncode)
            return
        end = time.monotonic() + 5
        while len(twists) < len(rec) and time.monotonic() < end:
            time.sleep(0.05)
        time.sleep(0.3)
        sub.undeclare()
        lsub.undeclare()
        session.close()
    finally:
        for p in procs:
            p.send_signal(signal.SIGTERM)
        for p in procs:
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()
        for f in logs.values():
            f.close()

    # Decode with rosbags' ROS 2 Jazzy types, not spvs's code.
    store = get_typestore(Stores.ROS2_JAZZY)
    got = []
    seqs = []
    for payload, att in twists:
        t = store.deserialize_cdr(payload, "geometry_msgs/msg/Twist")
        got.append((t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z))
        if att is None:
            bad.append("a sample without attachment")
            break
        seq, ts, gid = zext.z_deserialize(
            tuple[zext.Int64, zext.Int64, tuple[(zext.UInt8,) * 16]], zenoh.ZBytes(att))
        seqs.append(int(seq))
        if len(gid) != 16 or not int(ts) > 0:
            bad.append("attachment: timestamp %r gid %r" % (ts, gid))
            break
    want = [(v, 0.0, 0.0, 0.0, 0.0, w) for v, w in rec]
    print("key %s: %d Twists for %d frames of the in-process run; attachment sequence "
          "numbers %s..%s" % (key, len(got), len(rec), seqs[:1], seqs[-1:]))
    if got != want:
        k = next((i for i, (a, b) in enumerate(zip(got, want)) if a != b), min(len(got), len(want)))
        bad.append("the Twists differ from the run's (v, w) from frame %d (%d vs %d)"
                   % (k, len(got), len(want)))
    if seqs != list(range(1, len(got) + 1)):
        bad.append("attachment sequence numbers are not 1..%d" % len(got))
    pub = [t for t in tokens if "/MP/" in t]
    want_tail = "/MP/%%/%%/%s/%%cmd_vel/%s/%s/%s" % (
        ros2_keys.NODE_NAME, ros2_keys.TWIST_TYPE, ros2_keys.TWIST_HASH, ros2_keys.DEFAULT_QOS)
    print("liveliness tokens: %s" % sorted(tokens))
    if len(pub) != 1 or not pub[0].endswith(want_tail) or \
            not any("/NN/%/%/" + ros2_keys.NODE_NAME in t for t in tokens):
        bad.append("the liveliness tokens are not rmw_zenoh's for /cmd_vel")
    ours = get_typestore(Stores.EMPTY)
    types = {}
    for n in ("Vector3", "Twist"):
        p = os.path.join(root, "spvs_msgs", "external", "geometry_msgs", "msg", n + ".msg")
        types.update(get_types_from_msg(open(p).read(), "geometry_msgs/msg/" + n))
    ours.register(types)
    h = ours.hash_rihs01("geometry_msgs/msg/Twist")
    print("RIHS01 of spvs_msgs' Twist.msg (rosbags): %s" % h)
    if h != ros2_keys.TWIST_HASH or store.hash_rihs01("geometry_msgs/msg/Twist") != h:
        bad.append("type hash %s, the key says %s" % (h, ros2_keys.TWIST_HASH))


if __name__ == "__main__":
    main()
    if bad:
        print("FAIL:\n  " + "\n  ".join(bad))
        sys.exit(1)
    print("zenoh_ros2: /cmd_vel on rmw_zenoh's key equals the in-process run")
