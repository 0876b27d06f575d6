"""Shared pieces of the Zenoh side of spvs: key expressions, the Zenoh
session configuration built from command-line options, and the checks a
payload must pass before it crosses between Zenoh and LCM.

Payloads on Zenoh are the LCM-encoded messages of lcm_types/ byte for byte:
an 8-byte fingerprint of the type, then the fields big-endian (docs/ZENOH.md).
"""

import atexit
import json
import os
import re
import select
import shutil
import signal
import struct
import subprocess
import sys
import tempfile

# The LCM channels and the Zenoh key expressions that mirror them
# (DESIGN.md section 5).  The bridge maps each one in one direction only,
# so it never hears its own output.
CH_MATCHES = "SPVS_MATCHES"
CH_CMD = "SPVS_CMD"
CH_STATE = "SPVS_STATE"

ROBOT_RE = re.compile(r"^[A-Za-z0-9_.-]{1,64}$")

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))


class StopSignals:
    """SIGINT and SIGTERM end a wait; the handler takes no lock.

    threading.Event.set() must not be called from a signal handler: the
    handler runs in the main thread, and if that thread is just leaving
    Event.wait() it holds the Event's lock, so the process hangs on its own
    lock.  Here the handler only stores the signal and writes a byte to a
    pipe, and wait() selects on that pipe.
    """

    def __init__(self):
        self.signum = None
        self._r, self._w = os.pipe()
        os.set_blocking(self._w, False)
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, self._on_signal)

    def _on_signal(self, signum, frame):
        self.signum = signum
        try:
            os.write(self._w, b"x")
        except BlockingIOError:
            pass  # a wake-up is already pending

    def wait(self, timeout):
        """Sleep up to timeout s; True once a stop signal has come."""
        if self.signum is None:
            select.select([self._r], [], [], timeout)
        return self.signum is not None

    def ignore(self):
        """From here on the signals are ignored (while closing a session:
        an exception raised inside session.close() would leave it open)."""
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)


def key_expr(robot, what):
    """Key expression spvs/<robot>/<what> (what: matches, cmd or state)."""
    return "spvs/%s/%s" % (robot, what)


def check_robot(robot):
    """Return None if robot is usable inside a key expression, else why not.

    Zenoh reserves '*', '$', '#', '?' and '/' in key expressions; a robot
    name is one chunk, so only plain characters are allowed."""
    if not ROBOT_RE.match(robot):
        return ("robot name '%s' must be 1..64 characters from "
                "A-Z a-z 0-9 _ . -" % robot)
    return None


ENDPOINT_RE = re.compile(r"^(tcp|udp|tls|quic|unixsock-stream|ws)/.+")


def check_endpoint(ep):
    """Return None if ep looks like a Zenoh endpoint (proto/address)."""
    if not ENDPOINT_RE.match(ep):
        return ("endpoint '%s' is not of the form tcp/HOST:PORT "
                "(or udp/, tls/, quic/, ws/, unixsock-stream/)" % ep)
    return None


def zenoh_config(zenoh, mode, listen, connect, scouting):
    """A zenoh.Config for one process.

    mode: "peer" or "client"; listen, connect: lists of endpoints;
    scouting: True to discover others by multicast (off on loopback tests).
    A peer that only connects still listens somewhere; left alone it would
    listen on every interface, so it gets an ephemeral port on loopback."""
    cfg = zenoh.Config()
    cfg.insert_json5("mode", json.dumps(mode))
    cfg.insert_json5("scouting/multicast/enabled", json.dumps(bool(scouting)))
    # Shared memory off: a payload is 5 KB at most, and a process in another
    # network or user namespace (spvs-fleet's robots) that negotiates shared
    # memory with the router gets only the first large sample, then none.
    cfg.insert_json5("transport/shared_memory/enabled", "false")
    if mode == "peer" and not listen and connect:
        listen = ["tcp/127.0.0.1:0"]
    if mode == "peer" or listen:
        cfg.insert_json5("listen/endpoints", json.dumps(list(listen)))
    if connect:
        cfg.insert_json5("connect/endpoints", json.dumps(list(connect)))
    return cfg


