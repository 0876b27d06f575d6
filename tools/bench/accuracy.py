#!/usr/bin/python3
"""Accuracy of every cell of spvs-bench's matrix: ours against every OpenCV
estimator, and the cells where we are behind (docs/BENCHMARKS.md, section
"Accuracy in every cell").

usage:
  accuracy.py run [--bench PATH] [--out DIR] [--doc FILE] [--before CELLS.jsonl]
                  [-- BENCH_ARGS...]
      runs `nice spvs-bench --full --repeats 2 --warmup 5 --jsonl DIR/cells.jsonl
      --per-record` (stderr to DIR/records.jsonl), then renders as below
  accuracy.py render [DIR|CELLS.jsonl] [--doc FILE] [--before CELLS.jsonl]
      prints the tables made from DIR/cells.jsonl (and DIR/records.jsonl when
      it exists); with --doc, also writes them into FILE between the lines
      <!-- accuracy:begin --> and <!-- accuracy:end -->; with --before, adds
      ours in an earlier run (docs/data/bench_accuracy_before.jsonl holds
      the run docs/BENCHMARKS.md reports) beside ours now, cell by cell

Definitions (the doc repeats them):
  success   share of estimates whose mean corner transfer error is under 2 px
  median    median corner error over every estimate, one that returned no H
            (or an H that maps a corner behind the camera) counting as infinite
  best      the OpenCV estimator with the highest success, ties broken by the
            lower median
  behind    our success more than 0.05 below the best's, or our median above
            the best's by more than 0.01 px (ours computes in float32: smaller
            differences are rounding)
"""
import argparse
import json
import math
import os
import subprocess
import sys
from collections import defaultdict

BEGIN = "<!-- accuracy:begin -->"
END = "<!-- accuracy:end -->"
SUCCESS_SLACK = 0.05
MEDIAN_SLACK_PX = 0.01
FAMILIES = ("homing", "fig5", "grazing")
FIG5 = ((-3, -10, -30), (0, -8, -40), (6, -6, 0), (-6, 4, 20), (6, 8, 10), (5, 2, -50))


def fail(msg):
    sys.stderr.write("accuracy.py: %s\n" % msg)
    sys.exit(2)


def num(v):
    """A JSON number, null as infinity (a median that fell on a failure)."""
    return math.inf if v is None else float(v)


def fmt_med(v):
    if math.isinf(v):
        return "inf"
    if v < 0.001:
        return "%.0e" % v if v > 0 else "0"
    return "%.3f" % v if v < 10 else "%.1f" % v


def read_jsonl(path, need):
    rows = []
    with open(path) as f:
        for k, line in enumerate(f):
            if not line.startswith("{"):
                continue  # progress lines
            try:
                row = json.loads(line)
            except ValueError as e:
                fail("%s line %d is not JSON: %s" % (path, k + 1, e))
            for field in need:
                if field not in row:
                    fail("%s line %d lacks %s" % (path, k + 1, field))
            rows.append(row)
    return rows


def load_cells(path):
    rows = read_jsonl(path, ("case_id", "family", "estimator", "N", "mismatch", "sigma_px",
                             "success_rate", "median_corner_err_all_px"))
    cells = defaultdict(dict)
    for r in rows:
        cells[r["case_id"]][r["estimator"]] = r
    return cells


def best_opencv(cell):
    cv = [(n, r) for n, r in cell.items() if n.startswith("cv_")]
    if not cv:
        return None, None
    return min(cv, key=lambda nr: (-nr[1]["success_rate"],
                                   num(nr[1]["median_corner_err_all_px"])))


def behind(ours, best):
    """Why ours is behind the best OpenCV estimator ([] when it is not)."""
    why = []
    if ours["success_rate"] < best["success_rate"] - SUCCESS_SLACK - 1e-9:
        why.append("success")
    mo, mb = num(ours["median_corner_err_all_px"]), num(best["median_corner_err_all_px"])
    if mo > mb + MEDIAN_SLACK_PX:
        why.append("median")
    return why


def cell_key(r):
    return "%s, N %d, %d %%, %g px" % (r["family"], r["N"], round(100 * r["mismatch"]),
                                     r["sigma_px"])


