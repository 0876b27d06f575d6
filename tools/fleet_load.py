#!/usr/bin/env python3
"""Load figures of spvs-fleet: frames per second and per-frame latency for
fleets of several sizes (docs/ZENOH.md, "Load").

For each fleet size and pacing it runs sim_host/zenoh/spvs-fleet with
--timing, so every robot's Zenoh port writes when it put each frame on
spvs/<robot>/matches and when the frame's command arrived on
spvs/<robot>/cmd (CLOCK_MONOTONIC).  From those:

  frames/s   answered frames of all robots / (last command - first frame);
             per robot: the median of each robot's frames / its own span
  latency    command received - frame published, first put of each seq
             (a resent frame counts from its first send), p50 and p99
  CPU/frame  CPU time of each kind of process while every robot is
             running (sampled from /proc every 20 ms, so start-up and
             shut-down are left out) / frames answered meanwhile

Pacing: "lockstep" runs every robot as fast as its loop allows (each frame
waits for its command: the fleet's capacity); "realtime" paces every robot
at its 0.1 s control period, as on a robot.

usage: tools/fleet_load.py --build DIR [--robots 1,4,16]
                           [--pacing lockstep,realtime] [--noise PX]
                           [--repeat K]
Prints a Markdown table row per run (CPU only where the window of all
robots running lasted 2 s or more: the kernel counts CPU in 10 ms ticks),
and one JSON line per run with --json.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FLEET = os.path.join(ROOT, "sim_host", "zenoh", "spvs-fleet")
# Starts cycled through by the robots: methods, poses (m, m, deg).
STARTS = ["3:-3,-10,-30", "1:-2,-8,20", "2:1,-9,10", "3:2,-12,-15",
          "1:4,-14,-25", "2:-1,-6,5", "3:0,-11,40", "1:-4,-10,35"]


def percentile(xs, q):
    xs = sorted(xs)
    if not xs:
        return float("nan")
    k = (len(xs) - 1) * q
    lo = int(k)
    hi = min(lo + 1, len(xs) - 1)
    return xs[lo] + (xs[hi] - xs[lo]) * (k - lo)


KINDS = (("spvs-node", "node"), ("bridge.py", "bridge"),
         ("sim_port.py", "port"), ("spvs-sim", "sim"), ("router.py", "router"))
TICKS = os.sysconf("SC_CLK_TCK")


def proc_table():
    """{pid: (ppid, kind or None, cpu seconds)} of every process."""
    out = {}
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % d) as f:
                st = f.read()
            with open("/proc/%s/cmdline" % d, "rb") as f:
                cmd = f.read().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        rest = st[st.rindex(")") + 2:].split()
        kind = next((k for pat, k in KINDS if pat in cmd), None)
        out[int(d)] = (int(rest[1]), kind,
                       (int(rest[11]) + int(rest[12])) / TICKS)
    return out


class CpuWatch:
    """Samples the CPU time of the fleet's processes by kind, from the
    moment every robot has answered a frame (cmd.csv in the work folder)
    to the last sample in which all of them still run."""

    def __init__(self, root_pid, work, n):
        self.root, self.work, self.n = root_pid, work, n
        self.first = None   # {pid: cpu} at the start of the window
        self.last = None
        self.t0 = self.t1 = None
        self.kind = {}
        self.done = False
        self.th = threading.Thread(target=self.loop, daemon=True)
        self.th.start()

    def answering(self):
        """Every robot has had a frame answered (its cmd.csv)."""
        dirs = [d for d in os.listdir(self.work) if d[:2].isdigit()]
        if len(dirs) != self.n:
            return False
        for d in dirs:
            try:
                with open(os.path.join(self.work, d, "cmd.csv")) as f:
                    if not any(l.split(",")[1] not in ("seq", "-1")
                               for l in f.read().splitlines()):
                        return False
            except OSError:
                return False
        return True

    def complete(self, mine):
        """Every robot's four processes are there (none is ending)."""
        count = {}
        for kind, _ in mine.values():
            count[kind] = count.get(kind, 0) + 1
        return all(count.get(k, 0) == self.n
                   for k in ("node", "bridge", "sim", "port"))

    def loop(self):
        while not self.done:
            tab = proc_table()
            kids = {}
            for c, (pp, _, _) in tab.items():
                kids.setdefault(pp, []).append(c)
            mine, todo = {}, [self.root]
            while todo:
                for c in kids.get(todo.pop(), []):
                    if c not in mine:
                        mine[c] = tab[c][1:]
                        todo.append(c)
            t = time.monotonic()
            if not self.complete(mine):
                if self.first is not None and self.last is not None:
                    return
            elif self.first is None:
                if self.answering():
                    self.first, self.t0 = mine, t
            else:
                self.last, self.t1 = mine, t
            time.sleep(0.01)

    def per_kind(self):
        """CPU seconds by kind within the window, and the window."""
        self.done = True
        self.th.join(2)
        if self.first is None or self.last is None:
            return None, None, None
        use = {}
        for pid, (kind, cpu) in self.last.items():
            if kind and pid in self.first:
                use[kind] = use.get(kind, 0.0) + cpu - self.first[pid][1]
        return use, self.t0, self.t1


