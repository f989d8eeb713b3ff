#!/usr/bin/env python3
"""Engineering-quantity errors of this tree's railcrash and an earlier commit's, against one tight reference.

    bench/compare_accuracy.py [COMMIT] [--rtols 1e-3,1e-4] [--reference-rtol 1e-7] [--t-end 0.25]

The "equal accuracy" half of issue 14's goal for the two-car crash: both executables (the old
one built by compare_commit.py in /tmp/railcrash-COMMIT) run the same model (compare_commit.py's
choice: the old commit's copy when the old executable rejects this tree's) with IDA at each
rtol. Every quantity is taken the
same way from both runs' files, so the errors are comparable:

  max crush            the largest anticlimber.horizontal_deformation (R1 times the reference crush)
  peak coupler force   the largest |coupler_faces.normal_force|
  R2                   the largest |anticlimber.vertical_force| (R2 times the vertical yield force)
  CFC-60 car body      the largest |x acceleration| of the two centre bodies, differenced from
                       timeseries.csv's velocities at the model's output interval and filtered by
                       SAE J211-1's CFC 60 (two-pass second-order Butterworth, written out below)
  event timing         |t - t_ref| of the first occurrence of each (element, event) in events.csv
                       that both runs have, median and largest; absolute, in ms

Relative errors |q - q_ref| / |q_ref| for the first four.
"""
import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile

from compare_commit import MODEL, ROOT, accepts, build_commit

CAR_BODIES = ("car1_center_body", "car2_center_body")


def cfc_filter(samples, interval, cfc=60.0):
    """SAE J211-1 (1995) appendix C: second-order Butterworth run forward, then backward."""
    wd = 2.0 * math.pi * cfc * 2.0775
    wa = math.tan(wd * interval / 2.0)
    denominator = 1.0 + math.sqrt(2.0) * wa + wa * wa
    a0 = wa * wa / denominator
    a1, a2 = 2.0 * a0, a0
    b1 = -2.0 * (wa * wa - 1.0) / denominator
    b2 = (-1.0 + math.sqrt(2.0) * wa - wa * wa) / denominator

    def one_pass(x):
        y = list(x[:2])
        for i in range(2, len(x)):
            y.append(a0 * x[i] + a1 * x[i - 1] + a2 * x[i - 2] + b1 * y[i - 1] + b2 * y[i - 2])
        return y

    return one_pass(one_pass(samples)[::-1])[::-1]


def quantities(out):
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(out, "timeseries.csv")) as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    times = [float(r[0]) for r in rows[1:]]
    interval = times[1] - times[0]
    body_peak = 0.0
    for body in CAR_BODIES:
        k = rows[0].index(body + ".vx")
        velocity = [float(r[k]) for r in rows[1:]]
        acceleration = [(b - a) / interval for a, b in zip(velocity, velocity[1:])]
        body_peak = max(body_peak, max(abs(a) for a in cfc_filter(acceleration, interval)))
    first = {}
    with open(os.path.join(out, "events.csv")) as f:
        for event in csv.DictReader(line for line in f if not line.startswith("#")):
            first.setdefault((event["element"], event["event"]), float(event["t"]))
    def row_peak(column):
        k = rows[0].index(column)
        return max(abs(float(r[k])) for r in rows[1:])

    return {"max crush": row_peak("anticlimber.horizontal_deformation"),
            "peak coupler force": row_peak("coupler_faces.normal_force"),
            "R2": row_peak("anticlimber.vertical_force"),
            "CFC-60 car body": body_peak,
            "events": first,
            "steps": summary["stats"]["steps"]}


def run(executable, model, rtol, t_end, out):
    subprocess.run([executable, "run", model, "--integrator", "ida", "--rtol", rtol, "--t-end", str(t_end), "--out", out],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return quantities(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("commit", nargs="?", default="cbce2b9")
    parser.add_argument("--rtols", default="1e-3,1e-4")
    parser.add_argument("--reference-rtol", default="1e-7")
    parser.add_argument("--scratch", default=tempfile.gettempdir())
    parser.add_argument("--t-end", type=float, default=0.25)
    args = parser.parse_args()

    new_executable = os.path.join(ROOT, "build", "railcrash")
    old_source, old_executable = build_commit(args.commit, args.scratch)
    model = os.path.join(ROOT, MODEL)
    if not accepts(old_executable, model):
        model = os.path.join(old_source, MODEL)
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    work = tempfile.mkdtemp(prefix="railcrash-accuracy-")
    executables = {"old": old_executable, "new": new_executable}
    labels = {"old": f"old ({args.commit})", "new": f"new ({head})"}
    references = {which: run(executables[which], model, args.reference_rtol, args.t_end, os.path.join(work, "reference_" + which))
                  for which in ("old", "new")}
    names = ["max crush", "peak coupler force", "R2", "CFC-60 car body"]
    print(f"{model}, {args.t_end} s, IDA; each executable against its own run at rtol {args.reference_rtol}")
    for which, reference in references.items():
        print(f"  {labels[which]} reference: " + ", ".join(f"{name} {reference[name]:.6g}" for name in names))
    print("\n| run | rtol | steps | " + " | ".join(names) + " | event timing, median / largest dt [ms] (events compared) |")
    print("|---|---|---|" + "---|" * (len(names) + 1))

    def row(label, rtol, q, reference):
        errors = [abs(q[name] - reference[name]) / abs(reference[name]) for name in names]
        common = [key for key in q["events"] if key in reference["events"]]
        timing = sorted(abs(q["events"][key] - reference["events"][key]) for key in common) or [float("nan")]
        print(f"| {label} | {rtol} | {q['steps']} | " + " | ".join(f"{e:.2e}" for e in errors) +
              f" | {1e3 * statistics.median(timing):.4f} / {1e3 * timing[-1]:.4f} ({len(common)}) |", flush=True)

    for rtol in args.rtols.split(","):
        for which in ("old", "new"):
            q = run(executables[which], model, rtol, args.t_end, os.path.join(work, f"{which}_{rtol}"))
            row(labels[which], rtol, q, references[which])
    row(f"old reference against new's", args.reference_rtol, references["old"], references["new"])
    print(f"\nruns' output in {work}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
