"""The Zenoh end of `spvs-sim --transport zenoh`.

spvs-sim has no Zenoh library to link (none is in a reachable registry), so
its link (sim_host/zenoh/link_zenoh.c) starts this process and talks to it
over its standard input and output:

  stdin  (from spvs-sim): frames  u32 length (big-endian) + payload
         payload = one LCM-encoded matches_t, put on spvs/<robot>/matches
  stdout (to spvs-sim):   records u8 kind + u32 length (big-endian) + payload
         kind 'R': ready (payload: a line of text), sent once, first
         kind 'C': a sample of spvs/<robot>/cmd   (LCM-encoded cmd_t)
         kind 'S': a sample of spvs/<robot>/state (LCM-encoded state_t)
         kind 'E': a fatal error (payload: a line of text); the port exits

The port does not look inside payloads: spvs-sim encodes and decodes them
with the same wire code as the LCM link, and the bridge checks them.
It is ready once its publisher has a matching subscriber (normally the
bridge): samples put before that would be lost.  It exits when its input
closes, on SIGINT/SIGTERM, or when spvs-sim stops reading.
With $SPVS_ZENOH_TIMING set to a file name, it writes there one line per
frame put ("M SEQ T") and per command received ("C SEQ T"), T in seconds of
CLOCK_MONOTONIC: the fleet's load figures come from them (docs/ZENOH.md).
Exit status: 0 on end of input or a signal, 1 on a Zenoh failure, 2 on bad
options.
"""

import argparse
import os
import signal
import struct
import sys
import threading
import time

import spvs_zenoh_common as common

PROG = "spvs-sim zenoh port"
MAX_FRAME = 1 << 20  # far above one matches_t (5154 bytes)


class Out:
    """Records to stdout, one writer at a time (Zenoh calls back on its own
    threads)."""

    def __init__(self):
        self.lock = threading.Lock()
        self.broken = False

    def record(self, kind, payload):
        data = kind + struct.pack(">I", len(payload)) + payload
        with self.lock:
            if self.broken:
                return
            try:
                view = memoryview(data)
                while view:
                    n = os.write(1, view)
                    view = view[n:]
            except OSError:
                # spvs-sim is gone; the read loop sees end of input next.
                self.broken = True


def read_exact(n):
    """n bytes from stdin, or None at end of input."""
    chunks = []
    while n > 0:
        b = os.read(0, n)
        if not b:
            return None
        chunks.append(b)
        n -= len(b)
    return b"".join(chunks)


class Timing:
    """Put and receive times by seq, written to $SPVS_ZENOH_TIMING; a no-op
    without it.  Zenoh calls back on its own threads, hence the lock."""

    def __init__(self, path):
        self.lock = threading.Lock()
        self.lines = [] if path else None
        self.path = path

    def note(self, kind, payload):
        if self.lines is None or len(payload) < 16:
            return
        # seq is the int64 after the 8-byte fingerprint in matches_t and
        # cmd_t alike.
        seq = struct.unpack(">q", payload[8:16])[0]
        with self.lock:
            self.lines.append("%s %d %.6f\n" % (kind, seq, time.monotonic()))

    def write(self):
        if self.lines is None:
            return
        with self.lock:
            try:
                with open(self.path, "w") as f:
                    f.writelines(self.lines)
            except OSError:
                pass


class Stop(Exception):
    pass


def on_signal(signum, frame):
    raise Stop()


