#!/usr/bin/python3
"""IDA at each shipped model's own settings, with positions held relative (the default) and
absolute (simulation.position_tolerance; README "Position tolerances"): CPU and steps.

    /usr/bin/python3 bench/position_tolerance_cost.py [--executable build/railcrash] [--repeats 3]

Prints, per model, the least CPU (user + system) of --repeats runs and the steps under each
form, their ratio, and the totals.
"""
import argparse
import glob
import json
import os
import resource
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODELS = ["models/examples/*.yaml", "models/report/final_two_car*.yaml", "models/report/preliminary_car.yaml",
          "models/scenarios/*.yaml"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executable", default=os.path.join(ROOT, "build/railcrash"))
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    models = sorted(m for pattern in MODELS for m in glob.glob(os.path.join(ROOT, pattern)))
    totals = [0.0, 0.0]
    print("| model | relative: CPU s, steps | absolute: CPU s, steps | absolute / relative |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as scratch:
        out = os.path.join(scratch, "out")
        for model in models:
            row = []
            for extra in ([], ["--set", "simulation.position_tolerance=absolute"]):
                best = float("inf")
                for _ in range(args.repeats):
                    before = resource.getrusage(resource.RUSAGE_CHILDREN)
                    subprocess.run([args.executable, "run", model, "--integrator", "ida", "--out", out, "--quiet"] + extra,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
                    after = resource.getrusage(resource.RUSAGE_CHILDREN)
                    best = min(best, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
                with open(os.path.join(out, "summary.json")) as f:
                    summary = json.load(f)
                row.append((best, summary["stats"]["steps"], summary["status"]))
            totals[0] += row[0][0]
            totals[1] += row[1][0]
            ratio = row[1][0] / row[0][0] if row[0][0] > 0 else float("nan")
            print(f"| {os.path.relpath(model, ROOT)} | {row[0][0]:.3f}, {row[0][1]} ({row[0][2]}) | "
                  f"{row[1][0]:.3f}, {row[1][1]} ({row[1][2]}) | {ratio:.2f} |")
    print(f"\ntotal CPU: relative {totals[0]:.3f} s, absolute {totals[1]:.3f} s: {totals[1] / totals[0]:.2f}")


if __name__ == "__main__":
    main()
