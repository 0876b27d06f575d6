"""Checks of spvs-fleet and spvs-station (docs/ZENOH.md, "A fleet").

Run by ctest through tests/zenoh/netns.sh with the venv's Python, so the
whole check already sits in a loopback-only namespace; spvs-fleet makes
its own inside it for the robots' LCM traffic.  Every fleet gets its own
free router port and work folder under a temporary directory of the check's
own, and --max-time bounds it.

usage: check_fleet.py CHECK --build DIR --root DIR [--tol-m M --tol-deg D]
  equal --robots N [--noise PX] [--outliers F]: each robot's result through
          the fleet equals its own in-process run; each node saw exactly
          its own robot's frames.
  isolation  one robot's bridge and another's node killed mid-run: those
          two stop within the watchdog, the other two finish as in process.
  router  the router killed mid-run: every robot stops within the watchdog,
          resumes once the fleet has restarted the router, and finishes as
          in process.
  station spvs-station shows every robot live and flags the one whose node
          died as stale; SIGTERM ends the fleet and all its processes.
  decode  spvs-station's state_t layout is lcm-gen's: same fingerprint and
          size, and an encoded state_t unpacks to its fields, the arrival
          check's figures included (no network).
  cleanup SIGKILL of spvs-fleet itself still leaves no process behind.
  usage --case method|pose|seed|name|twice|help: a malformed --robot is
          refused (one line, status 2) before anything starts.
"""

import argparse
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

WATCHDOG = 0.5
MAX_TIME = 240
# Names from the whole allowed set (A-Z a-z 0-9 _ . -), one starting with
# '-' (given as --robot=...).
ROBOTS = ["r1:3:-3,-10,-30:1", "R_2.b:1:-2,-8,20:2", "..:2:1,-9,10:3",
          "-r4:3:2,-12,-15:4", "r5:1:4,-14,-25:5", "r6:2:-1,-6,5:6",
          "r7:3:0,-11,40:7", "r8:1:-4,-10,35:8"]
TOL = {"m": 0.0, "deg": 0.0}


class Fail(Exception):
    pass


