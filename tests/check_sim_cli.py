#!/usr/bin/python3
"""Checks of the spvs-sim command line contract (DESIGN.md section 5).

usage: check_sim_cli.py MODE -- COMMAND [ARGS...]

MODE
  json       exit 0; the last stdout line is one JSON object with the required
             keys, status "converged" and a final error under 0.05 m / 0.2 deg,
             and an "arrival" object whose figures passed the check
  usage      exit 2; stderr is exactly one line starting "spvs-sim: "
  help       exit 0; stdout describes every option of the contract
  failed     exit 0 (the run took place); status "failed" with a reason
  timeout    exit 0; status "timeout", the robot never moved, and the reason
             "too_few_matches" (the last frame's status)
  files      with --trace T --record R in COMMAND: exit 0, and T has one row
             per frame of the JSON result, R one frame per frame, both ending
             on step 4 (converged)
"""
import json
import math
import struct
import subprocess
import sys

REQUIRED = ("method", "status", "final_error", "time_s", "reason", "frames",
            "steps", "seed")
CONTRACT_OPTIONS = ("--method", "--pose", "--normal", "--distance", "--noise",
                    "--outliers", "--drift", "--focal-mm", "--pp-offset",
                    "--seed", "--json")


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run(cmd):
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        fail("command did not finish in 120 s: %s" % " ".join(cmd))
    return p


def last_json(p):
    lines = [l for l in p.stdout.splitlines() if l.strip()]
    if not lines:
        fail("no stdout")
    try:
        obj = json.loads(lines[-1])
    except ValueError as e:
        fail("last stdout line is not JSON (%s): %r" % (e, lines[-1][:200]))
    if not isinstance(obj, dict):
        fail("last stdout line is not a JSON object")
    for k in REQUIRED:
        if k not in obj:
            fail("JSON lacks key %r: %s" % (k, lines[-1][:300]))
    for k in ("x_m", "z_m", "phi_deg"):
        if not isinstance(obj["final_error"].get(k), (int, float)):
            fail("final_error.%s missing or not a number" % k)
    return obj


def check_converged(obj):
    fe = obj["final_error"]
    if obj["status"] != "converged":
        fail("status %r (reason %r), expected converged" %
             (obj["status"], obj["reason"]))
    if abs(fe["x_m"]) >= 0.05 or abs(fe["z_m"]) >= 0.05 or \
            abs(fe["phi_deg"]) >= 0.2:
        fail("final error too large: %s" % fe)
    steps = [s["step"] for s in obj["steps"]]
    if steps != [1, 2, 3]:
        fail("steps %s, expected 1, 2, 3" % steps)
    prev_end = 0.0
    for s in obj["steps"]:
        if s["end_s"] is None or not (prev_end <= s["start_s"] <= s["end_s"]):
            fail("step times out of order: %s" % obj["steps"])
        prev_end = s["end_s"]
    if not math.isclose(obj["steps"][-1]["end_s"], obj["time_s"]):
        fail("step 3 ends at %s, run at %s" % (obj["steps"][-1]["end_s"],
                                               obj["time_s"]))


ARRIVAL_KEYS = ("statistic", "threshold", "lateral_px", "lateral_sd_px",
                "depth_px", "depth_sd_px", "h13_px", "h13_sd_px", "corner_px",
                "parallax_px", "frames", "reentries", "next_step")
# The check's threshold, arrival_k, and the least standard deviation
# (SPVS_CTL_ARRIVAL_SD_MIN_MPX), by default (params.c, spvs_config.h); the
# dead zones each direction's residual may lie in without counting
# (arrival_resolution_px for the depth, tol_h13_px for h13, four times
# arrival_resolution_px for the horizontal parallax).
ARRIVAL_K = 3.0
ARRIVAL_SD_MIN_PX = 0.01
ARRIVAL_ZONE_PX = {"lateral": 2.0, "depth": 0.5, "h13": 0.5}
# The arrival check's parallax limit (control_steps.inc, arrival_decide):
# SPVS_CTL_ARRIVAL_PARALLAX_X100 / 100 x 1.665 x arrival_sigma_px, with the
# defaults 150 and 1 px.
ARRIVAL_PARALLAX_MAX_PX = 1.5 * 1.665 * 1.0
# The figures are printed with 6 significant digits (and the fixed-point
# core rounds its own): ratios are compared with this relative slack.
ARRIVAL_REL = 1e-3


def check_arrival(obj):
    """A converged run's last check accepted: its statistic is within the
    threshold, and each direction's residual within that many of its
    standard deviations (docs/CONTROL.md, "A verified arrival")."""
    a = obj.get("arrival")
    if not isinstance(a, dict):
        fail("JSON lacks the arrival object: %r" % a)
    for k in ARRIVAL_KEYS:
        if not isinstance(a.get(k), (int, float)):
            fail("arrival.%s missing or not a number: %s" % (k, a))
    if a["threshold"] != ARRIVAL_K:
        fail("arrival threshold %g, want arrival_k's default %g"
             % (a["threshold"], ARRIVAL_K))
    if not 0.0 <= a["statistic"] <= a["threshold"]:
        fail("converged with statistic %g over its threshold %g"
             % (a["statistic"], a["threshold"]))
    # The statistic is the most sd a residual lies beyond its dead zone, so
    # no direction's exceeds it, and no sd is under the least.
    for d in ("lateral", "depth", "h13"):
        res, sd = a[d + "_px"], a[d + "_sd_px"]
        if not sd >= ARRIVAL_SD_MIN_PX * (1.0 - ARRIVAL_REL):
            fail("arrival %s sd %g px under the least sd %g"
                 % (d, sd, ARRIVAL_SD_MIN_PX))
        beyond = max(0.0, abs(res) - ARRIVAL_ZONE_PX[d])
        if not beyond / sd <= a["statistic"] * (1.0 + ARRIVAL_REL) + 1e-4:
            fail("arrival %s %g px, sd %g px: over the statistic %g"
                 % (d, res, sd, a["statistic"]))
    # -1: no remembered off-plane point was seen over the hold.
    par = a["parallax_px"]
    if not (par == -1 or 0.0 <= par <= ARRIVAL_PARALLAX_MAX_PX):
        fail("converged with off-plane parallax %g px (limit %g px, -1 none)"
             % (par, ARRIVAL_PARALLAX_MAX_PX))
    if a["frames"] < 20 or a["next_step"] != 0:
        fail("converged after %d frames averaged, next step %d"
             % (a["frames"], a["next_step"]))


