#!/usr/bin/env bash
# closed_loop.sh SPVS_NODE SPVS_SIM TOL_M TOL_DEG [spvs-sim options...]
# The same run twice: spvs-sim with the controller in-process, then spvs-sim
# and spvs-node as two processes over LCM (loopback-only namespace).  The
# final pose errors must agree within TOL_M metres and TOL_DEG degrees (float
# rounding), and status and run time must be the same.  Every step is bounded
# in time, so a lost message fails the test instead of hanging it.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/netns.sh"
node=$1 sim=$2 tol_m=$3 tol_deg=$4
shift 4
method=3 seed=0
args=("$@")
for ((i = 0; i < ${#args[@]}; i++)); do
  case ${args[$i]} in
    --method) method=${args[$((i + 1))]} ;;
    --seed) seed=${args[$((i + 1))]} ;;
  esac
done

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

timeout 120 "$sim" "$@" --json >"$work/inproc.out"
tail -n 1 "$work/inproc.out" >"$work/inproc.json"

export NODE="$node" SIM="$sim" URL="$(spvs_lcm_url)" WORK="$work"
export METHOD="$method" SEED="$seed" SIM_ARGS="$*"
spvs_in_netns '
  "$NODE" --method "$METHOD" --seed "$SEED" --lcm-url "$URL" --log-level 2 \
      2>"$WORK/node.err" &
  pid=$!
  # $SIM_ARGS holds plain options without spaces, so word splitting is fine.
  timeout 120 "$SIM" $SIM_ARGS --transport lcm --lcm-url "$URL" --timeout 5 \
      --json >"$WORK/lcm.out"; rc=$?
  kill -TERM $pid 2>/dev/null
  timeout 5 sh -c "while kill -0 $pid 2>/dev/null; do sleep 0.05; done" \
      || kill -KILL $pid
  wait $pid; nrc=$?
  [ $nrc -eq 0 ] || { echo "spvs-node exit status $nrc"; rc=1; }
  exit $rc
' || { echo "LCM run failed"; cat "$work/node.err"; cat "$work/lcm.out" 2>/dev/null; exit 1; }
tail -n 1 "$work/lcm.out" >"$work/lcm.json"

/usr/bin/python3 - "$work/inproc.json" "$work/lcm.json" "$tol_m" "$tol_deg" <<'PY'
import json, sys
a = json.load(open(sys.argv[1]))
b = json.load(open(sys.argv[2]))
tol_m, tol_deg = float(sys.argv[3]), float(sys.argv[4])
ea, eb = a["final_error"], b["final_error"]
print("in-process:", a["status"], ea, "t", a["time_s"])
print("over LCM:  ", b["status"], eb, "t", b["time_s"])
bad = []
if a["status"] != b["status"]:
    bad.append("status %s != %s" % (a["status"], b["status"]))
if abs(a["time_s"] - b["time_s"]) > 1e-9:
    bad.append("time_s %r != %r" % (a["time_s"], b["time_s"]))
for k, tol in (("x_m", tol_m), ("z_m", tol_m), ("phi_deg", tol_deg)):
    d = abs(ea[k] - eb[k])
    if not d <= tol:
        bad.append("%s differs by %.3g (tolerance %.3g)" % (k, d, tol))
if bad:
    print("FAIL: " + "; ".join(bad))
    sys.exit(1)
print("closed_loop: in-process and LCM runs agree")
PY
