#!/usr/bin/env bash
# valgrind_loop.sh SPVS_NODE SPVS_SIM
# Memcheck on the node and the simulator: spvs-sim in process, then
# spvs-sim and spvs-node over LCM (loopback-only namespace, ttl=0), both
# under valgrind --error-exitcode=1 with definite leaks counted as errors.
# Passes when every valgrind run is clean and both runs converge.  One
# leak inside liblcm 1.3 itself is suppressed (lcm.supp says which).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lcm/netns.sh"
[ $# -eq 2 ] || { echo "usage: valgrind_loop.sh SPVS_NODE SPVS_SIM" >&2; exit 2; }
command -v valgrind >/dev/null || { echo "valgrind not installed (scripts/install_deps.sh)"; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export VG="valgrind --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite --suppressions=$here/lcm.supp --quiet"
export NODE=$1 SIM=$2 URL="$(spvs_lcm_url)" WORK="$work"
# The short run of the fault scenarios, lock-step (no --realtime).
export RUN="--method 3 --pose -1,-5,-20 --seed 0 --json --quiet"

status=0
timeout -k 5 300 $VG "$SIM" $RUN >"$work/inproc.out" 2>"$work/inproc.vg" \
  || { echo "valgrind: spvs-sim in process: errors"; cat "$work/inproc.vg"; status=1; }

spvs_in_netns '
  $VG "$NODE" --method 3 --lcm-url "$URL" --log-level 2 2>"$WORK/node.vg" &
  node=$!
  sleep 2  # the node starts slowly under valgrind
  rc=0
  timeout -k 5 300 $VG "$SIM" $RUN --transport lcm --lcm-url "$URL" --timeout 10 \
      >"$WORK/lcm.out" 2>"$WORK/sim.vg" || rc=1
  kill -TERM $node
  timeout 30 sh -c "while kill -0 $node 2>/dev/null; do sleep 0.1; done" || kill -KILL $node
  wait $node || { echo "valgrind: spvs-node: errors or bad exit"; rc=1; }
  exit $rc
' || { echo "valgrind: LCM loop: errors"; cat "$work/sim.vg" "$work/node.vg"; status=1; }

for f in inproc lcm; do
  line=$(tail -n 1 "$work/$f.out" 2>/dev/null || true)
  case $line in
    *'"status":"converged"'*) echo "valgrind $f: converged, memcheck clean: $(echo "$line" | grep -o '"final_error":{[^}]*}')" ;;
    *) echo "valgrind $f: did not converge: $line"; status=1 ;;
  esac
done
grep -h "ERROR SUMMARY\|definitely" "$work"/*.vg 2>/dev/null || true
exit $status
