"""spvs-fleet: many simulated robots, each with its own controller, through
one Zenoh router.

  spvs-fleet (this process, outside)
    router.py            Zenoh router: tcp/127.0.0.1:PORT (for stations)
                         and a unix socket in the work folder (for robots)
    unshare -r -n  fleet.py --inner   the supervisor, in a network namespace
                         of its own that has only loopback
      per robot:  spvs-node  <-LCM->  bridge.py  <-Zenoh->  spvs-sim (port)

Robot i (0-based, in --robot order) has its own LCM URL,
udpm://239.255.76.67:(7667+i)?ttl=0, inside the namespace, so the LCM
traffic of two robots never mixes, and its own key prefix spvs/<name>/.
The namespace cannot reach TCP on the host's loopback, so the robots reach
the router through its unix socket; a station connects over TCP.

The supervisor records every command each node publishes (the robot's
cmd.csv in the work folder), ends a robot whose node or bridge dies (its
spvs-sim at once, the rest after the watchdog), and restarts nothing but
the router (the outer process does that: robots resume on their own).

Exit status: 0 when every robot's run completed (any controller outcome),
1 when one failed or the fleet could not start, 2 on bad options.
Usage: --help; docs/ZENOH.md.
"""

import argparse
import ctypes
import json
import math
import os
import re
import select
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import spvs_zenoh_common as common  # noqa: E402

PROG = "spvs-fleet"
LCM_GROUP = "239.255.76.67"
LCM_PORT0 = 7667
MAX_ROBOTS = 64
NAME_RE = re.compile(r"^[A-Za-z0-9_.-]{1,64}$")
CMD_FIELDS = struct.Struct(">qqddbh")  # seq, utime, v, w, step, status
CMD_SIZE = 8 + CMD_FIELDS.size
ROUTER_RESTARTS_MAX = 10
TICK_S = 0.05


class UsageError(Exception):
    pass


class Parser(argparse.ArgumentParser):
    def error(self, message):
        raise UsageError(message)


def lcm_url(index):
    """The LCM provider of robot `index` inside the fleet's namespace."""
    return "udpm://%s:%d?ttl=0" % (LCM_GROUP, LCM_PORT0 + index)


def parse_robot(text):
    """NAME:METHOD:X,Z,PHI_DEG:SEED -> dict, or UsageError saying why."""
    parts = text.split(":")
    if len(parts) != 4:
        fields = ("name", "method", "pose", "seed")
        why = ("no %s" % " and no ".join(fields[len(parts):])) \
            if len(parts) < 4 else "%d fields" % len(parts)
        raise UsageError("--robot '%s': want NAME:METHOD:X,Z,PHI_DEG:SEED "
                         "(%s)" % (text, why))
    name, method, pose, seed = parts
    if not NAME_RE.match(name):
        raise UsageError("--robot '%s': name '%s' must be 1..64 characters "
                         "from A-Z a-z 0-9 _ . -" % (text, name))
    if method not in ("1", "2", "3"):
        raise UsageError("--robot '%s': method '%s' must be 1, 2 or 3"
                         % (text, method))
    xs = pose.split(",")
    try:
        vals = [float(v) for v in xs]
    except ValueError:
        vals = []
    if len(xs) != 3 or len(vals) != 3 or \
            not all(math.isfinite(v) for v in vals):
        raise UsageError("--robot '%s': pose '%s' must be three finite "
                         "numbers X,Z,PHI_DEG (metres, degrees)"
                         % (text, pose))
    if not re.match(r"^[0-9]{1,10}$", seed) or int(seed) > 0xFFFFFFFF:
        raise UsageError("--robot '%s': seed '%s' must be an integer in "
                         "0..4294967295" % (text, seed))
    return {"name": name, "method": int(method), "pose": pose,
            "seed": int(seed)}


