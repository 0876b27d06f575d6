#!/usr/bin/env bash
# The accelerated build and the reference path give the same closed loop:
# spvs-sim from a build with the accelerators (firmware/src/accel,
# firmware/src/fixed/accel) and from one with SPVS_ACCEL=OFF run every
# method, with noise and mismatches, from four start poses.
#   tests/compare_layouts.sh SIM_ACCEL SIM_REFERENCE
#       the same --json summary and the same per-frame trace, bit for bit
#       (the float core, and the fixed-point core's inlier count);
#   tests/compare_layouts.sh SIM_ACCEL SIM_REFERENCE TOL_M TOL_DEG
#       the same status, reason, frames and step switch times, and final
#       errors within TOL_M metres and TOL_DEG degrees of each other (the
#       fixed-point core, whose fast sums round otherwise than the exact
#       ones).
set -euo pipefail
if [ $# -ne 2 ] && [ $# -ne 4 ]; then
  echo "usage: $0 SIM_ACCEL SIM_REFERENCE [TOL_M TOL_DEG]" >&2
  exit 2
fi
a=$1
b=$2
tol_m=${3:-}
tol_deg=${4:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
runs=0
worst=0
for method in 1 2 3; do
  for pose in -3,-10,-30 0,-8,-40 6,-6,0 5,2,-50; do
    for extra in "--noise 1 --outliers 0.2 --seed 11" "--noise 1 --seed 5"; do
      # shellcheck disable=SC2086
      "$a" --method $method --pose=$pose $extra --json --trace "$tmp/a.csv" > "$tmp/a.json"
      # shellcheck disable=SC2086
      "$b" --method $method --pose=$pose $extra --json --trace "$tmp/b.csv" > "$tmp/b.json"
      if [ -z "$tol_m" ]; then
        if ! cmp -s "$tmp/a.json" "$tmp/b.json" || ! cmp -s "$tmp/a.csv" "$tmp/b.csv"; then
          echo "paths differ: --method $method --pose $pose $extra" >&2
          diff "$tmp/a.json" "$tmp/b.json" >&2 || true
          exit 1
        fi
      else
        if ! worst=$(python3 - "$tmp/a.json" "$tmp/b.json" "$tol_m" "$tol_deg" "$worst" <<'PY'
import json, sys
a = json.loads(open(sys.argv[1]).read().splitlines()[-1])
b = json.loads(open(sys.argv[2]).read().splitlines()[-1])
tol_m, tol_deg, worst = float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
same = all(a[k] == b[k] for k in ("status", "reason", "frames")) and \
    [s["end_s"] for s in a["steps"]] == [s["end_s"] for s in b["steps"]]
dm = max(abs(a["final_error"][k] - b["final_error"][k]) for k in ("x_m", "z_m"))
dd = abs(a["final_error"]["phi_deg"] - b["final_error"]["phi_deg"])
print("%.3g" % max(worst, dm))
sys.exit(0 if same and dm <= tol_m and dd <= tol_deg else 1)
PY
        ); then
          echo "paths differ beyond the tolerance: --method $method --pose $pose $extra" >&2
          diff "$tmp/a.json" "$tmp/b.json" >&2 || true
          exit 1
        fi
      fi
      runs=$((runs + 1))
    done
  done
done
if [ -z "$tol_m" ]; then
  echo "accelerated and reference: $runs closed loops identical (summary and every frame)"
else
  echo "accelerated and reference: $runs closed loops with the same statuses, frames and step times, final errors within $worst m of each other (tolerance $tol_m m, $tol_deg deg)"
fi
