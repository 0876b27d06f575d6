#!/usr/bin/env bash
# node_robust.sh SPVS_NODE TEST_NODE_MSGS
# Runs the message-robustness checks of test_node_msgs against a separate
# spvs-node process over UDP multicast (loopback only), then checks that the
# node is still alive and exits 0 on SIGTERM.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/netns.sh"
node=$1 tester=$2
url=$(spvs_lcm_url)
log=$(mktemp)
trap 'rm -f "$log"' EXIT

export NODE="$node" TESTER="$tester" URL="$url" LOG="$log"
spvs_in_netns '
  "$NODE" --method 3 --watchdog 0.3 --lcm-url "$URL" --log-level 2 2>"$LOG" &
  pid=$!
  sleep 0.3
  SPVS_NODE_URL="$URL" timeout 60 "$TESTER"; rc=$?
  if ! kill -0 $pid 2>/dev/null; then
    echo "FAIL: spvs-node died during the checks"; rc=1
  fi
  kill -TERM $pid 2>/dev/null
  if ! timeout 5 sh -c "while kill -0 $pid 2>/dev/null; do sleep 0.05; done"; then
    echo "FAIL: spvs-node ignored SIGTERM"; kill -KILL $pid; rc=1
  fi
  wait $pid; nrc=$?
  if [ $nrc -ne 0 ]; then echo "FAIL: spvs-node exit status $nrc after SIGTERM"; rc=1; fi
  exit $rc
' || { echo "--- spvs-node stderr ---"; cat "$log"; exit 1; }
echo "--- spvs-node stderr ---"
cat "$log"
# The node must have logged each rejected message with a one-line reason.
grep -q "count 300 outside 0..256" "$log"
grep -q "non-finite coordinate" "$log"
grep -q "undecodable SPVS_MATCHES message" "$log"
echo "node_robust: ok"
