#!/usr/bin/env bash
# The README's sample report held to a default run of the demo's loop:
# spvs-node and spvs-sim over LCM with lcm-logger recording the bus, as
# scripts/run_demo.sh runs them (method 3, seed 0, no other option), in a
# loopback-only network namespace (netns.sh).  The simulated time, frames
# and metres driven the README shows must be the run's (as the report
# rounds them), and the LCM log's event count per channel must be the
# log's (SPVS_CMD within one: the node's watchdog stops before the first
# frame depend on timing).  The run is paced (--realtime) so that
# lcm-logger misses no datagram on a busy machine; pacing changes no
# figure of the run.  docs/LCM.md quotes the same figures: checked too.
#
#   tests/lcm/readme_report.sh SPVS_NODE SPVS_SIM README.md LCM.md WORKDIR
#
# Exit status 0 when the documents hold the run's figures, 1 otherwise, 2 on
# a usage error.
set -euo pipefail
if [ $# -ne 5 ]; then
  sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
node=$1 sim=$2 readme=$3 lcm_md=$4 work=$5
here=$(cd "$(dirname "$0")" && pwd)
. "$here/netns.sh"
command -v lcm-logger >/dev/null || { echo "readme_report: lcm-logger is missing" >&2; exit 1; }
rm -rf "$work"
mkdir -p "$work"
export NODE=$node SIM=$sim URL=$(spvs_lcm_url) LOG=$work/demo.lcmlog OUT=$work/sim.out
spvs_in_netns '
  lcm-logger -q -f --lcm-url="$URL" "$LOG" 2>/dev/null &
  logger=$!
  "$NODE" --method 3 --seed 0 --lcm-url "$URL" --log-level 2 2>/dev/null &
  node=$!
  sleep 0.5
  "$SIM" --method 3 --seed 0 --transport lcm --lcm-url "$URL" --timeout 5 --realtime --json >"$OUT"
  rc=$?
  sleep 0.3
  kill -INT $node $logger 2>/dev/null
  wait $node
  wait $logger
  exit $rc
'
/usr/bin/python3 - "$OUT" "$LOG" "$readme" "$lcm_md" <<'PY'
import json, re, struct, sys
res = json.loads(open(sys.argv[1]).read().strip().splitlines()[-1])
counts, n = {}, 0
with open(sys.argv[2], "rb") as f:
    while True:
        head = f.read(28)
        if len(head) < 28:
            break
        sync, _, _, clen, dlen = struct.unpack(">IqqII", head)
        if sync != 0xEDA1DA01:
            sys.exit("readme_report: %s is damaged after %d events" % (sys.argv[2], n))
        ch = f.read(clen).decode("ascii", "replace")
        f.seek(dlen, 1)
        counts[ch] = counts.get(ch, 0) + 1
        n += 1
run = "%.1f s simulated, %d frames, %.2f m driven" % (res["time_s"], res["frames"], res["path_m"])
print("the run: %s, status %s; LCM log %d events: %s" % (
    run, res["status"], n, ", ".join("%s %d" % kv for kv in sorted(counts.items()))))
# The node's watchdog stops (one every 0.5 s while it waits for the first
# frame) are SPVS_CMD events beyond one per frame; how many fall in the
# 0.5 s before the simulator starts depends on timing, so the documents'
# SPVS_CMD count must differ from the run's by at most one, and each must
# exceed its frames by 1 to 4.
STOPS = (1, 4)
bad = 0
if res["status"] != "converged":
    print("readme_report: the default run did not converge (%s)" % res["status"])
    bad += 1
if not STOPS[0] <= counts.get("SPVS_CMD", 0) - res["frames"] <= STOPS[1]:
    print("readme_report: the run's SPVS_CMD count %d is not its frames %d plus 1-4 stops"
          % (counts.get("SPVS_CMD", 0), res["frames"]))
    bad += 1
for doc in sys.argv[3:]:
    text = open(doc).read()
    # The sample report's lines, wherever the document shows them.
    shown_run = re.findall(r"run +([0-9.]+ s simulated, [0-9,]+ frames, [0-9.]+ m driven)", text)
    shown_events = re.findall(r"\(([0-9,]+) events: ([A-Z_]+ [0-9,]+(?:, [A-Z_]+ [0-9,]+)*)\)", text)
    if not shown_run or not shown_events:
        print("readme_report: %s shows no sample report" % doc)
        bad += 1
    for s in shown_run:
        if re.sub(r"(?<=[0-9]),(?=[0-9]{3})", "", s) != run:
            print("readme_report: %s says '%s', the run '%s'" % (doc, s, run))
            bad += 1
    for total, per in shown_events:
        doc_counts = {k: int(v.replace(",", "")) for k, v in
                      (item.rsplit(" ", 1) for item in per.split(", "))}
        if sum(doc_counts.values()) != int(total.replace(",", "")):
            print("readme_report: %s: %s events is not the sum of its channels" % (doc, total))
            bad += 1
        if set(doc_counts) != set(counts):
            print("readme_report: %s names channels %s, the log %s"
                  % (doc, sorted(doc_counts), sorted(counts)))
            bad += 1
            continue
        for ch, k in sorted(doc_counts.items()):
            # Each LCM process of the demo (node, simulator) sends one
            # LCM_SELF_TEST when it opens LCM; the logger hears those sent
            # after it started, which timing decides: 1 or 2.
            if ch == "LCM_SELF_TEST":
                ok = 1 <= k <= 2 and 1 <= counts[ch] <= 2
            else:
                ok = abs(k - counts[ch]) <= 1 if ch == "SPVS_CMD" else k == counts[ch]
            if ch == "SPVS_CMD":
                ok = ok and STOPS[0] <= k - doc_counts.get("SPVS_MATCHES", 0) <= STOPS[1]
            if not ok:
                print("readme_report: %s says %s %d, the log %d" % (doc, ch, k, counts[ch]))
                bad += 1
sys.exit(1 if bad else 0)
PY
