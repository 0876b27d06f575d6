#!/usr/bin/env bash
# run_demo.sh [spvs-sim options...]
#
# The main job, end to end on this machine: installs the dependencies,
# builds (build/demo, Release), then runs the controller node spvs-node and
# the simulator spvs-sim as two processes talking LCM, records the bus with
# lcm-logger, plots the run and prints a short report.
#
# LCM's UDP multicast stays on this machine: the three LCM processes run in a
# network namespace of their own that has only a loopback interface (unshare
# -r: no root needed), with a multicast route on lo set up inside it and
# ttl=0 on the URL.  The host's routes are not touched.
#
# Default scenario: Method III from (-3 m, -10 m, -30 deg), seed 0.  Extra
# options go to spvs-sim; --method and --seed also go to spvs-node.
# --realtime paces the run at the control period (0.1 s) instead of running
# it as fast as the machine allows.
#
# Outputs (out/): demo.lcmlog (lcm-logger format; replay with lcm-logplayer),
# demo_trace.csv, demo_result.json, demo_{trajectory,states,homography}.png.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

method=3
seed=0
sim_args=()
while [ $# -gt 0 ]; do
  case $1 in
    --method|--seed)
      [ $# -ge 2 ] || { echo "run_demo: $1 needs a value" >&2; exit 2; }
      [ "$1" = --method ] && method=$2 || seed=$2
      shift 2 ;;
    --transport|--lcm-url|--trace|--json|--quiet)
      echo "run_demo: $1 is set by the demo itself" >&2; exit 2 ;;
    -h|--help)
      sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) sim_args+=("$1"); shift ;;
  esac
done
case $method in 1|2|3) ;; *) echo "run_demo: --method must be 1, 2 or 3" >&2; exit 2 ;; esac

echo "=== dependencies ==="
./scripts/install_deps.sh
command -v unshare >/dev/null || { echo "run_demo: unshare (util-linux) is missing" >&2; exit 1; }
command -v lcm-logger >/dev/null || { echo "run_demo: lcm-logger (liblcm-bin) is missing" >&2; exit 1; }

echo "=== build (build/demo, Release) ==="
cmake -S . -B build/demo -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/demo --target spvs-node spvs-sim

bin=build/demo/sim_host
mkdir -p out
log=out/demo.lcmlog
trace=out/demo_trace.csv
result=out/demo_result.json
rm -f "$log" "$trace" "$result" out/demo_node.err out/demo_logger.err

# Any group/port works inside the private namespace; ttl=0 keeps packets on
# the host even if the namespace were shared by mistake.
url="udpm://239.255.76.67:7667?ttl=0"

echo "=== run: spvs-node + spvs-sim over LCM (method $method, seed $seed) ==="
export NODE="$bin/node/spvs-node" SIM="$bin/spvs-sim" URL="$url" LOG="$log"
export TRACE="$trace" RESULT="$result" METHOD="$method" SEED="$seed"
export SIM_ARGS="${sim_args[*]:-}"
t0=$(date +%s.%N)
set +e
unshare -r -n sh -c '
  set -u
  ip link set lo up && ip route add 224.0.0.0/4 dev lo || {
    echo "run_demo: cannot set up the loopback-only namespace" >&2; exit 1; }
  lcm-logger -q -f --lcm-url="$URL" "$LOG" 2>out/demo_logger.err &
  logger=$!
  "$NODE" --method "$METHOD" --seed "$SEED" --lcm-url "$URL" --log-level 2 \
      2>out/demo_node.err &
  node=$!
  # Let both subscribe before the first frame goes out.
  sleep 0.5
  # $SIM_ARGS holds plain options (no spaces), so word splitting is wanted.
  "$SIM" --method "$METHOD" --seed "$SEED" $SIM_ARGS --transport lcm \
      --lcm-url "$URL" --timeout 5 --trace "$TRACE" --json >out/demo_sim.out &
  sim=$!
  # Progress: every 20th frame of the trace as spvs-sim writes it; tail ends
  # when spvs-sim does.
  tail -n +2 -F --pid=$sim "$TRACE" 2>/dev/null | awk -F, "\$1 != \"t\" && ++k % 20 == 1 {
      printf \"  t %6.1f s  step %s  x %+7.3f m  z %+7.3f m  phi %+7.2f deg  v %+.3f m/s  w %+.4f rad/s\n\",
             \$1, \$7, \$2, \$3, \$4, \$5, \$6; fflush() }"
  wait $sim
  rc=$?
  # Let the logger take the last messages before it stops.
  sleep 0.3
  kill -INT $node $logger 2>/dev/null
  wait $node; nrc=$?
  wait $logger
  [ $nrc -eq 0 ] || echo "run_demo: spvs-node exited with status $nrc" >&2
  exit $rc
'
rc=$?
set -e
t1=$(date +%s.%N)
grep -v '^{' out/demo_sim.out || true
tail -n 1 out/demo_sim.out >"$result" || true
if [ $rc -ne 0 ]; then
  echo "run_demo: the run failed (spvs-sim status $rc); node log: out/demo_node.err" >&2
  cat out/demo_node.err >&2 || true
  exit 1
fi

echo "=== plots ==="
tools/plot "$trace" --out out/demo --title "Method $method over LCM"

echo "=== report ==="
/usr/bin/python3 - "$result" "$log" "$t0" "$t1" "$root" <<'PY'
import json, struct, sys
res = json.load(open(sys.argv[1]))
log, t0, t1, root = sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), sys.argv[5]
# Count the log's events per channel (lcm-logger's event format: sync word,
# event number, utime, channel length, data length, channel, data).
counts, n = {}, 0
with open(log, "rb") as f:
    while True:
        head = f.read(28)
        if len(head) < 28:
            break
        sync, _, _, clen, dlen = struct.unpack(">IqqII", head)
        if sync != 0xEDA1DA01:
            print("warning: %s is damaged after %d events" % (log, n))
            break
        ch = f.read(clen).decode("ascii", "replace")
        f.seek(dlen, 1)
        counts[ch] = counts.get(ch, 0) + 1
        n += 1
e = res["final_error"]
print("method        %d (seed %d)" % (res["method"], res["seed"]))
print("status        %s%s" % (res["status"], (": " + res["reason"]) if res.get("reason") else ""))
print("final error   x %+.4f m, z %+.4f m, phi %+.3f deg" % (e["x_m"], e["z_m"], e["phi_deg"]))
print("run           %.1f s simulated, %d frames, %.2f m driven, %.1f s wall clock"
      % (res["time_s"], res["frames"], res["path_m"], t1 - t0))
print("LCM log       %s/%s (%d events: %s)" % (root, log, n,
      ", ".join("%s %d" % kv for kv in sorted(counts.items()))))
print("trace         %s/out/demo_trace.csv" % root)
print("plots         %s/out/demo_trajectory.png, demo_states.png, demo_homography.png" % root)
print("replay        lcm-logplayer %s  (see docs/LCM.md)" % log)
PY
