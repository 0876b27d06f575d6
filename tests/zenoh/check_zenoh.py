"""Checks of the Zenoh interface (issue: the controller on a Zenoh network).

Run by ctest through tests/zenoh/netns.sh, so inside a network namespace
with only loopback; run with the venv's Python (eclipse-zenoh, lcm).
Every process is started under `timeout -k`, every wait is bounded, Zenoh
peers use explicit tcp endpoints on 127.0.0.1 with random free ports and
multicast scouting off, LCM uses udpm with ttl=0.

usage: check_zenoh.py CHECK --build DIR --root DIR [CHECK OPTIONS]
  loop     --method M --seed S [--noise PX]: spvs-sim over Zenoh, bridge,
           spvs-node over LCM give exactly the in-process result.
  restart  --method M --seed S: the bridge stopped mid-run makes the node
           command stops (status stale) within its watchdog time; restarted,
           the run finishes with the in-process result.
  bad      bad payloads on spvs/<robot>/matches never reach LCM, each gives
           one logged error, and the bridge still relays good frames.
  cli      bad options, SIGTERM, and spvs-sim errors without a bridge or
           with a broken port.
"""

import argparse
import json
import os
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time

LCM_URL = "udpm://239.255.76.67:7667?ttl=0"
SPVS_E_STALE = -8
PROC_LIMIT_S = 120  # timeout(1) bound of every process started here
# --foreground: a signal sent here reaches the process once.  Without it
# timeout(1) also signals its own process group, so the process can get a
# signal twice and timeout itself can die of it, hiding the exit status.
TIMEOUT = ["timeout", "--foreground", "-k", "3", str(PROC_LIMIT_S)]


class Fail(Exception):
    pass


def expect(cond, what):
    if not cond:
        raise Fail(what)


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Env:
    def __init__(self, a):
        self.build = os.path.abspath(a.build)
        self.root = os.path.abspath(a.root)
        self.sim = os.path.join(self.build, "sim_host", "spvs-sim")
        self.node = os.path.join(self.build, "sim_host", "node", "spvs-node")
        self.bridge = os.path.join(self.root, "sim_host", "zenoh",
                                   "spvs-zenoh-bridge")
        self.types = os.path.join(self.build, "lcm_types", "python")
        self.tmp = tempfile.mkdtemp(prefix="spvs-zenoh-test-")
        self.procs = []
        for f in (self.sim, self.node, self.bridge):
            expect(os.access(f, os.X_OK), "%s is not built" % f)
        sys.path.insert(0, self.types)
        sys.path.insert(0, os.path.join(self.root, "sim_host", "zenoh"))

    def start(self, name, argv, env=None):
        """Start argv under timeout -k, stderr (and stdout) to files."""
        out = open(os.path.join(self.tmp, name + ".out"), "w")
        err = open(os.path.join(self.tmp, name + ".err"), "w")
        full_env = dict(os.environ, LCM_DEFAULT_URL=LCM_URL)
        if env:
            full_env.update(env)
        p = subprocess.Popen(TIMEOUT + argv,
                             stdout=out, stderr=err, env=full_env)
        p.name = name
        p.files = (out, err)
        self.procs.append(p)
        return p

    def text(self, name, which="err"):
        with open(os.path.join(self.tmp, "%s.%s" % (name, which))) as f:
            return f.read()

    def start_node(self, method, seed, watchdog=0.5, tag="node"):
        return self.start(tag, [self.node, "--method", str(method), "--seed",
                                str(seed), "--watchdog", str(watchdog),
                                "--log-level", "2", "--lcm-url", LCM_URL])

    def start_bridge(self, port, tag="bridge", extra=()):
        return self.start(tag, [self.bridge, "--listen",
                                "tcp/127.0.0.1:%d" % port, "--scouting", "off",
                                "--lcm-url", LCM_URL, "--lcm-types",
                                self.types, "--log-level", "2"] + list(extra))

    def stop(self, p, sig=signal.SIGTERM, within=5.0):
        """Signal p and return its exit status; Fail if it does not exit in
        time (the shutdown trap: a process that ignores SIGTERM)."""
        if p.poll() is None:
            p.send_signal(sig)
        try:
            return p.wait(within)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait(5)
            raise Fail("%s did not exit within %.1f s of signal %d"
                       % (p.name, within, sig))

    def cleanup(self):
        for p in self.procs:
            if p.poll() is None:
                p.kill()
                try:
                    p.wait(5)
                except subprocess.TimeoutExpired:
                    pass
            for f in p.files:
                f.close()

    def dump(self):
        for p in self.procs:
            for which in ("err", "out"):
                t = self.text(p.name, which).strip()
                if t:
                    print("---- %s %s (last lines) ----" % (p.name, which))
                    print("\n".join(t.splitlines()[-15:]))


