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
    count 0 and are listed;
  - libgcc's soft-float helpers (__aeabi_*, on a CPU without FPU) are
    assembly with no .su either: each gets every push and stack-pointer
    decrement in its whole body plus the deepest routine it calls with bl
    or branches into (__aeabi_fcmpgt -> __aeabi_cfrcmple -> __aeabi_cfcmple
    -> __cmpsf2), an upper bound.
Prints the deepest path with each frame and the total in bytes.
"""

import argparse
import bisect
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


def helper_frames(image, names):
    """Stack of assembly helpers: all stack-pointer decrements in the body
    (push, str ..., [sp, #-N]!, sub sp) plus the deepest bl callee."""
    try:
        syms = subprocess.run(["arm-none-eabi-nm", "-n", image], check=True,
                              capture_output=True, text=True).stdout
        dis = subprocess.run(["arm-none-eabi-objdump", "-d", image], check=True,
                             capture_output=True, text=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        sys.exit("stack_depth: nm/objdump failed on %s: %s" % (image, e))
    addr_of, starts = {}, set()
    for line in syms.splitlines():
        f = line.split()
        if len(f) == 3 and f[1] in "Tt" and not f[2].startswith("$"):
            addr_of[f[2]] = int(f[0], 16) & ~1
            starts.add(int(f[0], 16) & ~1)
    start_set = set(starts)
    starts = sorted(starts)
    own, callees = {}, {}
    insn = re.compile(r"^\s*([0-9a-f]+):\s+(?:[0-9a-f]{4}\s?){1,2}\s+(\S+)\s*(.*)$")
    for line in dis.splitlines():
        m = insn.match(line)
        if not m:
            continue
        at = int(m.group(1), 16)
        i = bisect.bisect_right(starts, at) - 1
        if i < 0:
            continue
        fn, op, args = starts[i], m.group(2), m.group(3)
        n = 0
        if re.match(r"(push|stmdb)", op) and ("sp" in args or op.startswith("push")):
            regs = re.search(r"\{([^}]*)\}", args)
            n = 4 * len(regs.group(1).split(",")) if regs else 0
        elif re.match(r"str", op):
            d = re.search(r"\[sp,\s*#-(\d+)\]!", args)
            n = int(d.group(1)) if d else 0
        elif re.match(r"sub", op):
            d = re.match(r"sp,\s*(?:sp,\s*)?#(\d+)", args)
            n = int(d.group(1)) if d else 0
        own[fn] = own.get(fn, 0) + n
        # Calls, and branches into another routine (a tail call, or the
        # branch of __aeabi_cfrcmple into __aeabi_cfcmple after swapping
        # its operands).
        if op in ("bl", "blx", "b", "b.n", "b.w"):
            t = re.match(r"([0-9a-f]+)", args)
            if t and (op.startswith("bl") or int(t.group(1), 16) in start_set) \
                    and int(t.group(1), 16) != fn:
                callees.setdefault(fn, set()).add(int(t.group(1), 16))
    memo = {}

    def deep(fn, seen=()):
        if fn in memo:
            return memo[fn]
        if fn in seen:
            sys.exit("stack_depth: helper recursion at 0x%x" % fn)
        best = max([deep(c, seen + (fn,)) for c in callees.get(fn, ())] or [0])
        memo[fn] = own.get(fn, 0) + best
        return memo[fn]

    return {n: deep(addr_of[n]) for n in names if n in addr_of}


def main():
    ap = argparse.ArgumentParser(description="worst-case stack depth from .su/.ci files")
    ap.add_argument("ci_dir")
    ap.add_argument("--root", default="spvs_update")
    ap.add_argument("--image", help="linked image, for library leaf frames")
    ap.add_argument("--indirect", default="est_fit,est_score,est_cost,est_refine",
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
    external, helpers = set(), set()
    for f, cs in calls.items():
        for c in cs:
            if c not in frames:
                (helpers if c.startswith("__aeabi_") else external).add(c)
    lib = prologue_frames(a.image, external) if a.image else {}
    hlp = helper_frames(a.image, helpers) if a.image and helpers else {}
    lib.update(hlp)
    external |= helpers

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
        src = ("su" if f in frames else "image, helper body" if f in hlp
               else "image prologue" if f in lib else "unknown, 0")
        print("  %-28s %5d B  (%s)" % (f, own, src))
    print("total: %d bytes" % total)
    if hlp:
        print("float helpers' frames (bytes): %s" %
              ", ".join("%s %d" % (n, hlp[n]) for n in sorted(hlp)))
    unknown = sorted(external - set(lib))
    if unknown:
        print("not counted (no frame size found): %s" % ", ".join(unknown))
    if bad:
        print("dynamic frames on the path: %s: unbounded" % ", ".join(bad))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