def parse_args(argv):
    p = Parser(
        prog=PROG,
        description="Run simulated robots, each with its own controller "
        "node (spvs-node) and Zenoh bridge, through one Zenoh router on "
        "127.0.0.1 (scouting off).  Robot i gets the key prefix "
        "spvs/<NAME>/ and the LCM URL udpm://239.255.76.67:(7667+i)?ttl=0 "
        "inside a loopback-only network namespace of the fleet's own.",
        epilog="Exit status: 0 every run completed, 1 a run failed or the "
        "fleet could not start, 2 bad options.  Details: docs/ZENOH.md.")
    p.add_argument("--robot", action="append", default=[],
                   metavar="NAME:METHOD:X,Z,PHI_DEG:SEED",
                   help="a robot: name (A-Z a-z 0-9 _ . -), method 1|2|3, "
                   "start pose (m, m, deg), seed; repeat for each robot")
    p.add_argument("--noise", default="0", metavar="SIGMA_PX",
                   help="image noise of every robot, pixels (0)")
    p.add_argument("--outliers", default="0", metavar="FRACTION",
                   help="mismatched fraction of every frame, [0,1) (0)")
    p.add_argument("--json", action="store_true",
                   help="one JSON line per robot (the spvs-sim --json "
                   "summary plus \"robot\"), then one fleet summary line")
    p.add_argument("--port", type=int, default=7447,
                   help="the router's TCP port on 127.0.0.1 (7447); 0 picks "
                   "a free one")
    p.add_argument("--watchdog", type=float, default=0.5, metavar="S",
                   help="each node's watchdog, seconds (0.5)")
    p.add_argument("--timeout", type=float, default=30.0, metavar="S",
                   help="longest wait of a robot for one command, resends "
                   "included, seconds (30): a router restart fits in it")
    p.add_argument("--max-time", type=float, default=600.0, metavar="S",
                   help="wall-clock bound of the whole run, seconds (600); "
                   "robots still running then are stopped and failed")
    p.add_argument("--realtime", action="store_true",
                   help="pace every robot at its control period (0.1 s)")
    p.add_argument("--workdir", default=None, metavar="DIR",
                   help="keep logs, pids and command records here (made if "
                   "missing); default: a temporary folder, removed at exit")
    p.add_argument("--build", default=None, metavar="DIR",
                   help="CMake build folder with sim_host/spvs-sim, "
                   "sim_host/node/spvs-node, lcm_types/python (default "
                   "$SPVS_BUILD, else build/test-float)")
    p.add_argument("--timing", action="store_true",
                   help="each robot's port writes its put and receive times "
                   "(timing.txt in its folder; tools/fleet_load.py)")
    p.add_argument("--quiet", action="store_true",
                   help="no progress lines on stderr")
    p.add_argument("--inner", default=None, help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.inner is not None:
        return a
    if not a.robot:
        raise UsageError("give at least one --robot NAME:METHOD:X,Z,PHI_DEG:"
                         "SEED")
    if len(a.robot) > MAX_ROBOTS:
        raise UsageError("at most %d robots (%d given)"
                         % (MAX_ROBOTS, len(a.robot)))
    robots, seen = [], set()
    for text in a.robot:
        r = parse_robot(text)
        if r["name"] in seen:
            raise UsageError("--robot '%s': robot name '%s' given twice"
                             % (text, r["name"]))
        seen.add(r["name"])
        robots.append(r)
    a.robots = robots
    a.noise = number(a.noise, "--noise", 0.0, 1000.0)
    a.outliers = number(a.outliers, "--outliers", 0.0, 0.999999)
    if not (0 <= a.port <= 65535):
        raise UsageError("--port must be in 0..65535")
    if not (0.0 < a.watchdog <= 60.0):
        raise UsageError("--watchdog must be in (0, 60] s")
    if not (0.0 < a.timeout <= 3600.0):
        raise UsageError("--timeout must be in (0, 3600] s")
    if not (0.0 < a.max_time <= 86400.0):
        raise UsageError("--max-time must be in (0, 86400] s")
    return a


def number(text, what, lo, hi):
    try:
        v = float(text)
    except ValueError:
        raise UsageError("%s: '%s' is not a number" % (what, text))
    if not (math.isfinite(v) and lo <= v <= hi):
        raise UsageError("%s: %s is outside [%g, %g]" % (what, text, lo, hi))
    return v


# ---- processes ------------------------------------------------------------

_libc = ctypes.CDLL(None, use_errno=True)
PR_SET_PDEATHSIG = 1


def die_with_parent():
    """In a child before exec: get SIGKILL when the parent dies, however it
    dies (kept across exec; only a credential change clears it)."""
    _libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)


