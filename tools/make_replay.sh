#!/usr/bin/env bash
# Record the replay run with the host float32 build of spvs-sim and convert
# it for the target image (tests/golden/replay_frames.h by default).
#   tools/make_replay.sh [--fixed] [HOST_BUILD_DIR] [OUTPUT_DIR]
# HOST_BUILD_DIR must be a float (SPVS_DOUBLE=OFF) build that has spvs-sim.
# --fixed: the run of the host's fixed-point core (spvs-sim --transport
# fixed), for the images of the fixed-point build (tests/golden/fixed/ by
# default), which must answer it bit for bit.
# Rerun after any change of the core's behaviour, then commit the header.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
fixed=0
if [ "${1:-}" = --fixed ]; then
  fixed=1
  shift
fi
build=${1:-$root/build/host-float}
if [ $fixed = 1 ]; then
  outdir=${2:-$root/tests/golden/fixed}
else
  outdir=${2:-$root/tests/golden}
fi
sim=$build/sim_host/spvs-sim
if [ ! -x "$sim" ]; then
  echo "make_replay: no spvs-sim in $build (build the host float tree first)" >&2
  exit 2
fi
if grep -q '^SPVS_DOUBLE:BOOL=ON' "$build/CMakeCache.txt" 2>/dev/null; then
  echo "make_replay: $build is a double build; the target replays float32" >&2
  exit 2
fi
# A short Method III run that passes all three step switches (about 90
# frames at 0.2 s), with noise and mismatches so RANSAC and its PRNG matter.
args=(--method 3 --pose 0.8,-2,-20 --noise 0.5 --outliers 0.1 --seed 0 --dt 0.2)
core="host float32 build"
if [ $fixed = 1 ]; then
  args+=(--transport fixed)
  core="the host's fixed-point core"
fi
mkdir -p "$outdir"
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
"$sim" "${args[@]}" --quiet --record "$tmp"
"$root/tools/rec2c.py" "$tmp" -o "$outdir/replay_frames.h" \
  --note "spvs-sim ${args[*]} --record FILE ($core)"