def read_timing(path):
    put, got = {}, {}
    with open(path) as f:
        for line in f:
            kind, seq, t = line.split()
            seq, t = int(seq), float(t)
            if kind == "M":
                put.setdefault(seq, t)
            elif kind == "C" and seq >= 0:
                got.setdefault(seq, t)
    return put, got


def run(build, n, pacing, noise):
    work = tempfile.mkdtemp(prefix="spvs-fleet-load-")
    argv = [FLEET, "--build", build, "--port", "0", "--workdir", work,
            "--timing", "--json", "--quiet", "--noise", str(noise),
            "--max-time", "900"]
    for i in range(n):
        argv += ["--robot", "r%02d:%s:%d" % (i, STARTS[i % len(STARTS)],
                                             100 + i)]
    if pacing == "realtime":
        argv.append("--realtime")
    load0 = os.getloadavg()[0]
    os.makedirs(work, exist_ok=True)
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    watch = CpuWatch(proc.pid, work, n)
    stdout, stderr = proc.communicate()
    use, w0, w1 = watch.per_kind()

    class Q:
        returncode = proc.returncode
    q = Q()
    q.stdout, q.stderr = stdout, stderr
    objs = [json.loads(l) for l in q.stdout.splitlines() if l.strip()]
    if q.returncode != 0 or not objs or "fleet" not in objs[-1]:
        shutil.rmtree(work, ignore_errors=True)
        raise SystemExit("fleet_load: spvs-fleet exited %d: %s"
                         % (q.returncode, q.stderr.strip()[-300:]))
    robots, fleet = objs[:-1], objs[-1]["fleet"]
    lat, t_first, t_last, frames, in_window = [], [], [], 0, 0
    rates = []
    for i, r in enumerate(robots):
        put, got = read_timing(os.path.join(work, "%02d-%s" % (i, r["robot"]),
                                            "timing.txt"))
        lat += [got[s] - put[s] for s in got if s in put]
        t_first.append(min(put.values()))
        t_last.append(max(got.values()))
        frames += len(got)
        rates.append(len(got) / (t_last[-1] - t_first[-1]))
        if w0 is not None:
            in_window += sum(w0 <= t <= w1 for t in got.values())
    span = max(t_last) - min(t_first)
    cpu = {k: (use.get(k, 0.0) / in_window if in_window else float("nan"))
           for _, k in KINDS} if use else {k: float("nan") for _, k in KINDS}
    shutil.rmtree(work, ignore_errors=True)
    return {"robots": n, "pacing": pacing, "frames": frames,
            "span_s": round(span, 3), "fps": round(frames / span, 1),
            "fps_per_robot": round(percentile(rates, 0.5), 1),
            "latency_ms": {"p50": round(1e3 * percentile(lat, 0.5), 3),
                           "p99": round(1e3 * percentile(lat, 0.99), 3),
                           "max": round(1e3 * max(lat), 3)},
            "cpu_us_per_frame": {k: round(1e6 * v, 1)
                                 for k, v in cpu.items()},
            "cpu_window": {"s": round(w1 - w0, 3) if w0 else None,
                           "frames": in_window},
            "converged": fleet["converged"], "load_avg_1min": load0}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--build", required=True,
                   help="CMake build folder (spvs-sim, spvs-node, lcm types)")
    p.add_argument("--robots", default="1,4,16",
                   help="fleet sizes, comma-separated (1,4,16)")
    p.add_argument("--pacing", default="lockstep,realtime",
                   help="lockstep, realtime or both (both)")
    p.add_argument("--noise", type=float, default=0.5,
                   help="image noise of every robot, px (0.5)")
    p.add_argument("--repeat", type=int, default=1,
                   help="runs of each configuration (1)")
    p.add_argument("--json", action="store_true")
    a = p.parse_args()
    sizes = [int(x) for x in a.robots.split(",")]
    pacings = a.pacing.split(",")
    rows = []
    print("| robots | pacing | frames/s (all) | per robot | latency p50 "
          "(ms) | p99 (ms) | CPU us/frame: node / bridge / sim / port / "
          "router | load avg |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for pacing in pacings:
        for n in sizes:
            for _ in range(a.repeat):
                r = run(os.path.abspath(a.build), n, pacing, a.noise)
                rows.append(r)
                c = r["cpu_us_per_frame"]
                if (r["cpu_window"]["s"] or 0.0) >= 2.0:
                    cpu = "%.0f / %.0f / %.0f / %.0f / %.0f" % tuple(
                        c[k] for k in ("node", "bridge", "sim", "port",
                                       "router"))
                else:
                    cpu = "-"
                print("| %d | %s | %.0f | %.1f | %.2f | %.2f | %s | %.1f |"
                      % (n, pacing, r["fps"], r["fps_per_robot"],
                         r["latency_ms"]["p50"], r["latency_ms"]["p99"], cpu,
                         r["load_avg_1min"]), flush=True)
                if a.json:
                    print(json.dumps(r), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
