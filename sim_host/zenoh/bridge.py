"""spvs-zenoh-bridge: relays the controller's LCM channels to Zenoh and back.

  Zenoh spvs/<robot>/matches  ->  LCM SPVS_MATCHES   (to spvs-node)
  LCM SPVS_CMD                ->  Zenoh spvs/<robot>/cmd
  LCM SPVS_STATE              ->  Zenoh spvs/<robot>/state

Payloads are the LCM-encoded messages, unchanged.  Every payload is checked
(size, fingerprint, count within the array capacity) before it is relayed;
a bad one is dropped with a logged error and the bridge keeps running.

Threads: Zenoh delivers samples on its own threads; they only check the
bytes and queue them.  The main thread owns the LCM instance: it waits on the
LCM socket and on a wake-up pipe together, so a queued frame goes out on LCM
without waiting for a polling period.

Exit status: 0 after SIGINT/SIGTERM, 1 when LCM or Zenoh cannot be opened
or fails, 2 on bad options.  Usage: docs/ZENOH.md.
"""

import argparse
import collections
import os
import select
import signal
import sys
import threading
import time

import ros2_keys
import spvs_zenoh_common as common

PROG = "spvs-zenoh-bridge"
DEFAULT_LCM_URL = "udpm://239.255.76.67:7667?ttl=0"
DEFAULT_LISTEN = "tcp/127.0.0.1:7447"


class UsageError(Exception):
    pass


class Parser(argparse.ArgumentParser):
    """argparse with the project's one-line usage error and exit status 2."""

    def error(self, message):
        raise UsageError(message)


def parse_args(argv):
    p = Parser(
        prog=PROG,
        description="Relay the spvs controller's LCM channels to Zenoh and "
        "back: spvs/<robot>/matches -> SPVS_MATCHES, SPVS_CMD -> "
        "spvs/<robot>/cmd, SPVS_STATE -> spvs/<robot>/state.  Payloads are "
        "the LCM-encoded messages (docs/ZENOH.md).",
        epilog="Exit status: 0 after SIGINT/SIGTERM, 1 when LCM or Zenoh "
        "fails, 2 on bad options.")
    p.add_argument("--robot", default="robot0",
                   help="robot name in the key expressions (default robot0)")
    p.add_argument("--lcm-url", default=None,
                   help="LCM provider (default $LCM_DEFAULT_URL or "
                   + DEFAULT_LCM_URL + ")")
    p.add_argument("--mode", choices=("peer", "client"), default="peer",
                   help="Zenoh mode (default peer)")
    p.add_argument("--listen", action="append", default=None, metavar="E",
                   help="Zenoh endpoint to listen on, repeatable (default "
                   + DEFAULT_LISTEN + " in peer mode; none in client mode)")
    p.add_argument("--connect", action="append", default=[], metavar="E",
                   help="Zenoh endpoint to connect to (a router or a peer), "
                   "repeatable")
    p.add_argument("--scouting", choices=("on", "off"), default="off",
                   help="Zenoh multicast scouting (default off: only the "
                   "endpoints given are used)")
    p.add_argument("--lcm-types", default=None, metavar="DIR",
                   help="folder with the generated Python package spvs/ "
                   "(a build's lcm_types/python); default: generate it with "
                   "lcm-gen from lcm_types/*.lcm")
    p.add_argument("--ros2-cmd-vel", action="store_true",
                   help="also put every command as a geometry_msgs/Twist on "
                   "/cmd_vel as ROS 2's rmw_zenoh names it, in the domain "
                   "$ROS_DOMAIN_ID (docs/ROS2.md)")
    p.add_argument("--log-level", type=int, choices=(0, 1, 2, 3), default=1,
                   help="0 quiet, 1 errors (default), 2 info, 3 every message")
    p.add_argument("--max-log-rate", type=float, default=20.0, metavar="N",
                   help="at most N error lines per second; the rest are "
                   "counted (default 20)")
    a = p.parse_args(argv)
    why = common.check_robot(a.robot)
    if why:
        raise UsageError("--robot: " + why)
    if a.listen is None:
        a.listen = [DEFAULT_LISTEN] if a.mode == "peer" else []
    if a.mode == "client" and a.listen:
        raise UsageError("--listen: a Zenoh client does not listen; use "
                         "--mode peer")
    if a.mode == "client" and not a.connect and a.scouting == "off":
        raise UsageError("a client needs --connect E (or --scouting on)")
    for ep in a.listen + a.connect:
        why = common.check_endpoint(ep)
        if why:
            raise UsageError(why)
    if not (a.max_log_rate > 0.0):
        raise UsageError("--max-log-rate must be positive")
    if a.lcm_url is None:
        a.lcm_url = os.environ.get("LCM_DEFAULT_URL") or DEFAULT_LCM_URL
    a.ros2_domain = None
    if a.ros2_cmd_vel:
        try:
            a.ros2_domain = ros2_keys.domain_from_env(os.environ)
        except ValueError as e:
            raise UsageError("--ros2-cmd-vel: %s" % e)
    return a


