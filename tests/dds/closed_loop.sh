#!/usr/bin/env bash
# closed_loop.sh SPVS_NODE SPVS_SIM DOMAIN [spvs-sim options...]
# The same run twice: spvs-sim with the controller in process, then spvs-sim
# --transport dds against spvs-node --dds on ROS_DOMAIN_ID=DOMAIN, in a
# loopback-only namespace.  The --json summaries must be equal but for the
# transport's name, and the --trace files (pose, v, w, step, status, H,
# e_x, parallax and counts of every frame) equal line for line.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/netns.sh"
spvs_dds_require_netns
node=$1 sim=$2 domain=$3
shift 3
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

timeout 120 "$sim" "$@" --json --quiet --trace "$work/inproc.csv" >"$work/inproc.out"

export NODE="$node" SIM="$sim" WORK="$work" METHOD="$method" SEED="$seed"
export SIM_ARGS="$*" ROS_DOMAIN_ID="$domain" CYCLONEDDS_URI="$(spvs_dds_uri)"
spvs_dds_in_netns '
  "$NODE" --dds --method "$METHOD" --seed "$SEED" --log-level 2 \
      2>"$WORK/node.err" &
  pid=$!
  # $SIM_ARGS holds plain options without spaces, so word splitting is fine.
  timeout 120 "$SIM" $SIM_ARGS --transport dds --timeout 5 --json --quiet \
      --trace "$WORK/dds.csv" >"$WORK/dds.out"; rc=$?
  kill -TERM $pid 2>/dev/null
  timeout 5 sh -c "while kill -0 $pid 2>/dev/null; do sleep 0.05; done" \
      || kill -KILL $pid
  wait $pid; nrc=$?
  [ $nrc -eq 0 ] || { echo "spvs-node exit status $nrc"; rc=1; }
  exit $rc
' || { echo "DDS run failed"; cat "$work/node.err"; cat "$work/dds.out" 2>/dev/null; exit 1; }
cat "$work/node.err"

/usr/bin/python3 - "$work" <<'PY'
import json, sys
w = sys.argv[1]
a = json.loads(open(w + "/inproc.out").read().splitlines()[-1])
b = json.loads(open(w + "/dds.out").read().splitlines()[-1])
print("in process:", a["status"], a["final_error"], "frames", a["frames"])
print("over DDS:  ", b["status"], b["final_error"], "frames", b["frames"])
bad = []
if b.pop("transport") != "dds":
    bad.append("the DDS run names another transport")
a.pop("transport")
for k in sorted(set(a) | set(b)):
    if a.get(k) != b.get(k):
        bad.append("%s: %r in process, %r over DDS" % (k, a.get(k), b.get(k)))
ta = open(w + "/inproc.csv").read().splitlines()
tb = open(w + "/dds.csv").read().splitlines()
if len(ta) != len(tb):
    bad.append("trace: %d rows in process, %d over DDS" % (len(ta), len(tb)))
for i, (x, y) in enumerate(zip(ta, tb)):
    if x != y:
        bad.append("trace row %d differs:\n  %s\n  %s" % (i, x, y))
        break
if bad:
    print("FAIL: " + "\n".join(bad))
    sys.exit(1)
print("closed_loop: the DDS run equals the in-process run (%d frames, "
      "status %s)" % (a["frames"], a["status"]))
PY
