#!/usr/bin/env bash
# python_decode.sh NODE SIM - the Python path of docs/INSTALL.md: the types
# made with the documented `lcm-gen -p`, a run over LCM recorded by
# lcm-logger, and examples/python/decode_log.py on the log: every frame's
# matches_t and state_t decoded, the last state and command those of the
# converged run (step 4, v = w = 0).
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
grep -q "^SPVS_MATCHES  matches_t  $frames messages$" "$tmp/out.txt" || fail "SPVS_MATCHES count != $frames frames"
grep -q "^SPVS_STATE    state_t    $frames messages$" "$tmp/out.txt" || fail "SPVS_STATE count != $frames frames"
grep -q "^last state    seq $((frames - 1)), step 4, status 0, " "$tmp/out.txt" ||
  fail "the last state is not the converged frame $((frames - 1))"
grep -q "^last command  seq $((frames - 1)), step 4, status 0, v 0.0000 m/s, w 0.0000 rad/s$" "$tmp/out.txt" ||
  fail "the last command is not the converged stop"
# Bad input: a file that is not a log gets one line and status 1.
echo "not a log, just some bytes of text here" >"$tmp/bad.lcmlog"
rc=0
/usr/bin/python3 "$SPVS_SOURCE/examples/python/decode_log.py" "$tmp/bad.lcmlog" \
    --types "$tmp/types" 2>"$tmp/err.txt" || rc=$?
[ $rc -eq 1 ] && grep -q "not an LCM log" "$tmp/err.txt" || fail "a bad log gave status $rc: $(cat "$tmp/err.txt")"
