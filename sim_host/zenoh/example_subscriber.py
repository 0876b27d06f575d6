"""Example: watch a robot's commands on Zenoh, without LCM installed.

Subscribes to spvs/<robot>/cmd and prints one line per command.  The payload
is an LCM-encoded spvs.cmd_t (lcm_types/cmd_t.lcm): an 8-byte type
fingerprint, then big-endian int64 seq, int64 utime (us), double v (m/s),
double w (rad/s), int8 step, int16 status -- 43 bytes in all.

  .venv/bin/python sim_host/zenoh/example_subscriber.py \
      --connect tcp/127.0.0.1:7447

Stops after --count commands (0: never), on Ctrl-C or SIGTERM.
"""

import argparse
import json
import signal
import struct
import sys
import threading
import time

import zenoh

CMD_FINGERPRINT = bytes.fromhex("9e05dc4618de8f04")
CMD_FIELDS = struct.Struct(">qqddbh")  # seq, utime, v, w, step, status


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--robot", default="robot0")
    p.add_argument("--connect", default="tcp/127.0.0.1:7447")
    p.add_argument("--count", type=int, default=0)
    a = p.parse_args()

    cfg = zenoh.Config()
    cfg.insert_json5("mode", '"peer"')
    cfg.insert_json5("scouting/multicast/enabled", "false")
    cfg.insert_json5("connect/endpoints", json.dumps([a.connect]))
    cfg.insert_json5("listen/endpoints", '["tcp/127.0.0.1:0"]')

    done = threading.Event()
    seen = [0]

    def on_cmd(sample):
        data = sample.payload.to_bytes()
        if len(data) != 8 + CMD_FIELDS.size or data[:8] != CMD_FINGERPRINT:
            print("not a cmd_t (%d bytes)" % len(data), file=sys.stderr)
            return
        seq, utime, v, w, step, status = CMD_FIELDS.unpack(data[8:])
        print("cmd seq %d t %.3f s v %+.4f m/s w %+.5f rad/s step %d "
              "status %d" % (seq, utime * 1e-6, v, w, step, status),
              flush=True)
        seen[0] += 1
        if a.count and seen[0] >= a.count:
            done.set()

    # Ctrl-C and SIGTERM only set a flag: an exception raised inside
    # session.close() (a second Ctrl-C) would leave the session open and
    # the process hanging at exit.  The handler must not call done.set():
    # it runs in the main thread, which may hold the Event's lock just then.
    signalled = []
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda signum, _frame: signalled.append(signum))
    session = zenoh.open(cfg)
    try:
        session.declare_subscriber("spvs/%s/cmd" % a.robot, on_cmd)
        while not signalled and not done.is_set():
            time.sleep(0.1)
    finally:
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)
        session.close()


if __name__ == "__main__":
    main()
