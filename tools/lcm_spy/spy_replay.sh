#!/usr/bin/env bash
# spy_replay.sh LOG SHOT.png [TYPES_JAR]
#
# Shows lcm-spy (spvs-lcm-spy) decoding the spvs types of an LCM log and
# takes a screenshot: in a network namespace of its own with only a loopback
# interface (unshare -r -n; LCM multicast cannot leave it), it starts a
# virtual X server (Xvfb), spvs-lcm-spy, then lcm-logplayer on LOG, and
# saves the screen with ImageMagick's import $SPY_WAIT seconds (default 4)
# after the replay started, while it runs or after it ended.  $SPY_SPEED is
# the replay speed (default 1: as recorded).  SHOT.before.png is the screen
# before the replay started.  With SPY_CLICK=X,Y and SPY_CLASSES (the
# folder of Click.class, BUILD/tools/lcm_spy/check_classes) it then
# double-clicks there, e.g. on a channel's row to open its viewer, and saves
# the screen again 2 s later as SHOT.viewer.png.
# Needs java, Xvfb, import, lcm-logplayer, unshare (docs/INSTALL.md).
# Exit 0 with the screenshot written, 1 on a failure (the reason on stderr),
# 2 on bad arguments.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
[ $# -ge 2 ] && [ $# -le 3 ] || { sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
log=$(readlink -f "$1")
shot=$(readlink -m "$2")
[ -f "$log" ] || { echo "spy_replay: no log $log" >&2; exit 2; }
export SPY_LOG=$log SPY_SHOT=$shot SPY_LAUNCHER=$here/spvs-lcm-spy
export SPY_SPEED=${SPY_SPEED:-1} SPY_WAIT=${SPY_WAIT:-4} SPY_CLICK=${SPY_CLICK:-} SPY_CLASSES=${SPY_CLASSES:-}
export SPY_TYPES=${3:-${SPVS_LCM_TYPES_JAR:-}}
export SPY_URL="udpm://239.255.76.67:$((20000 + $$ % 20000))?ttl=0"
work=$(mktemp -d "${TMPDIR:-/tmp}/spvs-spy.XXXXXX")
trap 'rm -rf "$work"' EXIT
export SPY_WORK=$work

unshare -r -n bash -c '
  set -u
  ip link set lo up && ip route add 224.0.0.0/4 dev lo || {
    echo "spy_replay: cannot set up the loopback-only namespace" >&2; exit 1; }
  pids=()
  cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; }
  trap cleanup EXIT
  # Xvfb picks a free display itself and writes its number to fd 3.
  Xvfb -displayfd 3 -screen 0 1000x700x24 -nolisten tcp 3>"$SPY_WORK/display" \
      2>"$SPY_WORK/xvfb.err" &
  pids+=($!)
  for _ in $(seq 100); do [ -s "$SPY_WORK/display" ] && break; sleep 0.1; done
  [ -s "$SPY_WORK/display" ] || { echo "spy_replay: Xvfb did not start:" >&2; cat "$SPY_WORK/xvfb.err" >&2; exit 1; }
  export DISPLAY=:$(cat "$SPY_WORK/display")
  "$SPY_LAUNCHER" ${SPY_TYPES:+--types "$SPY_TYPES"} --lcm-url "$SPY_URL" \
      >"$SPY_WORK/spy.out" 2>&1 &
  spy=$!
  pids+=($spy)
  # The JVM and Swing take a few seconds to put the window up.
  sleep 5
  kill -0 $spy 2>/dev/null || { echo "spy_replay: lcm-spy exited:" >&2; cat "$SPY_WORK/spy.out" >&2; exit 1; }
  import -window root "${SPY_SHOT%.png}.before.png" || exit 1
  lcm-logplayer --speed="$SPY_SPEED" --lcm-url="$SPY_URL" "$SPY_LOG" >"$SPY_WORK/player.out" 2>&1 &
  player=$!
  pids+=($player)
  sleep "$SPY_WAIT"
  kill -0 $spy 2>/dev/null || { echo "spy_replay: lcm-spy exited during the replay:" >&2; cat "$SPY_WORK/spy.out" >&2; exit 1; }
  import -window root "$SPY_SHOT" || exit 1
  if [ -n "$SPY_CLICK" ]; then
    java -cp "$SPY_CLASSES" Click "${SPY_CLICK%,*}" "${SPY_CLICK#*,}" ||
      { echo "spy_replay: the click at $SPY_CLICK failed" >&2; exit 1; }
    sleep 2
    import -window root "${SPY_SHOT%.png}.viewer.png" || exit 1
  fi
  wait $player || { echo "spy_replay: lcm-logplayer failed:" >&2; cat "$SPY_WORK/player.out" >&2; exit 1; }
  exit 0
'
echo "spy_replay: $shot"
