#!/usr/bin/env python3
"""Per-function instruction counts from a QEMU `-d in_asm,exec,nochain`
log: every executed translation block's instructions, attributed to the
functions of the image by address, between the first execution of
prof_begin and the next of prof_end (profile.sh).

    profile.py LOG ELF [TOP [ADDR_OUT]]

prints the total and the TOP functions (default 40); ADDR_OUT, if given,
gets one line per executed instruction address: address, count, function
(for annotating a disassembly)."""
import bisect
import collections
import re
import subprocess
import sys


def symbols(elf):
    out = subprocess.run(["arm-none-eabi-nm", "-S", "--defined-only", "-n", elf],
                         capture_output=True, text=True, check=True).stdout
    syms = []
    for line in out.splitlines():
        f = line.split()
        if len(f) == 4 and f[2] in "tTwW":
            syms.append((int(f[0], 16) & ~1, int(f[1], 16), f[3]))
    syms.sort()
    return syms


def main():
    log, elf = sys.argv[1], sys.argv[2]
    top = int(sys.argv[3]) if len(sys.argv) > 3 else 40
    syms = symbols(elf)
    starts = [s[0] for s in syms]

    def func(a):
        i = bisect.bisect_right(starts, a) - 1
        if i >= 0 and a < syms[i][0] + syms[i][1]:
            return syms[i][2]
        return "?%x" % a

    begin = [s[0] for s in syms if s[2] == "prof_begin"][0]
    end = [s[0] for s in syms if s[2] == "prof_end"][0]
    pending = {}  # translated block's first address -> its instruction addresses
    blocks = {}   # host pointer -> instruction addresses
    count = collections.Counter()
    on = False
    cur = None
    with open(log, errors="replace") as fh:
        for line in fh:
            if line.startswith("IN:"):
                cur = []
                continue
            if cur is not None:
                m = re.match(r"0x([0-9a-f]+):", line)
                if m:
                    cur.append(int(m.group(1), 16))
                    continue
                if cur:
                    pending[cur[0]] = cur
                cur = None
            if line.startswith("Trace"):
                m = re.match(r"Trace \d+: (0x[0-9a-f]+) \[[0-9a-f]+/([0-9a-f]+)/", line)
                ptr, pc = m.group(1), int(m.group(2), 16)
                if pc in pending:
                    blocks[ptr] = pending.pop(pc)
                if pc == begin:
                    on = True
                elif pc == end:
                    on = False
                if on:
                    for a in blocks[ptr]:
                        count[a] += 1
    per = collections.Counter()
    for a, c in count.items():
        per[func(a)] += c
    total = sum(per.values())
    print("total %d" % total)
    for f, c in per.most_common(top):
        print("%8d %5.1f%%  %s" % (c, 100.0 * c / total, f))
    if len(sys.argv) > 4:
        with open(sys.argv[4], "w") as o:
            for a in sorted(count):
                o.write("%x %d %s\n" % (a, count[a], func(a)))


if __name__ == "__main__":
    main()
