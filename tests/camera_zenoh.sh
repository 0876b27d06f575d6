#!/usr/bin/env bash
# camera_zenoh.sh ROOT BUILD MIRE2_DIR
# spvs-camera's matches over Zenoh: frames 1-30 of ViSP's mire-2 go out on
# spvs/robot0/matches through spvs-zenoh-bridge to spvs-node (Method 1,
# focal 600 px, seed 0), and the commands that come back must equal, frame
# by frame, those of spvs-camera --method 1 running the controller
# in-process (float build: 1e-6 allowed for the frame time's trip through
# microseconds).  Run inside tests/zenoh/netns.sh (loopback only).
# Missing data: a failure under CI=true, else skipped (77).
set -euo pipefail
root=$1 build=$2 mire=$3
if [ ! -f "$mire/image.0001.pgm" ]; then
  echo "missing: $mire"
  case ${CI:-} in 1|true|yes) echo "FAIL: CI is set"; exit 1 ;; esac
  exit 77
fi
cam=$build/sim_host/camera/spvs-camera
node=$build/sim_host/node/spvs-node
work=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  sleep 0.2
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
mkdir "$work/frames"
for i in $(seq 1 30); do
  ln -s "$mire/$(printf 'image.%04d.pgm' "$i")" "$work/frames/"
done
export OPENCV_FOR_THREADS_NUM=1
common=(--goal "$mire/image.0001.pgm" --source "$work/frames" --focal-px 600 --json)
timeout 120 "$cam" "${common[@]}" --method 1 >"$work/local.json"

url="udpm://239.255.76.67:$((20000 + $$ % 20000))?ttl=0"
port=$((30000 + $$ % 20000))
timeout 120 "$node" --method 1 --alpha 600 --seed 0 --lcm-url "$url" \
    2>"$work/node.err" & pids+=($!)
timeout 120 "$root/sim_host/zenoh/spvs-zenoh-bridge" --listen "tcp/127.0.0.1:$port" \
    --scouting off --lcm-url "$url" --lcm-types "$build/lcm_types/python" \
    2>"$work/bridge.err" & pids+=($!)
timeout 120 "$cam" "${common[@]}" --transport zenoh \
    --zenoh-endpoint "tcp/127.0.0.1:$port" --timeout 15 >"$work/zenoh.json" ||
  { echo "FAIL: spvs-camera --transport zenoh"; cat "$work/node.err" "$work/bridge.err"; exit 1; }

/usr/bin/python3 "$(dirname "$0")/camera_same_commands.py" "$work/local.json" "$work/zenoh.json" Zenoh