class Log:
    """Lines on stderr, errors rate-limited so a flood of bad payloads
    cannot flood the log (the dropped count is still exact)."""

    def __init__(self, level, max_rate):
        self.level = level
        self.max_rate = max_rate
        self.window_start = time.monotonic()
        self.window_count = 0
        self.suppressed = 0
        self.lock = threading.Lock()

    def info(self, text, level=2):
        if self.level >= level:
            with self.lock:
                sys.stderr.write("%s: %s\n" % (PROG, text))
                sys.stderr.flush()

    def error(self, text):
        if self.level < 1:
            return
        with self.lock:
            now = time.monotonic()
            if now - self.window_start >= 1.0:
                if self.suppressed:
                    sys.stderr.write("%s: error: %d more errors not shown\n"
                                     % (PROG, self.suppressed))
                self.window_start = now
                self.window_count = 0
                self.suppressed = 0
            if self.window_count < self.max_rate:
                self.window_count += 1
                sys.stderr.write("%s: error: %s\n" % (PROG, text))
            else:
                self.suppressed += 1
            sys.stderr.flush()


class Bridge:
    def __init__(self, args, zenoh, lcm_mod, types, log):
        self.args = args
        self.zenoh = zenoh
        self.log = log
        self.check_matches = common.PayloadCheck(types.matches_t, "x_tgt")
        self.check_cmd = common.PayloadCheck(types.cmd_t)
        self.check_state = common.PayloadCheck(types.state_t)
        self.counts = collections.Counter()
        self.queue = collections.deque()
        self.queue_lock = threading.Lock()
        self.wake_r, self.wake_w = os.pipe()
        os.set_blocking(self.wake_r, False)
        os.set_blocking(self.wake_w, False)
        self.stop = False
        self.session = None
        self.lcm = lcm_mod.LCM(args.lcm_url)
        self.key_matches = common.key_expr(args.robot, "matches")
        self.key_cmd = common.key_expr(args.robot, "cmd")
        self.key_state = common.key_expr(args.robot, "state")

    def wake(self):
        try:
            os.write(self.wake_w, b"x")
        except BlockingIOError:
            pass  # a wake-up is already pending

    def open_zenoh(self):
        a = self.args
        cfg = common.zenoh_config(self.zenoh, a.mode, a.listen, a.connect,
                                  a.scouting == "on")
        self.session = self.zenoh.open(cfg)
        remote = self.zenoh.Locality.REMOTE
        # Remote only on both ends: with a local monitor or a second mapping
        # in the same process the bridge still never hears its own output.
        self.pub_cmd = self.session.declare_publisher(
            self.key_cmd, allowed_destination=remote)
        self.pub_state = self.session.declare_publisher(
            self.key_state, allowed_destination=remote)
        self.sub_matches = self.session.declare_subscriber(
            self.key_matches, self.on_zenoh_matches, allowed_origin=remote)
        self.ros2 = None
        if a.ros2_domain is not None:
            self.ros2 = ros2_keys.CmdVelPublisher(self.zenoh, self.session,
                                                  a.ros2_domain)
            self.log.info("ROS 2 /cmd_vel on %s" % self.ros2.key)

    def open_lcm(self):
        # One direction per channel: SPVS_MATCHES is only ever published
        # here, so subscribing to CMD and STATE alone cannot loop.
        self.lcm.subscribe(common.CH_CMD, self.on_lcm_cmd)
        self.lcm.subscribe(common.CH_STATE, self.on_lcm_state)

    # ---- Zenoh -> LCM (Zenoh's threads) ----------------------------------

    def on_zenoh_matches(self, sample):
        data = bytes(sample.payload.to_bytes())
        msg, why = self.check_matches.check(data)
        if why:
            self.counts["dropped_matches"] += 1
            self.log.error("dropped payload on %s: %s"
                           % (self.key_matches, why))
            return
        if self.log.level >= 3:
            self.log.info("%s seq %d count %d -> %s"
                          % (self.key_matches, msg.seq, msg.count,
                             common.CH_MATCHES), 3)
        with self.queue_lock:
            self.queue.append(data)
        self.wake()

    # ---- LCM -> Zenoh (main thread) --------------------------------------

    def relay_lcm(self, what, checker, pub, key, data):
        msg, why = checker.check(data)
        if why:
            self.counts["dropped_" + what] += 1
            self.log.error("dropped message on %s: %s"
                           % ("SPVS_" + what.upper(), why))
            return
        try:
            pub.put(data)
        except Exception as e:
            # Zenoh refusing one sample (session closing, congestion) is
            # not a reason to stop relaying the next ones.
            self.counts["failed_" + what] += 1
            self.log.error("putting SPVS_%s seq %d on %s failed: %s"
                           % (what.upper(), msg.seq, key,
                              common.short_error(e)))
            return
        self.counts[what] += 1
        if self.log.level >= 3:
            self.log.info("SPVS_%s seq %d -> %s" % (what.upper(), msg.seq,
                                                     key), 3)

    def on_lcm_cmd(self, channel, data):
        self.relay_lcm("cmd", self.check_cmd, self.pub_cmd, self.key_cmd,
                       data)
        if getattr(self, "ros2", None) is not None:
            _, why = self.check_cmd.check(data)
            if not why:
                try:
                    cmd = self.check_cmd.cls.decode(data)
                    self.ros2.put(cmd.v, cmd.w)
                except Exception as e:
                    self.counts["failed_ros2"] += 1
                    self.log.error("putting /cmd_vel on %s failed: %s"
                                   % (self.ros2.key, common.short_error(e)))

    def on_lcm_state(self, channel, data):
        self.relay_lcm("state", self.check_state, self.pub_state,
                       self.key_state, data)

    # ---- main loop ---------------------------------------------------------

    def flush_queue(self):
        try:
            while os.read(self.wake_r, 4096):
                pass
        except BlockingIOError:
            pass
        while True:
            with self.queue_lock:
                if not self.queue:
                    return
                data = self.queue.popleft()
            try:
                self.lcm.publish(common.CH_MATCHES, data)
            except OSError as e:
                self.counts["failed_matches"] += 1
                self.log.error("publishing on %s failed: %s"
                               % (common.CH_MATCHES, e))
                continue
            self.counts["matches"] += 1

    def run(self):
        lcm_fd = self.lcm.fileno()
        while not self.stop:
            ready, _, _ = select.select([lcm_fd, self.wake_r], [], [], 0.5)
            if self.stop:
                break
            if lcm_fd in ready:
                self.lcm.handle()
            self.flush_queue()

    def close(self):
        # Undeclare first so no callback runs into a half-closed bridge,
        # then close the session: a session left open keeps Zenoh's threads
        # alive and the process would hang at exit.
        if getattr(self, "ros2", None) is not None:
            self.ros2.close()
        for name in ("sub_matches", "pub_cmd", "pub_state"):
            ent = getattr(self, name, None)
            if ent is not None:
                try:
                    ent.undeclare()
                except Exception:
                    pass
        if self.session is not None:
            try:
                self.session.close()
            except Exception:
                pass
            self.session = None