def short_error(e):
    """One line of an exception's text, without the Rust source location
    that Zenoh appends ("... at /path/lib.rs:62.")."""
    text = str(e).strip().splitlines()[0] if str(e).strip() else repr(e)
    cut = text.find(" at /")
    return text[:cut] if cut > 0 else text


def load_lcm_types(types_dir=None):
    """Import the Python classes of lcm_types/ (module `spvs`).

    types_dir: a folder holding the generated package spvs/ (the build's
    lcm_types/python); None generates them with lcm-gen from the .lcm files
    of this checkout into a temporary folder.  Returns the module."""
    if types_dir is None:
        sources = [os.path.join(REPO_ROOT, "lcm_types", n + ".lcm")
                   for n in ("matches_t", "cmd_t", "state_t")]
        for s in sources:
            if not os.path.isfile(s):
                raise RuntimeError("message type %s not found; pass "
                                   "--lcm-types BUILD/lcm_types/python" % s)
        types_dir = tempfile.mkdtemp(prefix="spvs-lcm-types-")
        atexit.register(shutil.rmtree, types_dir, True)
        try:
            subprocess.run(["lcm-gen", "-p", "--ppath", types_dir] + sources,
                           check=True, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, timeout=60)
        except FileNotFoundError:
            raise RuntimeError("lcm-gen not found (Debian: liblcm-bin); or "
                               "pass --lcm-types BUILD/lcm_types/python")
        except subprocess.CalledProcessError as e:
            raise RuntimeError("lcm-gen failed: %s"
                               % e.stderr.decode(errors="replace").strip())
    if not os.path.isfile(os.path.join(types_dir, "spvs", "matches_t.py")):
        raise RuntimeError("no generated spvs/matches_t.py in '%s'"
                           % types_dir)
    sys.path.insert(0, types_dir)
    import spvs  # noqa: E402  (generated package, path set just above)
    return spvs


class Header:
    """The leading fields of a message, read without decoding its arrays."""

    def __init__(self, seq, count=None):
        self.seq = seq
        self.count = count


# After the fingerprint every message starts with int64 seq; matches_t goes
# on with int64 utime, int64 run_id, int16 count (lcm_types/matches_t.lcm).
SEQ_FIELD = struct.Struct(">q")
MATCHES_HEAD = struct.Struct(">qqqh")


class PayloadCheck:
    """Checks of one message type on the wire: exact size (every type has
    fixed-size arrays, so every message of a type has one size), the
    fingerprint, and for matches the count against the array capacity.

    With the size and fingerprint right, every byte pattern decodes (the
    arrays have fixed sizes and the fields are plain numbers), so only the
    header is read: decoding a whole matches_t in Python costs several
    times the rest of the bridge's work per frame (docs/ZENOH.md, "Load").
    The node checks the values themselves (finite, indices in range)."""

    def __init__(self, cls, capacity_field=None):
        self.cls = cls
        self.name = cls.__name__
        self.fingerprint = cls._get_packed_fingerprint()
        self.size = len(cls().encode())
        self.capacity = None
        if capacity_field is not None:
            self.capacity = len(getattr(cls(), capacity_field))

    def check(self, data):
        """Return (header, None) for good bytes, (None, reason) otherwise;
        header has .seq (and .count for matches)."""
        if len(data) != self.size:
            return None, ("%s: wrong size %d bytes (want %d)"
                          % (self.name, len(data), self.size))
        if data[:8] != self.fingerprint:
            return None, ("%s: wrong fingerprint %s (want %s)"
                          % (self.name, data[:8].hex(),
                             self.fingerprint.hex()))
        if self.capacity is None:
            return Header(SEQ_FIELD.unpack_from(data, 8)[0]), None
        seq, _, _, count = MATCHES_HEAD.unpack_from(data, 8)
        if not 0 <= count <= self.capacity:
            return None, ("%s: count %d outside 0..%d"
                          % (self.name, count, self.capacity))
        return Header(seq, count), None