def every_cell_table(cells):
    names = None
    for cid in sorted(cells):
        cv = sorted(n for n in cells[cid] if n.startswith("cv_"))
        if names is None or len(cv) > len(names):
            names = cv
    out = ["| case | family | N | mismatch | sigma px | spvs | " + " | ".join(names) +
           " | best OpenCV | behind |",
           "|---" * (7 + len(names)) + "|---|"]
    n_behind = 0
    for cid in sorted(cells):
        cell = cells[cid]
        if "spvs" not in cell:
            continue
        ours = cell["spvs"]
        bname, best = best_opencv(cell)
        why = behind(ours, best) if best else []
        n_behind += bool(why)

        def sm(r):
            return "%.3f / %s" % (r["success_rate"], fmt_med(num(r["median_corner_err_all_px"])))
        cols = [str(cid), ours["family"], str(ours["N"]), "%g" % ours["mismatch"],
                "%g" % ours["sigma_px"], sm(ours)]
        cols += [sm(cell[n]) if n in cell else "-" for n in names]
        cols += [bname or "-", ("**" + ", ".join(why) + "**") if why else "no"]
        out.append("| " + " | ".join(cols) + " |")
    return out, n_behind


def behind_list(cells):
    out = ["| case | cell | ours success | best OpenCV | its success | success gap | "
           "ours median px | its median px | ours / its median, target-image px |",
           "|---|---|---|---|---|---|---|---|---|"]
    for cid in sorted(cells):
        cell = cells[cid]
        if "spvs" not in cell:
            continue
        ours = cell["spvs"]
        bname, best = best_opencv(cell)
        if not best or not behind(ours, best):
            continue
        tgt = "%s / %s" % (fmt_med(num(ours.get("median_corner_err_tgt_px"))),
                           fmt_med(num(best.get("median_corner_err_tgt_px"))))
        out.append("| %d | %s | %.3f | %s | %.3f | %+.3f | %s | %s | %s |" % (
            cid, cell_key(ours), ours["success_rate"], bname, best["success_rate"],
            ours["success_rate"] - best["success_rate"],
            fmt_med(num(ours["median_corner_err_all_px"])),
            fmt_med(num(best["median_corner_err_all_px"])), tgt))
    return out