def sim_args(method, seed, noise):
    return ["--method", str(method), "--seed", str(seed), "--noise",
            str(noise), "--json", "--quiet"]


def last_json(text, what):
    lines = [l for l in text.splitlines() if l.strip()]
    expect(lines, "%s printed nothing" % what)
    try:
        return json.loads(lines[-1])
    except ValueError:
        raise Fail("%s: last line is not JSON: %r" % (what, lines[-1][:200]))


def in_process(env, method, seed, noise):
    q = subprocess.run(TIMEOUT + [env.sim] +
                       sim_args(method, seed, noise), capture_output=True,
                       text=True)
    expect(q.returncode == 0, "in-process run exited %d: %s"
           % (q.returncode, q.stderr.strip()))
    return last_json(q.stdout, "the in-process run")


TOL = {"m": 0.0, "deg": 0.0}  # set from --tol-m, --tol-deg


def agreement():
    if TOL["m"] == 0.0 and TOL["deg"] == 0.0:
        return "identical to the in-process run"
    return ("within %g m, %g deg of the in-process run"
            % (TOL["m"], TOL["deg"]))


def same_result(over, ref, what):
    """Exactly the same run (float build: the wire carries what the core
    computes with), or within the tolerances (double build: the matches
    travel as float32, so the two runs differ by that rounding)."""
    if TOL["m"] == 0.0 and TOL["deg"] == 0.0:
        keys = ("status", "reason", "final_error", "time_s", "frames",
                "steps")
    else:
        keys = ("status",)
        for k, tol in (("x_m", TOL["m"]), ("z_m", TOL["m"]),
                       ("phi_deg", TOL["deg"])):
            a, b = over["final_error"][k], ref["final_error"][k]
            expect(abs(a - b) <= tol, "%s: final error %s %r over Zenoh, "
                   "%r in process (tolerance %g)" % (what, k, a, b, tol))
    for key in keys:
        expect(over.get(key) == ref.get(key),
               "%s: %s differs: %r over Zenoh, %r in process"
               % (what, key, over.get(key), ref.get(key)))


class LcmWatch:
    """Records every SPVS_CMD and SPVS_MATCHES on LCM with its arrival time
    (monotonic seconds), on a thread of its own."""

    def __init__(self):
        import lcm
        import spvs
        self.spvs = spvs
        self.lc = lcm.LCM(LCM_URL)
        self.cmds = []      # (t_s, cmd_t)
        self.matches = []   # (t_s, raw bytes)
        self.lock = threading.Lock()
        self.lc.subscribe("SPVS_CMD", self.on_cmd)
        self.lc.subscribe("SPVS_MATCHES", self.on_matches)
        self.running = True
        self.th = threading.Thread(target=self.loop, daemon=True)
        self.th.start()

    def on_cmd(self, ch, data):
        msg = self.spvs.cmd_t.decode(data)
        with self.lock:
            self.cmds.append((time.monotonic(), msg))

    def on_matches(self, ch, data):
        with self.lock:
            self.matches.append((time.monotonic(), data))

    def loop(self):
        while self.running:
            try:
                self.lc.handle_timeout(50)
            except OSError:
                break

    def snapshot(self):
        with self.lock:
            return list(self.cmds), list(self.matches)

    def wait_for(self, pred, within, what):
        end = time.monotonic() + within
        while time.monotonic() < end:
            cmds, matches = self.snapshot()
            r = pred(cmds, matches)
            if r:
                return r
            time.sleep(0.005)
        raise Fail("timed out after %.1f s waiting for %s" % (within, what))

    def close(self):
        self.running = False
        self.th.join(2)


