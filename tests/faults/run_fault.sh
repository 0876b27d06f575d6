#!/usr/bin/env bash
# run_fault.sh SPVS_NODE SPVS_SIM SPVS_LCM_FAULTS SCENARIO [OUT_DIR]
# One transport-fault scenario of docs/ROBUSTNESS.md, closed loop over LCM:
#   spvs-sim --realtime --keep-last 1.0 --timeout 0.1 (one period)
#     -> SPVS_MATCHES_RAW -> spvs-lcm-faults (the faults) -> SPVS_MATCHES
#     -> spvs-node --watchdog 0.5 -> SPVS_CMD/SPVS_STATE -> spvs-sim
# inside a loopback-only network namespace (tests/lcm/netns.sh, ttl=0),
# every process bounded in time.  check_fault.py then asserts the final
# errors and, for the pause, that the robot stopped.  SCENARIO: none, drop,
# delay, dup_reorder, time_back, pause, restart, and pause_no_watchdog (the
# pause with the node's watchdog and the base's timeout at 30 s: the robot
# must be seen drifting, which shows that the pause check can fail).
# OUT_DIR keeps the trace and logs (default: a temporary folder, removed).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lcm/netns.sh"
[ $# -ge 4 ] || { echo "usage: run_fault.sh NODE SIM RELAY SCENARIO [OUT_DIR]" >&2; exit 2; }
node=$1 sim=$2 relay=$3 scenario=$4
if [ $# -ge 5 ]; then
  work=$5; mkdir -p "$work"
else
  work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
fi

# The faults, and when the node is killed and for how long (restart).
kill_at=0 down_s=0 watchdog=0.5 keep_last=1.0
case $scenario in
  none)        faults="" ;;
  drop)        faults="--drop 0.2" ;;
  delay)       faults="--delay-max 0.3" ;;
  dup_reorder) faults="--dup 0.2 --reorder 0.2" ;;
  time_back)   faults="--time-back 0.1" ;;
  pause)       faults="--pause-after 100 --pause 2.0" ;;
  restart)     faults=""; kill_at=10; down_s=1.5 ;;
  pause_no_watchdog) faults="--pause-after 100 --pause 2.0"; watchdog=30; keep_last=30 ;;
  *) echo "run_fault.sh: unknown scenario '$scenario'" >&2; exit 2 ;;
esac

export NODE="$node" SIM="$sim" RELAY="$relay" URL="$(spvs_lcm_url)" WORK="$work"
export FAULTS="$faults" KILL_AT="$kill_at" DOWN_S="$down_s"
export WATCHDOG="$watchdog" KEEP_LAST="$keep_last"
spvs_in_netns '
  start_node() {
    "$NODE" --method 3 --lcm-url "$URL" --watchdog "$WATCHDOG" --log-level 2 \
        2>>"$WORK/node.err" &
    echo $! >"$WORK/node.pid"
  }
  stop() {  # stop PID: TERM, then KILL after 5 s
    kill -TERM "$1" 2>/dev/null || true
    timeout 5 sh -c "while kill -0 $1 2>/dev/null; do sleep 0.05; done" \
        || kill -KILL "$1" 2>/dev/null || true
    wait "$1" 2>/dev/null || true
  }
  start_node
  # $FAULTS holds plain options without spaces: word splitting is wanted.
  "$RELAY" --lcm-url "$URL" --seed 1 $FAULTS >"$WORK/relay.out" 2>"$WORK/relay.err" &
  relay=$!
  sleep 0.3
  timeout -k 5 90 "$SIM" --method 3 --pose -1,-5,-20 --seed 0 --realtime \
      --transport lcm --lcm-url "$URL" --lcm-matches-channel SPVS_MATCHES_RAW \
      --timeout 0.1 --keep-last "$KEEP_LAST" --json --quiet \
      --trace "$WORK/trace.csv" >"$WORK/sim.out" 2>"$WORK/sim.err" &
  sim=$!
  if [ "$KILL_AT" != 0 ]; then
    sleep "$KILL_AT"
    echo "restart: node killed at $KILL_AT s, down $DOWN_S s" >>"$WORK/node.err"
    kill -KILL "$(cat "$WORK/node.pid")"
    wait "$(cat "$WORK/node.pid")" 2>/dev/null || true
    sleep "$DOWN_S"
    start_node
  fi
  rc=0
  wait $sim || rc=$?
  stop $relay
  stop "$(cat "$WORK/node.pid")"
  exit $rc
' || { echo "run_fault: spvs-sim failed ($scenario)"; cat "$work/sim.err" "$work/node.err" "$work/relay.err" 2>/dev/null | tail -20; exit 1; }

exec /usr/bin/python3 "$here/check_fault.py" "$scenario" "$work"
