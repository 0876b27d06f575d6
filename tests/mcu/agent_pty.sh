#!/usr/bin/env bash
# agent_pty.sh SPVS_SIM SPVS_SERIAL_AGENT IMAGE
# The agent on a pseudo-terminal, as on a real serial port: QEMU's UART on
# -serial pty, the agent opens the /dev/pts path QEMU names (raw, 921,600
# baud), and a short closed loop over LCM (loopback-only namespace) must get
# one computed answer per frame from the MCU.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../lcm/netns.sh"
sim=$1 agent=$2 image=$3
command -v qemu-system-arm >/dev/null || { echo "SKIP: qemu-system-arm not installed"; exit 77; }
[ -f "$image" ] || { echo "SKIP: no application image $image"; exit 77; }
[ -e /dev/ptmx ] || { echo "SKIP: no /dev/ptmx"; exit 77; }
work=$(mktemp -d)
trap '[ -n "${KEEP:-}" ] || rm -rf "$work"' EXIT
export SIM="$sim" AGENT="$agent" IMAGE="$image" URL="$(spvs_lcm_url)" WORK="$work"
spvs_in_netns '
  qemu-system-arm -M mps2-an386 -nographic -monitor none \
      -semihosting-config enable=on,target=native -serial pty \
      -kernel "$IMAGE" >"$WORK/qemu.out" 2>&1 &
  q=$!
  pty=""
  for i in $(seq 100); do
    pty=$(sed -n "s/.*redirected to \(\/dev\/pts\/[0-9]*\).*/\1/p" "$WORK/qemu.out")
    [ -n "$pty" ] && break
    sleep 0.05
  done
  [ -n "$pty" ] || { echo "QEMU named no pty"; kill $q; exit 1; }
  echo "QEMU UART on $pty"
  "$AGENT" --device "$pty" --baud 921600 --lcm-url "$URL" --ready-file "$WORK/ready" \
      --summary "$WORK/agent.json" --log-level 2 2>"$WORK/agent.err" &
  a=$!
  for i in $(seq 300); do [ -e "$WORK/ready" ] && break; sleep 0.05; done
  rc=0
  timeout 120 "$SIM" --transport lcm --lcm-url "$URL" --timeout 10 --max-time 3 \
      --json --quiet >"$WORK/sim.out" || rc=1
  kill -TERM $a; wait $a || rc=1
  kill $q; wait $q 2>/dev/null || true
  exit $rc
' || { echo "FAIL: the run over the pty failed"; cat "$work/agent.err"; exit 1; }
/usr/bin/python3 - "$work/sim.out" "$work/agent.json" <<'PY'
import json, sys
sim = json.loads(open(sys.argv[1]).read().strip().splitlines()[-1])
ag = json.load(open(sys.argv[2]))
computed = ag["results"] - ag["rejected"] - ag["repeats"]
print("over the pty: %d frames, %d answers computed by the MCU, %d bad frames"
      % (sim["frames"], computed, ag["bad_crc"] + ag["bad_framing"]))
ok = sim["frames"] >= 30 and computed == sim["frames"] and ag["bad_crc"] + ag["bad_framing"] == 0
sys.exit(0 if ok else 1)
PY
