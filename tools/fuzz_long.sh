#!/usr/bin/env bash
# The documented long fuzzing run (docs/ROBUSTNESS.md): builds the libFuzzer
# targets with clang (ASan + UBSan) and runs
#   fuzz_core  for CORE_RUNS executions in all (default 10,000,000),
#   fuzz_core_fixed for FIXED_SECONDS of wall time per worker (default
#              600; the fixed-point core with the float core beside it),
#   fuzz_node  for NODE_SECONDS of wall time per worker (default 300),
# each split over JOBS independent workers (default: the number of cores;
# worker K uses libFuzzer -seed=K and its own corpus), all from the
# committed seeds in fresh corpus folders.  Prints each worker's executions,
# time and crash count, then the totals.  A crash, hang (10 s per input),
# leak or sanitizer report fails the run (exit 1) and leaves a reproducer in
# BUILD/crash-TARGET-K/; replay it with BUILD/TARGET FILE.
#
# usage: tools/fuzz_long.sh [BUILD_DIR]   (default build/fuzz-long)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="${1:-$root/build/fuzz-long}"
core_runs="${CORE_RUNS:-10000000}"
fixed_seconds="${FIXED_SECONDS:-600}"
node_seconds="${NODE_SECONDS:-300}"
jobs="${JOBS:-$(nproc 2>/dev/null || echo 1)}"

command -v clang >/dev/null || { echo "fuzz_long.sh: clang not found (scripts/install_deps.sh)" >&2; exit 2; }
"$root/tests/fuzz/run_fuzz.sh" build "$dir" >/dev/null
rm -rf "$dir"/corpus-fuzz_* "$dir"/crash-fuzz_*

echo "fuzz_long: $(clang --version | head -1), $jobs workers on $(nproc) cores, started $(date -u +%FT%TZ)"
status=0
# run TARGET BUDGET: JOBS workers in parallel; prints their lines and a total.
run() {
  local target=$1 budget=$2 pids=() k
  for ((k = 1; k <= jobs; k++)); do
    SPVS_FUZZ_WORKER=$k "$root/tests/fuzz/run_fuzz.sh" run "$dir" "$target" "$budget" \
        >"$dir/$target-$k.summary" 2>&1 &
    pids+=($!)
  done
  for k in "${!pids[@]}"; do wait "${pids[$k]}" || status=1; done
  cat "$dir/$target"-*.summary
  awk -v t="$target" '/executions in/ { n += $3; if ($6 > s) s = $6; c += $NF }
       END { printf "fuzz %s total: %d executions, %.1f s wall, crashes: %d\n", t, n, s, c }' \
      "$dir/$target"-*.summary
}
run fuzz_core "runs=$(( (core_runs + jobs - 1) / jobs ))"
run fuzz_core_fixed "$fixed_seconds"
run fuzz_node "$node_seconds"
echo "fuzz_long: finished $(date -u +%FT%TZ), status $status"
exit $status
