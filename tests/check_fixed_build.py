#!/usr/bin/env python3
"""In the fixed-point build (SPVS_FIXED=ON) spvs.h's pipeline is the Q
pipeline: spvs-sim's in-process run (spvs_update) and its `--transport
fixed` run (spvs_q_update called directly) must give the same result, to
the last digit of every figure, for each method.

usage: check_fixed_build.py SPVS_SIM
"""
import json
import subprocess
import sys

# A success (DESIGN.md section 6, docs/RESULTS.md): converged and home.
POS_TOL_M = 0.25
PHI_TOL_DEG = 0.5

RUN = ["--pose", "0.8,-2,-20", "--noise", "0.5", "--outliers", "0.1",
       "--seed", "3", "--json", "--quiet"]


def result(sim, method, transport):
    out = subprocess.run([sim, "--method", str(method), "--transport", transport]
                         + RUN, capture_output=True, text=True, timeout=120)
    if out.returncode != 0:
        sys.exit("spvs-sim --transport %s exited %d: %s"
                 % (transport, out.returncode, out.stderr.strip()))
    r = json.loads(out.stdout)
    if r.pop("transport") != transport:
        sys.exit("spvs-sim reports another transport than %s" % transport)
    return r


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    for method in (1, 2, 3):
        a = result(sys.argv[1], method, "inproc")
        b = result(sys.argv[1], method, "fixed")
        if a != b:
            sys.exit("method %d: spvs_update and spvs_q_update differ:\n%s\n%s"
                     % (method, json.dumps(a), json.dumps(b)))
        e = a["final_error"]
        if a["status"] != "converged":
            sys.exit("method %d: status %s (converged expected)" % (method, a["status"]))
        if not (abs(e["x_m"]) <= POS_TOL_M and abs(e["z_m"]) <= POS_TOL_M
                and abs(e["phi_deg"]) <= PHI_TOL_DEG):
            sys.exit("method %d: final error %.4f m, %.4f m, %.4f deg (limits %.2f m, %.1f deg)"
                     % (method, e["x_m"], e["z_m"], e["phi_deg"], POS_TOL_M, PHI_TOL_DEG))
        print("method %d: the same run on both (%s, %d frames, final error "
              "%.4f m, %.4f m, %.4f deg)" % (method, a["status"], a["frames"],
                                            e["x_m"], e["z_m"], e["phi_deg"]))


if __name__ == "__main__":
    main()
