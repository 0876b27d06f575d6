#!/usr/bin/python3
"""Check the output of `spvs-bench --short` (the CI mode of the benchmark).

Reads JSON lines on stdin and fails (exit 1, one line on stderr) unless every
line parses, carries the fields an outside harness relies on, the expected
estimators are present, and ours meets the accuracy bar on the case: success
rate 1.0 and mean corner transfer error under 2 px.

usage: spvs-bench --short | check_short.py [--min-success S] [--max-err PX|inf]
                                          [--order O] [--between B]
                                          [--family F] [--need a,b] [--records R]
--order, --between and --family: every line must say it was timed so, or
come from that pose family; --records: ours must have timed that many
records; --max-err inf: no bound on the corner error (only that it is
reported).  --max-err-tgt PX: ours' median corner error in target-image
pixels (median_corner_err_tgt_px, H's magnification taken out) must be
under PX.
"""
import argparse
import json
import math
import sys

REQUIRED = ("case_id", "family", "estimator", "N", "median_us", "success_rate",
            "mean_corner_err_px", "median_corner_err_all_px", "median_corner_err_tgt_px")


def fail(msg):
    sys.stderr.write("check_short: %s\n" % msg)
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--min-success", type=float, default=1.0)
    ap.add_argument("--max-err-tgt", type=float, default=math.inf)
    ap.add_argument("--max-err", type=float, default=2.0)
    ap.add_argument("--need", default="spvs,cv_ransac,cv_usac_default",
                    help="estimators that must be present")
    ap.add_argument("--order", choices=("turns", "blocks"), default="turns")
    ap.add_argument("--between", choices=("none", "frame"), default="none")
    ap.add_argument("--family", choices=("homing", "fig5", "grazing"), default="homing")
    ap.add_argument("--records", type=int, default=None)
    args = ap.parse_args()

    rows = {}
    for k, line in enumerate(sys.stdin):
        line = line.strip()
        if not line:
            continue
        try:
            row = json.loads(line)
        except ValueError as e:
            fail("line %d is not JSON: %s" % (k + 1, e))
        for f in REQUIRED:
            if f not in row:
                fail("line %d lacks field %s" % (k + 1, f))
        if not (isinstance(row["median_us"], (int, float)) and row["median_us"] > 0):
            fail("%s: median_us %r is not a positive time" % (row["estimator"], row["median_us"]))
        for f in ("order", "between", "family"):
            if row.get(f) != getattr(args, f):
                fail("%s: %s is %r, expected %r" % (row["estimator"], f, row.get(f),
                                                     getattr(args, f)))
        rows[row["estimator"]] = row
    for name in args.need.split(","):
        if name not in rows:
            fail("no line for estimator %s" % name)
    ours = rows["spvs"]
    if ours["N"] != 200:
        fail("short case should have N = 200, got %r" % ours["N"])
    if args.records is not None and ours.get("records") != args.records:
        fail("ours timed %r records, expected %d" % (ours.get("records"), args.records))
    if ours["success_rate"] < args.min_success:
        fail("our success rate %.3f is below %.3f" % (ours["success_rate"], args.min_success))
    err = ours["mean_corner_err_px"]
    if math.isfinite(args.max_err) and (err is None or not math.isfinite(err) or
                                        err >= args.max_err):
        fail("our mean corner error %r px is not under %.2f px" % (err, args.max_err))
    err_tgt = ours.get("median_corner_err_tgt_px")
    if math.isfinite(args.max_err_tgt) and (err_tgt is None or not math.isfinite(err_tgt) or
                                            err_tgt >= args.max_err_tgt):
        fail("our median corner error in the target image %r px is not under %.2f px"
             % (err_tgt, args.max_err_tgt))
    sys.stdout.write("check_short: %s, spvs %.1f us, success %.3f, corner error %s px; "
                     "fastest OpenCV %.1f us\n" % (
                         ours["family"], ours["median_us"], ours["success_rate"],
                         "none" if err is None else "%.3f" % err,
                         min((r["median_us"] for n, r in rows.items() if n.startswith("cv_")),
                             default=float("nan"))))


if __name__ == "__main__":
    main()