# ---- checks ---------------------------------------------------------------

def check_loop(env, a):
    ref = in_process(env, a.method, a.seed, a.noise)
    port = free_port()
    node = env.start_node(a.method, a.seed)
    bridge = env.start_bridge(port)
    # The documented example subscriber watches the commands on Zenoh.
    example = env.start("example", [
        os.path.join(env.root, ".venv", "bin", "python"),
        os.path.join(env.root, "sim_host", "zenoh", "example_subscriber.py"),
        "--connect", "tcp/127.0.0.1:%d" % port])
    # It is on the network once the node's idle watchdog stops reach it.
    end = time.monotonic() + 15
    while "cmd seq -1 " not in env.text("example", "out"):
        expect(time.monotonic() < end, "the example subscriber received "
               "nothing in 15 s")
        time.sleep(0.05)
    t0 = time.monotonic()
    sim = env.start("sim", [env.sim, "--transport", "zenoh",
                            "--zenoh-endpoint", "tcp/127.0.0.1:%d" % port,
                            "--timeout", "10"] +
                    sim_args(a.method, a.seed, a.noise))
    try:
        rc = sim.wait(PROC_LIMIT_S)
    except subprocess.TimeoutExpired:
        raise Fail("spvs-sim over Zenoh did not finish")
    wall = time.monotonic() - t0
    expect(rc == 0, "spvs-sim over Zenoh exited %d: %s"
           % (rc, env.text("sim").strip()))
    over = last_json(env.text("sim", "out"), "the Zenoh run")
    expect(over.get("transport") == "zenoh", "the run says transport %r"
           % over.get("transport"))
    same_result(over, ref, "method %d seed %d" % (a.method, a.seed))

    last = "cmd seq %d " % (over["frames"] - 1)
    end = time.monotonic() + 3
    while last not in env.text("example", "out") and time.monotonic() < end:
        time.sleep(0.05)
    rc = env.stop(example, signal.SIGINT)
    expect(rc == 0, "the example subscriber exited %d on SIGINT" % rc)
    lines = [l for l in env.text("example", "out").splitlines()
             if l.startswith("cmd seq ") and not l.startswith("cmd seq -1 ")]
    seqs = set(int(l.split()[2]) for l in lines)
    expect(seqs == set(range(over["frames"])),
           "the example subscriber saw %d of the %d frames' commands"
           % (len(seqs), over["frames"]))
    final = [l for l in lines if l.startswith(last)]
    want_step = "step 4 " if ref["status"] == "converged" else "step "
    expect(final and want_step in final[-1],
           "the example subscriber's answer to the last frame: %r"
           % (final[-1] if final else None))

    expect(env.stop(bridge) == 0, "the bridge did not exit 0 on SIGTERM")
    expect(env.stop(node) == 0, "spvs-node did not exit 0 on SIGTERM")
    print("ok: method %d seed %d noise %g over Zenoh: %s, final error %s "
          "(x m, z m, phi deg), %d frames, %s; %.2f s wall; example "
          "subscriber saw %d commands, last %r"
          % (a.method, a.seed, a.noise, over["status"], over["final_error"],
             over["frames"], agreement(), wall, len(lines), final[-1]))