class Child:
    """One process: output to files, reaped with its CPU time."""

    def __init__(self, name, argv, folder, env=None, stdout=None,
                 inherit_stderr=False):
        self.name = name
        self.argv = argv
        self.err_path = os.path.join(folder, name + ".err")
        err = None if inherit_stderr else open(self.err_path, "w")
        out = stdout if stdout is not None else \
            open(os.path.join(folder, name + ".out"), "w")
        self.proc = subprocess.Popen(
            argv, stdin=subprocess.DEVNULL, stdout=out, stderr=err,
            env=env, preexec_fn=die_with_parent, close_fds=True)
        if stdout is None:
            out.close()
        if err is not None:
            err.close()
        self.pid = self.proc.pid
        self.t_start = time.monotonic()
        self.t_end = None
        self.rc = None
        self.cpu_s = None

    def poll(self):
        """Exit code (negative: signal) once it has ended, else None."""
        if self.rc is not None:
            return self.rc
        try:
            pid, status, ru = os.wait4(self.pid, os.WNOHANG)
        except ChildProcessError:
            pid, status, ru = self.pid, 0, None
        if pid == 0:
            return None
        self.rc = os.waitstatus_to_exitcode(status)
        self.proc.returncode = self.rc
        self.t_end = time.monotonic()
        if ru is not None:
            self.cpu_s = ru.ru_utime + ru.ru_stime
        return self.rc

    def signal(self, sig):
        if self.poll() is None:
            try:
                os.kill(self.pid, sig)
            except ProcessLookupError:
                pass

    def stop(self, grace=3.0):
        """SIGTERM, then SIGKILL after `grace` seconds; returns the code."""
        self.signal(signal.SIGTERM)
        end = time.monotonic() + grace
        while self.poll() is None and time.monotonic() < end:
            time.sleep(0.01)
        if self.poll() is None:
            self.signal(signal.SIGKILL)
            while self.poll() is None:
                time.sleep(0.01)
        return self.rc

    def stderr_text(self):
        try:
            with open(self.err_path) as f:
                return f.read()
        except OSError:
            return ""


def describe_exit(rc):
    if rc is None:
        return "running"
    if rc < 0:
        try:
            return "signal %s" % signal.Signals(-rc).name
        except ValueError:
            return "signal %d" % -rc
    return "status %d" % rc


def last_line(text):
    lines = [l for l in text.strip().splitlines() if l.strip()]
    return lines[-1].strip() if lines else ""


def log(args, text):
    if not args.quiet:
        sys.stderr.write("%s: %s\n" % (PROG, text))
        sys.stderr.flush()


# ---- inside the namespace: the supervisor ---------------------------------

