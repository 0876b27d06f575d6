#!/usr/bin/python3
"""The fixed-point update against the Cortex-M4F's, frame by frame.

usage: spread_ratio.py [--limit R] M4F_OUTPUT M3_FIXED_OUTPUT

Reads the `spread:` lines (one per frame: pose, seed, hypotheses,
update_typ) of two runs of tools/embedded_measure.sh, the Cortex-M4F
float core's and the Cortex-M3 fixed-point core's:

    tools/embedded_measure.sh > m4f.txt
    tools/embedded_measure.sh --cpu cortex-m3 --fixed > m3f.txt
    tools/fixed_m3_bench/spread_ratio.py m4f.txt m3f.txt

and prints each frame's instructions in both builds and their ratio
(marked * above the limit, 1.5 by default: issue 23's goal,
docs/FIXED.md, followed by the instructions the fixed-point update would
have to lose to reach it), then the median ratio, the range and how many
frames are within the limit.  Exit status 0, or 2 when a file has no spread lines or
the two runs do not cover the same frames.
"""
import math
import re
import statistics
import sys

LINE = re.compile(r"^spread: pose=(\d+) seed=(\d+) .*iters=(\d+) update_typ=(\d+)")


def frames(path):
    """{(pose, seed): (hypotheses, instructions)} of one run's output."""
    out = {}
    try:
        with open(path) as f:
            for line in f:
                m = LINE.match(line)
                if m:
                    out[(int(m[1]), int(m[2]))] = (int(m[3]), int(m[4]))
    except OSError as e:
        print("spread_ratio.py: %s" % e, file=sys.stderr)
        sys.exit(2)
    if not out:
        print("spread_ratio.py: no 'spread:' lines in %s" % path, file=sys.stderr)
        sys.exit(2)
    return out


def main(argv):
    limit = 1.5
    args = list(argv)
    if args[:1] in (["-h"], ["--help"]):
        print(__doc__.strip())
        return 0
    if args[:1] == ["--limit"]:
        try:
            limit = float(args[1])
        except (IndexError, ValueError):
            print("spread_ratio.py: --limit needs a number", file=sys.stderr)
            return 2
        args = args[2:]
    if len(args) != 2:
        print("spread_ratio.py: give the M4F run's output and the M3 fixed run's "
              "(--help)", file=sys.stderr)
        return 2
    m4f, m3f = frames(args[0]), frames(args[1])
    if set(m4f) != set(m3f):
        print("spread_ratio.py: the two runs do not cover the same frames",
              file=sys.stderr)
        return 2
    ratios = []
    print("pose seed  hyp  M4F float  M3 fixed  ratio")
    for key in sorted(m4f):
        r = m3f[key][1] / m4f[key][1]
        ratios.append(r)
        over = ""
        if r > limit:
            # Whole instructions: the count that brings the ratio to the limit.
            over = " * %d to lose" % math.ceil(m3f[key][1] - limit * m4f[key][1])
        print("%4d %4d %4d %10d %9d  %.2fx%s" % (key[0], key[1], m3f[key][0], m4f[key][1],
                                                 m3f[key][1], r, over))
    within = sum(r <= limit for r in ratios)
    print("median %.3fx, %.2fx to %.2fx; %d of %d frames within %.2fx" %
          (statistics.median(ratios), min(ratios), max(ratios), within, len(ratios), limit))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