def check_restart(env, a):
    watchdog = 0.5
    ref = in_process(env, a.method, a.seed, 0)
    watch = LcmWatch()
    port = free_port()
    node = env.start_node(a.method, a.seed, watchdog)
    bridge = env.start_bridge(port)
    # A frame lost while the bridge is away is sent again every 0.1 s, for
    # up to 30 s per frame.
    sim = env.start("sim", [env.sim, "--transport", "zenoh",
                            "--zenoh-endpoint", "tcp/127.0.0.1:%d" % port,
                            "--timeout", "30"] + sim_args(a.method, a.seed, 0),
                    env={"SPVS_ZENOH_RESEND_S": "0.1"})
    kill_at = 40
    watch.wait_for(lambda c, m: any(x.seq >= kill_at for _, x in c), 30,
                   "the node to answer frame %d" % kill_at)
    rc = env.stop(bridge, within=5.0)
    t_kill = time.monotonic()
    expect(rc == 0, "the bridge exited %d on SIGTERM" % rc)
    expect(sim.poll() is None, "spvs-sim ended while the bridge was down")

    # The node's stop: the first watchdog command after the last answered
    # frame.  Wait long enough for two of them.
    def stops_after_kill(cmds, _m):
        s = [(t, x) for t, x in cmds if x.seq == -1 and t > t_kill]
        return s if len(s) >= 2 else None
    watch.wait_for(stops_after_kill, 5 * watchdog, "watchdog stops")
    cmds, _ = watch.snapshot()
    answered = [(t, x) for t, x in cmds if x.seq >= 0 and t <= t_kill + 0.2]
    expect(answered, "no answered frame before the bridge stopped")
    t_last, last = answered[-1]
    after = [(t, x) for t, x in cmds if t > t_last]
    t_stop, stop = after[0]
    expect(stop.seq == -1, "the first command after frame %d answers frame "
           "%d instead of being a stop" % (last.seq, stop.seq))
    delay = t_stop - t_last
    expect(stop.status == SPVS_E_STALE and stop.v == 0.0 and stop.w == 0.0,
           "the stop has status %d, v %g, w %g (want %d, 0, 0)"
           % (stop.status, stop.v, stop.w, SPVS_E_STALE))
    # The node's loop checks its watchdog every 50 ms; allow that and
    # scheduling on a loaded machine (arrival times are taken here, after
    # LCM and a Python thread).
    expect(0.8 * watchdog <= delay <= watchdog + 0.2,
           "the stop came %.3f s after the last command (watchdog %.2f s)"
           % (delay, watchdog))
    moving = [x for t, x in after if x.v != 0.0 or x.w != 0.0]
    expect(not moving, "a moving command went out while the bridge was down")

    # Restart on the same endpoint: the port reconnects, resends the frame
    # it is waiting on, and the run goes on.
    t_restart = time.monotonic()
    bridge2 = env.start_bridge(port, tag="bridge2")
    try:
        rc = sim.wait(PROC_LIMIT_S)
    except subprocess.TimeoutExpired:
        raise Fail("spvs-sim did not finish after the bridge restarted")
    expect(rc == 0, "spvs-sim exited %d: %s" % (rc, env.text("sim").strip()))
    over = last_json(env.text("sim", "out"), "the interrupted Zenoh run")
    same_result(over, ref, "interrupted run")
    cmds, _ = watch.snapshot()
    resumed = [t for t, x in cmds if x.seq > last.seq and t > t_restart]
    expect(resumed, "no frame was answered after the restart")
    expect("were sent again" in env.text("sim"),
           "spvs-sim did not report resending the lost frame")
    expect(env.stop(bridge2) == 0, "the restarted bridge did not exit 0")
    expect(env.stop(node) == 0, "spvs-node did not exit 0")
    watch.close()
    print("ok: bridge stopped after frame %d: node stop (v = w = 0, status "
          "%d) %.3f s after the last command (watchdog %.2f s); bridge back "
          "after %.2f s, run resumed %.2f s later and finished %s, final "
          "error %s, %s"
          % (last.seq, stop.status, delay, watchdog, t_restart - t_kill,
             resumed[0] - t_restart, over["status"], over["final_error"],
             agreement()))