class Robot:
    """One robot: its node, bridge and simulator, its command record."""

    def __init__(self, index, spec, cfg, workdir):
        self.index = index
        self.spec = spec
        self.name = spec["name"]
        self.cfg = cfg
        self.dir = os.path.join(workdir, "%02d-%s" % (index, self.name))
        os.makedirs(self.dir, exist_ok=True)
        self.url = lcm_url(index)
        self.node = self.bridge = self.sim = None
        self.state = "starting"
        self.result = None
        self.failure = None
        self.t_failed = None
        self.frames = 0
        # Line-buffered: tests and tools follow it while the robot runs.
        self.cmd_file = open(os.path.join(self.dir, "cmd.csv"), "w",
                             buffering=1)
        self.cmd_file.write("t_mono_s,seq,v,w,step,status\n")
        self.lcm = None

    def env(self):
        e = dict(os.environ, LCM_DEFAULT_URL=self.url)
        return e

    def start_controller(self):
        c = self.cfg
        self.node = Child("node", [c["node"], "--method",
                                   str(self.spec["method"]), "--seed",
                                   str(self.spec["seed"]), "--watchdog",
                                   repr(c["watchdog"]), "--lcm-url", self.url,
                                   "--log-level", "2"], self.dir, self.env())
        self.bridge = Child("bridge", [sys.executable,
                                       os.path.join(HERE, "bridge.py"),
                                       # = keeps a name like -a a value
                                       "--robot=" + self.name, "--mode",
                                       "client", "--connect", c["endpoint"],
                                       "--scouting", "off", "--lcm-url",
                                       self.url, "--lcm-types", c["types"],
                                       "--log-level", "2"], self.dir,
                            self.env())
        self.write_pids()

    def controller_ready(self):
        """The node has opened LCM and the bridge its Zenoh session."""
        return ("spvs-node: method" in self.node.stderr_text() and
                "spvs-zenoh-bridge: robot " in self.bridge.stderr_text())

    def start_sim(self):
        c = self.cfg
        argv = [c["sim"], "--method", str(self.spec["method"]), "--pose",
                self.spec["pose"], "--seed", str(self.spec["seed"]),
                "--noise", repr(c["noise"]), "--outliers",
                repr(c["outliers"]), "--transport", "zenoh",
                "--zenoh-endpoint", c["endpoint"], "--timeout",
                repr(c["timeout"]), "--json", "--quiet"]
        if c["realtime"]:
            argv.append("--realtime")
        env = self.env()
        env.update(SPVS_PYTHON=sys.executable, SPVS_ZENOH_MODE="client",
                   SPVS_ZENOH_ROBOT=self.name, SPVS_ZENOH_RESEND_S="0.2",
                   SPVS_ZENOH_PORT=os.path.join(HERE, "sim_port.py"))
        if c["timing"]:
            env["SPVS_ZENOH_TIMING"] = os.path.join(self.dir, "timing.txt")
        self.sim = Child("sim", argv, self.dir, env)
        self.state = "running"
        self.write_pids()

    def write_pids(self):
        with open(os.path.join(self.dir, "pids"), "w") as f:
            for ch in (self.node, self.bridge, self.sim):
                if ch is not None:
                    f.write("%s %d\n" % (ch.name, ch.pid))

    def on_cmd(self, channel, data):
        if len(data) != CMD_SIZE:
            return
        seq, utime, v, w, step, status = CMD_FIELDS.unpack(data[8:])
        if seq >= 0:
            self.frames += 1
        self.cmd_file.write("%.6f,%d,%.9g,%.9g,%d,%d\n"
                            % (time.monotonic(), seq, v, w, step, status))

    def fail(self, why, linger=True):
        """End this robot: its spvs-sim now (the vehicle stops), its node and
        bridge after the watchdog (so the node's own stop is recorded)."""
        now = time.monotonic()
        if self.failure is None:
            self.failure = why
            self.t_failed = now
        self.t_linger = now + (self.cfg["watchdog"] + 0.5 if linger else 0.0)
        if self.sim is not None:
            self.sim.signal(signal.SIGTERM)
        self.state = "failing"

    def base_result(self):
        s = self.spec
        x, z, phi = (float(v) for v in s["pose"].split(","))
        return {"robot": self.name, "method": s["method"], "seed": s["seed"],
                "start": {"x_m": x, "z_m": z, "phi_deg": phi},
                "transport": "zenoh"}

    def drain(self):
        """Record the commands still waiting on this robot's LCM socket
        (its last answers arrive just before its spvs-sim ends)."""
        if self.lcm is None:
            return
        fd = self.lcm.fileno()
        for _ in range(10000):
            if not select.select([fd], [], [], 0.02)[0]:
                return
            self.lcm.handle()

    def begin_stop(self):
        """Collect the result; ask the node and bridge to end.  Nothing here
        waits: the supervisor keeps reading every other robot's LCM socket
        meanwhile, or their commands would overflow its buffers."""
        self.drain()
        res = None
        if self.failure is None:
            rc = self.sim.poll()
            try:
                with open(os.path.join(self.dir, "sim.out")) as f:
                    line = last_line(f.read())
            except OSError:
                line = ""
            if rc == 0 and line.startswith("{"):
                try:
                    res = dict(robot=self.name, **json.loads(line))
                except ValueError:
                    res = None
            if res is None:
                self.failure = "spvs-sim ended (%s): %s" % (
                    describe_exit(rc), last_line(self.sim.stderr_text())
                    or "no result")
        if res is None:
            res = self.base_result()
            res.update(status="failed", reason=self.failure,
                       frames=self.frames)
        self.result = res
        for ch in (self.bridge, self.node):
            if ch is not None:
                ch.signal(signal.SIGTERM)
        self.t_stop_sent = time.monotonic()
        self.state = "stopping"

    def complete(self):
        res = self.result
        if self.t_failed is not None:
            # When the fleet saw the failure and when the robot (its
            # spvs-sim) had stopped, CLOCK_MONOTONIC seconds.
            res["ended"] = {"t_failed_s": round(self.t_failed, 6),
                            "t_stopped_s": round(self.sim.t_end, 6)
                            if self.sim is not None and self.sim.t_end
                            else None}
        res["cpu_s"] = {ch.name: ch.cpu_s for ch in
                        (self.node, self.bridge, self.sim)
                        if ch is not None and ch.cpu_s is not None}
        self.state = "done"
        self.cmd_file.close()
        self.lcm = None
        with open(os.path.join(self.dir, "result.json"), "w") as f:
            f.write(json.dumps(res) + "\n")

    def tick(self, now):
        """Advance this robot's state without waiting; True once done."""
        if self.state == "done":
            return True
        if self.state == "stopping":
            kids = [ch for ch in (self.bridge, self.node) if ch is not None]
            for ch in kids:
                if ch.poll() is None and now - self.t_stop_sent > 3.0:
                    ch.signal(signal.SIGKILL)
            if all(ch.poll() is not None for ch in kids):
                self.complete()
            return self.state == "done"
        if self.state == "failing":
            sim_over = self.sim is None or self.sim.poll() is not None
            if not sim_over and now - self.t_failed > 3.0:
                self.sim.signal(signal.SIGKILL)
            if sim_over and now >= self.t_linger:
                self.begin_stop()
            return False
        for ch, what in ((self.node, "spvs-node"), (self.bridge, "bridge")):
            if ch.poll() is not None:
                self.fail("%s exited (%s)%s" % (
                    what, describe_exit(ch.rc),
                    (" after frame %d" % (self.frames - 1))
                    if self.frames else ""))
                return False
        if self.state == "running" and self.sim.poll() is not None:
            self.begin_stop()
        return False


