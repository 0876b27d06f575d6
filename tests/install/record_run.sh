#!/usr/bin/env bash
# record_run.sh NODE SIM LOG RESULT_JSON [SIM_OPTIONS...] - one closed-loop
# run over LCM (spvs-node + spvs-sim, lcm-logger recording the bus to LOG),
# inside a network namespace of its own with only a loopback interface
# (tests/lcm/netns.sh); spvs-sim's --json result goes to RESULT_JSON.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lcm/netns.sh"
[ $# -ge 4 ] || { echo "usage: record_run.sh NODE SIM LOG RESULT_JSON [SIM_OPTIONS...]" >&2; exit 2; }
export NODE=$1 SIM=$2 LOG=$3 RESULT=$4
shift 4
export SIM_ARGS="$*" URL=$(spvs_lcm_url)
spvs_in_netns '
  lcm-logger -q -f --lcm-url="$URL" "$LOG" 2>"$LOG.logger.err" &
  logger=$!
  "$NODE" --lcm-url "$URL" 2>"$LOG.node.err" &
  node=$!
  sleep 0.5
  "$SIM" --transport lcm --lcm-url "$URL" --timeout 5 --json $SIM_ARGS >"$RESULT"
  rc=$?
  sleep 0.3
  kill -INT $node $logger
  wait $node $logger
  exit $rc
' || { cat "$LOG.node.err" "$LOG.logger.err" >&2; echo "record_run: the LCM run failed" >&2; exit 1; }
