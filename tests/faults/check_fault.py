#!/usr/bin/python3
"""check_fault.py SCENARIO DIR - the assertions of one transport-fault run.

DIR holds what run_fault.sh wrote: sim.out (spvs-sim --json, last line),
trace.csv (one row per frame: t, pose, the command acted on), relay.out
(spvs-lcm-faults counts) and node.err.

Every scenario: spvs-sim must report "converged" with the final pose error
inside the bounds below, and the relay must have injected the faults it was
asked for (so a run in which nothing happened cannot pass).
pause: the robot must also have kept its last command for the first frames
of the pause (it was moving) and then stopped on the node's watchdog: after
the watchdog time it moves less than PAUSE_MAX_MOVE_M and turns less than
PAUSE_MAX_TURN_DEG until the frames come back.
pause_no_watchdog: the same pause with the node's watchdog and the base's
timeout at 30 s; the robot must be seen moving more than PAUSE_DRIFT_M after
the watchdog time (the pause check above detects drift when there is some).
Prints one line with the figures (docs/ROBUSTNESS.md quotes them).
"""
import csv
import json
import math
import os
import sys

# Final-error bounds.  The fault-free loop ends within 1 cm and 0.05 deg of
# the target; the faults may cost a little, never a drift.
MAX_XZ_M = 0.05
MAX_PHI_DEG = 0.5
DT_S = 0.1
WATCHDOG_S = 0.5
# After the watchdog time (plus a period for the stop to be acted on and
# the node's 50 ms poll), the robot stands still.
SETTLE_S = WATCHDOG_S + DT_S + 0.1
PAUSE_MAX_MOVE_M = 0.03
PAUSE_MAX_TURN_DEG = 0.5
# Before the watchdog it keeps driving on the last command.
PAUSE_MIN_MOVE_BEFORE_M = 0.02
# Without a watchdog the robot drives on through the pause.
PAUSE_DRIFT_M = 0.1


def relay_counts(path):
    with open(path) as f:
        words = f.read().split()
    if not words or words[0] != "lcm_faults:":
        return {}
    return {words[i]: int(words[i + 1]) for i in range(1, len(words) - 1, 2)}


def main():
    scenario, work = sys.argv[1], sys.argv[2]
    failures = []
    with open(os.path.join(work, "sim.out")) as f:
        lines = [ln for ln in f.read().splitlines() if ln.strip()]
    res = json.loads(lines[-1])
    err = res["final_error"]
    counts = relay_counts(os.path.join(work, "relay.out"))
    with open(os.path.join(work, "trace.csv")) as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]

    if res["status"] != "converged":
        failures.append("status %s (%s)" % (res["status"], res.get("reason")))
    if not (abs(err["x_m"]) < MAX_XZ_M and abs(err["z_m"]) < MAX_XZ_M):
        failures.append("final position error (%.4f, %.4f) m over %.3f m"
                        % (err["x_m"], err["z_m"], MAX_XZ_M))
    if not abs(err["phi_deg"]) < MAX_PHI_DEG:
        failures.append("final heading error %.3f deg over %.2f deg"
                        % (err["phi_deg"], MAX_PHI_DEG))

    # The faults must really have happened.
    need = {"drop": "dropped", "delay": "delayed", "dup_reorder": "duplicated",
            "time_back": "time_back", "pause": "paused",
            "pause_no_watchdog": "paused"}
    if not counts:
        failures.append("no counts from spvs-lcm-faults")
    elif scenario in need and counts.get(need[scenario], 0) == 0:
        failures.append("the relay injected no %s frames" % need[scenario])
    if scenario == "dup_reorder" and counts.get("reordered", 0) == 0:
        failures.append("the relay reordered no frames")

    extra = ""
    if scenario.startswith("pause") and counts:
        first, last = counts["pause_first"], counts["pause_last"]
        by_frame = {int(round(r["t"] / DT_S)): r for r in rows}
        settle = first + int(math.ceil(SETTLE_S / DT_S))
        if first < 0 or last < settle + 5 or any(
                k not in by_frame for k in (first, settle, last)):
            failures.append("pause frames %d..%d not in the trace" % (first, last))
        else:
            a, b, c = by_frame[first], by_frame[settle], by_frame[last]
            before = math.hypot(b["x"] - a["x"], b["z"] - a["z"])
            moved = math.hypot(c["x"] - b["x"], c["z"] - b["z"])
            turned = abs(c["phi_deg"] - b["phi_deg"])
            extra = (" pause frames %d..%d: %.3f m before the watchdog, then "
                     "%.4f m and %.3f deg in %.1f s"
                     % (first, last, before, moved, turned, (last - settle) * DT_S))
            if not before > PAUSE_MIN_MOVE_BEFORE_M:
                failures.append("the robot was not moving when the pause began "
                                "(%.3f m): the scenario shows nothing" % before)
            if scenario == "pause_no_watchdog":
                if not moved > PAUSE_DRIFT_M:
                    failures.append("without a watchdog the robot should have "
                                    "driven on, but moved only %.4f m" % moved)
            elif not (moved < PAUSE_MAX_MOVE_M and turned < PAUSE_MAX_TURN_DEG):
                failures.append("the robot drifted during the pause: %.4f m, "
                                "%.3f deg after the watchdog" % (moved, turned))

    if scenario == "restart":
        steps = [int(r["step"]) for r in rows]
        # The new node starts from step 1: the step goes back at least once.
        back = sum(1 for i in range(1, len(steps))
                   if 1 <= steps[i] < steps[i - 1] <= 3)
        extra = " step went back %d time(s) after the restart" % back
        if back == 0:
            failures.append("no restart seen: the step never went back")

    print("fault %s: %s, final error x %.4f m, z %.4f m, phi %.3f deg, "
          "time %.1f s, frames %d, relay %s%s"
          % (scenario, res["status"], err["x_m"], err["z_m"], err["phi_deg"],
             res["time_s"], res.get("frames", len(rows)),
             " ".join("%s=%d" % kv for kv in counts.items()
                      if kv[0] not in ("pause_first", "pause_last")), extra))
    if failures:
        print("FAIL: " + "; ".join(failures))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
