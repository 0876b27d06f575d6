"""The fleet's Zenoh router: eclipse-zenoh opened in router mode (the same
Rust implementation as zenohd), listening on the endpoints given and nowhere
else, multicast scouting off.  spvs-fleet starts it and restarts it if it
dies; it can also run on its own:

  .venv/bin/python sim_host/zenoh/router.py --listen tcp/127.0.0.1:7447

It writes one line "ready" on stdout once it listens, then waits for SIGINT
or SIGTERM.  Exit status: 0 after a signal, 1 when Zenoh cannot open (for
example the port is taken), 2 on bad options.
"""

import argparse
import os
import sys

import spvs_zenoh_common as common

PROG = "spvs-fleet router"


def main(argv):
    p = argparse.ArgumentParser(prog="router.py",
                                description="Zenoh router of spvs-fleet.")
    p.add_argument("--listen", action="append", required=True, metavar="E",
                   help="endpoint to listen on, repeatable")
    a = p.parse_args(argv)
    for ep in a.listen:
        why = common.check_endpoint(ep)
        if why:
            sys.stderr.write("%s: %s\n" % (PROG, why))
            return 2

    # A signal only ends the wait: raised inside session.close() it would
    # leave the session open and the process hanging.
    stop = common.StopSignals()
    try:
        import zenoh
    except ImportError as e:
        sys.stderr.write("%s: %s: run scripts/setup_venv.sh\n" % (PROG, e))
        return 1
    # A stale socket file of a router that was killed would make the bind
    # fail; nothing else owns a path under the fleet's own directory.
    for ep in a.listen:
        if ep.startswith("unixsock-stream/"):
            path = ep[len("unixsock-stream/"):]
            try:
                os.unlink(path)
            except FileNotFoundError:
                pass
    try:
        cfg = common.zenoh_config(zenoh, "router", a.listen, [], False)
        session = zenoh.open(cfg)
    except Exception as e:
        sys.stderr.write("%s: cannot listen on %s: %s\n"
                         % (PROG, ", ".join(a.listen), common.short_error(e)))
        return 1
    try:
        sys.stdout.write("ready\n")
        sys.stdout.flush()
        while not stop.wait(1.0):
            pass
    finally:
        stop.ignore()
        session.close()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
