#!/usr/bin/env python3
"""tools/experiments.py's arrival check (docs/CONTROL.md), judged on a
stand-in for spvs-sim whose results are known:

- the runs are the six Figure 5 poses x three methods x SEEDS seeds, twice
  (0 and 20 % mismatches), on seeds seed0 .. seed0 + SEEDS - 1, where
  --seed0 (default 1000) chooses seed0;
- a run that says "converged" outside 0.25 m / 0.5 deg is counted in its
  method's row and makes the exit status 1; with none the status is 0;
- --latency and --accel-limit reach every run, and none is given without
  them;
- --seed0 without --arrival, or out of spvs-sim's range, and a negative
  latency or a malformed acceleration limit, are misuse: exit 2 and a
  one-line message.

The stand-in logs its --method and --seed and reports Method II on the
second seed as converged 0.5 m from the target, every other run as
converged 1 mm from it.

usage: check_experiments_arrival.py EXPERIMENTS_PY
"""
import os
import re
import stat
import subprocess
import sys
import tempfile

FAKE_SIM = r'''#!/usr/bin/env python3
import json, os, sys
opts = dict(a[2:].split("=", 1) for a in sys.argv[1:] if a.startswith("--") and "=" in a)
with open(os.environ["ARRIVAL_LOG"], "a") as f:
    f.write("%s %s %s %s\n" % (opts["method"], opts["seed"], opts.get("latency", "-"),
                               opts.get("accel-limit", "-")))
far = opts["method"] == "2" and int(opts["seed"]) == int(os.environ["ARRIVAL_FAR_SEED"])
x = 0.5 if far else 0.001
print(json.dumps({"method": int(opts["method"]), "status": "converged", "reason": None,
                  "final_error": {"x_m": x, "z_m": 0.0, "phi_deg": 0.0}, "time_s": 1.0}))
'''

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL: " + what)


def run(exp, sim, log, far_seed, *args):
    env = dict(os.environ, ARRIVAL_LOG=log, ARRIVAL_FAR_SEED=str(far_seed))
    if os.path.exists(log):
        os.remove(log)
    p = subprocess.run([sys.executable, exp, "--sim", sim, "--jobs", "2"] + list(args),
                       capture_output=True, text=True, env=env, timeout=120)
    calls = []
    if os.path.exists(log):
        with open(log) as f:
            lines = [line.split() for line in f]
        calls = [(int(w[0]), int(w[1])) for w in lines]
        robots.clear()
        robots.extend((w[2], w[3]) for w in lines)
    return p, calls


# The robot options each run of the last call got: (latency, accel-limit),
# "-" where none was given.
robots = []


def rows(stdout):
    """{(method name, mismatches): (runs, converged outside)} of the table."""
    out = {}
    for line in stdout.splitlines():
        m = re.match(r"\| (Method \w+) \| (\d+) % \| (\d+) \|.*\| (\d+) \| [^|]* \| [\d.]+ \| [^|]* \|$",
                     line)
        if m:
            out[(m.group(1), int(m.group(2)))] = (int(m.group(3)), int(m.group(4)))
    return out


def main():
    if len(sys.argv) != 2:
        print(__doc__.strip().splitlines()[-1])
        return 2
    exp = sys.argv[1]
    with tempfile.TemporaryDirectory(prefix="spvs-arrival-check-") as tmp:
        sim = os.path.join(tmp, "fake-spvs-sim")
        with open(sim, "w") as f:
            f.write(FAKE_SIM)
        os.chmod(sim, os.stat(sim).st_mode | stat.S_IXUSR)
        log = os.path.join(tmp, "calls.log")

        # Seeds 7000 and 7001: 3 methods x 6 poses x 2 seeds x 2 cases.
        p, calls = run(exp, sim, log, 7001, "--arrival", "2", "--seed0", "7000")
        check(p.returncode == 1, "a converged run 0.5 m away gives exit 1 (got %d: %s)"
              % (p.returncode, p.stderr.strip()[-200:]))
        check(len(calls) == 72, "72 runs (got %d)" % len(calls))
        check(sorted({s for _, s in calls}) == [7000, 7001],
              "seeds 7000 and 7001 (got %s)" % sorted({s for _, s in calls}))
        check(sorted({m for m, _ in calls}) == [1, 2, 3], "methods 1, 2, 3")
        t = rows(p.stdout)
        check(len(t) == 6, "six table rows (got %d)" % len(t))
        for (name, mis), (n, outside) in sorted(t.items()):
            check(n == 12, "%s, %d %%: 12 runs (got %d)" % (name, mis, n))
            want = 6 if name == "Method II" else 0
            check(outside == want, "%s, %d %%: %d converged outside (got %d)"
                  % (name, mis, want, outside))

        # The default first seed is 1000; no run far away: exit 0.
        p, calls = run(exp, sim, log, 99, "--arrival", "1")
        check(p.returncode == 0, "no false claim gives exit 0 (got %d)" % p.returncode)
        check({s for _, s in calls} == {1000}, "default seed 1000 (got %s)"
              % sorted({s for _, s in calls}))

        # No robot options by default; --latency and --accel-limit reach
        # every run.
        check(set(robots) == {("-", "-")}, "no robot options by default (got %s)" % set(robots))
        p, calls = run(exp, sim, log, 99, "--arrival", "1", "--latency", "0.2",
                       "--accel-limit", "0.5,1")
        check(p.returncode == 0 and len(calls) == 36 and set(robots) == {("0.2", "0.5,1")},
              "--latency 0.2 --accel-limit 0.5,1 in all 36 runs (got %d, %d, %s)"
              % (p.returncode, len(calls), set(robots)))

        # The last seed spvs-sim takes, 2^32 - 1, as the last run's.
        p, calls = run(exp, sim, log, 99, "--arrival", "2", "--seed0", "4294967294")
        check(p.returncode == 0 and {s for _, s in calls} == {4294967294, 4294967295},
              "seeds up to 2^32 - 1 (got %d, %s)" % (p.returncode, sorted({s for _, s in calls})))

        # Misuse.
        for args, msg in ((["--seed0", "5"], "--seed0 goes with --arrival"),
                          (["--seed0", "1000"], "--seed0 goes with --arrival"),
                          (["--arrival", "2", "--seed0", "-1"], "--seed0 must be"),
                          (["--arrival", "2", "--seed0", "4294967295"], "--seed0 must be"),
                          (["--arrival", "1", "--latency", "-0.1"], "--latency must be"),
                          (["--arrival", "1", "--accel-limit", "0.5"], "--accel-limit must be"),
                          (["--arrival", "1", "--accel-limit", "0.5,0"], "--accel-limit must be")):
            p, calls = run(exp, sim, log, 99, *args)
            check(p.returncode == 2 and msg in p.stderr and not calls,
                  "%s: exit 2, '%s', no run (got %d: %s)"
                  % (" ".join(args), msg, p.returncode, p.stderr.strip()))
    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    print("arrival check: seeds, counts and exit statuses as expected")
    return 0


if __name__ == "__main__":
    sys.exit(main())