def check_bad(env, a):
    import zenoh
    import spvs
    import spvs_zenoh_common as common
    watch = LcmWatch()
    port = free_port()
    node = env.start_node(3, 0)
    bridge = env.start_bridge(port, extra=["--robot", "r1"])
    cfg = common.zenoh_config(zenoh, "peer", [],
                              ["tcp/127.0.0.1:%d" % port], False)
    session = zenoh.open(cfg)
    try:
        answers = []
        lock = threading.Lock()

        def on_cmd(s):
            with lock:
                answers.append(spvs.cmd_t.decode(bytes(s.payload.to_bytes())))
        session.declare_subscriber("spvs/r1/cmd", on_cmd)
        pub = session.declare_publisher("spvs/r1/matches")
        end = time.monotonic() + 10
        while not pub.matching_status.matching:
            expect(time.monotonic() < end, "the bridge never subscribed to "
                   "spvs/r1/matches")
            time.sleep(0.02)

        good = spvs.matches_t()
        good.seq, good.utime, good.run_id, good.count = 1, 0, 77, 0
        good_bytes = good.encode()
        over = spvs.matches_t()
        over.seq, over.run_id, over.count = 2, 77, 300
        wrong_fp = bytearray(good_bytes)
        wrong_fp[0] ^= 0xFF
        bad = [("wrong size", good_bytes[:-1]),
               ("wrong size", good_bytes + b"\0"),
               ("wrong size", b""),
               ("wrong fingerprint", bytes(wrong_fp)),
               ("count 300 outside 0..256", over.encode()),
               ("wrong fingerprint", spvs.cmd_t().encode() +
                bytes(len(good_bytes) - 43))]
        # A good frame first proves the path is up (the first samples after
        # opening a session can be lost), then the bad ones, then a good one
        # again: it must still be relayed and answered.
        def answered(seq):
            with lock:
                return any(x.seq == seq for x in answers)
        end = time.monotonic() + 10
        while not answered(1):
            expect(time.monotonic() < end, "the first good frame was never "
                   "answered on spvs/r1/cmd")
            pub.put(good_bytes)
            time.sleep(0.2)
        _, before = watch.snapshot()
        for _, payload in bad:
            pub.put(payload)
        good.seq = 3
        pub.put(good.encode())
        end = time.monotonic() + 10
        while not answered(3):
            expect(time.monotonic() < end, "the good frame after the bad "
                   "ones was not answered: the bridge stopped relaying")
            time.sleep(0.02)
        time.sleep(0.2)
        _, after = watch.snapshot()
        new = [d for _, d in after[len(before):]]
        expect(new == [good.encode()],
               "LCM saw %d new SPVS_MATCHES messages (want exactly the good "
               "one): bad payloads got through" % len(new))
        expect(bridge.poll() is None, "the bridge died on bad payloads")
    finally:
        session.close()
    expect(env.stop(bridge) == 0, "the bridge did not exit 0")
    expect(env.stop(node) == 0, "spvs-node did not exit 0")
    watch.close()
    log = [l for l in env.text("bridge").splitlines() if "error:" in l]
    expect(len(log) == len(bad), "the bridge logged %d errors for %d bad "
           "payloads: %r" % (len(log), len(bad), log))
    for (why, _), line in zip(bad, log):
        expect(why in line and "spvs/r1/matches" in line,
               "error line %r does not say '%s'" % (line, why))
    expect("dropped 6 matches" in env.text("bridge"),
           "the bridge's exit line does not count 6 dropped matches")
    print("ok: %d bad payloads dropped with one logged error each (%s), "
          "none reached LCM, the next good frame was relayed and answered"
          % (len(bad), ", ".join(sorted(set(w for w, _ in bad)))))


def one_line_exit(env, name, argv, want_rc, want_text, env_extra=None,
                  within=20.0):
    t0 = time.monotonic()
    p = env.start(name, argv, env=env_extra)
    try:
        rc = p.wait(within)
    except subprocess.TimeoutExpired:
        raise Fail("%s did not exit within %.0f s" % (name, within))
    took = time.monotonic() - t0
    err = env.text(name).strip().splitlines()
    expect(rc == want_rc, "%s exited %d (want %d): %r" % (name, rc, want_rc,
                                                          err))
    expect(len(err) == 1 and want_text in err[0],
           "%s: want one stderr line with %r, got %r" % (name, want_text, err))
    return took, err[0]