def expect(cond, what):
    if not cond:
        raise Fail(what)


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def port_free(port):
    """Nobody listens on 127.0.0.1:port (connections refused)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.settimeout(2.0)
        try:
            s.connect(("127.0.0.1", port))
            return False
        except OSError:
            return True


class Env:
    def __init__(self, a):
        self.build = os.path.abspath(a.build)
        self.root = os.path.abspath(a.root)
        self.sim = os.path.join(self.build, "sim_host", "spvs-sim")
        self.fleet = os.path.join(self.root, "sim_host", "zenoh", "spvs-fleet")
        self.station = os.path.join(self.root, "sim_host", "zenoh",
                                    "spvs-station")
        self.tmp = tempfile.mkdtemp(prefix="spvs-fleet-test-")
        self.procs = []
        self.works = []
        self.noise = a.noise
        self.outliers = a.outliers

    def start_fleet(self, robots, extra=(), tag="fleet"):
        """spvs-fleet in the background; returns (process, workdir, port)."""
        port = free_port()
        work = os.path.join(self.tmp, tag)
        self.works.append(work)
        argv = [self.fleet, "--build", self.build, "--port", str(port),
                "--workdir", work, "--json", "--watchdog", str(WATCHDOG),
                "--max-time", str(MAX_TIME), "--noise", str(self.noise),
                "--outliers", str(self.outliers)]
        for r in robots:
            argv.append("--robot=" + r)
        out = open(os.path.join(self.tmp, tag + ".out"), "w")
        err = open(os.path.join(self.tmp, tag + ".err"), "w")
        p = subprocess.Popen(argv + list(extra), stdout=out, stderr=err)
        p.tag = tag
        self.procs.append(p)
        return p, work, port

    def fleet_output(self, p, within=MAX_TIME + 40):
        try:
            rc = p.wait(within)
        except subprocess.TimeoutExpired:
            raise Fail("spvs-fleet did not end within %d s" % within)
        with open(os.path.join(self.tmp, p.tag + ".out")) as f:
            lines = [l for l in f.read().splitlines() if l.strip()]
        try:
            objs = [json.loads(l) for l in lines]
        except ValueError:
            raise Fail("spvs-fleet printed a line that is not JSON: %r"
                       % lines)
        expect(objs and "fleet" in objs[-1],
               "spvs-fleet's last line is not the fleet summary: %r"
               % (lines[-1:] or None))
        return rc, {o["robot"]: o for o in objs[:-1]}, objs[-1]["fleet"]

    def text(self, tag, which="err"):
        with open(os.path.join(self.tmp, "%s.%s" % (tag, which))) as f:
            return f.read()

    def cleanup(self):
        for p in self.procs:
            if p.poll() is None:
                p.kill()
                p.wait(10)


def robot_dir(work, index, name):
    return os.path.join(work, "%02d-%s" % (index, name))


def parse_spec(spec):
    name, method, pose, seed = spec.split(":")
    return name, method, pose, seed


def in_process(env, spec):
    name, method, pose, seed = parse_spec(spec)
    q = subprocess.run(["timeout", "-k", "3", "120", env.sim, "--method",
                        method, "--pose", pose, "--seed", seed, "--noise",
                        str(env.noise), "--outliers", str(env.outliers),
                        "--json", "--quiet"], capture_output=True, text=True)
    expect(q.returncode == 0, "in-process run of %s exited %d: %s"
           % (name, q.returncode, q.stderr.strip()))
    return json.loads(q.stdout.strip().splitlines()[-1])


def same_result(got, ref, name):
    expect(got.get("robot") == name, "a result line names robot %r, not %r"
           % (got.get("robot"), name))
    expect(got.get("transport") == "zenoh", "%s ran over %r"
           % (name, got.get("transport")))
    if TOL["m"] == 0.0 and TOL["deg"] == 0.0:
        keys = ("status", "reason", "final_error", "time_s", "frames",
                "steps")
    else:
        keys = ("status",)
        for k, tol in (("x_m", TOL["m"]), ("z_m", TOL["m"]),
                       ("phi_deg", TOL["deg"])):
            a, b = got["final_error"][k], ref["final_error"][k]
            expect(abs(a - b) <= tol, "%s: final error %s %r in the fleet, "
                   "%r in process (tolerance %g)" % (name, k, a, b, tol))
    for k in keys:
        expect(got.get(k) == ref.get(k), "%s: %s differs: %r in the fleet, "
               "%r in process" % (name, k, got.get(k), ref.get(k)))


def read_cmds(work, index, name):
    """The robot's recorded commands: [(t_s, seq, v, w, step, status)]."""
    rows = []
    with open(os.path.join(robot_dir(work, index, name), "cmd.csv")) as f:
        for line in f.read().splitlines()[1:]:
            p = line.split(",")
            if len(p) == 6:
                rows.append((float(p[0]), int(p[1]), float(p[2]),
                             float(p[3]), int(p[4]), int(p[5])))
    return rows


def answered(work, index, name):
    try:
        return max([c[1] for c in read_cmds(work, index, name)] + [-1])
    except OSError:
        return -1


def pid_of(work, index, name, what):
    with open(os.path.join(robot_dir(work, index, name), "pids")) as f:
        for line in f:
            k, v = line.split()
            if k == what:
                return int(v)
    raise Fail("no %s pid for robot %s" % (what, name))


def wait_until(pred, within, what):
    end = time.monotonic() + within
    while time.monotonic() < end:
        if pred():
            return
        time.sleep(0.003)
    raise Fail("timed out after %.0f s waiting for %s" % (within, what))


def descendants(pid):
    """Every process below pid (from /proc), pid itself excluded."""
    parent = {}
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open("/proc/%s/stat" % d) as f:
                    st = f.read()
                parent[int(d)] = int(st[st.rindex(")") + 2:].split()[1])
            except (OSError, ValueError):
                pass
    found, todo = set(), [pid]
    while todo:
        p = todo.pop()
        for c, pp in parent.items():
            if pp == p and c not in found:
                found.add(c)
                todo.append(c)
    return found


