"""spvs-station: a ground-station view of a fleet in the terminal.

It subscribes to spvs/*/state on a Zenoh router (or peer) and shows, per
robot: the frame (seq), the step, the status, the inliers of the frame's
homography, v, w, and the time since the robot's last state message.  A
robot silent for longer than --stale seconds is flagged STALE: its
controller has stopped publishing (no frames, a dead node or bridge, a lost
link).  The view refreshes live until Ctrl-C; --once prints one snapshot
after --wait seconds (for scripts and tests).

Payloads are LCM-encoded state_t (docs/ZENOH.md); this decodes them with
struct, so it needs only eclipse-zenoh.  A payload of the wrong size or
fingerprint is counted and ignored.

Exit status: 0 (--once: at least one robot seen), 1 when Zenoh cannot be
opened or --once saw no robot, 2 on bad options.
"""

import argparse
import json
import math
import os
import struct
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import spvs_zenoh_common as common  # noqa: E402

PROG = "spvs-station"
STATE_FINGERPRINT = bytes.fromhex("62032d1020f36306")
# seq, utime (us), H[9], h_valid, n_matches, n_inliers, n_offplane, e_x (px),
# e_valid, parallax (px), eq11, v (m/s), w (rad/s), step, status, then the
# arrival check: statistic, threshold (standard deviations), lateral and its
# sd, depth and its sd, h13 and its sd, corner, parallax (px; parallax -1: no
# off-plane point seen), frames, re-entries, next step, arriving
STATE_FIELDS = struct.Struct(">qq9dbhhhdbdbddbh10dhbbb")
STATE_SIZE = 8 + STATE_FIELDS.size

# The core's status enum (firmware/include/spvs/status.h).
STATUS_NAMES = {0: "ok", -1: "arg", -2: "too_few", -3: "nonfinite",
                -4: "range", -5: "capacity", -6: "degenerate",
                -7: "no_consensus", -8: "stale", -9: "no_parallax",
                -10: "plane_nz", -11: "plane_ny", -12: "step_timeout",
                -13: "config", -14: "not_at_target"}


class UsageError(Exception):
    pass


class Parser(argparse.ArgumentParser):
    def error(self, message):
        raise UsageError(message)


def parse_args(argv):
    p = Parser(prog=PROG, description="Watch a fleet: subscribes to "
               "spvs/*/state and shows each robot's step, status, inliers, "
               "v, w and the time since its last message; stale robots are "
               "flagged.",
               epilog="Exit status: 0; 1 Zenoh cannot be opened or --once "
               "saw no robot; 2 bad options.")
    p.add_argument("--connect", action="append", default=None, metavar="E",
                   help="router or peer to connect to, repeatable (default "
                   "tcp/127.0.0.1:7447, spvs-fleet's router)")
    p.add_argument("--mode", choices=("client", "peer"), default="client",
                   help="Zenoh mode (default client)")
    p.add_argument("--stale", type=float, default=1.0, metavar="S",
                   help="flag a robot silent for more than S s (1.0)")
    p.add_argument("--refresh", type=float, default=0.5, metavar="S",
                   help="redraw every S s (0.5)")
    p.add_argument("--once", action="store_true",
                   help="print one snapshot after --wait s and exit")
    p.add_argument("--wait", type=float, default=1.5, metavar="S",
                   help="with --once: listen this long first (1.5)")
    p.add_argument("--json", action="store_true",
                   help="with --once: one JSON line per robot")
    a = p.parse_args(argv)
    if a.connect is None:
        a.connect = ["tcp/127.0.0.1:7447"]
    for ep in a.connect:
        why = common.check_endpoint(ep)
        if why:
            raise UsageError(why)
    for name in ("stale", "refresh", "wait"):
        v = getattr(a, name)
        if not (math.isfinite(v) and 0.0 < v <= 3600.0):
            raise UsageError("--%s must be in (0, 3600] s" % name)
    if a.json and not a.once:
        raise UsageError("--json goes with --once")
    return a