def check_cli(env, a):
    port = free_port()
    ep = "tcp/127.0.0.1:%d" % port
    b = [env.bridge, "--lcm-url", LCM_URL, "--lcm-types", env.types]
    cases = [
        ("bad_robot", b + ["--robot", "a/b"], 2, "robot name"),
        ("bad_mode", b + ["--mode", "router"], 2, "invalid choice"),
        ("bad_endpoint", b + ["--listen", "127.0.0.1:7447"], 2,
         "tcp/HOST:PORT"),
        ("client_listens", b + ["--mode", "client", "--connect", ep,
                                "--listen", ep], 2, "does not listen"),
        ("unknown_option", b + ["--bogus"], 2, "unrecognized"),
        ("bad_types", b + ["--lcm-types", env.tmp], 1,
         "no generated spvs/matches_t.py"),
    ]
    for name, argv, rc, text in cases:
        one_line_exit(env, name, argv, rc, text)
    print("ok: %d bad bridge invocations: one line each, exit 2 or 1"
          % len(cases))

    # SIGTERM and SIGINT: the bridge closes its session and exits 0 at once,
    # idle or just started.
    for sig in (signal.SIGTERM, signal.SIGINT):
        br = env.start_bridge(port, tag="bridge_sig%d" % sig)
        time.sleep(1.5)
        t0 = time.monotonic()
        rc = env.stop(br, sig, within=3.0)
        expect(rc == 0, "the bridge exited %d on signal %d" % (rc, sig))
        print("ok: bridge exits 0 %.3f s after signal %d"
              % (time.monotonic() - t0, sig))

    sim = [env.sim, "--transport", "zenoh", "--zenoh-endpoint", ep,
           "--json", "--quiet", "--timeout", "1"]
    took, line = one_line_exit(env, "sim_no_bridge", sim, 1,
                               "nobody subscribes to spvs/robot0/matches")
    expect(took < 1 + 3 + 15, "no bridge: error after %.1f s" % took)
    print("ok: spvs-sim without a bridge: exit 1 after %.1f s: %s"
          % (took, line))

    # A port that dies, one that never starts, and bad settings.
    fake = os.path.join(env.tmp, "dying_port.py")
    with open(fake, "w") as f:
        f.write("import os, struct, sys\n"
                "os.write(1, b'R' + struct.pack('>I', 2) + b'ok')\n"
                "os.read(0, 4)\n"
                "sys.exit(3)\n")
    took, line = one_line_exit(env, "sim_port_dies", sim, 1,
                               "exit status 3",
                               {"SPVS_ZENOH_PORT": fake})
    print("ok: a port that dies mid-run: %s" % line)
    silent = os.path.join(env.tmp, "silent_port.py")
    with open(silent, "w") as f:
        f.write("import os, struct, time\n"
                "os.write(1, b'R' + struct.pack('>I', 2) + b'ok')\n"
                "time.sleep(60)\n")
    t0 = time.monotonic()
    took, line = one_line_exit(env, "sim_port_silent", sim + ["--timeout",
                                                              "0.5"], 1,
                               "no spvs/robot0/cmd for frame 0",
                               {"SPVS_ZENOH_PORT": silent,
                                "SPVS_ZENOH_RESEND_S": "0.1"})
    expect(took < 0.5 + 8, "a silent port was given up after %.1f s" % took)
    print("ok: a port that never answers: exit 1 after %.2f s" % took)
    for name, extra, text in (
            ("sim_no_python", {"SPVS_PYTHON": "/nonexistent/python"},
             "run scripts/setup_venv.sh"),
            ("sim_bad_robot", {"SPVS_ZENOH_ROBOT": "x/*"}, "SPVS_ZENOH_ROBOT"),
            ("sim_bad_resend", {"SPVS_ZENOH_RESEND_S": "-1"},
             "SPVS_ZENOH_RESEND_S"),
            ("sim_bad_mode", {"SPVS_ZENOH_MODE": "router"},
             "SPVS_ZENOH_MODE")):
        one_line_exit(env, name, sim, 1, text, extra)
    print("ok: missing venv and bad settings: exit 1 with one line each")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("check", choices=("loop", "restart", "bad", "cli"))
    p.add_argument("--build", required=True)
    p.add_argument("--root", required=True)
    p.add_argument("--method", type=int, default=3)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--noise", type=float, default=0.0)
    p.add_argument("--tol-m", type=float, default=0.0)
    p.add_argument("--tol-deg", type=float, default=0.0)
    a = p.parse_args()
    TOL["m"], TOL["deg"] = a.tol_m, a.tol_deg
    env = Env(a)
    try:
        {"loop": check_loop, "restart": check_restart, "bad": check_bad,
         "cli": check_cli}[a.check](env, a)
    except Fail as e:
        print("FAIL: %s" % e)
        env.cleanup()
        env.dump()
        return 1
    env.cleanup()
    return 0


if __name__ == "__main__":
    sys.exit(main())
