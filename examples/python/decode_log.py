#!/usr/bin/python3
"""Decode the spvs messages of an LCM log with the Python types of lcm_types/.

    lcm-gen -p --ppath TYPES_DIR lcm_types/*.lcm      # makes TYPES_DIR/spvs/
    examples/python/decode_log.py out/demo.lcmlog --types TYPES_DIR

prints, per channel, the type and the number of messages, then the last
telemetry (spvs.state_t) and the last command that answered a frame
(spvs.cmd_t, seq >= 0).  The log format (lcm-logger) is read here with
struct, so nothing but the generated modules is needed; a program on the
bus would pass the same bytes from an lcm.LCM() subscription to the same
decode().  Exit status 0, 1 when the log is unreadable or holds no spvs
message, 2 on bad arguments.
"""
import argparse
import struct
import sys

LOG_SYNC = 0xEDA1DA01


def events(path):
    """(channel, data) of every event of an lcm-logger file."""
    with open(path, "rb") as f:
        while True:
            head = f.read(28)
            if len(head) < 28:
                return
            sync, _num, _utime, clen, dlen = struct.unpack(">IqqII", head)
            if sync != LOG_SYNC:
                raise ValueError("%s: not an LCM log, or damaged" % path)
            channel = f.read(clen).decode("ascii", "replace")
            data = f.read(dlen)
            if len(data) < dlen:
                raise ValueError("%s: truncated event on %s" % (path, channel))
            yield channel, data


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log", help="LCM log (lcm-logger), e.g. out/demo.lcmlog")
    ap.add_argument("--types", required=True,
                    help="folder holding the generated package spvs/ (lcm-gen -p --ppath)")
    a = ap.parse_args()
    sys.path.insert(0, a.types)
    try:
        from spvs import cmd_t, matches_t, state_t
    except ImportError as e:
        print("decode_log: no spvs types in %s (%s): run lcm-gen -p --ppath %s lcm_types/*.lcm"
              % (a.types, e, a.types), file=sys.stderr)
        return 1
    # Each type's fingerprint leads its encoding: pick the class by it.
    by_fp = {t._get_packed_fingerprint(): t for t in (cmd_t, matches_t, state_t)}
    counts, last = {}, {}
    try:
        for channel, data in events(a.log):
            cls = by_fp.get(data[:8])
            if cls is None:
                continue
            msg = cls.decode(data)
            counts[channel] = (cls.__name__, counts.get(channel, ("", 0))[1] + 1)
            if cls is not cmd_t or msg.seq >= 0:
                last[cls.__name__] = msg
    except (OSError, ValueError) as e:
        print("decode_log: %s" % e, file=sys.stderr)
        return 1
    if not counts:
        print("decode_log: no spvs message in %s" % a.log, file=sys.stderr)
        return 1
    for channel in sorted(counts):
        print("%-13s %-10s %d messages" % ((channel,) + counts[channel]))
    s = last.get("state_t")
    if s is not None:
        print("last state    seq %d, step %d, status %d, %d of %d matches on the plane, "
              "H[0] %.4f, H[2] %.2f px" % (s.seq, s.step, s.status, s.n_inliers,
                                          s.n_matches, s.H[0], s.H[2]))
    c = last.get("cmd_t")
    if c is not None:
        print("last command  seq %d, step %d, status %d, v %.4f m/s, w %.4f rad/s"
              % (c.seq, c.step, c.status, c.v, c.w))
    return 0


if __name__ == "__main__":
    sys.exit(main())
