#!/usr/bin/env bash
# The documented long fuzzing run (docs/ROBUSTNESS.md): builds the libFuzzer
# targets with clang (ASan + UBSan) and runs
#   fuzz_core  for CORE_RUNS executions (default 10,000,000),
#   fuzz_node  for NODE_SECONDS of wall time (default 600),
# each from the committed seeds in a fresh corpus folder, and prints the
# executions, time and crash count of each.  A crash, hang (10 s per input),
# leak or sanitizer report fails the run (exit 1) and leaves a reproducer in
# BUILD/crash-TARGET/; replay it with BUILD/TARGET FILE.
#
# usage: tools/fuzz_long.sh [BUILD_DIR]   (default build/fuzz-long)
# environment: CORE_RUNS, NODE_SECONDS, JOBS (parallel workers per target, 1)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="${1:-$root/build/fuzz-long}"
core_runs="${CORE_RUNS:-10000000}"
node_seconds="${NODE_SECONDS:-600}"
jobs="${JOBS:-1}"

command -v clang >/dev/null || { echo "fuzz_long.sh: clang not found (scripts/install_deps.sh)" >&2; exit 2; }
"$root/tests/fuzz/run_fuzz.sh" build "$dir" >/dev/null
# A fresh corpus, so that the figures describe a run from the seeds.
rm -rf "$dir/corpus-fuzz_core" "$dir/corpus-fuzz_node"

extra=()
if [ "$jobs" -gt 1 ]; then extra=(-fork="$jobs"); fi
echo "fuzz_long: $(clang --version | head -1), $(nproc) cores, started $(date -u +%FT%TZ)"
status=0
"$root/tests/fuzz/run_fuzz.sh" run "$dir" fuzz_core "runs=$core_runs" "${extra[@]}" || status=1
"$root/tests/fuzz/run_fuzz.sh" run "$dir" fuzz_node "$node_seconds" "${extra[@]}" || status=1
echo "fuzz_long: finished $(date -u +%FT%TZ), status $status"
exit $status
