#!/usr/bin/env python3
"""faults.py FAULT SPVS_SIM SPVS_SERIAL_AGENT IMAGE

One link fault in the closed loop through the emulated MCU.  QEMU runs the
controller application; a relay in this script sits on the serial line
between spvs-serial-agent (which reaches it at unix:WORK/relay.sock) and
QEMU's UART socket, reads every frame in both directions with its own decoder
(COBS and zlib's CRC-32, written apart from serial/spvs_serial.c) and damages
the host -> MCU frames of a window; spvs-sim drives the loop over LCM
(--transport lcm, lock-step: an unanswered frame goes out again every
0.25 s).  Everything runs in a loopback-only network namespace.

The relay passes the agent's bytes on no faster than QEMU's UART takes them
(it reads more only once its socket to QEMU is drained), so the backlog
stays where the agent sees it, as on a serial port's output queue.

Faults (the window starts at the K-th matches frame on the wire and holds R
of them, repeats included; for the faults that silence the link, flip,
drop, truncate and garbage, it lasts on until the MCU has reported its
watchdog stop: the MCU's clock counts executed instructions, so how many
frames 300 ms of it takes depends on the host's speed, and the test sets
the pace instead of assuming one):
  flip      one bit flipped in each frame of the window
  drop      ten bytes cut out of the middle of each
  truncate  each cut in half, then the delimiter
  garbage   random bytes between all frames of the run, and the window's
            frames replaced by garbage
  count     the window's frames say 300 matches (CRC made right)
  range     a coordinate of the window's frames at 32100 (2006 px; CRC right)
  agent_restart  the agent killed (SIGKILL) at frame K, restarted once the
                 MCU's watchdog has stopped the robot (at least 1.5 s later)
  mcu_reset      QEMU's system_reset (QMP) half way through frame K

Asserted, from what the relay saw on the wire:
  - no command from a bad frame: the MCU's computed answers are one per
    frame of the run, seq 0..N-1 in order, and (flip, drop, truncate,
    garbage, agent_restart) the run's --json summary equals the in-process
    run with the serial rounding bit for bit; count/range frames are answered
    with a stop flagged REJECTED with SPVS_E_CAPACITY / SPVS_E_RANGE;
  - the robot is stopped within the watchdog time: a WATCHDOG status (a stop)
    with age_ms in [watchdog_ms, watchdog_ms + 5] after the fault began (an
    MCU reset: a BOOT status, which the agent answers with a stop);
  - the loop resumes: the run converges;
  - the agent never crashes: it exits 0 on SIGTERM with its summary written.
Exit 77 (skipped) without qemu-system-arm or the image.
"""
import array, fcntl, json, os, random, select, signal, socket, subprocess, sys, tempfile, termios, threading, time, zlib, struct

FAULT, SIM, AGENT, IMAGE = sys.argv[1:5]
FAULTS = ("flip", "drop", "truncate", "garbage", "count", "range", "agent_restart", "mcu_reset")
if FAULT not in FAULTS:
    print("faults.py: unknown fault %r" % FAULT); sys.exit(2)
if subprocess.run(["sh", "-c", "command -v qemu-system-arm"], capture_output=True).returncode != 0:
    print("SKIP: qemu-system-arm not installed"); sys.exit(77)
if not os.path.isfile(IMAGE):
    print("SKIP: no application image %s (cross build missing)" % IMAGE); sys.exit(77)
if os.environ.get("SPVS_FAULTS_NETNS") != "1":
    os.environ["SPVS_FAULTS_NETNS"] = "1"
    sh = 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"'
    os.execvp("unshare", ["unshare", "-r", "-n", "sh", "-c", sh, "sh", sys.executable] + sys.argv)

ARGS = ["--method", "3", "--pose", "0.8,-6,-20", "--noise", "0.5", "--outliers", "0.1",
        "--seed", "5", "--dt", "0.2"]
