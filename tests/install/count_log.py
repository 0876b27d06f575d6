#!/usr/bin/python3
"""count_log.py LOG: events per channel of an lcm-logger file, one
"CHANNEL COUNT" line each (the install and lcm-spy checks compare what a
decoder found with what the log holds; lcm-logger may miss datagrams of a
run on a busy machine, so the log, not the run, is the reference)."""
import struct
import sys

counts = {}
with open(sys.argv[1], "rb") as f:
    while True:
        head = f.read(28)
        if len(head) < 28:
            break
        sync, _, _, clen, dlen = struct.unpack(">IqqII", head)
        if sync != 0xEDA1DA01:
            sys.exit("count_log: %s is damaged" % sys.argv[1])
        ch = f.read(clen).decode("ascii", "replace")
        f.seek(dlen, 1)
        counts[ch] = counts.get(ch, 0) + 1
for ch in sorted(counts):
    print(ch, counts[ch])
