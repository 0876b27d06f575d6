#!/usr/bin/env bash
# faults.sh SPVS_NODE SPVS_SIM DDS_PROBE DOMAIN
# spvs-node --dds under faults, in a loopback-only namespace:
#  1. malformed frames on /spvs/matches (count above the capacity, NaN and
#     infinite coordinates, a negative count): each gets one zero Twist and
#     a State of its seq with the status (dds_probe faults);
#  2. a second node on ROS_DOMAIN_ID DOMAIN+50 while a run goes on DOMAIN:
#     it runs no frame, and a listener there hears no Twist and no State,
#     while a listener on DOMAIN hears every frame's State;
#  3. the node stopped (SIGTERM) mid-run (the simulator held meanwhile):
#     its last Twist is a zero Twist, sent after the moving ones, and
#     nothing follows it while the simulator keeps sending its frame.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
. "$here/netns.sh"
spvs_dds_require_netns
node=$1 sim=$2 probe=$3 domain=$4

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export NODE="$node" SIM="$sim" PROBE="$probe" WORK="$work"
export D1="$domain" D2="$((domain + 50))" CYCLONEDDS_URI="$(spvs_dds_uri)"

spvs_dds_in_netns '
  set -e
  wait_file() { i=0; while [ ! -e "$1" ] && [ $i -lt 200 ]; do sleep 0.05; i=$((i+1)); done; [ -e "$1" ]; }
  stop() { kill -TERM $1 2>/dev/null || true; wait $1 || true; }

  ROS_DOMAIN_ID=$D1 "$NODE" --dds --method 3 --watchdog 30 --log-level 2 2>"$WORK/node1.err" &
  n1=$!
  ROS_DOMAIN_ID=$D2 "$NODE" --dds --method 3 --watchdog 30 --log-level 2 2>"$WORK/node2.err" &
  n2=$!

  echo "== 1. malformed frames"
  ROS_DOMAIN_ID=$D1 timeout 30 "$PROBE" faults >"$WORK/faults.out" || echo fail >"$WORK/faults.failed"
  cat "$WORK/faults.out"

  echo "== 2. another domain"
  ROS_DOMAIN_ID=$D1 "$PROBE" listen "$WORK/a.txt" 60 & la=$!
  ROS_DOMAIN_ID=$D2 "$PROBE" listen "$WORK/b.txt" 60 & lb=$!
  wait_file "$WORK/a.txt.ready"; wait_file "$WORK/b.txt.ready"
  ROS_DOMAIN_ID=$D1 timeout 60 "$SIM" --method 3 --max-time 5 --transport dds --timeout 5 --json --quiet >"$WORK/sim2.out"
  sleep 0.5
  stop $la; stop $lb
  stop $n2

  echo "== 3. node stopped mid-run"
  ROS_DOMAIN_ID=$D1 "$PROBE" listen "$WORK/c.txt" 60 & lc=$!
  wait_file "$WORK/c.txt.ready"
  # Not under timeout(1): the signals below must reach spvs-sim itself (its
  # --timeout bounds it once the node is gone).
  ROS_DOMAIN_ID=$D1 "$SIM" --method 1 --transport dds --timeout 2 --json --quiet \
      --trace "$WORK/c.csv" >"$WORK/sim3.out" 2>"$WORK/sim3.err" & s3=$!
  rows() { if [ -e "$WORK/c.csv" ]; then wc -l <"$WORK/c.csv"; else echo 0; fi; }
  i=0; while [ "$(rows)" -lt 50 ] && [ $i -lt 400 ]; do sleep 0.01; i=$((i+1)); done
  # Mid-run for sure: the simulator is held while the node stops, then
  # resumes and waits for an answer that never comes.
  kill -STOP $s3
  kill -TERM $n1
  # The node leaves within its writer linger (1 s); 10 s is a hang.
  i=0; while kill -0 $n1 2>/dev/null && [ $i -lt 200 ]; do sleep 0.05; i=$((i+1)); done
  if kill -0 $n1 2>/dev/null; then echo hang >"$WORK/node1.hung"; kill -KILL $n1; fi
  wait $n1 || true
  kill -CONT $s3
  wait $s3 && echo 0 >"$WORK/sim3.rc" || echo $? >"$WORK/sim3.rc"
  stop $lc
'
echo "--- node on domain $D1"; cat "$work/node1.err"
echo "--- node on domain $D2"; cat "$work/node2.err"
echo "--- simulator after the node stopped (exit $(cat "$work/sim3.rc"))"; cat "$work/sim3.err"

/usr/bin/python3 - "$work" "$D2" <<'PY'
import json, os, sys
w, d2 = sys.argv[1], sys.argv[2]
bad = []
if os.path.exists(w + "/faults.failed"):
    bad.append("1: malformed frames (see above)")

def lines(name):
    return [l.split() for l in open(os.path.join(w, name)).read().splitlines()]

# 2. The other domain.
run = json.loads(open(w + "/sim2.out").read().splitlines()[-1])
a, b = lines("a.txt"), lines("b.txt")
a_states = [l for l in a if l[0] == "S" and int(l[2]) >= 0]
print("2: run of %d frames on the first domain; its listener heard %d States, "
      "the other domain's listener %d samples" % (run["frames"], len(a_states), len(b)))
if len(a_states) != run["frames"]:
    bad.append("2: the listener on the run's domain heard %d States for %d frames"
               % (len(a_states), run["frames"]))
if b:
    bad.append("2: the listener on domain %s heard %d samples" % (d2, len(b)))
n2 = open(w + "/node2.err").read()
if "exit: 0 frames" not in n2 or " 0 runs" not in n2:
    bad.append("2: the node on domain %s ran frames: %s" % (d2, n2.strip()))

# 3. Stopped mid-run.
c = lines("c.txt")
tw = [l for l in c if l[0] == "T"]
st = [l for l in c if l[0] == "S"]
moving = [l for l in tw if any(float(x) != 0.0 for x in l[2:])]
frames = len(open(w + "/c.csv").read().splitlines()) - 1
print("3: %d Twists (%d moving), %d States, %d frames answered before the stop"
      % (len(tw), len(moving), len(st), frames))
if not moving:
    bad.append("3: the robot never moved before the node stopped")
if not tw or any(float(x) != 0.0 for x in tw[-1][2:]):
    bad.append("3: the last Twist is not a stop: %s" % (tw[-1:] or "none"))
if not st or int(st[-1][2]) != -1 or int(st[-1][3]) != -8:
    bad.append("3: the last State is not the node's stop (seq -1, status -8): %s" % st[-1:])
if len(tw) != len(st):
    bad.append("3: %d Twists but %d States (one of each per answer)" % (len(tw), len(st)))
# The answers are frames 0, 1, ... in order: those the simulator recorded,
# perhaps the one in flight when it was held, then the node's stop.
answers = [int(l[2]) for l in st[:-1]]
if answers != list(range(len(answers))) or len(answers) not in (frames, frames + 1):
    bad.append("3: the States answer frames %s..%s (%d) for %d frames recorded"
               % (answers[:1], answers[-1:], len(answers), frames))
if os.path.exists(w + "/node1.hung"):
    bad.append("3: spvs-node did not exit within 10 s of SIGTERM")
if int(open(w + "/sim3.rc").read()) != 1:
    bad.append("3: spvs-sim did not end with a link error")
if bad:
    print("FAIL:\n  " + "\n  ".join(bad))
    sys.exit(1)
print("faults: all as required")
PY