def pump(fds, timeout):
    """Take the LCM messages waiting (for at most `timeout` seconds)."""
    for fd in [fd for fd, r in fds.items() if r.lcm is None]:
        del fds[fd]
    try:
        ready, _, _ = select.select(list(fds), [], [], timeout)
    except InterruptedError:
        ready = []
    # All that waits on each socket: it carries the robot's frames and
    # states too (LCM filters channels after reading), and UDP drops what
    # overflows the socket's buffer.
    for fd in ready:
        r = fds[fd]
        for _ in range(1000):
            r.lcm.handle()
            if not select.select([fd], [], [], 0)[0]:
                break


def setup_namespace():
    for cmd in (["ip", "link", "set", "lo", "up"],
                ["ip", "route", "add", "224.0.0.0/4", "dev", "lo"]):
        r = subprocess.run(cmd, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, timeout=10)
        if r.returncode != 0:
            raise RuntimeError("cannot set up the loopback-only namespace "
                               "(%s: %s)" % (" ".join(cmd),
                                             r.stderr.decode().strip()))


def inner_main(workdir):
    """The supervisor, run by the outer process inside `unshare -r -n`."""
    try:
        with open(os.path.join(workdir, "fleet.json")) as f:
            cfg = json.load(f)
    except (OSError, ValueError) as e:
        sys.stderr.write("%s: --inner is spvs-fleet's own: no fleet in '%s' "
                         "(%s)\n" % (PROG, workdir, e))
        return 2

    class A:
        quiet = cfg["quiet"]
    args = A()
    parent = os.getppid()
    stop = {"why": None}

    def on_signal(signum, frame):
        stop["why"] = ("the fleet was stopped (%s)"
                       % signal.Signals(signum).name)
    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)

    try:
        setup_namespace()
        import lcm as lcm_mod
    except (RuntimeError, ImportError, OSError) as e:
        sys.stderr.write("%s: %s\n" % (PROG, e))
        return 1

    robots = [Robot(i, s, cfg, workdir) for i, s in enumerate(cfg["robots"])]
    fds = {}
    for r in robots:
        # The recorder hears each robot's frames too (LCM filters channels
        # after reading): a large socket buffer carries it through the
        # moments another process holds the CPU.
        r.lcm = lcm_mod.LCM(r.url + "&recv_buf_size=4194304")
        r.lcm.subscribe(common.CH_CMD, r.on_cmd)
        fds[r.lcm.fileno()] = r
    deadline = time.monotonic() + cfg["max_time"]
    for r in robots:
        r.start_controller()
    # Every node and bridge up before the first frame goes out; a frame
    # lost anyway would be sent again, only later.
    # Dozens of Python processes importing Zenoh at once take a while on a
    # small machine.
    ready_s = 30.0 + 1.0 * len(robots)
    ready_by = time.monotonic() + ready_s
    pending = list(robots)
    while pending and stop["why"] is None:
        for r in list(pending):
            if r.controller_ready():
                r.start_sim()
                pending.remove(r)
            elif r.node.poll() is not None or r.bridge.poll() is not None \
                    or time.monotonic() > ready_by:
                why = last_line(r.bridge.stderr_text()) or \
                    last_line(r.node.stderr_text()) or \
                    "no ready line in %.0f s" % ready_s
                r.fail("did not start: %s" % why)
                pending.remove(r)
        pump(fds, TICK_S)
    log(args, "%d robots started (router %s)" % (
        len(robots) - len(pending), cfg["router"]))

    t0 = time.monotonic()
    next_progress = t0 + 5.0
    stopping = False
    hard_end = None
    while True:
        now = time.monotonic()
        if stop["why"] is None and os.getppid() != parent:
            stop["why"] = "spvs-fleet itself ended"
        if stop["why"] is None and now > deadline:
            stop["why"] = "--max-time %g s reached" % cfg["max_time"]
        if stop["why"] is not None and not stopping:
            stopping = True
            hard_end = now + 10.0
            for r in robots:
                if r.state in ("starting", "running"):
                    r.failure = stop["why"]
                    r.t_failed = now
                    r.fail(stop["why"], linger=False)
        if stopping and now > hard_end:
            break
        pump(fds, TICK_S)
        if all([r.tick(now) for r in robots]):
            break
        if now >= next_progress:
            next_progress = now + 5.0
            log(args, "%.0f s: %d running, %d done, %d frames answered" % (
                now - t0, sum(r.state == "running" for r in robots),
                sum(r.state == "done" for r in robots),
                sum(r.frames for r in robots)))
    return 0


