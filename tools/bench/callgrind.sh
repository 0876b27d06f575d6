#!/bin/sh
# Instructions per estimate under callgrind: run one estimator for K estimates
# with collection switched on only inside the bench's estimate() calls
# (--toggle-collect), divide by K.  Start-up (loading OpenCV and its
# dependencies, some 635 M instructions that vary from run to run by a few
# hundred thousand) is not counted, so no baseline run is subtracted.
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
[ "$k" -ge 1 ] 2>/dev/null || { echo "callgrind.sh: K must be a whole number >= 1" >&2; exit 2; }
command -v valgrind >/dev/null || { echo "callgrind.sh: valgrind not installed" >&2; exit 2; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

total() {
    # The "summary:" line of a callgrind output file holds the total Ir.
    sed -n 's/^summary: *\([0-9]*\).*/\1/p' "$1"
}

for est in $(echo "$ests" | tr ',' ' '); do
    valgrind --tool=callgrind --toggle-collect='*Estimator::estimate*' \
        --callgrind-out-file="$dir/$est.$k.out" \
        "$exe" --callgrind "$est" --n "$n" --count "$k" --mismatch 0.2 --sigma 1 \
        >"$dir/$est.$k.log" 2>&1 || { cat "$dir/$est.$k.log" >&2; exit 1; }
    full=$(total "$dir/$est.$k.out")
    per=$(( full / k ))
    echo "$est N=$n: $per instructions per estimate ($k estimates: $full Ir inside estimate())"
    if [ "$annotate" = "--annotate" ]; then
        callgrind_annotate --inclusive=no "$dir/$est.$k.out" 2>/dev/null | sed -n '1,40p' | \
            grep -E '^[ 0-9,]+ \(' | head -15
    fi
done