def listeners():
    """(protocol, local address hex, port) of every listening TCP socket and
    every bound UDP socket in this network namespace (/proc/net)."""
    out = []
    for proto in ("tcp", "tcp6", "udp", "udp6"):
        try:
            with open("/proc/net/" + proto) as f:
                rows = f.read().splitlines()[1:]
        except OSError:
            continue
        for row in rows:
            f = row.split()
            addr, port = f[1].split(":")
            if proto.startswith("tcp") and f[3] != "0A":
                continue
            out.append((proto, addr, int(port, 16)))
    return out


def alive(pid):
    try:
        with open("/proc/%d/stat" % pid) as f:
            st = f.read()
        return st[st.rindex(")") + 2] != "Z"
    except OSError:
        return False


def node_frames(work, index, name):
    """The node's own count of frames, from its exit line."""
    with open(os.path.join(robot_dir(work, index, name), "node.err")) as f:
        for line in f:
            if line.startswith("spvs-node: exit: "):
                return int(line.split()[2])
    raise Fail("robot %s: spvs-node printed no exit line" % name)


def stop_after(cmds, t_from, name):
    """The first stop after t_from and the last answered command before it;
    checks the stop is the watchdog's (seq -1, v = w = 0, stale) and comes
    one watchdog after that answer.  Returns (t_last, seq_last, delay)."""
    stops = [c for c in cmds if c[0] > t_from and c[1] == -1]
    expect(stops, "robot %s: no stop command after the fault" % name)
    stop = stops[0]
    before = [c for c in cmds if c[0] < stop[0] and c[1] >= 0]
    expect(before, "robot %s: nothing answered before the stop" % name)
    last = before[-1]
    delay = stop[0] - last[0]
    expect(stop[2] == 0.0 and stop[3] == 0.0 and stop[5] == -8,
           "robot %s: the stop has v %g, w %g, status %d (want 0, 0, -8)"
           % (name, stop[2], stop[3], stop[5]))
    # The node checks its watchdog every 50 ms; the supervisor stamps the
    # commands after LCM and its own loop, on a machine that may be busy
    # with other builds (0.93 s seen at a load average of 24 on 2 cores).
    expect(0.8 * WATCHDOG <= delay <= WATCHDOG + 0.5,
           "robot %s: the stop came %.3f s after the last answer (watchdog "
           "%.2f s)" % (name, delay, WATCHDOG))
    return last[0], last[1], delay, stop[0]


# ---- checks ---------------------------------------------------------------

def check_equal(env, a):
    specs = ROBOTS[:a.robots]
    refs = [in_process(env, s) for s in specs]
    p, work, port = env.start_fleet(specs)
    rc, res, summary = env.fleet_output(p)
    expect(rc == 0, "spvs-fleet exited %d: %s" % (rc, env.text("fleet")
                                                  [-400:]))
    names = [parse_spec(s)[0] for s in specs]
    expect(list(res) == names, "result lines for %s, want %s"
           % (list(res), names))
    for i, (name, ref) in enumerate(zip(names, refs)):
        same_result(res[name], ref, name)
        # Each node ran exactly its own robot's frames: traffic of another
        # robot on its LCM URL would add frames (the runs differ in length).
        n = node_frames(work, i, name)
        expect(n == ref["frames"], "robot %s: its node saw %d frames, the "
               "robot sent %d" % (name, n, ref["frames"]))
        # The fleet's record of the commands on the robot's URL holds none
        # beyond its own frames.  (It is a monitor on UDP: on a loaded
        # machine it may miss some, so it is not required to hold all.)
        seqs = set(c[1] for c in read_cmds(work, i, name) if c[1] >= 0)
        expect(seqs <= set(range(ref["frames"])) and
               len(seqs) >= ref["frames"] // 2,
               "robot %s: the commands recorded on its LCM URL answer %d "
               "seqs (%d..%d), its run had frames 0..%d"
               % (name, len(seqs), min(seqs, default=-1),
                  max(seqs, default=-1), ref["frames"] - 1))
    conv = sum(r["status"] == "converged" for r in refs)
    expect(summary["robots"] == len(specs) and summary["converged"] == conv
           and summary["failed"] == 0 and summary["router_restarts"] == 0,
           "fleet summary %r (want %d robots, %d converged, 0 failed)"
           % (summary, len(specs), conv))
    expect(summary["frames"] == sum(r["frames"] for r in refs),
           "fleet summary frames %d, robots' sum %d"
           % (summary["frames"], sum(r["frames"] for r in refs)))
    print("ok: %d robots through one router, each equal to its in-process "
          "run (%s), %d frames in %.2f s wall; statuses %s"
          % (len(specs), "exactly" if TOL["m"] == 0 else "within tolerance",
             summary["frames"], summary["wall_s"], summary["statuses"]))


