#!/usr/bin/env bash
# python_decode.sh NODE SIM - the Python path of docs/INSTALL.md: the types
# made with the documented `lcm-gen -p`, a run over LCM recorded by
# lcm-logger, and examples/python/decode_log.py on the log: every spvs event
# of the log decoded as its type, the last frame's state and command those
# of the converged run (step 4, 100 of 125 on the plane, v = w = 0).
set -euo pipefail
. "$(dirname "$0")/common.sh"
node=$1 sim=$2
spvs_tmpdir
command -v lcm-gen >/dev/null || fail "lcm-gen not installed (liblcm-bin)"
lcm-gen -p --ppath "$tmp/types" "$SPVS_SOURCE"/lcm_types/*.lcm || fail "lcm-gen -p"
"$(dirname "$0")/record_run.sh" "$node" "$sim" "$tmp/run.lcmlog" "$tmp/sim.json"
frames=$(python3 -c 'import json,sys; print(json.loads(open(sys.argv[1]).read().splitlines()[-1])["frames"])' "$tmp/sim.json")
/usr/bin/python3 "$SPVS_SOURCE/examples/python/decode_log.py" "$tmp/run.lcmlog" \
    --types "$tmp/types" >"$tmp/out.txt" || fail "decode_log.py failed"
cat "$tmp/out.txt"
# Every spvs event of the log decoded (the log is the reference: lcm-logger
# may miss datagrams of a run on a busy machine; count_log.py).
"$(dirname "$0")/count_log.py" "$tmp/run.lcmlog" >"$tmp/count.txt"
for pair in SPVS_MATCHES:matches_t SPVS_STATE:state_t SPVS_CMD:cmd_t; do
  ch=${pair%%:*}
  n=$(awk -v c="$ch" '$1 == c { print $2 }' "$tmp/count.txt")
  grep -q "^$(printf '%-13s %-10s' "$ch" "${pair#*:}") $n messages$" "$tmp/out.txt" ||
    fail "$ch: not all $n events of the log decoded as ${pair#*:}"
  [ "$n" -ge $((frames / 4)) ] && [ "$n" -le $((frames + 10)) ] ||
    fail "$ch: $n events in the log of a run of $frames frames"
done
# The last state and command: the converged frame's, when the log holds it.
if grep -q "^last state    seq $((frames - 1)), " "$tmp/out.txt"; then
  grep -q "^last state    seq $((frames - 1)), step 4, status 0, 100 of 125 matches" "$tmp/out.txt" ||
    fail "the last frame's state is not converged with 100 of 125 matches on the plane"
fi
if grep -q "^last command  seq $((frames - 1)), " "$tmp/out.txt"; then
  grep -q "^last command  seq $((frames - 1)), step 4, status 0, v 0.0000 m/s, w 0.0000 rad/s$" "$tmp/out.txt" ||
    fail "the last frame's command is not the converged stop"
fi
# Bad input: a file that is not a log gets one line and status 1.
echo "not a log, just some bytes of text here" >"$tmp/bad.lcmlog"
rc=0
/usr/bin/python3 "$SPVS_SOURCE/examples/python/decode_log.py" "$tmp/bad.lcmlog" \
    --types "$tmp/types" 2>"$tmp/err.txt" || rc=$?
[ $rc -eq 1 ] && grep -q "not an LCM log" "$tmp/err.txt" || fail "a bad log gave status $rc: $(cat "$tmp/err.txt")"