class Fleet:
    """The newest state of each robot, filled from Zenoh's threads."""

    def __init__(self):
        self.lock = threading.Lock()
        self.robots = {}
        self.bad = 0

    def on_state(self, sample):
        key = str(sample.key_expr)
        parts = key.split("/")
        data = bytes(sample.payload.to_bytes())
        now = time.monotonic()
        if len(parts) != 3 or len(data) != STATE_SIZE or \
                data[:8] != STATE_FINGERPRINT:
            with self.lock:
                self.bad += 1
            return
        f = STATE_FIELDS.unpack(data[8:])
        row = {"robot": parts[1], "seq": f[0], "utime": f[1],
               "n_matches": f[12], "n_inliers": f[13], "v": f[19],
               "w": f[20], "step": f[21], "status": f[22],
               "status_name": STATUS_NAMES.get(f[22], str(f[22])),
               "t": now}
        with self.lock:
            prev = self.robots.get(parts[1])
            row["messages"] = (prev["messages"] + 1) if prev else 1
            self.robots[parts[1]] = row

    def snapshot(self, stale_s):
        now = time.monotonic()
        with self.lock:
            rows = [dict(r) for r in self.robots.values()]
            bad = self.bad
        for r in rows:
            r["age_s"] = round(now - r.pop("t"), 3)
            r["stale"] = r["age_s"] > stale_s
        rows.sort(key=lambda r: r["robot"])
        return rows, bad


def render(rows, bad, stale_s, endpoints):
    lines = ["spvs-station  %s  %d robots, %d stale (silent > %.1f s)%s"
             % (",".join(endpoints), len(rows),
                sum(r["stale"] for r in rows), stale_s,
                ("  %d bad payloads ignored" % bad) if bad else ""),
             "%-16s %7s %4s %-13s %9s %9s %10s %8s" % (
                 "robot", "frame", "step", "status", "inliers", "v (m/s)",
                 "w (rad/s)", "age (s)")]
    for r in rows:
        lines.append("%-16s %7d %4d %-13s %4d/%-4d %+9.4f %+10.5f %8.1f%s"
                     % (r["robot"][:16], r["seq"], r["step"],
                        r["status_name"], r["n_inliers"], r["n_matches"],
                        r["v"], r["w"], r["age_s"],
                        "  STALE" if r["stale"] else ""))
    if not rows:
        lines.append("(no robot has published on spvs/*/state yet)")
    return "\n".join(lines)


def main(argv):
    try:
        a = parse_args(argv)
    except UsageError as e:
        sys.stderr.write("%s: %s (see --help)\n" % (PROG, e))
        return 2
    stop = common.StopSignals()
    try:
        import zenoh
    except ImportError as e:
        sys.stderr.write("%s: %s: run scripts/setup_venv.sh\n" % (PROG, e))
        return 1
    fleet = Fleet()
    try:
        cfg = common.zenoh_config(zenoh, a.mode, [], a.connect, False)
        session = zenoh.open(cfg)
    except Exception as e:
        sys.stderr.write("%s: cannot connect to %s: %s\n"
                         % (PROG, ",".join(a.connect), common.short_error(e)))
        return 1
    rc = 0
    try:
        session.declare_subscriber("spvs/*/state", fleet.on_state)
        if a.once:
            # One line on stderr: from here on every robot that publishes
            # is heard (scripts can wait for it).
            sys.stderr.write("%s: listening on spvs/*/state at %s for %g s\n"
                             % (PROG, ",".join(a.connect), a.wait))
            sys.stderr.flush()
            stop.wait(a.wait)
            rows, bad = fleet.snapshot(a.stale)
            if a.json:
                for r in rows:
                    print(json.dumps(r))
            else:
                print(render(rows, bad, a.stale, a.connect))
            if not rows:
                sys.stderr.write("%s: no robot state on spvs/*/state within "
                                 "%g s\n" % (PROG, a.wait))
                rc = 1
        else:
            tty = sys.stdout.isatty()
            while stop.signum is None:
                rows, bad = fleet.snapshot(a.stale)
                text = render(rows, bad, a.stale, a.connect)
                if tty:
                    sys.stdout.write("\x1b[H\x1b[2J" + text + "\n")
                else:
                    sys.stdout.write(text + "\n\n")
                sys.stdout.flush()
                stop.wait(a.refresh)
    finally:
        stop.ignore()
        session.close()
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
