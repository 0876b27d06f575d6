#!/usr/bin/env bash
# sim_timeout.sh SPVS_SIM
# spvs-sim --transport lcm with no controller on the bus must stop after its
# --timeout with a clear one-line reason and a non-zero status, not hang.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/netns.sh"
export SIM=$1 URL="$(spvs_lcm_url)"
out=$(spvs_in_netns '
  start=$(date +%s%N)
  timeout 20 "$SIM" --transport lcm --lcm-url "$URL" --timeout 0.4 --quiet \
      2>&1 >/dev/null; rc=$?
  end=$(date +%s%N)
  echo "rc=$rc ms=$(( (end - start) / 1000000 ))"
' || true)
echo "$out"
rc=$(echo "$out" | sed -n 's/^rc=\([0-9]*\) .*/\1/p')
ms=$(echo "$out" | sed -n 's/^rc=[0-9]* ms=\([0-9]*\)$/\1/p')
[ -n "$rc" ] && [ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] || { echo "FAIL: exit status '$rc'"; exit 1; }
# One frame's wait (0.4 s) plus start-up, far from the 20 s guard.
[ "$ms" -ge 350 ] && [ "$ms" -lt 5000 ] || { echo "FAIL: took $ms ms"; exit 1; }
echo "$out" | grep -q "no SPVS_CMD for frame 0 within 0.4 s" || { echo "FAIL: no clear reason"; exit 1; }
echo "sim_timeout: ok"
