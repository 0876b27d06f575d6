#!/usr/bin/env python3
"""camera_same_commands.py LOCAL.json REMOTE.json NAME

The per-frame --json lines of spvs-camera --method 1 (the controller in
process, LOCAL) and of the same frames sent to spvs-node over a transport
(REMOTE, called NAME in the messages): 30 frames each, (v, w) equal within
1e-6 (the frame time's trip through microseconds), no transport error, and
at least 5 frames with a non-zero command.  Exit 0 (PASS) or 1 (FAIL)."""
import json
import sys


def main():
    if len(sys.argv) != 4:
        print(__doc__.splitlines()[0], file=sys.stderr)
        return 2
    rd = lambda p: [json.loads(l) for l in open(p) if l.startswith('{"frame"')]
    a, b, name = rd(sys.argv[1]), rd(sys.argv[2]), sys.argv[3]
    if len(a) != 30 or len(b) != 30:
        print(f"FAIL: {len(a)} local and {len(b)} {name} frames, want 30")
        return 1
    worst = max(max(abs(x["v"] - y["v"]), abs(x["w"] - y["w"])) for x, y in zip(a, b))
    errs = [y["frame"] for y in b if y["status"] == "transport_error"]
    moving = sum(1 for x in a if x["v"] or x["w"])
    print(f"30 frames over {name}: largest (v, w) difference {worst:.3g}, "
          f"{moving} frames with a non-zero command, transport errors {errs}")
    if errs or worst > 1e-6 or moving < 5:
        print("FAIL")
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
