#!/usr/bin/env bash
# docs_screenshot.sh BUILD [LOG] - remakes docs/figures/lcm_spy.png: lcm-spy
# (spvs-lcm-spy) under Xvfb while lcm-logplayer replays LOG (default
# out/demo.lcmlog; make it paced at 10 Hz with ./scripts/run_demo.sh
# --realtime), its channel table 8 s into the replay beside its viewer of
# SPVS_STATE (opened by a double-click on that row).  BUILD holds the
# spvs_lcm_jar target's outputs (cmake --build BUILD --target spvs_lcm_jar).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
[ $# -ge 1 ] && [ $# -le 2 ] || { sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
build=$(readlink -f "$1")
log=${2:-$root/out/demo.lcmlog}
jar=$build/tools/lcm_spy/spvs_lcm_types.jar
[ -f "$jar" ] || { echo "docs_screenshot: no $jar (cmake --build $1 --target spvs_lcm_jar)" >&2; exit 1; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/spvs-shot.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
# The rows are sorted by channel: LCM_SELF_TEST, SPVS_CMD, SPVS_MATCHES,
# SPVS_STATE; the fourth is at y = 75 in a window at the screen's corner.
SPY_WAIT=8 SPY_CLICK=80,75 SPY_CLASSES=$build/tools/lcm_spy/check_classes \
  "$here/spy_replay.sh" "$log" "$tmp/shot.png" "$jar"
# Without a window manager both windows sit at (0, 0): the table (the top
# 800x400 of its window) from the first screen, the viewer (650x400) from
# the second.
convert "$tmp/shot.png" -crop 800x400+0+0 +repage "$tmp/table.png"
convert "$tmp/shot.viewer.png" -crop 650x400+0+0 +repage "$tmp/viewer.png"
convert -background white -gravity north "$tmp/table.png" "$tmp/viewer.png" +append \
  "$root/docs/figures/lcm_spy.png"
echo "docs_screenshot: $root/docs/figures/lcm_spy.png"