def parse_args(argv):
    """The options, checked: (namespace, None), or (None, 2) after an error
    line (argparse itself exits 2 on what it refuses)."""
    p = argparse.ArgumentParser(prog="sim_port.py",
                                description="Zenoh end of spvs-sim "
                                "--transport zenoh (started by spvs-sim).")
    p.add_argument("--robot", default="robot0")
    p.add_argument("--connect", action="append", default=[], metavar="E")
    p.add_argument("--listen", action="append", default=[], metavar="E")
    p.add_argument("--mode", choices=("peer", "client"), default="peer")
    p.add_argument("--scouting", choices=("on", "off"), default="off")
    p.add_argument("--wait", type=float, default=5.0, metavar="S",
                   help="longest wait for a subscriber of the matches, s")
    # spvs-sim passes "--robot NAME" as two words; joined, a legal name
    # that starts with '-' is not taken for an option.
    argv = list(argv)
    for i in range(len(argv) - 1):
        if argv[i] == "--robot":
            argv[i:i + 2] = ["--robot=" + argv[i + 1]]
            break
    a = p.parse_args(argv)
    for why in [common.check_robot(a.robot)] + \
            [common.check_endpoint(e) for e in a.connect + a.listen]:
        if why:
            sys.stderr.write("%s: %s\n" % (PROG, why))
            return None, 2
    if not (0.0 < a.wait <= 3600.0):
        sys.stderr.write("%s: --wait must be in (0, 3600] s\n" % PROG)
        return None, 2
    return a, None


def declare(zenoh, session, a, out, timing):
    """The matches publisher and the subscribers that pass the commands and
    the telemetry on to spvs-sim.  Returns (publisher, its key)."""
    remote = zenoh.Locality.REMOTE
    key_m = common.key_expr(a.robot, "matches")
    pub = session.declare_publisher(key_m, allowed_destination=remote)

    def on_cmd(sample):
        data = bytes(sample.payload.to_bytes())
        timing.note("C", data)
        out.record(b"C", data)
    session.declare_subscriber(common.key_expr(a.robot, "cmd"),
                               on_cmd, allowed_origin=remote)
    session.declare_subscriber(
        common.key_expr(a.robot, "state"),
        lambda s: out.record(b"S", bytes(s.payload.to_bytes())),
        allowed_origin=remote)
    return pub, key_m


def await_subscriber(pub, key_m, a, out):
    """True once the publisher has a subscriber; False after an 'E' record
    when none came within --wait."""
    deadline = time.monotonic() + a.wait
    while not pub.matching_status.matching:
        if time.monotonic() > deadline:
            out.record(b"E", ("nobody subscribes to %s after %.3g s (is "
                              "spvs-zenoh-bridge running at %s with "
                              "--robot %s?)" % (key_m, a.wait,
                                                ",".join(a.connect),
                                                a.robot)).encode())
            return False
        time.sleep(0.02)
    return True


def forward_frames(pub, out, timing):
    """Frames from stdin onto the matches key until the input ends (0) or
    a frame is too long (1, after an 'E' record)."""
    while True:
        head = read_exact(4)
        if head is None:
            return 0
        (n,) = struct.unpack(">I", head)
        if n > MAX_FRAME:
            out.record(b"E", ("frame of %d bytes from spvs-sim, more "
                              "than %d" % (n, MAX_FRAME)).encode())
            return 1
        payload = read_exact(n)
        if payload is None:
            return 0
        timing.note("M", payload)
        pub.put(payload)


def close_session(session):
    """Always close the session: an open one keeps Zenoh's threads running
    and the process would not exit."""
    if session is None:
        return
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        session.close()
    except Exception:
        pass


def main(argv):
    a, status = parse_args(argv)
    if a is None:
        return status

    out = Out()
    timing = Timing(os.environ.get("SPVS_ZENOH_TIMING"))
    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)
    # A broken pipe is handled where it happens (Out.record).
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)

    try:
        import zenoh
    except ImportError as e:
        out.record(b"E", ("cannot import zenoh (%s): run scripts/setup_venv.sh"
                          % e).encode())
        return 1

    session = None
    try:
        try:
            cfg = common.zenoh_config(zenoh, a.mode, a.listen, a.connect,
                                      a.scouting == "on")
            session = zenoh.open(cfg)
            pub, key_m = declare(zenoh, session, a, out, timing)
        except Stop:
            raise
        except Exception as e:
            out.record(b"E", ("cannot open Zenoh (connect %s): %s"
                              % (a.connect, common.short_error(e))).encode())
            return 1
        if not await_subscriber(pub, key_m, a, out):
            return 1
        out.record(b"R", ("%s ready" % key_m).encode())
        return forward_frames(pub, out, timing)
    except Stop:
        return 0
    finally:
        timing.write()
        close_session(session)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
