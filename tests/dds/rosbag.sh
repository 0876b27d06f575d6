#!/usr/bin/env bash
# rosbag.sh SPVS_NODE SPVS_SIM DOMAIN PYTHON
# spvs-sim --rosbag: a bag of an in-process run and one of the same run over
# DDS (spvs-node --dds, ROS_DOMAIN_ID=DOMAIN, loopback-only namespace),
# checked by check_rosbag.py with PYTHON (the venv's: mcap,
# mcap-ros2-support, rosbags): both readers decode every frame's /cmd_vel,
# /spvs/state and /spvs/matches equal to the run's recording, and the two
# bags are equal byte for byte.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/netns.sh"
spvs_dds_require_netns
node=$1 sim=$2 domain=$3 py=$4
args=(--method 2 --seed 4 --noise 0.5 --outliers 0.1)

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
timeout 120 "$sim" "${args[@]}" --json --quiet --record "$work/run.rec" \
    --rosbag "$work/inproc_bag" >"$work/inproc.out"

export NODE="$node" SIM="$sim" WORK="$work" SIM_ARGS="${args[*]}"
export ROS_DOMAIN_ID="$domain" CYCLONEDDS_URI="$(spvs_dds_uri)"
spvs_dds_in_netns '
  "$NODE" --dds --method 2 --seed 4 2>"$WORK/node.err" & node=$!
  timeout 120 "$SIM" $SIM_ARGS --transport dds --timeout 5 --json --quiet \
      --rosbag "$WORK/dds_bag" >"$WORK/dds.out"; rc=$?
  kill -TERM $node; wait $node
  exit $rc
' || { echo "DDS run failed"; cat "$work/node.err"; exit 1; }
tail -n 1 "$work/inproc.out"
"$py" "$here/check_rosbag.py" "$work/inproc_bag" "$work/run.rec" "$work/dds_bag"
