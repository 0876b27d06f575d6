#!/usr/bin/python3
"""A program refusing a bad command line as every spvs program does: exit
status 2, nothing on stdout, exactly one line on stderr, starting with the
program's name and holding the text that names the option (sim/cli.h).

usage: check_refused.py PROGRAM SAYS -- COMMAND [ARGS...]
"""
import subprocess
import sys


def main(argv):
    if len(argv) < 5 or argv[3] != "--":
        sys.stderr.write(__doc__)
        return 2
    program, says, cmd = argv[1], argv[2], argv[4:]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=30,
                           stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        print("FAIL: no answer within 30 s: %s" % " ".join(cmd))
        return 1
    lines = p.stderr.splitlines()
    problems = []
    if p.returncode != 2:
        problems.append("exit status %d, expected 2" % p.returncode)
    if len(lines) != 1:
        problems.append("%d lines on stderr, expected 1" % len(lines))
    elif not lines[0].startswith(program + ": "):
        problems.append("stderr does not start with '%s: '" % program)
    elif says not in lines[0]:
        problems.append("stderr does not say %r" % says)
    if p.stdout:
        problems.append("stdout not empty: %r" % p.stdout[:200])
    if problems:
        print("FAIL: %s: %s; stderr: %r" % (" ".join(cmd), "; ".join(problems),
                                           p.stderr[:400]))
        return 1
    print("ok: exit 2, %s" % lines[0])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
