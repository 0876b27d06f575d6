#!/bin/sh
# Instructions per estimate under callgrind: run one estimator for K estimates
# and for 0 estimates (same generation and set-up), subtract, divide by K.
# Prints one line per estimator and, with --annotate, the top functions of
# the K-estimate run.
#
# usage: tools/bench/callgrind.sh BENCH_EXE [N] [K] [ESTIMATORS] [--annotate]
#   BENCH_EXE   path to spvs-bench
#   N           matches per estimate (default 100)
#   K           estimates (default 200)
#   ESTIMATORS  comma-separated (default spvs,cv_usac_default)
set -eu
exe=${1:?usage: callgrind.sh BENCH_EXE [N] [K] [ESTIMATORS] [--annotate]}
n=${2:-100}
k=${3:-200}
ests=${4:-spvs,cv_usac_default}
annotate=${5:-}
command -v valgrind >/dev/null || { echo "callgrind.sh: valgrind not installed" >&2; exit 2; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

total() {
    # The "summary:" line of a callgrind output file holds the total Ir.
    sed -n 's/^summary: *\([0-9]*\).*/\1/p' "$1"
}

for est in $(echo "$ests" | tr ',' ' '); do
    for count in 0 "$k"; do
        valgrind --tool=callgrind --callgrind-out-file="$dir/$est.$count.out" \
            "$exe" --callgrind "$est" --n "$n" --count "$count" --mismatch 0.2 --sigma 1 \
            >"$dir/$est.$count.log" 2>&1 || { cat "$dir/$est.$count.log" >&2; exit 1; }
    done
    base=$(total "$dir/$est.0.out")
    full=$(total "$dir/$est.$k.out")
    per=$(( (full - base) / k ))
    echo "$est N=$n: $per instructions per estimate ($k estimates: $full Ir, baseline $base Ir)"
    if [ "$annotate" = "--annotate" ]; then
        callgrind_annotate --inclusive=no "$dir/$est.$k.out" 2>/dev/null | sed -n '1,40p' | \
            grep -E '^[ 0-9,]+ \(' | head -15
    fi
done
