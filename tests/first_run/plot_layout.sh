#!/usr/bin/env bash
# plot_layout.sh SPVS_SIM PLOT - the demo's figures keep every title, axis
# label, step label and legend entry inside the picture: tools/plot
# --strict-layout (exit 1 when a text reaches past an edge) on the demo's
# run (Method III, with its title) and on Method II (the README's other example).
set -euo pipefail
sim=$1 plot=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for method in 3 2; do
  "$sim" --method "$method" --trace "$work/t$method.csv" --quiet
  if ! "$plot" "$work/t$method.csv" --out "$work/m$method" --title "Method $method over LCM" \
       --strict-layout >/dev/null 2>"$work/err"; then
    cat "$work/err" >&2
    echo "FAIL: Method $method: texts cut at the figures' edges" >&2
    exit 1
  fi
done
echo "plot_layout: nothing cut in the figures of Methods 3 and 2"
