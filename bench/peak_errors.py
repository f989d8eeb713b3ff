#!/usr/bin/python3
"""Why a peak's error need not fall monotonically with rtol (issue 14, item 3).

Runs a model with IDA at a ladder of rtol values and at a reference rtol (as `railcrash
converge` does, with the model's own output interval unless --output-interval is given) and
prints, per element output column and rtol:
  * the peak's relative error: summary.json's peak (taken from every accepted step, both sides
    of every event and every output row) against the reference's;
  * the history's error: the largest and the RMS difference of the column over the output
    rows, over the reference's largest |value|;
  * the signed error of the column at the reference's peak row;
  * the steps of the run.
A history error that falls with rtol while the peak error does not means the peak error is a
cancellation (the signed global error passing near zero at the peak instant) or the sampling
of a smooth maximum by the steps (error about f''h^2/8 for steps of h), not a bifurcation.

Usage, from the repository root (about 1 minute per model):
  /usr/bin/python3 bench/peak_errors.py MODEL COLUMN[,COLUMN...] [--executable build/railcrash]
      [--rtols 1e-3,1e-4,1e-5,1e-6,1e-7] [--reference-rtol 1e-9] [--output-interval S]
"""
import argparse
import csv
import json
import os
import subprocess
import tempfile


def run(executable, model, rtol, interval, out):
    command = [executable, "run", model, "--rtol", rtol, "--out", out, "--quiet"]
    if interval:
        command += ["--output-interval", interval]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(out, "timeseries.csv")) as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    return summary, rows[0], rows[1:]


def column(header, rows, name):
    k = header.index(name)
    return [float(r[k]) for r in rows]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("model")
    parser.add_argument("columns", help="element output columns, e.g. coupler_faces.normal_force")
    parser.add_argument("--executable", default="build/railcrash")
    parser.add_argument("--rtols", default="1e-3,1e-4,1e-5,1e-6,1e-7")
    parser.add_argument("--reference-rtol", default="1e-9")
    parser.add_argument("--output-interval", default="", help="default: the model's own")
    args = parser.parse_args()
    work = tempfile.mkdtemp(prefix="railcrash-peaks-")
    runs = {}
    for rtol in [args.reference_rtol] + args.rtols.split(","):
        runs[rtol] = run(args.executable, args.model, rtol, args.output_interval, os.path.join(work, rtol))
    ref_summary, ref_header, ref_rows = runs[args.reference_rtol]
    ref_times = [float(r[0]) for r in ref_rows]
    interval = args.output_interval or "the model's"
    for name in args.columns.split(","):
        reference = column(ref_header, ref_rows, name)
        scale = max(abs(v) for v in reference)
        peak = largest_magnitude(ref_summary["peaks"][name])
        peak_row = min(range(len(ref_times)), key=lambda i: abs(ref_times[i] - peak["t"]))
        print(f"\n{args.model}: {name}; reference rtol {args.reference_rtol}: peak {peak['abs_max']:.9g} at "
              f"t = {peak['t']:.6f} s; output interval {interval}")
        print("| rtol | steps | peak error | peak at [s] | history error, largest | history error, RMS | "
              "signed error at the reference's peak row |")
        print("|---|---|---|---|---|---|---|")
        for rtol in args.rtols.split(","):
            summary, header, rows = runs[rtol]
            values = column(header, rows, name)
            n = min(len(values), len(reference))
            errors = [abs(values[i] - reference[i]) / scale for i in range(n)]
            p = largest_magnitude(summary["peaks"][name])
            print(f"| {rtol} | {summary['stats']['steps']} | "
                  f"{(p['abs_max'] - peak['abs_max']) / peak['abs_max']:.2e} | {p['t']:.6f} | {max(errors):.2e} | "
                  f"{(sum(e * e for e in errors) / n) ** 0.5:.2e} | {(values[peak_row] - reference[peak_row]) / scale:.2e} |")


def largest_magnitude(peak):
    """The larger |value| of summary.json's signed peaks {max, t_max, min, t_min}, and when."""
    if abs(peak["max"]) >= abs(peak["min"]):
        return {"abs_max": abs(peak["max"]), "t": peak["t_max"]}
    return {"abs_max": abs(peak["min"]), "t": peak["t_min"]}


if __name__ == "__main__":
    main()
