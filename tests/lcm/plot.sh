#!/usr/bin/env bash
# plot.sh SPVS_SIM PLOT
# tools/plot on a real trace writes the three figures as PNGs of the expected
# pixel size (6x6 in, 7x9 in and 9x7 in at 120 dpi), and refuses a file that
# is not a trace, or a trace with a broken row, with exit status 2.
set -euo pipefail
sim=$1 plot=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$sim" --method 2 --trace "$work/t.csv" --quiet
"$plot" "$work/t.csv" --out "$work/fig" --title "Method II" >/dev/null
/usr/bin/python3 - "$work" <<'PY'
import struct, sys
want = {"trajectory": (720, 720), "states": (840, 1080), "homography": (1080, 840)}
for name, size in want.items():
    with open("%s/fig_%s.png" % (sys.argv[1], name), "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n", name + ": not a PNG"
    w, h = struct.unpack(">II", head[16:24])
    assert (w, h) == size, "%s: %dx%d, expected %dx%d" % ((name, w, h) + size)
print("plot: three PNGs of the right size")
PY
echo "t,x" >"$work/bad.csv"
set +e
"$plot" "$work/bad.csv" --out "$work/bad" 2>"$work/err"; rc=$?
head -n 5 "$work/t.csv" >"$work/cut.csv"; echo "1.0,2,oops" >>"$work/cut.csv"
"$plot" "$work/cut.csv" --out "$work/cut" 2>>"$work/err"; rc2=$?
set -e
cat "$work/err"
[ $rc -eq 2 ] && [ $rc2 -eq 2 ] || { echo "FAIL: exit $rc, $rc2 for bad traces"; exit 1; }
[ "$(wc -l <"$work/err")" -eq 2 ] || { echo "FAIL: expected one line per error"; exit 1; }
echo "plot: ok"