URL = "udpm://239.255.76.67:%d?ttl=0" % (20000 + os.getpid() % 20000)
K, R = 20, (1 if FAULT in ("agent_restart", "mcu_reset") else 6)
SILENCING = ("flip", "drop", "truncate", "garbage")
# The watchdog time the agent sets up (the documented default, given
# explicitly), and how long a silencing window may wait for its stop.
WATCHDOG_MS = 300
WINDOW_MAX_S = 45.0
T_MATCHES, T_RESULT, T_STATUS = 1, 2, 3
work = tempfile.mkdtemp(prefix="spvs-faults-")
procs = []

def cobs_decode(b):
    out, i = bytearray(), 0
    while i < len(b):
        c = b[i]; i += 1
        if c == 0 or i + c - 1 > len(b):
            return None
        out += b[i:i + c - 1]; i += c - 1
        if c != 0xFF and i < len(b):
            out.append(0)
    return bytes(out)

def cobs_encode(b):
    out, block = bytearray(), bytearray()
    for x in b:
        if x == 0:
            out += bytes([len(block) + 1]) + block; block = bytearray()
        else:
            block.append(x)
            if len(block) == 254:
                out += b"\xff" + block; block = bytearray()
    out += bytes([len(block) + 1]) + block
    return bytes(out) + b"\x00"

def unpack(frame):
    """frame without its delimiter -> (type, body) or None."""
    p = cobs_decode(frame)
    if p is None or len(p) < 8 or zlib.crc32(p[:-4]) != struct.unpack("<I", p[-4:])[0]:
        return None
    if p[0] != 1 or struct.unpack("<H", p[2:4])[0] != len(p) - 8:
        return None
    return p[1], p[4:-4]

def repack(ftype, body):
    p = bytes([1, ftype]) + struct.pack("<H", len(body)) + body
    return cobs_encode(p + struct.pack("<I", zlib.crc32(p)))