def check_isolation(env, a):
    specs = ROBOTS[:4]
    names = [parse_spec(s)[0] for s in specs]
    refs = [in_process(env, s) for s in specs]
    p, work, port = env.start_fleet(specs)
    kill_at = 40
    victims = {1: "bridge", 2: "node"}
    t_kill = {}
    def step():
        for i, what in victims.items():
            if i not in t_kill and answered(work, i, names[i]) >= kill_at:
                os.kill(pid_of(work, i, names[i], what), signal.SIGKILL)
                t_kill[i] = time.monotonic()
        return len(t_kill) == len(victims)
    wait_until(step, 60, "frame %d of robots %s and %s"
               % (kill_at, names[1], names[2]))
    rc, res, summary = env.fleet_output(p)
    expect(rc == 1, "spvs-fleet exited %d with two robots failed" % rc)
    for i in (0, 3):
        same_result(res[names[i]], refs[i], names[i])
    report = []
    for i, what in victims.items():
        name = names[i]
        r = res[name]
        want = {"bridge": "bridge exited (signal SIGKILL)",
                "node": "spvs-node exited (signal SIGKILL)"}[what]
        expect(r["status"] == "failed" and want in r.get("reason", ""),
               "robot %s: %s / %r (want failed: %s)"
               % (name, r["status"], r.get("reason"), want))
        expect(r["frames"] < refs[i]["frames"],
               "robot %s was not killed mid-run (%d of %d frames)"
               % (name, r["frames"], refs[i]["frames"]))
        # From the kill no command can reach the robot (the process that
        # makes or relays them is gone); the fleet sees it and ends the
        # robot's spvs-sim at its next 50 ms poll.  The process's exit after
        # that is the kernel's and the machine's business, bounded loosely.
        seen = r["ended"]["t_failed_s"] - t_kill[i]
        stopped = r["ended"]["t_stopped_s"] - t_kill[i]
        # t_kill is taken just after the signal is sent, so the fleet may
        # see the death a moment before it.  The fleet polls its children
        # every 50 ms; on a machine busy with other builds its loop can be
        # held off for longer (0.573 s seen under a full CI), so the bound
        # is the watchdog plus the same 0.5 s as the stops' bound above.
        expect(-0.05 <= seen <= WATCHDOG + 0.5,
               "robot %s: the fleet saw its %s's death %.3f s after the kill "
               "(watchdog %.2f s, plus 0.5 s for a busy machine)"
               % (name, what, seen, WATCHDOG))
        expect(stopped <= WATCHDOG + 1.0,
               "robot %s: its spvs-sim ended %.3f s after the kill"
               % (name, stopped))
        cmds = read_cmds(work, i, name)
        moving = [c for c in cmds if c[0] > t_kill[i] + 0.05 and
                  (c[2] != 0.0 or c[3] != 0.0)]
        expect(not moving, "robot %s: %d moving commands after its %s died"
               % (name, len(moving), what))
        extra = ""
        if what == "bridge":
            # The node outlives its bridge by a watchdog: its own stop is
            # on record.
            t_run = min(c[0] for c in cmds if c[1] >= 0)
            t_last, seq, delay, _ = stop_after(cmds, t_run, name)
            extra = "; its node's stop %.3f s after frame %d" % (delay, seq)
        report.append("%s (%s killed after frame %d): seen %.3f s later, "
                      "its spvs-sim ended %.3f s later%s"
                      % (name, what, r["frames"] - 1, seen, stopped, extra))
    print("ok: %s; %s and %s equal to their in-process runs"
          % ("; ".join(report), names[0], names[3]))


