#!/usr/bin/env bash
# lcm_rosbag.sh SPVS_NODE SPVS_SIM LCM_TYPES PYTHON
# An LCM log of a run, as the demo makes it (lcm-logger beside spvs-node and
# spvs-sim --transport lcm, loopback-only namespace), converted to a
# rosbag2 by tools/rosbag/lcm2rosbag.py and checked by check_rosbag.py
# (mcap-ros2-support and rosbags): the log's messages, one /cmd_vel and
# /spvs/state per SPVS_CMD (watchdog stops: zero Twists) and one
# /spvs/matches per SPVS_MATCHES, each frame equal to the run's recording.  The run starts once
# the logger has logged the node's first stop, so no frame is sent before
# the logger listens; the logger's socket has a receive buffer of 4 MiB (a
# lock-step run bursts faster than a busy logger may take the datagrams).
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
  # A large receive buffer: the logger writes 5 kB frames to disk while
  # the run goes as fast as the node answers.
  lcm-logger -q -f --lcm-url="$URL&recv_buf_size=4194304" "$WORK/run.lcmlog" 2>"$WORK/logger.err" & lg=$!
  "$NODE" --method 1 --seed 2 --watchdog 0.2 --lcm-url "$URL" 2>"$WORK/node.err" & n=$!
  i=0; while [ ! -s "$WORK/run.lcmlog" ] && [ $i -lt 200 ]; do sleep 0.05; i=$((i+1)); done
  timeout 120 "$SIM" --method 1 --seed 2 --noise 0.3 --transport lcm --lcm-url "$URL" \
      --timeout 5 --quiet --record "$WORK/run.rec"; rc=$?
  sleep 0.5
  kill -INT $n $lg; wait $n; wait $lg
  exit $rc
' || { echo "LCM run failed"; cat "$work/node.err" "$work/logger.err"; exit 1; }
"$py" "$root/tools/rosbag/lcm2rosbag.py" --lcm-types "$types" "$work/run.lcmlog" "$work/bag"
"$py" "$here/check_rosbag.py" --log "$work/run.lcmlog" "$work/bag" "$work/run.rec"
