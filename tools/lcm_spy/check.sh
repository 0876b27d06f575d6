#!/usr/bin/env bash
# check.sh NODE SIM TYPES_JAR CHECK_CLASSES - lcm-spy shows the spvs types of
# a replayed run (ctest lcm_spy_replay; docs/INSTALL.md).
#
# 1. A closed-loop run over LCM (spvs-node + spvs-sim + lcm-logger, in a
#    loopback-only network namespace) writes a log.
# 2. LogDecode (LogDecode.java) decodes the log with lcm-spy's own type
#    lookup (lcm.spy.LCMTypeDatabase on the class path of spvs-lcm-spy):
#    SPVS_MATCHES, SPVS_CMD and SPVS_STATE must decode as spvs.matches_t,
#    cmd_t and state_t, every event of them in the log (at least a quarter
#    of the run's frames, lcm-logger on a busy machine may miss some), and
#    the last frame's command must be the converged stop (step 4).
# 3. spy_replay.sh runs spvs-lcm-spy under Xvfb while lcm-logplayer replays
#    the log: lcm-spy must stay up, and its window must change when the
#    messages arrive (pixels differing between the screenshots before and
#    during the replay).
# Exit 77 (skipped) with the reason where java, Xvfb, import, jchart2d.jar,
# lcm.jar or the LCM tools are missing.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
node=$1 sim=$2 jar=$3 classes=$4
skip() { echo "SKIP: $*"; exit 77; }
for t in java Xvfb import compare lcm-logger lcm-logplayer unshare; do
  command -v $t >/dev/null || skip "$t not installed (scripts/install_deps.sh)"
done
lcm_jar=${LCM_JAR:-/usr/share/java/lcm.jar}
chart_jar=${JCHART2D_JAR:-/usr/share/java/jchart2d.jar}
for j in "$lcm_jar" "$chart_jar"; do
  [ -f "$j" ] || skip "$j not installed (liblcm-java, libjchart2d-java)"
done
[ -f "$jar" ] && [ -f "$classes/LogDecode.class" ] || { echo "FAIL: $jar not built" >&2; exit 1; }
fail() { echo "FAIL: $*" >&2; exit 1; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/spvs-spycheck.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

# 1. The run and its log.
"$here/../../tests/install/record_run.sh" "$node" "$sim" "$tmp/run.lcmlog" "$tmp/sim.json" ||
  fail "the LCM run failed"
frames=$(python3 -c 'import json,sys; print(json.loads(open(sys.argv[1]).read().splitlines()[-1])["frames"])' "$tmp/sim.json")
[ "$frames" -gt 100 ] || fail "the run has $frames frames"

# 2. Decoded as lcm-spy decodes.
java -cp "$lcm_jar:$chart_jar:$jar:$classes" LogDecode "$tmp/run.lcmlog" >"$tmp/decode.txt" ||
  fail "LogDecode failed"
cat "$tmp/decode.txt"
grep -q "^Found 3 LCM types" "$tmp/decode.txt" || fail "lcm-spy's type lookup does not find the 3 spvs types"
# Every event of the three channels in the log decodes, as the right class.
# (The log is the reference: on a busy machine lcm-logger may miss some of a
# run's datagrams, so the counts are the log's, checked against the run's.)
"$here/../../tests/install/count_log.py" "$tmp/run.lcmlog" >"$tmp/count.txt" || fail "count_log.py"
chan() { awk -v c="$1" '$1 == "channel" && $2 == c { print $3, $5, $7 }' "$tmp/decode.txt"; }
logged() { awk -v c="$1" '$1 == c { print $2 }' "$tmp/count.txt"; }
for pair in SPVS_MATCHES:matches_t SPVS_STATE:state_t SPVS_CMD:cmd_t; do
  ch=${pair%%:*} want=spvs.${pair#*:}
  read -r cls n bad <<<"$(chan "$ch")"
  in_log=$(logged "$ch")
  [ "$cls" = "$want" ] && [ "$n" = "$in_log" ] && [ "$bad" = 0 ] ||
    fail "$ch: $cls, $n decoded, $bad not (want $want, all $in_log of the log, 0)"
  [ "$n" -ge $((frames / 4)) ] && [ "$n" -le $((frames + 10)) ] ||
    fail "$ch: $n events in the log of a run of $frames frames"
done
# The last command: the converged stop, when the log holds the last frame's.
read -r seq step status v w <<<"$(awk '$1 == "last_cmd" { print $3, $5, $7, $9, $11 }' "$tmp/decode.txt")"
[ "$seq" -le $((frames - 1)) ] && [ "$step" -ge 1 ] && [ "$step" -le 4 ] ||
  fail "the last command (seq $seq, step $step) does not fit a converged run of $frames frames"
if [ "$seq" = $((frames - 1)) ]; then
  [ "$step $status $v $w" = "4 0 0.000000 0.000000" ] ||
    fail "the last frame's command is not the converged stop: step $step, status $status, v $v, w $w"
fi

# 3. lcm-spy under Xvfb during the replay.
SPY_SPEED=1 SPY_WAIT=4 "$here/spy_replay.sh" "$tmp/run.lcmlog" "$tmp/shot.png" "$jar" ||
  fail "spy_replay.sh failed"
changed=$(compare -metric AE "$tmp/shot.before.png" "$tmp/shot.png" null: 2>&1 || true)
changed=${changed%% *}
echo "lcm-spy window: $changed pixels changed by the replay"
[ "${changed%.*}" -gt 2000 ] || fail "lcm-spy's window did not change during the replay ($changed pixels)"