def option_value(cmd, name):
    i = cmd.index(name)
    return cmd[i + 1]


def read_record(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"SPVSREC1":
        fail("recording does not start with SPVSREC1")
    pos, frames = 8, []
    while pos < len(data):
        if pos + 14 > len(data):
            fail("recording ends inside a frame header")
        seq, t, n = struct.unpack_from("<IdH", data, pos)
        pos += 14 + 18 * n
        if pos + 11 > len(data):
            fail("recording ends inside frame %d" % seq)
        v, w, status, step = struct.unpack_from("<ffhB", data, pos)
        pos += 11
        frames.append((seq, t, n, v, w, status, step))
    return frames


def main():
    if len(sys.argv) < 4 or sys.argv[2] != "--":
        print(__doc__)
        sys.exit(2)
    mode, cmd = sys.argv[1], sys.argv[3:]
    p = run(cmd)
    if mode == "json":
        if p.returncode != 0:
            fail("exit %d, expected 0; stderr: %s" % (p.returncode, p.stderr))
        obj = last_json(p)
        check_converged(obj)
        check_arrival(obj)
    elif mode == "failed":
        if p.returncode != 0:
            fail("exit %d, expected 0 for a failed run" % p.returncode)
        obj = last_json(p)
        if obj["status"] != "failed" or not isinstance(obj["reason"], str) \
                or not obj["reason"]:
            fail("status %r reason %r, expected failed with a reason" %
                 (obj["status"], obj["reason"]))
    elif mode == "timeout":
        if p.returncode != 0:
            fail("exit %d, expected 0 for a run that timed out" % p.returncode)
        obj = last_json(p)
        if obj["status"] != "timeout" or obj["reason"] != "too_few_matches":
            fail("status %r reason %r, expected timeout with too_few_matches" %
                 (obj["status"], obj["reason"]))
        if obj["steps"][0].get("end_s") is not None or obj.get("path_m", 0) != 0:
            fail("the robot moved without an estimate: %s" % obj)
    elif mode == "usage":
        if p.returncode != 2:
            fail("exit %d, expected 2" % p.returncode)
        lines = p.stderr.splitlines()
        if len(lines) != 1:
            fail("stderr has %d lines, expected 1: %r" % (len(lines), p.stderr))
        if not lines[0].startswith("spvs-sim: "):
            fail("stderr line does not start with 'spvs-sim: ': %r" % lines[0])
        if p.stdout:
            fail("a usage error printed to stdout: %r" % p.stdout[:200])
    elif mode == "help":
        if p.returncode != 0:
            fail("exit %d, expected 0" % p.returncode)
        for opt in CONTRACT_OPTIONS:
            if opt not in p.stdout:
                fail("--help does not mention %s" % opt)
    elif mode == "files":
        if p.returncode != 0:
            fail("exit %d, expected 0; stderr: %s" % (p.returncode, p.stderr))
        obj = last_json(p)
        check_converged(obj)
        with open(option_value(cmd, "--trace")) as f:
            rows = [l.rstrip("\n").split(",") for l in f if l.strip()]
        header = rows[0]
        if header[:8] != ["t", "x", "z", "phi_deg", "v", "w", "step", "status"] \
                or len(header) != 18:
            fail("unexpected trace header %s" % header)
        body = rows[1:]
        if len(body) != obj["frames"]:
            fail("trace has %d rows, JSON says %d frames" %
                 (len(body), obj["frames"]))
        if any(len(r) != 18 for r in body):
            fail("a trace row does not have 18 columns")
        if int(body[-1][6]) != 4:
            fail("last trace row is step %s, expected 4" % body[-1][6])
        # The last row's pose is the final pose of the run.
        fe = obj["final_error"]
        if abs(float(body[-1][1]) - fe["x_m"]) > 1e-5 or \
                abs(float(body[-1][2]) - fe["z_m"]) > 1e-5:
            fail("last trace pose differs from the JSON final error")
        frames = read_record(option_value(cmd, "--record"))
        if len(frames) != obj["frames"]:
            fail("recording has %d frames, JSON says %d" %
                 (len(frames), obj["frames"]))
        if [fr[0] for fr in frames] != list(range(len(frames))):
            fail("recording sequence numbers are not 0, 1, 2, ...")
        if frames[-1][6] != 4 or frames[0][2] < 100:
            fail("recording: last step %d, first frame %d matches" %
                 (frames[-1][6], frames[0][2]))
        # Commands agree between the two outputs (trace v column).
        for fr, row in zip(frames, body):
            if abs(fr[3] - float(row[4])) > 1e-4 * max(1.0, abs(fr[3])):
                fail("frame %d: v %g in the recording, %s in the trace" %
                     (fr[0], fr[3], row[4]))
    else:
        fail("unknown mode %r" % mode)
    print("ok: %s" % mode)


if __name__ == "__main__":
    main()