def check_router(env, a):
    specs = ROBOTS[:4]
    names = [parse_spec(s)[0] for s in specs]
    refs = [in_process(env, s) for s in specs]
    # Paced at 10 Hz: every robot is surely mid-run when the router dies,
    # however far apart a busy machine started them.
    p, work, port = env.start_fleet(specs, ["--realtime"])
    kill_at = 30
    wait_until(lambda: min(answered(work, i, n) for i, n in
                           enumerate(names)) >= kill_at, 60,
               "frame %d of every robot" % kill_at)
    with open(os.path.join(work, "router.pid")) as f:
        router = int(f.read())
    os.kill(router, signal.SIGKILL)
    t_kill = time.monotonic()
    rc, res, summary = env.fleet_output(p)
    expect(rc == 0, "spvs-fleet exited %d after the router restart: %s"
           % (rc, env.text("fleet")[-400:]))
    expect(summary["router_restarts"] == 1, "the fleet reports %d router "
           "restarts" % summary["router_restarts"])
    report = []
    for i, name in enumerate(names):
        same_result(res[name], refs[i], name)
        cmds = read_cmds(work, i, name)
        t_last, seq, delay, t_stop = stop_after(cmds, t_kill, name)
        expect(seq < refs[i]["frames"] - 1, "robot %s had finished before "
               "the router was killed" % name)
        after = [c for c in cmds if c[0] > t_stop]
        resumed = [c for c in after if c[1] >= 0]
        expect(resumed, "robot %s never resumed" % name)
        between = [c for c in after if c[0] < resumed[0][0]]
        expect(all(c[1] == -1 and c[2] == 0.0 and c[3] == 0.0
                   for c in between), "robot %s: a moving command while "
               "the router was away" % name)
        report.append("%s stop %.3f s after frame %d, resumed %.2f s after "
                      "the kill" % (name, delay, seq, resumed[0][0] - t_kill))
    print("ok: router killed and restarted by the fleet: %s; every result "
          "equal to its in-process run" % "; ".join(report))


def station(env, port, tag, extra):
    out = open(os.path.join(env.tmp, tag + ".out"), "w")
    err = open(os.path.join(env.tmp, tag + ".err"), "w")
    p = subprocess.Popen([env.station, "--connect",
                          "tcp/127.0.0.1:%d" % port, "--once"] + extra,
                         stdout=out, stderr=err)
    p.tag = tag
    env.procs.append(p)
    return p


