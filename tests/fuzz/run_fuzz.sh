#!/usr/bin/env bash
# Build and run the libFuzzer targets (tests/fuzz/CMakeLists.txt).
#
#   run_fuzz.sh build BUILD_DIR
#       configure and build the fuzz project with clang into BUILD_DIR
#   run_fuzz.sh run BUILD_DIR TARGET SECONDS|runs=N [extra libFuzzer flags]
#       fuzz TARGET (fuzz_core, fuzz_core_fixed, fuzz_node, fuzz_serial)
#       for SECONDS of wall time, or for exactly N executions, starting from
#       the committed seeds (fuzz_core_fixed: fuzz_core's); new inputs go
#       to BUILD_DIR/corpus-TARGET (the source tree is never written), crash
#       reproducers to BUILD_DIR/crash-TARGET/.  Prints one summary line:
#       "fuzz TARGET: EXECS executions in SECS s, ... crashes: 0".
#       SPVS_FUZZ_WORKER=K (optional) names a parallel worker: its corpus,
#       crashes and log get the suffix -K and libFuzzer's -seed=K.
# Exit status: 0 clean, 1 a crash, leak, hang or sanitizer report, 2 misuse.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"

usage() { echo "usage: run_fuzz.sh build DIR | run DIR TARGET SECONDS|runs=N [flags]" >&2; exit 2; }
[ $# -ge 2 ] || usage
cmd=$1 dir=$2

if [ "$cmd" = build ]; then
  cc=${SPVS_FUZZ_CC:-clang}
  cmake -S "$here" -B "$dir" -G Ninja -DCMAKE_C_COMPILER="$cc" \
        -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  # Two jobs unless told otherwise: ctest may run other tests beside it.
  cmake --build "$dir" -j "${CMAKE_BUILD_PARALLEL_LEVEL:-2}"
  exit 0
fi
[ "$cmd" = run ] && [ $# -ge 4 ] || usage
target=$3 budget=$4
shift 4
case "$target" in
  # Both cores read one input format: the same seeds.
  fuzz_core|fuzz_core_fixed) seeds="$here/corpus/core"; maxlen=4096 ;;
  fuzz_node) seeds="$here/corpus/node"; maxlen=6000 ;;
  fuzz_serial) seeds="$here/corpus/serial"; maxlen=8192 ;;
  *) echo "run_fuzz.sh: unknown target '$target'" >&2; exit 2 ;;
esac
exe="$dir/$target"
[ -x "$exe" ] || { echo "run_fuzz.sh: $exe not built (run_fuzz.sh build $dir)" >&2; exit 2; }
case "$budget" in
  runs=*) limit=(-runs="${budget#runs=}") ;;
  *[!0-9]*|'') usage ;;
  *) limit=(-max_total_time="$budget") ;;
esac

suffix="" seedflag=()
if [ -n "${SPVS_FUZZ_WORKER:-}" ]; then
  suffix="-$SPVS_FUZZ_WORKER"; seedflag=(-seed="$SPVS_FUZZ_WORKER")
fi
corpus="$dir/corpus-$target$suffix"
crashes="$dir/crash-$target$suffix"
# Reproducers of an earlier run are not this run's findings.
rm -rf "$crashes"
mkdir -p "$corpus" "$crashes"
log="$dir/$target$suffix.log"
start=$(date +%s.%N)
set +e
# -timeout: one input taking 10 s is a hang; -rss_limit_mb: a leak.
"$exe" "${limit[@]}" -max_len=$maxlen -timeout=10 -rss_limit_mb=2048 \
       -print_final_stats=1 -artifact_prefix="$crashes/" "${seedflag[@]}" "$@" \
       "$corpus" "$seeds" >"$log" 2>&1
rc=$?
set -e
end=$(date +%s.%N)
execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
ncrash=$(find "$crashes" -type f | wc -l)
secs=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')
printf 'fuzz %s%s: %s executions in %s s (%s exec/s), coverage %s edges, corpus %s inputs, crashes: %s\n' \
       "$target" "$suffix" "${execs:-?}" "$secs" \
       "${speed:-?}" "${cov:-?}" "$(find "$corpus" -type f | wc -l)" "$ncrash"
if [ $rc -ne 0 ] || [ "$ncrash" -ne 0 ]; then
  echo "fuzz $target FAILED (exit $rc); the last lines of $log:" >&2
  tail -40 "$log" >&2
  exit 1
fi
