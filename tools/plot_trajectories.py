#!/usr/bin/python3
"""Plot robot paths from spvs-sim --trace files side by side (top view, x
right, z forward, metres; the target pose is the origin).  One panel per
LABEL; several traces joined with '+' share a panel.

usage: plot_trajectories.py OUT.png LABEL=TRACE.csv[+TRACE.csv ...] [...]
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(argv):
    if len(argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    runs = []
    for arg in argv[2:]:
        label, sep, paths = arg.partition("=")
        if not sep:
            sys.stderr.write("plot_trajectories: '%s' is not LABEL=FILE\n" % arg)
            return 2
        paths_xz = []
        for path in paths.split("+"):
            try:
                with open(path, newline="") as f:
                    rows = list(csv.DictReader(f))
                xs = [float(r["x"]) for r in rows]
                zs = [float(r["z"]) for r in rows]
            except (OSError, KeyError, ValueError) as e:
                sys.stderr.write("plot_trajectories: cannot read '%s': %s\n"
                                 % (path, e))
                return 1
            paths_xz.append((xs, zs))
        runs.append((label, paths_xz))
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
    fig.savefig(argv[1], dpi=80)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