def check_station(env, a):
    specs = ROBOTS[:3]
    names = [parse_spec(s)[0] for s in specs]
    p, work, port = env.start_fleet(specs, ["--realtime"])
    wait_until(lambda: min(answered(work, i, n) for i, n in
                           enumerate(names)) >= 10, 60,
               "frame 10 of every robot")
    # --stale 1.5 s: robot 2 will have been silent for about 3.2 s at the
    # snapshot, the others for a frame period (0.1 s) or so, with room for
    # a machine busy with other builds.
    js = station(env, port, "station_json", ["--json", "--wait", "4",
                                             "--stale", "1.5"])
    tx = station(env, port, "station_text", ["--wait", "4", "--stale",
                                             "1.5"])
    # Both stations hear every robot before robot 2's node is killed.
    wait_until(lambda: all("listening on" in env.text(x.tag)
                           for x in (js, tx)), 60, "the stations to listen")
    time.sleep(0.8)
    os.kill(pid_of(work, 1, names[1], "node"), signal.SIGKILL)
    for s in (js, tx):
        expect(s.wait(30) == 0, "spvs-station --once exited %d: %s"
               % (s.returncode, env.text(s.tag).strip()))
    rows = {}
    for line in env.text("station_json", "out").splitlines():
        r = json.loads(line)
        rows[r["robot"]] = r
    expect(sorted(rows) == sorted(names), "the station saw %s, want %s"
           % (sorted(rows), names))
    for i, name in enumerate(names):
        r = rows[name]
        if i == 1:
            expect(r["stale"] and r["age_s"] > 1.5, "robot %s (node killed "
                   "3.2 s before the snapshot) is not flagged stale: %r" % (name, r))
            continue
        latest = answered(work, i, name)
        # The station started after every robot's frame 10; on a busy
        # machine its newest state may trail the node by a few frames.
        expect(not r["stale"] and r["age_s"] <= 1.5 and r["step"] >= 1 and
               r["n_inliers"] > 0 and 10 <= r["seq"] <= latest,
               "robot %s: station row %r (its node has answered frame %d)"
               % (name, r, latest))
    text = env.text("station_text", "out").splitlines()
    flagged = [l.split()[0] for l in text if l.endswith("STALE")]
    expect(flagged == [names[1]], "the text view flags %s as stale, want %s"
           % (flagged, names[1]))
    kids = descendants(p.pid)
    expect(len(kids) >= 10, "only %d processes under spvs-fleet" % len(kids))
    # This check's namespace holds only the fleet: the router is the one
    # TCP listener, on 127.0.0.1, and no Zenoh scouting socket (UDP 7446)
    # is open.  (LCM's sockets live in the fleet's own namespace.)
    socks = listeners()
    tcp = [x for x in socks if x[0].startswith("tcp")]
    expect(tcp == [("tcp", "0100007F", port)],
           "TCP listeners %r (want only the router on 127.0.0.1:%d)"
           % (tcp, port))
    expect(not [x for x in socks if x[2] == 7446],
           "a Zenoh scouting socket is open: %r" % socks)
    p.send_signal(signal.SIGTERM)
    rc, res, summary = env.fleet_output(p, 20)
    expect(rc == 1, "spvs-fleet exited %d after SIGTERM (want 1)" % rc)
    wait_until(lambda: not any(alive(k) for k in kids), 10,
               "the fleet's %d processes to end" % len(kids))
    expect("spvs-node exited (signal SIGKILL)" in res[names[1]]["reason"]
           and "stopped (SIGTERM)" in res[names[0]]["reason"],
           "results after SIGTERM: %r" % res)
    expect(port_free(port), "the router's port %d is still taken" % port)
    print("ok: the station showed %s live (step %s, inliers %s) and %s "
          "stale after %.1f s; only the router listened (127.0.0.1:%d); "
          "SIGTERM ended the fleet and its %d processes"
          % (", ".join(n for n in names if n != names[1]),
             [rows[n]["step"] for n in names if n != names[1]],
             [rows[n]["n_inliers"] for n in names if n != names[1]],
             names[1], rows[names[1]]["age_s"], port, len(kids)))


def check_cleanup(env, a):
    specs = ROBOTS[:2]
    names = [parse_spec(s)[0] for s in specs]
    p, work, port = env.start_fleet(specs, ["--realtime"])
    wait_until(lambda: min(answered(work, i, n) for i, n in
                           enumerate(names)) >= 5, 60,
               "frame 5 of every robot")
    kids = descendants(p.pid)
    expect(len(kids) >= 7, "only %d processes under spvs-fleet" % len(kids))
    p.kill()
    p.wait(10)
    t0 = time.monotonic()
    wait_until(lambda: not any(alive(k) for k in kids), 10,
               "the %d processes of a SIGKILLed fleet to end" % len(kids))
    took = time.monotonic() - t0
    expect(port_free(port), "the router's port %d is still taken" % port)
    print("ok: spvs-fleet SIGKILLed: its %d processes ended within %.2f s"
          % (len(kids), took))