class Relay:
    def __init__(self):
        self.lock = threading.Lock()
        self.n_matches = 0
        self.events = []          # (t, kind, fields)
        self.fault_t = None
        self.damaged = 0
        self.window_over = False
        self.wd_seen = False
        self.agent_sock = None
        self.rng = random.Random(1)
        self.up = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        for _ in range(200):
            try:
                self.up.connect(os.path.join(work, "uart.sock")); break
            except OSError:
                time.sleep(0.05)
        self.path = os.path.join(work, "relay.sock")
        self.ls = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self.ls.bind(self.path); self.ls.listen(1)
        self.buf_dn, self.buf_up = bytearray(), bytearray()
        threading.Thread(target=self.run, daemon=True).start()

    def on_mcu_frame(self, frame):
        u = unpack(frame)
        if u is None:
            self.events.append((time.monotonic(), "bad", None)); return
        ftype, body = u
        if ftype == T_STATUS:
            reason = body[0]
            age, wd = struct.unpack("<I", body[24:28])[0], struct.unpack("<I", body[32:36])[0]
            if reason == 1 and self.fault_t is not None:
                self.wd_seen = True
            self.events.append((time.monotonic(), "status", dict(
                reason=reason, age_ms=age, watchdog_ms=wd,
                counters=struct.unpack("<8I", body[36:68]))))
        elif ftype == T_RESULT:
            run, seq, t_ms, v, w, st, step, flags = struct.unpack("<IIIffhBB", body[:24])
            self.events.append((time.monotonic(), "result", dict(seq=seq, v=v, w=w, status=st, flags=flags)))

    def damage(self, frame):
        """frame with delimiter -> bytes to send (host -> MCU)."""
        u = unpack(frame[:-1])
        if u is None or u[0] != T_MATCHES:
            return frame
        idx = self.n_matches; self.n_matches += 1
        out = frame
        if FAULT == "garbage":
            junk = bytes(self.rng.randrange(256) for _ in range(self.rng.randrange(1, 40)))
            out = frame + junk + b"\x00"
        if not self.in_window(idx):
            return out
        if self.fault_t is None:
            self.fault_t = time.monotonic()
        self.damaged += 1
        body = bytearray(u[1])
        if FAULT == "flip":
            b = bytearray(frame); i = len(b) // 2
            bit = next(k for k in range(8) if b[i] ^ (1 << k) != 0)
            b[i] ^= 1 << bit; return bytes(b)
        if FAULT == "drop":
            m = len(frame) // 2; return frame[:m] + frame[m + 10:]
        if FAULT == "truncate":
            return frame[:len(frame) // 2] + b"\x00"
        if FAULT == "garbage":
            return bytes(self.rng.randrange(256) for _ in range(len(frame)))
        if FAULT == "count":
            body[12:14] = struct.pack("<H", 300); return repack(T_MATCHES, bytes(body))
        if FAULT == "range":
            body[16:18] = struct.pack("<h", 32100); return repack(T_MATCHES, bytes(body))
        if FAULT == "agent_restart":
            threading.Thread(target=restart_agent, daemon=True).start()
            return frame
        if FAULT == "mcu_reset":
            self.up.sendall(frame[:len(frame) // 2])
            time.sleep(0.05)
            qmp(["system_reset"])
            return b""
        return frame

    def in_window(self, idx):
        if idx < K or self.window_over:
            return False
        if self.damaged < R or (FAULT in SILENCING and not self.wd_seen and
                                time.monotonic() - self.fault_t < WINDOW_MAX_S):
            return True
        self.window_over = True
        return False

    def up_backlog(self):
        """Bytes QEMU has not read from the relay yet (SIOCOUTQ)."""
        b = array.array("i", [0])
        try:
            fcntl.ioctl(self.up.fileno(), termios.TIOCOUTQ, b)
        except OSError:
            return 0
        return b[0]

    def run(self):
        while True:
            busy = self.up_backlog() > 0
            socks = [self.ls, self.up] + ([self.agent_sock] if self.agent_sock and not busy else [])
            r, _, _ = select.select(socks, [], [], 0.005 if busy else 0.2)
            if self.ls in r:
                s, _ = self.ls.accept()
                if self.agent_sock: self.agent_sock.close()
                self.agent_sock = s; self.buf_up = bytearray()
            if self.up in r:
                try:
                    data = self.up.recv(65536)
                except OSError as e:
                    self.events.append((time.monotonic(), "uart_lost", str(e)))
                    return
                if not data:
                    self.events.append((time.monotonic(), "uart_lost", "closed"))
                    return
                if self.agent_sock:
                    try: self.agent_sock.sendall(data)
                    except OSError: self.agent_sock = None
                self.buf_dn += data
                while b"\x00" in self.buf_dn:
                    i = self.buf_dn.index(0); f = bytes(self.buf_dn[:i]); del self.buf_dn[:i + 1]
                    if f: self.on_mcu_frame(f)
            if self.agent_sock and self.agent_sock in r:
                try:
                    # A little at a time: what QEMU has not taken stays
                    # queued on the agent's side.
                    data = self.agent_sock.recv(256)
                except OSError:
                    data = b""
                if not data:
                    self.agent_sock.close(); self.agent_sock = None; continue
                self.buf_up += data
                while b"\x00" in self.buf_up:
                    i = self.buf_up.index(0); f = bytes(self.buf_up[:i + 1]); del self.buf_up[:i + 1]
                    out = self.damage(f)
                    try:
                        if out: self.up.sendall(out)
                    except OSError as e:
                        self.events.append((time.monotonic(), "uart_lost", str(e)))
                        return

def qmp(cmd):
    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    s.connect(os.path.join(work, "qmp.sock")); f = s.makefile("rw")
    f.readline()
    for c in ({"execute": "qmp_capabilities"}, {"execute": cmd[0]}):
        f.write(json.dumps(c) + "\n"); f.flush(); f.readline()
    s.close()

agents = []
def start_agent(n):
    log = open(os.path.join(work, "agent%d.log" % n), "w")
    p = subprocess.Popen([AGENT, "--device", "unix:%s" % relay.path, "--lcm-url", URL,
                          "--method", "3", "--seed", "5", "--alpha", "800",
                          "--watchdog-ms", str(WATCHDOG_MS), "--log-level", "2",
                          "--ready-file", os.path.join(work, "ready%d" % n),
                          "--summary", os.path.join(work, "agent%d.json" % n)], stderr=log)
    agents.append(p); procs.append(p)
    return p

def restart_agent():
    agents[-1].send_signal(signal.SIGKILL); agents[-1].wait()
    t_kill = time.monotonic()
    # Back after the MCU's watchdog has stopped the robot (its clock counts
    # instructions, so on a loaded host this takes longer than 300 ms of
    # wall time), and at least 1.5 s later.
    while time.monotonic() - t_kill < 15:
        if time.monotonic() - t_kill >= 1.5 and any(
                e[1] == "status" and e[2]["reason"] == 1 and e[0] > t_kill for e in list(relay.events)):
            break
        time.sleep(0.05)
    start_agent(len(agents))

def fail(msg):
    print("FAIL (%s): %s" % (FAULT, msg))
    for n in range(len(agents)):
        path = os.path.join(work, "agent%d.log" % n)
        if os.path.exists(path):
            print("--- agent%d.log (tail)" % n); print("".join(open(path).readlines()[-15:]))
    cleanup(); sys.exit(1)

def cleanup():
    for p in procs:
        if p.poll() is None:
            p.kill(); p.wait()
    subprocess.run(["rm", "-rf", work])

try:
    ref = subprocess.run([SIM] + ARGS + ["--quantize-serial", "--json", "--quiet"],
                         capture_output=True, text=True, timeout=120)
    ref = json.loads(ref.stdout.strip().splitlines()[-1])
    qemu = subprocess.Popen(["qemu-system-arm", "-M", "mps2-an386", "-nographic", "-monitor", "none",
                             "-semihosting-config", "enable=on,target=native",
                             "-icount", "shift=3,align=off,sleep=off",
                             "-serial", "unix:%s,server=on,wait=on" % os.path.join(work, "uart.sock"),
                             "-qmp", "unix:%s,server=on,wait=off" % os.path.join(work, "qmp.sock"),
                             "-kernel", IMAGE], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    procs.append(qemu)
    relay = Relay()
    start_agent(0)
    t0 = time.monotonic()
    while not os.path.exists(os.path.join(work, "ready0")):
        if time.monotonic() - t0 > 30: fail("the MCU never reported ready")
        time.sleep(0.05)
    run = subprocess.run([SIM] + ARGS + ["--transport", "lcm", "--lcm-url", URL, "--timeout", "60",
                                         "--json", "--quiet"], capture_output=True, text=True, timeout=600)
    if run.returncode != 0:
        fail("spvs-sim exit %d: %s" % (run.returncode, run.stderr.strip()))
    got = json.loads(run.stdout.strip().splitlines()[-1])
    time.sleep(0.3)
    last = agents[-1]
    last.send_signal(signal.SIGTERM)
    if last.wait(timeout=10) != 0:
        fail("the agent exited with %d" % last.returncode)
    summary = json.load(open(os.path.join(work, "agent%d.json" % (len(agents) - 1))))
    for n, p in enumerate(agents[:-1]):
        if p.returncode not in (0, -signal.SIGKILL):
            fail("agent %d exited with %d" % (n, p.returncode))

    ev = list(relay.events)
    lost = [e for e in ev if e[1] == "uart_lost"]
    if lost:
        fail("the relay lost QEMU's UART socket: %s" % lost[0][2])
    results = [e[2] for e in ev if e[1] == "result"]
    computed = [r for r in results if not r["flags"] & 0x18]
    rejected = [r for r in results if r["flags"] & 0x08]
    statuses = [(e[0], e[2]) for e in ev if e[1] == "status"]
    print("fault %s: %d matches frames on the wire, %d answers computed, %d refused, "
          "%d repeats; agent summary %s" % (FAULT, relay.n_matches, len(computed), len(rejected),
                                          len(results) - len(computed) - len(rejected), json.dumps(summary)))
    print("in process:", ref["status"], ref["final_error"], "frames", ref["frames"])
    print("via MCU:   ", got["status"], got["final_error"], "frames", got["frames"])
    if got["status"] != "converged":
        fail("the loop did not resume to convergence: %s" % got["status"])
    if relay.fault_t is None and FAULT != "agent_restart":
        fail("the fault window was never reached")
    seqs = [r["seq"] for r in computed]
    if FAULT in ("flip", "drop", "truncate", "garbage", "agent_restart"):
        a, b = dict(ref), dict(got)
        a.pop("transport"); b.pop("transport")
        diff = [k for k in a if a[k] != b.get(k)]
        if diff:
            fail("differs from the in-process run in %s" % diff)
        if seqs != list(range(got["frames"])):
            fail("computed answers are not one per frame 0..%d" % (got["frames"] - 1))
        mcu = summary["mcu"]
        if FAULT != "agent_restart" and mcu["crc_errors"] + mcu["framing_errors"] < max(R, relay.damaged):
            fail("the MCU counted %d bad frames, fewer than the %d damaged" %
                 (mcu["crc_errors"] + mcu["framing_errors"], relay.damaged))
    if FAULT in ("count", "range"):
        want = -5 if FAULT == "count" else -4
        bad = [r for r in rejected if r["status"] == want and r["v"] == 0.0 and r["w"] == 0.0]
        # A repeat of a frame can be damaged too, so count what was damaged.
        if len(bad) != relay.damaged or len(rejected) != relay.damaged:
            fail("%d stops with status %d for the %d damaged frames" % (len(bad), want, relay.damaged))
        if seqs != sorted(set(seqs)) or set(seqs) | {r["seq"] for r in rejected} != set(range(got["frames"])):
            fail("computed answers %d and refused seqs do not make up the %d frames" % (len(seqs), got["frames"]))
        print("each of the %d damaged frames answered with a stop (status %d); the core never ran on them"
              % (relay.damaged, want))
    else:
        t_f = relay.fault_t
        if FAULT == "mcu_reset":
            boots = [s for t, s in statuses if s["reason"] == 0 and t >= t_f]
            if not boots or summary["boots"] < 1:
                fail("no BOOT status after the reset")
            # Frames that reached the rebooted MCU before its set-up are
            # refused (SPVS_E_CONFIG), never run on a default controller.
            if any(r["status"] != -13 for r in rejected):
                fail("refusals other than SPVS_E_CONFIG: %s" % rejected)
            print("the MCU rebooted; the agent published a stop and resent the set-up")
        else:
            wd = [s for t, s in statuses if s["reason"] == 1 and t >= t_f and s["age_ms"] != 0xFFFFFFFF]
            if not wd:
                fail("no watchdog stop after the fault")
            w = wd[0]
            if w["watchdog_ms"] != WATCHDOG_MS:
                fail("the MCU runs a %d ms watchdog, not the %d ms set up" % (w["watchdog_ms"], WATCHDOG_MS))
            if not (w["watchdog_ms"] <= w["age_ms"] <= w["watchdog_ms"] + 5):
                fail("the first watchdog stop came %d ms after the last valid frame (watchdog %d ms)"
                     % (w["age_ms"], w["watchdog_ms"]))
            print("watchdog stop %d ms after the last valid frame (watchdog %d ms); %d stops in all"
                  % (w["age_ms"], w["watchdog_ms"], len(wd)))
    print("mcu fault %s: PASS" % FAULT)
    cleanup()
except subprocess.TimeoutExpired as e:
    fail("timed out: %s" % e)
