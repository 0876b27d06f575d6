#!/usr/bin/python3
"""Plot robot paths from spvs-sim --trace files side by side (top view, x
right, z forward, metres; the target pose is the origin).  One panel per
LABEL; several traces joined with '+' share a panel.

Exit status: 0, 1 when a trace cannot be read, 2 on bad arguments.
"""
import argparse
import csv
import sys


PROG = "plot_trajectories"


class UsageError(Exception):
    pass


class Parser(argparse.ArgumentParser):
    """argparse with the project's one-line usage error and exit status 2."""

    def error(self, message):
        raise UsageError(message)


def parse_args(argv):
    p = Parser(prog="plot_trajectories.py",
               description=__doc__.split("\n\n")[0].replace("\n", " "),
               epilog=__doc__.split("\n\n")[1].strip())
    p.add_argument("out", metavar="OUT.png", help="the figure to write")
    p.add_argument("panels", nargs="+",
                   metavar="LABEL=TRACE.csv[+TRACE.csv ...]",
                   help="one panel: its title and the spvs-sim --trace "
                   "files drawn in it")
    return p.parse_args(argv)


def read_panels(panels):
    """[(label, [(xs, zs) per trace])] from LABEL=TRACE[+TRACE] arguments,
    or the exit status after an error line."""
    runs = []
    for arg in panels:
        label, sep, paths = arg.partition("=")
        if not sep:
            sys.stderr.write("%s: '%s' is not LABEL=FILE\n" % (PROG, arg))
            return 2
        paths_xz = []
        for path in paths.split("+"):
            try:
                with open(path, newline="") as f:
                    rows = list(csv.DictReader(f))
                xs = [float(r["x"]) for r in rows]
                zs = [float(r["z"]) for r in rows]
            except (OSError, KeyError, ValueError) as e:
                sys.stderr.write("%s: cannot read '%s': %s\n"
                                 % (PROG, path, e))
                return 1
            paths_xz.append((xs, zs))
        runs.append((label, paths_xz))
    return runs


def draw(out, runs):
    # Imported here: --help and the argument errors need no matplotlib.
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(runs), figsize=(3.2 * len(runs), 3.4),
                             sharex=True, sharey=True)
    if len(runs) == 1:
        axes = [axes]
    for ax, (label, paths_xz) in zip(axes, runs):
        for i, (xs, zs) in enumerate(paths_xz):
            ax.plot(xs, zs, "-", lw=1.5, color="C%d" % (i % 10))
            ax.plot(xs[:1], zs[:1], "o", ms=4, color="C%d" % (i % 10),
                    label="start" if i == 0 else None)
        ax.plot([0], [0], "k^", ms=6, label="target")
        ax.set_title(label, fontsize=9)
        ax.set_xlabel("x (m)")
        ax.grid(True, lw=0.3)
        ax.set_aspect("equal", adjustable="box")
    axes[0].set_ylabel("z (m)")
    axes[0].legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(out, dpi=80)


def main(argv):
    try:
        a = parse_args(argv[1:])
    except UsageError as e:
        sys.stderr.write("%s: %s (see --help)\n" % (PROG, e))
        return 2
    runs = read_panels(a.panels)
    if isinstance(runs, int):
        return runs
    draw(a.out, runs)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
