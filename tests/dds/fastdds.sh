#!/usr/bin/env bash
# fastdds.sh SPVS_NODE SPVS_SIM DOMAIN FASTDDS_CMD_VEL
# An independent DDS implementation hears /cmd_vel: a Fast DDS subscriber
# (fastdds_cmd_vel) listens on rt/cmd_vel while spvs-sim --transport dds
# runs a closed loop against spvs-node --dds (ROS_DOMAIN_ID=DOMAIN,
# loopback-only namespace).  It must receive one Twist per frame, equal to
# the in-process run's command of that frame: linear.x = v, angular.z = w
# (the recording's float32 values, which the float core computes), the
# other four components zero.  And the sign is REP 103's: on the frames
# where angular.z > 0 the simulated robot's heading turns to its left
# (towards -X when it faces +Z: X right, Y down, Z forward).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/netns.sh"
node=$1 sim=$2 domain=$3 sub=${4:-}
if [ -z "$sub" ]; then
  echo "no Fast DDS subscriber in this build (libfastrtps-dev, fastddsgen:" \
       "run scripts/install_deps.sh)"
  [ "${CI:-}" = true ] && exit 1
  exit 77
fi
spvs_dds_require_netns
args=(--method 3 --seed 0)

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
timeout 120 "$sim" "${args[@]}" --json --quiet --record "$work/inproc.rec" \
    --trace "$work/inproc.csv" >"$work/inproc.out"

export NODE="$node" SIM="$sim" SUB="$sub" WORK="$work" SIM_ARGS="${args[*]}"
export ROS_DOMAIN_ID="$domain" CYCLONEDDS_URI="$(spvs_dds_uri)"
spvs_dds_in_netns '
  set -e
  "$SUB" "$WORK/fastdds.txt" 120 2>"$WORK/sub.err" & sub=$!
  "$NODE" --dds --method 3 --seed 0 --watchdog 30 --log-level 2 2>"$WORK/node.err" & node=$!
  i=0; while [ ! -e "$WORK/fastdds.txt.ready" ] && [ $i -lt 400 ]; do sleep 0.05; i=$((i+1)); done
  [ -e "$WORK/fastdds.txt.ready" ] || { echo "Fast DDS never matched spvs-node /cmd_vel writer"; kill $sub $node; exit 1; }
  timeout 120 "$SIM" $SIM_ARGS --transport dds --timeout 5 --json --quiet >"$WORK/dds.out"
  sleep 0.5
  # The subscriber leaves before the node, whose last stop is not part of
  # the run.
  kill -TERM $sub; wait $sub
  kill -TERM $node; wait $node
'
cat "$work/sub.err" "$work/node.err"

/usr/bin/python3 - "$work" <<'PY'
import math, struct, sys
w = sys.argv[1]

def frames(path):
    data = open(path, "rb").read()
    assert data[:8] == b"SPVSREC1"
    pos, out = 8, []
    while pos < len(data):
        seq, t, n = struct.unpack_from("<IdH", data, pos)
        pos += 14 + 18 * n
        v, w_, status, step = struct.unpack_from("<ffhB", data, pos)
        pos += 11
        out.append((v, w_))
    return out

rec = frames(w + "/inproc.rec")
tw = [[float(x) for x in l.split()[2:]] for l in open(w + "/fastdds.txt")
      if l.startswith("T ")]
print("in-process run: %d frames; Fast DDS received %d Twists on rt/cmd_vel"
      % (len(rec), len(tw)))
bad = []
if len(tw) != len(rec):
    bad.append("%d Twists for %d frames" % (len(tw), len(rec)))
for k, ((v, om), t) in enumerate(zip(rec, tw)):
    if t[0] != v or t[5] != om or any(t[i] != 0.0 for i in (1, 2, 3, 4)):
        bad.append("frame %d: Twist %s, in process v %r w %r" % (k, t, v, om))
        break

# REP 103: positive angular.z turns the robot to its left.
rows = [l.split(",") for l in open(w + "/inproc.csv").read().splitlines()[1:]]
phi = [math.radians(float(r[3])) for r in rows]
left_turns = 0
for k in range(min(len(tw), len(phi) - 1)):
    if tw[k][5] <= 1e-3:
        continue
    # Heading (-sin phi, cos phi) in (X, Z); the robot's left is up x
    # heading with up = -Y: (-cos phi, -sin phi).
    dh = (-math.sin(phi[k + 1]) + math.sin(phi[k]), math.cos(phi[k + 1]) - math.cos(phi[k]))
    left = (-math.cos(phi[k]), -math.sin(phi[k]))
    if dh[0] * left[0] + dh[1] * left[1] > 0:
        left_turns += 1
    else:
        bad.append("frame %d: angular.z %g > 0 but the robot turned right" % (k, tw[k][5]))
        break
print("frames with angular.z > 0: %d, on each the robot turned left" % left_turns)
if left_turns == 0:
    bad.append("no frame with angular.z > 0: the sign is not shown")
if bad:
    print("FAIL: " + "; ".join(bad))
    sys.exit(1)
print("fastdds: one Twist per frame, equal to the in-process (v, w)")
PY
