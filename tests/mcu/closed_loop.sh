#!/usr/bin/env bash
# closed_loop.sh [--ref TRANSPORT] SPVS_SIM IMAGE [spvs-sim options...]
# The same run twice: in process with the serial link's rounding applied
# (--quantize-serial; with --ref fixed, on the host's fixed-point core, for
# an image of the fixed-point build), then through the controller
# application on the emulated MCU the image was built for (--transport mcu:
# QEMU, spvs-serial-agent, LCM inside a loopback-only network namespace).  The two --json summaries must be equal
# field for field (the transport name aside): bit for bit the same
# commands, so the same trajectory to the last printed digit.
# Exit 77 (skipped) when qemu-system-arm or the image is missing.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lcm/netns.sh"
ref=inproc
if [ "${1:-}" = --ref ]; then
  ref=${2:?--ref needs a transport}
  shift 2
fi
sim=$1 image=$2
shift 2
command -v qemu-system-arm >/dev/null || { echo "SKIP: qemu-system-arm not installed"; exit 77; }
[ -f "$image" ] || { echo "SKIP: no application image $image (cross build missing)"; exit 77; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

timeout 120 "$sim" "$@" --transport "$ref" --quantize-serial --json --quiet >"$work/inproc.out"
tail -n 1 "$work/inproc.out" >"$work/inproc.json"

export SIM="$sim" IMAGE="$image" URL="$(spvs_lcm_url)" WORK="$work" SIM_ARGS="$*"
spvs_in_netns '
  # $SIM_ARGS holds plain options without spaces, so word splitting is fine.
  timeout 600 "$SIM" $SIM_ARGS --transport mcu --mcu-image "$IMAGE" \
      --lcm-url "$URL" --timeout 10 --json --quiet >"$WORK/mcu.out" 2>"$WORK/mcu.err"
' || { echo "MCU run failed"; cat "$work/mcu.err"; cat "$work/mcu.out"; exit 1; }
tail -n 1 "$work/mcu.out" >"$work/mcu.json"

/usr/bin/python3 - "$work/inproc.json" "$work/mcu.json" <<'PY'
import json, sys
a = json.load(open(sys.argv[1]))
b = json.load(open(sys.argv[2]))
print("in process (%s), serial rounding:" % a["transport"], a["status"], a["final_error"], "t", a["time_s"], "frames", a["frames"])
print("through the emulated MCU:   ", b["status"], b["final_error"], "t", b["time_s"], "frames", b["frames"])
assert b["transport"] == "mcu", b["transport"]
a.pop("transport"); b.pop("transport")
bad = [k for k in a if a[k] != b.get(k)]
if bad:
    print("FAIL: fields differ: " + ", ".join("%s: %r != %r" % (k, a[k], b.get(k)) for k in bad))
    sys.exit(1)
if a["status"] != "converged":
    print("FAIL: the run did not converge (%s), so it shows little" % a["status"])
    sys.exit(1)
# The arrival check's figures came through the RESULT frame: the threshold
# and the three standard deviations (its last 16 bytes) are never 0 after a
# check, so equal figures show the whole body travelled.
arr = b["arrival"]
zero = [k for k in ("threshold", "lateral_sd_px", "depth_sd_px", "h13_sd_px")
        if not arr[k] > 0]
if zero:
    print("FAIL: arrival figures at 0 after the check: " + ", ".join(zero))
    sys.exit(1)
print("arrival check through the link: statistic %g of threshold %g, sd %g / %g / %g px"
      % (arr["statistic"], arr["threshold"], arr["lateral_sd_px"],
         arr["depth_sd_px"], arr["h13_sd_px"]))
print("mcu closed loop: bit for bit the in-process run (%d frames)" % a["frames"])
PY
