#!/usr/bin/env bash
# check.sh NODE SIM TYPES_JAR CHECK_CLASSES - lcm-spy shows the spvs types of
# a replayed run (ctest lcm_spy_replay; docs/INSTALL.md).
#
# 1. A closed-loop run over LCM (spvs-node + spvs-sim + lcm-logger, in a
#    loopback-only network namespace) writes a log.
# 2. LogDecode (LogDecode.java) decodes the log with lcm-spy's own type
#    lookup (lcm.spy.LCMTypeDatabase on the class path of spvs-lcm-spy):
#    SPVS_MATCHES, SPVS_CMD and SPVS_STATE must decode as spvs.matches_t,
#    cmd_t and state_t, every event of them, as many as the run's frames,
#    and the last command must be the converged stop (step 4).
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
chan() { awk -v c="$1" '$1 == "channel" && $2 == c { print $3, $5, $7 }' "$tmp/decode.txt"; }
read -r cls n bad <<<"$(chan SPVS_MATCHES)"
[ "$cls" = spvs.matches_t ] && [ "$n" = "$frames" ] && [ "$bad" = 0 ] ||
  fail "SPVS_MATCHES: $cls, $n decoded, $bad not (want spvs.matches_t, $frames, 0)"
read -r cls n bad <<<"$(chan SPVS_STATE)"
[ "$cls" = spvs.state_t ] && [ "$n" = "$frames" ] && [ "$bad" = 0 ] ||
  fail "SPVS_STATE: $cls, $n decoded, $bad not (want spvs.state_t, $frames, 0)"
read -r cls n bad <<<"$(chan SPVS_CMD)"
# The node's watchdog stops while it waits for the first frame are extra.
[ "$cls" = spvs.cmd_t ] && [ "$n" -ge "$frames" ] && [ "$n" -le $((frames + 10)) ] && [ "$bad" = 0 ] ||
  fail "SPVS_CMD: $cls, $n decoded, $bad not (want spvs.cmd_t, $frames..$((frames + 10)), 0)"
grep -q "^last_cmd seq $((frames - 1)) step 4 status 0 v 0.000000 w 0.000000$" "$tmp/decode.txt" ||
  fail "the last command is not the converged stop of frame $((frames - 1))"

# 3. lcm-spy under Xvfb during the replay.
SPY_SPEED=1 SPY_WAIT=4 "$here/spy_replay.sh" "$tmp/run.lcmlog" "$tmp/shot.png" "$jar" ||
  fail "spy_replay.sh failed"
changed=$(compare -metric AE "$tmp/shot.before.png" "$tmp/shot.png" null: 2>&1 || true)
changed=${changed%% *}
echo "lcm-spy window: $changed pixels changed by the replay"
[ "${changed%.*}" -gt 2000 ] || fail "lcm-spy's window did not change during the replay ($changed pixels)"