USAGE_CASES = {
    "method": (["a:4:-3,-10,-30:1"], ["a:x:-3,-10,-30:1"],
               ["a::-3,-10,-30:1"]),
    "pose": (["a:3:-3,-10:1"], ["a:3:-3,-10,x:1"], ["a:3:nan,-10,-30:1"],
             ["a:3:-3,-10,-30,4:1"]),
    "seed": (["a:3:-3,-10,-30:-1"], ["a:3:-3,-10,-30:4294967296"],
             ["a:3:-3,-10,-30:1.5"], ["a:3:-3,-10,-30"]),
    "name": (["a/b:3:-3,-10,-30:1"], ["a*:3:-3,-10,-30:1"],
             [":3:-3,-10,-30:1"], ["r\u00e9:3:-3,-10,-30:1"],
             ["%s:3:-3,-10,-30:1" % ("x" * 65)]),
    "twice": (["a:3:-3,-10,-30:1", "b:1:-2,-8,20:2", "a:2:1,-9,10:3"],),
}
USAGE_WORDS = {"method": "method", "pose": "pose", "seed": "seed",
               "name": "name", "twice": "given twice"}


def check_usage(env, a):
    if a.case == "help":
        q = subprocess.run([env.fleet, "--help"], capture_output=True,
                           text=True, timeout=30)
        expect(q.returncode == 0 and "NAME:METHOD:X,Z,PHI_DEG:SEED" in
               q.stdout, "spvs-fleet --help: status %d" % q.returncode)
        print("ok: --help exits 0 and documents --robot")
        return
    shown = []
    for robots in USAGE_CASES[a.case]:
        work = os.path.join(env.tmp, "never")
        argv = [env.fleet, "--build", env.build, "--workdir", work]
        for r in robots:
            argv += ["--robot", r]
        q = subprocess.run(argv, capture_output=True, text=True, timeout=30)
        lines = q.stderr.strip().splitlines()
        expect(q.returncode == 2, "%s: exit %d, want 2" % (robots,
                                                           q.returncode))
        expect(len(lines) == 1 and USAGE_WORDS[a.case] in lines[0],
               "%s: stderr %r (want one line naming the %s)"
               % (robots, q.stderr, USAGE_WORDS[a.case]))
        expect(q.stdout == "", "%s: printed %r" % (robots, q.stdout))
        expect(not os.path.exists(work), "%s: the work folder was made, so "
               "the fleet had started" % robots)
        shown.append(lines[0])
    print("ok: %d malformed --robot refused with status 2 before anything "
          "started, e.g. %s" % (len(shown), shown[0]))