# ---- outside: the router and the run ---------------------------------------

def find_build(a):
    build = a.build or os.environ.get("SPVS_BUILD") or \
        os.path.join(common.REPO_ROOT, "build", "test-float")
    build = os.path.abspath(build)
    need = {"sim": os.path.join(build, "sim_host", "spvs-sim"),
            "node": os.path.join(build, "sim_host", "node", "spvs-node"),
            "types": os.path.join(build, "lcm_types", "python")}
    for what, path in need.items():
        ok = os.access(path, os.X_OK) if what != "types" else \
            os.path.isfile(os.path.join(path, "spvs", "cmd_t.py"))
        if not ok:
            raise RuntimeError("%s not found in the build folder %s (build "
                               "spvs-sim, spvs-node and spvs_lcm_python, or "
                               "pass --build DIR)" % (path, build))
    return need


def free_port():
    import socket
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Router:
    def __init__(self, workdir, tcp, sock):
        self.workdir = workdir
        self.listen = [tcp, "unixsock-stream/" + sock]
        self.child = None
        self.restarts = 0
        self.cpu_s = 0.0  # of the routers that have ended

    def start(self, wait_s=20.0):
        rd, wr = os.pipe()
        out = os.fdopen(wr, "w")
        argv = [sys.executable, os.path.join(HERE, "router.py")]
        for ep in self.listen:
            argv += ["--listen", ep]
        name = "router" if self.restarts == 0 else \
            "router-%d" % self.restarts
        self.child = Child(name, argv, self.workdir, stdout=out)
        out.close()
        with open(os.path.join(self.workdir, "router.pid"), "w") as f:
            f.write("%d\n" % self.child.pid)
        got = b""
        end = time.monotonic() + wait_s
        try:
            while b"ready" not in got and time.monotonic() < end:
                r, _, _ = select.select([rd], [], [], 0.1)
                if r:
                    chunk = os.read(rd, 256)
                    if not chunk:
                        break
                    got += chunk
        finally:
            os.close(rd)
        if b"ready" not in got:
            self.child.stop()
            raise RuntimeError("the router did not start: %s" % (
                last_line(self.child.stderr_text()) or "no ready line"))


