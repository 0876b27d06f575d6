#!/usr/bin/env bash
# camera_dds.sh BUILD MIRE2_DIR DOMAIN
# spvs-camera's matches over DDS with ROS 2's names: frames 1-30 of ViSP's
# mire-2 go out on /spvs/matches to spvs-node --dds (Method 1, focal 600 px,
# seed 0) on ROS_DOMAIN_ID=DOMAIN, and the commands that come back must
# equal, frame by frame, those of spvs-camera --method 1 running the
# controller in process.  In a loopback-only namespace (tests/dds/netns.sh).
# Missing data: a failure under CI=true, else skipped (77).
set -euo pipefail
build=$1 mire=$2 domain=$3
here=$(cd "$(dirname "$0")" && pwd)
. "$here/dds/netns.sh"
if [ ! -f "$mire/image.0001.pgm" ]; then
  echo "missing: $mire"
  case ${CI:-} in 1|true|yes) echo "FAIL: CI is set"; exit 1 ;; esac
  exit 77
fi
spvs_dds_require_netns
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir "$work/frames"
for i in $(seq 1 30); do
  ln -s "$mire/$(printf 'image.%04d.pgm' "$i")" "$work/frames/"
done
export OPENCV_FOR_THREADS_NUM=1
cam=$build/sim_host/camera/spvs-camera
timeout 120 "$cam" --goal "$mire/image.0001.pgm" --source "$work/frames" --focal-px 600 \
    --json --method 1 >"$work/local.json"

export CAM="$cam" NODE="$build/sim_host/node/spvs-node" WORK="$work" MIRE="$mire"
export ROS_DOMAIN_ID="$domain" CYCLONEDDS_URI="$(spvs_dds_uri)"
spvs_dds_in_netns '
  "$NODE" --dds --method 1 --alpha 600 --seed 0 2>"$WORK/node.err" &
  pid=$!
  timeout 120 "$CAM" --goal "$MIRE/image.0001.pgm" --source "$WORK/frames" \
      --focal-px 600 --json --transport dds --timeout 15 >"$WORK/dds.json"; rc=$?
  kill -TERM $pid 2>/dev/null
  timeout 5 sh -c "while kill -0 $pid 2>/dev/null; do sleep 0.05; done" || kill -KILL $pid
  exit $rc
' || { echo "FAIL: spvs-camera --transport dds"; cat "$work/node.err"; exit 1; }

/usr/bin/python3 "$(dirname "$0")/camera_same_commands.py" "$work/local.json" "$work/dds.json" DDS
