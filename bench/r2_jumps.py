#!/usr/bin/python3
"""Why R2's error jumps between tolerances on the report's two-car model (issue 14, item 3).

Runs models/report/final_two_car.yaml with IDA at a ladder of rtol values and at a reference
rtol, every run with 10 us output, and prints per run: R2 and its error against the reference,
the time of the largest vertical anticlimber force (the R2 peak), the first time the vertical
anticlimber force departs from the reference's by 100 lbf, and how many kink crossings of the
rail hangers (compression <-> extension, events.csv) the run and the reference have before
that time; plus the hangers' deformation range and crossing rates in the reference.

Usage, from the repository root (about 1 minute):
  /usr/bin/python3 bench/r2_jumps.py [--executable build/railcrash] [--rtols 1e-3,...]
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile

MODEL = "models/report/final_two_car.yaml"
FORCE = "anticlimber.vertical_force"
HANGERS = ("car1_rail_hanger", "car2_rail_hanger")


def run(executable, rtol, out):
    subprocess.run([executable, "run", MODEL, "--rtol", rtol, "--output-interval", "1e-5", "--out", out, "--quiet"],
                   check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(out, "timeseries.csv")) as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    column = rows[0].index(FORCE)
    force = [(float(r[0]), float(r[column])) for r in rows[1:]]
    with open(os.path.join(out, "events.csv")) as f:
        crossings = [(float(e["t"]), e["element"], e["event"]) for e in csv.DictReader(line for line in f if not line.startswith("#")) if e["element"] in HANGERS]
    return summary["responses"]["R2"], force, crossings, rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--executable", default="build/railcrash")
    parser.add_argument("--rtols", default="1e-3,5e-4,2e-4,1e-4,5e-5,2e-5,1e-5,5e-6,2e-6,1e-6")
    parser.add_argument("--reference-rtol", default="1e-9")
    args = parser.parse_args()
    work = tempfile.mkdtemp(prefix="railcrash-r2-")
    r2_ref, force_ref, crossings_ref, rows_ref = run(args.executable, args.reference_rtol, os.path.join(work, "reference"))
    peak_ref = max(force_ref, key=lambda p: abs(p[1]))
    print(f"{MODEL}, IDA; reference rtol {args.reference_rtol}: R2 {r2_ref:.6f}, peak {peak_ref[1]:.0f} lbf "
          f"at t = {peak_ref[0]:.5f} s; {len(crossings_ref)} rail-hanger kink crossings")
    header = rows_ref[0]
    for hanger in HANGERS:
        k = header.index(hanger + ".deformation")
        series = [(float(r[0]), float(r[k])) for r in rows_ref[1:]]
        window = [s for s in series if 0.06 < s[0] < peak_ref[0]]
        rates = [abs((b[1] - a[1]) / (b[0] - a[0])) for a, b in zip(window, window[1:]) if (a[1] < 0.0) != (b[1] < 0.0)]
        print(f"  {hanger}: deformation {min(s[1] for s in window):.4f} to {max(s[1] for s in window):.4f} in "
              f"over 0.06 s to the peak; {len(rates)} sign changes at {min(rates):.0f}-{max(rates):.0f} in/s")
    print("\n| rtol | R2 | R2 error | peak at [s] | force 100 lbf off from [s] | hanger kink crossings before it, ref / run |")
    print("|---|---|---|---|---|---|")
    for rtol in args.rtols.split(","):
        r2, force, crossings, _ = run(args.executable, rtol, os.path.join(work, rtol))
        peak = max(force, key=lambda p: abs(p[1]))
        departs = next((t for (t, a), (_, b) in zip(force_ref, force) if abs(a - b) > 100.0), None)
        limit = departs if departs is not None else peak[0]
        before_ref = [c for c in crossings_ref if c[0] < limit]
        before = [c for c in crossings if c[0] < limit]
        departs_text = f"{departs:.5f}" if departs is not None else "never"
        print(f"| {rtol} | {r2:.6f} | {abs(r2 / r2_ref - 1):.1e} | {peak[0]:.5f} | {departs_text} | "
              f"{len(before_ref)} / {len(before)} |", flush=True)
    print(f"\nruns in {work}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
