#!/usr/bin/python3
"""Worst-case stack depth of a function of the core, from GCC's own data:
the per-function frame sizes of -fstack-usage (.su) and the call graph of
-fcallgraph-info=su (.ci, VCG text), summed along the deepest call path.

  tools/stack_depth.py --root spvs_update --image IMAGE.elf DIR_WITH_CI_FILES

Rules:
  - a frame marked "dynamic" (alloca, VLA) makes the result unbounded: the
    script says so and exits 1;
  - recursion (a cycle in the graph) likewise;
  - indirect calls (the RANSAC estimator's fit and score) are resolved to
    the functions named with --indirect (default: the core's estimator);
  - functions outside the .ci files (libm's sqrtf/logf, memcpy, memset) get
    their frame from the image's disassembly (push/vpush/sub sp in the
    prologue), since newlib ships without .su files; with no image they
    count 0 and are listed.
Prints the deepest path with each frame and the total in bytes.
"""

import argparse
import glob
import os
import re
import subprocess
import sys

NODE = re.compile(r'node: \{ title: "([^"]+)" label: "([^"]*)"')
EDGE = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')
SIZE = re.compile(r'\\n(\d+) bytes \((\w+)')


def short(title):
    return title.rsplit(":", 1)[-1]


def load(ci_dir):
    frames, kinds, calls = {}, {}, {}
    files = glob.glob(os.path.join(ci_dir, "**", "*.ci"), recursive=True)
    if not files:
        sys.exit("stack_depth: no .ci files under %s (build with -fcallgraph-info=su)" % ci_dir)
    for path in files:
        for line in open(path):
            m = NODE.search(line)
            if m:
                s = SIZE.search(m.group(2))
                if s:
                    frames[short(m.group(1))] = int(s.group(1))
                    kinds[short(m.group(1))] = s.group(2)
                continue
            m = EDGE.search(line)
            if m:
                calls.setdefault(short(m.group(1)), set()).add(short(m.group(2)))
    return frames, kinds, calls


def prologue_frames(image, names):
    """Stack of leaf library functions from their prologue in the image."""
    out = {}
    try:
        dis = subprocess.run(["arm-none-eabi-objdump", "-d", image], check=True,
                             capture_output=True, text=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        sys.exit("stack_depth: objdump failed on %s: %s" % (image, e))
    cur, count = None, 0
    for line in dis.splitlines():
        m = re.match(r"^[0-9a-f]+ <([^>]+)>:", line)
        if m:
            cur, count = m.group(1), 0
            if cur in names:
                out[cur] = 0
            continue
        if cur not in names or count >= 8:
            continue
        count += 1
        m = re.search(r"\t(push|stmdb)(?:\.w)?\s+(?:sp!,\s*)?\{([^}]*)\}", line)
        if m:
            out[cur] += 4 * len(m.group(2).split(","))
        m = re.search(r"\tvpush\s+\{([^}]*)\}", line)
        if m:
            regs = m.group(1).split(",")
            n = 0
            for r in regs:
                r = r.strip()
                if "-" in r:
                    a, b = r.split("-")
                    n += int(b.strip()[1:]) - int(a[1:]) + 1
                else:
                    n += 1
            out[cur] += 4 * n
        m = re.search(r"\tsub(?:\.w|w)?\s+sp,\s*(?:sp,\s*)?#(\d+)", line)
        if m:
            out[cur] += int(m.group(1))
    return out


def main():
    ap = argparse.ArgumentParser(description="worst-case stack depth from .su/.ci files")
    ap.add_argument("ci_dir")
    ap.add_argument("--root", default="spvs_update")
    ap.add_argument("--image", help="linked image, for library leaf frames")
    ap.add_argument("--indirect", default="est_fit,est_score",
                    help="functions an indirect call may reach")
    a = ap.parse_args()
    frames, kinds, calls = load(a.ci_dir)
    if a.root not in frames:
        sys.exit("stack_depth: %s not found in the call graph" % a.root)
    dyn = [f for f, k in kinds.items() if k != "static"]
    indirect = [s for s in a.indirect.split(",") if s]
    for f in list(calls):
        if "__indirect_call" in calls[f]:
            calls[f].discard("__indirect_call")
            calls[f].update(indirect)
    external = set()
    for f, cs in calls.items():
        for c in cs:
            if c not in frames and not c.startswith("__aeabi_"):
                external.add(c)
    lib = prologue_frames(a.image, external) if a.image else {}

    memo, onpath = {}, set()

    def depth(f):
        if f in memo:
            return memo[f]
        if f in onpath:
            sys.exit("stack_depth: recursion through %s: no static bound" % f)
        onpath.add(f)
        own = frames.get(f, lib.get(f, 0))
        best, path = 0, []
        for c in sorted(calls.get(f, ())):
            d, p = depth(c)
            if d > best:
                best, path = d, p
        onpath.discard(f)
        memo[f] = (own + best, [(f, own)] + path)
        return memo[f]

    total, path = depth(a.root)
    bad = [f for f, _ in path if f in dyn]
    print("deepest path from %s:" % a.root)
    for f, own in path:
        src = "su" if f in frames else ("image prologue" if f in lib else "unknown, 0")
        print("  %-28s %5d B  (%s)" % (f, own, src))
    print("total: %d bytes" % total)
    unknown = sorted(external - set(lib))
    if unknown:
        print("not counted (no frame size found): %s" % ", ".join(unknown))
    if bad:
        print("dynamic frames on the path: %s: unbounded" % ", ".join(bad))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
