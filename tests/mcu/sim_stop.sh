#!/usr/bin/env bash
# sim_stop.sh SPVS_SIM IMAGE
# spvs-sim --transport mcu stops QEMU and the agent however the run ends:
#   1. SIGTERM to spvs-sim in the middle of a run (--realtime);
#   2. QEMU stopped (SIGSTOP) mid-run, so no answer comes: the link's
#      --timeout ends the run with a link error (exit 1);
#   3. an image QEMU cannot run: a link error naming QEMU (exit 1).
# After each, neither process may be left (their pids, from spvs-sim's
# "MCU ready" line, or a marker path in QEMU's command line).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lcm/netns.sh"
sim=$1 image=$2
command -v qemu-system-arm >/dev/null || { echo "SKIP: qemu-system-arm not installed"; exit 77; }
[ -f "$image" ] || { echo "SKIP: no application image $image"; exit 77; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export SIM="$sim" IMAGE="$image" URL="$(spvs_lcm_url)" WORK="$work"
spvs_in_netns '
fails=0
gone() { # pid...: all gone within 5 s?
  for i in $(seq 100); do
    alive=0
    for p in "$@"; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ $alive -eq 0 ] && return 0
    sleep 0.05
  done
  return 1
}
pids() { sed -n "s/.*QEMU pid \([0-9]*\), agent pid \([0-9]*\).*/\1 \2/p" "$1"; }
wait_ready() { for i in $(seq 600); do [ -n "$(pids "$1")" ] && return 0; sleep 0.05; done; return 1; }

# 1. SIGTERM
"$SIM" --transport mcu --mcu-image "$IMAGE" --lcm-url "$URL" --realtime --json \
    >"$WORK/1.out" 2>"$WORK/1.err" &
s=$!
wait_ready "$WORK/1.err" || { echo "FAIL 1: no ready line"; cat "$WORK/1.err"; fails=1; }
sleep 1
kill -TERM $s; wait $s; rc=$?
set -- $(pids "$WORK/1.err")
if gone "$@"; then echo "ok 1: SIGTERM (spvs-sim status $rc): QEMU $1 and agent $2 gone"
else echo "FAIL 1: QEMU or agent left after SIGTERM"; fails=1; fi

# 2. no answer: QEMU stopped
"$SIM" --transport mcu --mcu-image "$IMAGE" --lcm-url "$URL" --timeout 1 --realtime \
    --json >"$WORK/2.out" 2>"$WORK/2.err" &
s=$!
wait_ready "$WORK/2.err" || { echo "FAIL 2: no ready line"; fails=1; }
set -- $(pids "$WORK/2.err")
sleep 0.5
kill -STOP "$1"
wait $s; rc=$?
if [ $rc -eq 1 ] && grep -q "no SPVS_CMD" "$WORK/2.err" && gone "$@"; then
  echo "ok 2: timeout: exit 1, $(grep -o "link error.*within [0-9.]* s" "$WORK/2.err"), QEMU and agent gone"
else echo "FAIL 2: exit $rc"; cat "$WORK/2.err"; kill -KILL "$@" 2>/dev/null; fails=1; fi

# 3. an image QEMU refuses
printf "not an image" >"$WORK/bad-image.elf"
"$SIM" --transport mcu --mcu-image "$WORK/bad-image.elf" --lcm-url "$URL" \
    >"$WORK/3.out" 2>"$WORK/3.err"; rc=$?
sleep 0.2
if [ $rc -eq 1 ] && grep -q "QEMU exited" "$WORK/3.err" && ! pgrep -f "$WORK/bad-image.elf" >/dev/null; then
  echo "ok 3: bad image: exit 1: $(cat "$WORK/3.err" | head -c 200)"
else echo "FAIL 3: exit $rc"; cat "$WORK/3.err"; fails=1; fi
exit $fails
'
