#!/usr/bin/python3
"""Checks tools/fixed_m3_bench/spread_ratio.py on made-up runs (ctest
fixed_spread_ratio): each frame's ratio, the median, the count within the
limit, the instructions a frame above it would have to lose, and the
refusals (no spread lines, different frames).

usage: test_spread_ratio.py SCRATCH_DIR
"""
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
TOOL = os.path.join(HERE, "spread_ratio.py")


def check(cond, what):
    if not cond:
        sys.stderr.write("test_spread_ratio: %s\n" % what)
        sys.exit(1)


def write(path, rows):
    with open(path, "w") as f:
        f.write("case: n=256 mismatch_pct=20 status=0 update_typ=1\n")
        for pose, seed, instr in rows:
            f.write("spread: pose=%d seed=%d n=256 status=0 inliers=180 iters=11 "
                    "update_typ=%d\n" % (pose, seed, instr))
        f.write("spread_summary: frames=%d\n" % len(rows))


def run(*args):
    return subprocess.run(["/usr/bin/python3", TOOL] + list(args), capture_output=True,
                          text=True, timeout=30)


def main():
    scratch = sys.argv[1] if len(sys.argv) > 1 else "."
    os.makedirs(scratch, exist_ok=True)
    a = os.path.join(scratch, "spread_ratio_m4f.txt")
    b = os.path.join(scratch, "spread_ratio_m3f.txt")
    c = os.path.join(scratch, "spread_ratio_other.txt")
    # Ratios 1.40, 1.50, 1.60: the median 1.50, two within 1.5 (1.5 itself
    # counts), one marked.
    write(a, [(0, 0, 200000), (0, 1, 200000), (1, 0, 250000)])
    write(b, [(0, 0, 280000), (0, 1, 300000), (1, 0, 400000)])
    p = run(a, b)
    check(p.returncode == 0, "exit %d: %s" % (p.returncode, p.stderr))
    lines = p.stdout.splitlines()
    check(lines[-1] == "median 1.500x, 1.40x to 1.60x; 2 of 3 frames within 1.50x",
          "summary %r" % lines[-1])
    # 400,000 - 1.5 x 250,000: the instructions above the limit.
    check(lines[3].endswith("1.60x * 25000 to lose") and "*" not in lines[1] + lines[2],
          "marks: %r" % lines[1:4])
    p = run("--limit", "1.6", a, b)
    check(p.stdout.splitlines()[-1].endswith("3 of 3 frames within 1.60x"),
          "--limit: %r" % p.stdout)
    # Refused: a run without spread lines, and runs of different frames.
    write(c, [])
    p = run(a, c)
    check(p.returncode == 2 and "no 'spread:' lines" in p.stderr, "empty: %r" % p.stderr)
    write(c, [(0, 0, 1), (0, 1, 1), (2, 0, 1)])
    p = run(a, c)
    check(p.returncode == 2 and "same frames" in p.stderr, "frames: %r" % p.stderr)
    p = run(a)
    check(p.returncode == 2, "one file: exit %d" % p.returncode)
    return 0


if __name__ == "__main__":
    sys.exit(main())
