#!/usr/bin/env bash
# The accelerated build and the reference path give the same closed loop,
# bit for bit: spvs-sim from a build with the columns (SIMD lanes,
# firmware/src/accel) and from one with SPVS_ACCEL=OFF (the rows of
# firmware/src/points.c, the Cortex-M4F's layout) must print the same
# --json summary and the same per-frame trace for every method, with noise and
# mismatches, from four start poses.
#   tests/compare_layouts.sh SIM_COLUMNS SIM_ROWS
set -euo pipefail
a=$1
b=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
runs=0
for method in 1 2 3; do
  for pose in -3,-10,-30 0,-8,-40 6,-6,0 5,2,-50; do
    for extra in "--noise 1 --outliers 0.2 --seed 11" "--noise 1 --seed 5"; do
      # shellcheck disable=SC2086
      "$a" --method $method --pose=$pose $extra --json --trace "$tmp/a.csv" > "$tmp/a.json"
      # shellcheck disable=SC2086
      "$b" --method $method --pose=$pose $extra --json --trace "$tmp/b.csv" > "$tmp/b.json"
      if ! cmp -s "$tmp/a.json" "$tmp/b.json" || ! cmp -s "$tmp/a.csv" "$tmp/b.csv"; then
        echo "layouts differ: --method $method --pose $pose $extra" >&2
        diff "$tmp/a.json" "$tmp/b.json" >&2 || true
        exit 1
      fi
      runs=$((runs + 1))
    done
  done
done
echo "accelerated and reference: $runs closed loops identical (summary and every frame)"