def view_tables(records_path):
    """Noisy records (sigma > 0) grouped by where they were seen from."""
    rows = read_jsonl(records_path, ("case_id", "family", "estimator", "successes", "estimates",
                                     "off_axis_deg", "inliers_over_3px", "sigma_px"))
    groups = defaultdict(lambda: defaultdict(lambda: [0, 0]))
    over = defaultdict(list)
    sampson = defaultdict(list)
    order = []

    def add(key, r):
        if key not in groups:
            order.append(key)
        g = groups[key][r["estimator"]]
        g[0] += r["successes"]
        g[1] += r["estimates"]
        if r["estimator"] == "spvs":
            over[key].append(r["inliers_over_3px"])
            sampson[key].append(r.get("inliers_over_sampson_99", math.nan))

    for r in rows:
        if not r["sigma_px"]:
            continue
        off = abs(num(r["off_axis_deg"]))
        band = "%d-%d" % (10 * int(off // 10), 10 * int(off // 10) + 10)
        if r["family"] == "fig5" and r.get("start") is not None:
            add(("fig5 start", "(%g, %g, %g)" % FIG5[r["start"]]), r)
        add((r["family"] + " off-axis deg", band), r)

    out = ["| family | group | records | true inliers over 3 px at the true H | "
           "over the Sampson 0.99 bound at the true H | ours success | "
           "best OpenCV success (estimator) |",
           "|---|---|---|---|---|---|---|"]

    def sort_key(key):
        label, group = key
        if label == "fig5 start":
            rank = ["(%g, %g, %g)" % p for p in FIG5].index(group)
        else:
            rank = int(group.split("-")[0])
        return (FAMILIES.index(label.split()[0]), label, rank)
    order.sort(key=sort_key)
    for key in order:
        g = groups[key]
        if "spvs" not in g:
            continue
        o = g["spvs"]
        cv = [(n, s[0] / s[1]) for n, s in g.items() if n.startswith("cv_") and s[1]]
        bn, bs = max(cv, key=lambda x: x[1]) if cv else ("-", math.nan)
        ov, sa = over[key], sampson[key]
        out.append("| %s | %s | %d | %.3f | %.3f | %.3f | %.3f (%s) |" % (
            key[0], key[1], len(ov), sum(ov) / len(ov), sum(sa) / len(sa),
            o[0] / o[1] if o[1] else math.nan, bs, bn))
    return out


def before_table(cells, before_path):
    old = load_cells(before_path)
    out = ["| case | cell | ours success, before -> now | ours median px, before -> now | "
           "best OpenCV success / median now | behind now |",
           "|---|---|---|---|---|---|"]
    for cid in sorted(cells):
        if "spvs" not in cells[cid] or "spvs" not in old.get(cid, {}):
            continue
        o, n = old[cid]["spvs"], cells[cid]["spvs"]
        bname, best = best_opencv(cells[cid])
        out.append("| %d | %s | %.3f -> %.3f | %s -> %s | %s | %s |" % (
            cid, cell_key(n), o["success_rate"], n["success_rate"],
            fmt_med(num(o["median_corner_err_all_px"])),
            fmt_med(num(n["median_corner_err_all_px"])),
            "%.3f / %s" % (best["success_rate"], fmt_med(num(best["median_corner_err_all_px"])))
            if best else "-", ", ".join(behind(n, best)) or "no" if best else "-"))
    return out


def render(path, doc, before=None):
    if os.path.isdir(path):
        cells_path = os.path.join(path, "cells.jsonl")
    else:
        cells_path = path
    if not os.path.exists(cells_path):
        fail("no %s (run `accuracy.py run` first)" % cells_path)
    out_dir = os.path.dirname(cells_path)
    cells = load_cells(cells_path)
    table, n_behind = every_cell_table(cells)
    n_cells = sum(1 for c in cells.values() if "spvs" in c)
    text = ["Every cell (`success / median corner error px`; generated by "
            "`tools/bench/accuracy.py` from `%s`):" % os.path.basename(cells_path), ""]
    text += table
    text += ["", "Cells where we are behind: %d of %d." % (n_behind, n_cells), ""]
    text += behind_list(cells)
    rec = os.path.join(out_dir, "records.jsonl")
    if os.path.exists(rec):
        text += ["", "Noisy records (1 px) by view, all N and mismatch shares pooled (from "
                 "`records.jsonl`, the `--per-record` lines):", ""]
        text += view_tables(rec)
    if before:
        text += ["", "Ours against the run in `%s`:" % before, ""]
        text += before_table(cells, before)
    body = "\n".join(text) + "\n"
    sys.stdout.write(body)
    if doc:
        with open(doc) as f:
            old = f.read()
        if BEGIN not in old or END not in old:
            fail("%s has no %s ... %s block" % (doc, BEGIN, END))
        head, rest = old.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        with open(doc, "w") as f:
            f.write(head + BEGIN + "\n" + body + END + tail)
        sys.stderr.write("accuracy.py: wrote the tables into %s\n" % doc)


def run(bench, out_dir, extra):
    os.makedirs(out_dir, exist_ok=True)
    cmd = ["nice", "-n", "10", bench, "--full", "--repeats", "2", "--warmup", "5",
           "--jsonl", os.path.join(out_dir, "cells.jsonl"), "--per-record"] + extra
    sys.stderr.write("accuracy.py: %s 2> %s\n" % (" ".join(cmd),
                                                   os.path.join(out_dir, "records.jsonl")))
    with open(os.path.join(out_dir, "records.jsonl"), "w") as err, \
            open(os.path.join(out_dir, "tables.md"), "w") as tables:
        p = subprocess.Popen(cmd, stdout=tables, stderr=subprocess.PIPE, text=True)
        for line in p.stderr:
            err.write(line)
            if not line.startswith("{"):
                sys.stderr.write(line)  # progress and notes
        if p.wait() != 0:
            fail("spvs-bench exited with status %d" % p.returncode)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--bench", default="build/bench/tools/bench/spvs-bench")
    r.add_argument("--out", default="build/bench/accuracy")
    r.add_argument("--doc", default=None)
    r.add_argument("--before", default=None)
    r.add_argument("extra", nargs="*", help="more spvs-bench options, after --")
    d = sub.add_parser("render")
    d.add_argument("dir", nargs="?", default="build/bench/accuracy")
    d.add_argument("--doc", default=None)
    d.add_argument("--before", default=None)
    a = ap.parse_args()
    if a.cmd == "run":
        if not os.access(a.bench, os.X_OK):
            fail("no spvs-bench at %s (cmake --preset bench && cmake --build --preset bench "
                 "--target spvs-bench)" % a.bench)
        run(a.bench, a.out, a.extra)
        render(a.out, a.doc, a.before)
    else:
        render(a.dir, a.doc, a.before)


if __name__ == "__main__":
    main()