def outer_main(a):
    try:
        paths = find_build(a)
    except RuntimeError as e:
        sys.stderr.write("%s: %s\n" % (PROG, e))
        return 1
    if subprocess.run(["unshare", "-r", "-n", "true"],
                      stderr=subprocess.DEVNULL).returncode != 0:
        sys.stderr.write("%s: cannot make a network namespace (unshare -r "
                         "-n): LCM multicast must stay inside one\n" % PROG)
        return 1
    own_tmp = a.workdir is None
    if not own_tmp:
        sock = os.path.join(os.path.abspath(a.workdir), "router.sock")
        if len(sock.encode()) > 100:
            sys.stderr.write("%s: the work folder's path is too long for a "
                             "unix socket (%s; at most 100 bytes)\n"
                             % (PROG, sock))
            return 1
    workdir = tempfile.mkdtemp(prefix="spvs-fleet-") if own_tmp else \
        os.path.abspath(a.workdir)
    os.makedirs(workdir, exist_ok=True)
    try:
        return run_fleet(a, paths, workdir, own_tmp)
    finally:
        if own_tmp:
            shutil.rmtree(workdir, ignore_errors=True)


def start_inner(a, paths, workdir, router, tcp):
    """Writes the fleet's set-up for the supervisor and starts it in a
    network namespace of its own."""
    cfg = dict(robots=a.robots, noise=a.noise, outliers=a.outliers,
               watchdog=a.watchdog, timeout=a.timeout,
               max_time=a.max_time, realtime=a.realtime,
               timing=a.timing, quiet=a.quiet, router=tcp,
               endpoint=router.listen[1],
               **paths)
    with open(os.path.join(workdir, "fleet.json"), "w") as f:
        json.dump(cfg, f)
    log(a, "router on %s; %d robots; work folder %s"
        % (tcp, len(a.robots), workdir))
    return Child("supervisor", ["unshare", "-r", "-n", sys.executable,
                                os.path.abspath(__file__), "--inner",
                                workdir], workdir, stdout=sys.stderr,
                 inherit_stderr=True)


def supervise(a, router, inner, stopping, hard_end):
    """Until the supervisor ends: pass a signal on to it, bound it by
    --max-time, restart the router when it dies (at most
    ROUTER_RESTARTS_MAX times)."""
    while inner.poll() is None:
        if stopping["sig"] is not None:
            inner.signal(signal.SIGTERM)
            end = time.monotonic() + 15.0
            while inner.poll() is None and time.monotonic() < end:
                time.sleep(TICK_S)
            break
        if time.monotonic() > hard_end:
            sys.stderr.write("%s: the supervisor outlived --max-time\n"
                             % PROG)
            break
        if router.child.poll() is not None:
            if router.restarts >= ROUTER_RESTARTS_MAX:
                sys.stderr.write("%s: the router died %d times; giving "
                                 "up\n" % (PROG, router.restarts + 1))
                inner.signal(signal.SIGTERM)
                stopping["sig"] = signal.SIGTERM
                continue
            log(a, "router exited (%s); restarting it"
                % describe_exit(router.child.rc))
            router.cpu_s += router.child.cpu_s or 0.0
            router.restarts += 1
            try:
                router.start()
            except RuntimeError as e:
                log(a, str(e))
        time.sleep(TICK_S)


