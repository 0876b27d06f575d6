#!/usr/bin/python3
"""Checks tools/bench/accuracy.py's rules on made-up cells (ctest
bench_accuracy_rules): which OpenCV estimator is the best, when ours is
behind, and that the doc block is rewritten in place and nothing else.

usage: test_accuracy.py SCRATCH_DIR
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import accuracy  # noqa: E402


def line(cid, est, success, median, family="fig5", sigma=1):
    return {"case_id": cid, "family": family, "estimator": est, "N": 200, "mismatch": 0.2,
            "sigma_px": sigma, "success_rate": success, "median_corner_err_all_px": median,
            "median_corner_err_tgt_px": median}


def check(cond, what):
    if not cond:
        sys.stderr.write("test_accuracy: %s\n" % what)
        sys.exit(1)


def main():
    scratch = sys.argv[1]
    os.makedirs(scratch, exist_ok=True)
    rows = [
        # 0: ours 0.06 below the best in success: behind.
        line(0, "spvs", 0.70, 1.0), line(0, "cv_usac_magsac", 0.76, 1.2),
        line(0, "cv_usac_fast", 0.76, 1.1),
        # 1: 0.05 below exactly, median equal within 0.01 px: not behind.
        line(1, "spvs", 0.70, 1.005), line(1, "cv_usac_magsac", 0.75, 1.0),
        # 2: success equal, median 0.02 px above: behind on the median.
        line(2, "spvs", 1.0, 0.52), line(2, "cv_usac_default", 1.0, 0.50),
        # 3: ours returned nothing often (median infinite, null in JSON).
        line(3, "spvs", 0.0, None), line(3, "cv_ransac", 0.0, 40.0),
        # 4: every OpenCV median infinite, ours finite: not behind.
        line(4, "spvs", 0.0, 30.0), line(4, "cv_ransac", 0.0, None),
    ]
    cells_path = os.path.join(scratch, "cells.jsonl")
    with open(cells_path, "w") as f:
        for r in rows:
            f.write(json.dumps(r) + "\n")
    cells = accuracy.load_cells(cells_path)
    name, best = accuracy.best_opencv(cells[0])
    check(name == "cv_usac_fast", "ties in success go to the lower median, got %s" % name)
    want = {0: ["success"], 1: [], 2: ["median"], 3: ["median"], 4: []}
    for cid, why in want.items():
        got = accuracy.behind(cells[cid]["spvs"], accuracy.best_opencv(cells[cid])[1])
        check(got == why, "cell %d: behind %r, expected %r" % (cid, got, why))

    doc = os.path.join(scratch, "doc.md")
    with open(doc, "w") as f:
        f.write("head\n%s\nold table\n%s\ntail\n" % (accuracy.BEGIN, accuracy.END))
    out = subprocess.run([sys.executable, os.path.join(HERE, "accuracy.py"), "render", scratch,
                          "--doc", doc], capture_output=True, text=True)
    check(out.returncode == 0, "render failed: %s" % out.stderr.strip())
    check("Cells where we are behind: 3 of 5." in out.stdout, "render: wrong count of cells behind")
    text = open(doc).read()
    check(text.startswith("head\n" + accuracy.BEGIN + "\n") and text.endswith(
        accuracy.END + "\ntail\n") and "old table" not in text and "| 2 | fig5" in text,
        "the doc block was not replaced in place")
    # A doc without the markers is refused, and left alone.
    with open(doc, "w") as f:
        f.write("no markers\n")
    out = subprocess.run([sys.executable, os.path.join(HERE, "accuracy.py"), "render", scratch,
                          "--doc", doc], capture_output=True, text=True)
    check(out.returncode == 2 and "no <!-- accuracy:begin -->" in out.stderr and
          open(doc).read() == "no markers\n", "a doc without markers was not refused")
    print("test_accuracy: best, behind and the doc block as expected")


if __name__ == "__main__":
    main()