def check_decode(env, a):
    sys.path.insert(0, os.path.join(env.build, "lcm_types", "python"))
    sys.path.insert(0, os.path.join(env.root, "sim_host", "zenoh"))
    import spvs
    import station
    fp = spvs.state_t._get_packed_fingerprint()
    expect(station.STATE_FINGERPRINT == fp,
           "station fingerprint %s, lcm-gen's state_t %s"
           % (station.STATE_FINGERPRINT.hex(), fp.hex()))
    expect(fp.hex() == "62032d1020f36306" and station.STATE_SIZE == 225,
           "state_t fingerprint %s, station size %d (docs/ZENOH.md: "
           "62032d1020f36306, 225 B)" % (fp.hex(), station.STATE_SIZE))
    s = spvs.state_t()
    s.seq, s.utime, s.step, s.status = 41, 4100000, 4, -14
    s.n_matches, s.n_inliers = 125, 97
    s.v, s.w = 0.0, 0.0
    s.arrival_stat, s.arrival_threshold = 3.4375, 4.0
    s.arrival_lateral_px, s.arrival_lateral_sd_px = 0.5, 0.1875
    s.arrival_depth_px, s.arrival_depth_sd_px = -0.25, 0.0625
    s.arrival_h13_px, s.arrival_h13_sd_px = -0.125, 0.046875
    s.arrival_corner_px, s.arrival_parallax_px = 0.75, 2.9
    s.arrival_frames, s.arrival_reentries = 21, 3
    s.arrival_next, s.arriving = 1, 0
    data = s.encode()
    expect(len(data) == station.STATE_SIZE,
           "an encoded state_t has %d bytes, the station expects %d"
           % (len(data), station.STATE_SIZE))
    f = station.STATE_FIELDS.unpack(data[8:])
    # The arrival check's figures follow status (index 22): statistic,
    # threshold, lateral, its sd, depth, its sd, h13, its sd, corner,
    # parallax, frames, re-entries, next step, arriving.
    want = (3.4375, 4.0, 0.5, 0.1875, -0.25, 0.0625, -0.125, 0.046875,
            0.75, 2.9, 21, 3, 1, 0)
    expect(tuple(f[23:37]) == want, "arrival figures unpacked as %r, want %r"
           % (tuple(f[23:37]), want))
    s.arrival_parallax_px = -1.0
    f = station.STATE_FIELDS.unpack(s.encode()[8:])
    expect(f[32] == -1.0 and f[33] == 21,
           "parallax -1 (none seen) unpacked as %r, frames %r" % (f[32], f[33]))

    class Sample:
        def __init__(self, key, payload):
            self.key_expr = key
            self.payload = self

            def to_bytes():
                return payload
            self.to_bytes = to_bytes
    fleet = station.Fleet()
    fleet.on_state(Sample("spvs/r1/state", s.encode()))
    fleet.on_state(Sample("spvs/r2/state", data[:-8]))
    rows, bad = fleet.snapshot(1.0)
    expect(bad == 1 and len(rows) == 1, "%d rows, %d bad from one good and "
           "one short payload" % (len(rows), bad))
    r = rows[0]
    expect(r["seq"] == 41 and r["step"] == 4 and r["n_inliers"] == 97 and
           r["status_name"] == "not_at_target", "station row %r" % r)
    print("ok: station state_t %s, %d B, arrival figures (parallax %.2f px, "
          "-1 none) unpacked as encoded" % (fp.hex(), station.STATE_SIZE, 2.9))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("check", choices=("equal", "isolation", "router",
                                     "station", "decode", "cleanup", "usage"))
    p.add_argument("--build", required=True)
    p.add_argument("--root", required=True)
    p.add_argument("--robots", type=int, default=4)
    p.add_argument("--noise", type=float, default=0.0)
    p.add_argument("--outliers", type=float, default=0.0)
    p.add_argument("--case", default="method")
    p.add_argument("--tol-m", type=float, default=0.0)
    p.add_argument("--tol-deg", type=float, default=0.0)
    a = p.parse_args()
    TOL["m"], TOL["deg"] = a.tol_m, a.tol_deg
    env = Env(a)
    fn = globals()["check_" + a.check]
    try:
        fn(env, a)
        return 0
    except Fail as e:
        print("FAIL: %s" % e)
        for name in sorted(os.listdir(env.tmp)):
            path = os.path.join(env.tmp, name)
            if os.path.isfile(path) and name.endswith(".err"):
                with open(path) as f:
                    t = f.read().strip()
                if t:
                    print("---- %s (last lines) ----\n%s"
                          % (name, "\n".join(t.splitlines()[-10:])))
        # Every robot's own logs, so a failure on a busy machine can be
        # told from a fault.
        for work in env.works:
            for d in sorted(os.listdir(work)) if os.path.isdir(work) else []:
                folder = os.path.join(work, d)
                if not os.path.isdir(folder):
                    continue
                for name in ("node.err", "bridge.err", "sim.err",
                             "result.json"):
                    try:
                        with open(os.path.join(folder, name)) as f:
                            t = f.read().strip().splitlines()
                    except OSError:
                        continue
                    if t:
                        print("---- %s/%s ----\n%s"
                              % (d, name, "\n".join(t[-4:])[:1500]))
        return 1
    finally:
        env.cleanup()
        if not os.environ.get("SPVS_KEEP_TMP"):
            shutil.rmtree(env.tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
