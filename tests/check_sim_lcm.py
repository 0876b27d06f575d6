#!/usr/bin/python3
"""The same run in process and across LCM gives the same result
(DESIGN.md section 5).

usage: check_sim_lcm.py SPVS_SIM SPVS_NODE METHOD SEED NOISE

Runs spvs-node and `spvs-sim --transport lcm` inside a private network
namespace that has only loopback (multicast routed to lo, ttl=0), then the
same settings in process, and compares the JSON results field by field.
Exit 77 (skipped) when this machine cannot make such a namespace.
"""
import json
import shlex
import subprocess
import sys

SKIP = 77


def last_json(text, what):
    lines = [l for l in text.splitlines() if l.strip()]
    if not lines:
        print("FAIL: %s printed nothing" % what)
        sys.exit(1)
    return json.loads(lines[-1])


def main():
    sim, node, method, seed, noise = sys.argv[1:6]
    common = ["--method", method, "--seed", seed, "--noise", noise, "--json",
              "--quiet"]
    probe = subprocess.run(["unshare", "-r", "-n", "true"],
                           capture_output=True)
    if probe.returncode != 0:
        print("skipped: cannot create a network namespace")
        sys.exit(SKIP)
    script = (
        "ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 77; "
        "%s --method %s --seed %s --log-level 0 & NODE=$!; sleep 0.3; "
        "%s --transport lcm --timeout 5 %s; RC=$?; kill $NODE; wait $NODE; "
        "exit $RC" % (shlex.quote(node), method, seed, shlex.quote(sim),
                      " ".join(common)))
    p = subprocess.run(["unshare", "-r", "-n", "sh", "-c", script],
                       capture_output=True, text=True, timeout=240)
    if p.returncode == SKIP:
        print("skipped: no multicast route on loopback")
        sys.exit(SKIP)
    if p.returncode != 0:
        print("FAIL: LCM run exited %d: %s" % (p.returncode, p.stderr.strip()))
        sys.exit(1)
    over_lcm = last_json(p.stdout, "the LCM run")
    q = subprocess.run([sim] + common, capture_output=True, text=True,
                       timeout=240)
    in_proc = last_json(q.stdout, "the in-process run")
    for key in ("status", "reason", "final_error", "time_s", "frames",
                "steps"):
        if over_lcm.get(key) != in_proc.get(key):
            print("FAIL: %s differs: LCM %r, in process %r" %
                  (key, over_lcm.get(key), in_proc.get(key)))
            sys.exit(1)
    print("ok: method %s seed %s noise %s: %s, final error %s, both ways" %
          (method, seed, noise, in_proc["status"], in_proc["final_error"]))


if __name__ == "__main__":
    main()