def read_results(a, workdir, inner):
    """Each robot's result.json, or a failed result saying there is none."""
    results = []
    for i, r in enumerate(a.robots):
        path = os.path.join(workdir, "%02d-%s" % (i, r["name"]),
                            "result.json")
        try:
            with open(path) as f:
                results.append(json.loads(f.read()))
        except (OSError, ValueError):
            results.append({"robot": r["name"], "method": r["method"],
                            "seed": r["seed"], "status": "failed",
                            "reason": "no result (supervisor %s)"
                            % describe_exit(inner.rc if inner else None)})
    return results


def fleet_summary(results, wall, tcp, router, inner, workdir, own_tmp):
    """The fleet's summary line as a dict."""
    statuses = {}
    for res in results:
        statuses[res["status"]] = statuses.get(res["status"], 0) + 1
    return {"robots": len(results),
            "converged": statuses.get("converged", 0),
            "failed": statuses.get("failed", 0),
            "statuses": statuses,
            "frames": sum(res.get("frames", 0) for res in results),
            "wall_s": round(wall, 3), "router": tcp,
            "router_restarts": router.restarts,
            "cpu_s": {"router": round(router.cpu_s, 3),
                      "supervisor_and_robots": round(inner.cpu_s, 3)
                      if inner is not None and inner.cpu_s else None},
            "workdir": None if own_tmp else workdir}


def run_fleet(a, paths, workdir, own_tmp):
    stopping = {"sig": None}

    def on_signal(signum, frame):
        stopping["sig"] = signum
    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGHUP, on_signal)

    sock = os.path.join(workdir, "router.sock")
    port = a.port or free_port()
    tcp = "tcp/127.0.0.1:%d" % port
    router = Router(workdir, tcp, sock)
    inner = None
    t0 = time.monotonic()
    try:
        try:
            router.start()
        except RuntimeError as e:
            sys.stderr.write("%s: %s (another router on port %d? use "
                             "--port)\n" % (PROG, e, port))
            return 1
        inner = start_inner(a, paths, workdir, router, tcp)
        supervise(a, router, inner, stopping, t0 + a.max_time + 30.0)
    finally:
        if inner is not None and inner.poll() is None:
            inner.stop(5.0)
        if router.child is not None:
            router.child.stop()
            router.cpu_s += router.child.cpu_s or 0.0
    wall = time.monotonic() - t0

    results = read_results(a, workdir, inner)
    summary = fleet_summary(results, wall, tcp, router, inner, workdir,
                            own_tmp)
    if a.json:
        for res in results:
            print(json.dumps(res))
        print(json.dumps({"fleet": summary}))
    else:
        print_table(results, summary)
    if stopping["sig"] is not None:
        return 1
    return 1 if summary["failed"] else 0


def print_table(results, summary):
    print("%-16s %-6s %-10s %10s %10s %10s %8s %6s" % (
        "robot", "method", "status", "x (m)", "z (m)", "phi (deg)",
        "time (s)", "frames"))
    for r in results:
        e = r.get("final_error")
        if e:
            print("%-16s %-6s %-10s %+10.4f %+10.4f %+10.3f %8.1f %6d" % (
                r["robot"], r["method"], r["status"], e["x_m"], e["z_m"],
                e["phi_deg"], r["time_s"], r["frames"]))
        else:
            print("%-16s %-6s %-10s %s" % (r["robot"], r["method"],
                                           r["status"], r.get("reason", "")))
    print("fleet: %d robots, %d converged, %d failed, %d frames in %.1f s; "
          "router %s (%d restarts)" % (
              summary["robots"], summary["converged"], summary["failed"],
              summary["frames"], summary["wall_s"], summary["router"],
              summary["router_restarts"]))


def main(argv):
    try:
        a = parse_args(argv)
    except UsageError as e:
        sys.stderr.write("%s: %s (see --help)\n" % (PROG, e))
        return 2
    if a.inner is not None:
        return inner_main(a.inner)
    return outer_main(a)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
