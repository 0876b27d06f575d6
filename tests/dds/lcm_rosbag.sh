#!/usr/bin/env bash
# lcm_rosbag.sh SPVS_NODE SPVS_SIM LCM_TYPES PYTHON
# An LCM log of a run, as the demo makes it (lcm-logger beside spvs-node and
# spvs-sim --transport lcm, loopback-only namespace), converted to a
# rosbag2 by tools/rosbag/lcm2rosbag.py and checked by check_rosbag.py
# (mcap-ros2-support and rosbags): one /cmd_vel, /spvs/state and
# /spvs/matches per frame, equal to the run's recording.  The node's
# watchdog is long, so the log holds answers only.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
. "$here/../lcm/netns.sh"
node=$1 sim=$2 types=$3 py=$4
if ! unshare -r -n true 2>/dev/null; then
  echo "cannot make a network namespace (unshare -r -n)"
  [ "${CI:-}" = true ] && exit 1
  exit 77
fi
command -v lcm-logger >/dev/null || { echo "lcm-logger (liblcm-bin) missing"; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export NODE="$node" SIM="$sim" WORK="$work" URL="$(spvs_lcm_url)"
spvs_in_netns '
  lcm-logger -q -f --lcm-url="$URL" "$WORK/run.lcmlog" 2>"$WORK/logger.err" & lg=$!
  "$NODE" --method 1 --seed 2 --watchdog 30 --lcm-url "$URL" 2>"$WORK/node.err" & n=$!
  sleep 0.3
  timeout 120 "$SIM" --method 1 --seed 2 --noise 0.3 --transport lcm --lcm-url "$URL" \
      --timeout 5 --quiet --record "$WORK/run.rec"; rc=$?
  sleep 0.3
  kill -INT $n $lg; wait $n; wait $lg
  exit $rc
' || { echo "LCM run failed"; cat "$work/node.err" "$work/logger.err"; exit 1; }
"$py" "$root/tools/rosbag/lcm2rosbag.py" --lcm-types "$types" "$work/run.lcmlog" "$work/bag"
"$py" "$here/check_rosbag.py" --log-stamps "$work/bag" "$work/run.rec"