def main(argv):
    try:
        args = parse_args(argv)
    except UsageError as e:
        sys.stderr.write("%s: %s (see --help)\n" % (PROG, e))
        return 2

    log = Log(args.log_level, args.max_log_rate)
    try:
        import lcm as lcm_mod
        import zenoh
    except ImportError as e:
        sys.stderr.write("%s: %s: run scripts/setup_venv.sh and start the "
                         "bridge with .venv/bin/python\n" % (PROG, e))
        return 1
    try:
        types = common.load_lcm_types(args.lcm_types)
    except RuntimeError as e:
        sys.stderr.write("%s: %s\n" % (PROG, e))
        return 1

    try:
        bridge = Bridge(args, zenoh, lcm_mod, types, log)
    except (RuntimeError, OSError) as e:
        sys.stderr.write("%s: cannot open LCM at '%s': %s\n"
                         % (PROG, args.lcm_url, e))
        return 1

    def on_signal(signum, frame):
        bridge.stop = True
        bridge.wake()

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)

    rc = 0
    try:
        try:
            bridge.open_zenoh()
        except Exception as e:
            sys.stderr.write("%s: cannot open Zenoh (%s, listen %s, connect "
                             "%s): %s\n" % (PROG, args.mode, args.listen,
                                            args.connect,
                                            common.short_error(e)))
            return 1
        bridge.open_lcm()
        log.info("robot %s: %s <-> LCM %s; Zenoh %s, listen %s, connect %s, "
                 "scouting %s" % (args.robot, "spvs/%s/*" % args.robot,
                                  args.lcm_url, args.mode, args.listen,
                                  args.connect, args.scouting))
        try:
            bridge.run()
        except OSError as e:
            # A signal during the LCM call can surface as OSError; after a
            # stop request that is the normal way out.
            if not bridge.stop:
                sys.stderr.write("%s: error: LCM receive failed: %s\n"
                                 % (PROG, e))
                rc = 1
    finally:
        bridge.close()
    c = bridge.counts
    log.info("exit: relayed %d matches, %d cmd, %d state; dropped %d "
             "matches, %d cmd, %d state"
             % (c["matches"], c["cmd"], c["state"], c["dropped_matches"],
                c["dropped_cmd"], c["dropped_state"]))
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
