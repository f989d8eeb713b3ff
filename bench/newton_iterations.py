#!/usr/bin/env python3
"""IDA at loose tolerances on the models whose joints carry friction: which runs fail, where a
convergence failure raised IDA's Newton iterations per step, and how far each run's largest car
crush lies from the model's run at rtol 1e-7.

    /usr/bin/python3 bench/newton_iterations.py [--executable build/railcrash] [--base OTHER]

Each model runs under IDA at rtol 1e-2 ... 1e-4 with each KLU ordering (simulation:
linear_ordering amd and colamd), with the executable and, given --base, with another build.
A line per model and build gives the failures out of 20, the runs that raised the iterations,
and the largest relative crush error of the runs that finished (and of those that raised the
iterations) (bench/HISTORY.md, "Newton
iterations after a convergence failure").
"""
import argparse
import json
import os
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODELS = ["models/report/preliminary_car.yaml", "models/report/final_two_car.yaml",
          "models/scenarios/scenario1_report_car.yaml", "models/scenarios/scenario2_report_car.yaml",
          "models/scenarios/scenario1_barrier_cars.yaml"]
RTOLS = ["1e-2", "5e-3", "3e-3", "2e-3", "1e-3", "7e-4", "5e-4", "3e-4", "2e-4", "1e-4"]


def run(executable, model, out, options):
    summary = os.path.join(out, "summary.json")
    if os.path.exists(summary):
        os.remove(summary)  # (a run that writes none must not be read as the last one)
    subprocess.run([executable, "run", model, "--integrator", "ida", "--quiet", "--out", out] + options,
                   cwd=ROOT, capture_output=True, text=True)
    with open(summary) as f:
        return json.load(f)


def largest_crush(summary):
    return max((c["max_crush"] for c in summary.get("car_crush", {}).values()), default=0.0)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executable", default=os.path.join(ROOT, "build", "railcrash"))
    parser.add_argument("--base", help="another build to compare with")
    parser.add_argument("--models", default=",".join(MODELS))
    args = parser.parse_args()
    builds = [("this", args.executable)] + ([("base", args.base)] if args.base else [])
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "run")
        for model in args.models.split(","):
            reference = largest_crush(run(args.executable, model, out, ["--rtol", "1e-7"]))
            for label, executable in builds:
                failed, raised, worst, worst_raised = [], [], 0.0, 0.0
                for rtol in RTOLS:
                    for ordering in ("amd", "colamd"):
                        s = run(executable, model, out, ["--rtol", rtol, "--set", "simulation.linear_ordering=" + ordering])
                        if s["status"] != "ok":
                            failed.append(f"{rtol}/{ordering} ({s['message'][:60]}...)")
                            continue
                        error = abs(largest_crush(s) - reference) / reference
                        if s["stats"].get("newton_iterations_raised_at") is not None:
                            raised.append(f"{rtol}/{ordering} at {s['stats']['newton_iterations_raised_at']:.4g}")
                            worst_raised = max(worst_raised, error)
                        worst = max(worst, error)
                print(f"{model} [{label}]: {len(failed)} of {2 * len(RTOLS)} failed; iterations raised in {len(raised)}"
                      f"{': ' + ', '.join(raised) if raised else ''}; largest crush {reference:.6g} at rtol 1e-7, "
                      f"worst relative error of the others {worst:.2e}"
                      f"{f', of those that raised the iterations {worst_raised:.2e}' if raised else ''}", flush=True)
                for f in failed:
                    print(f"    failed {f}")


if __name__ == "__main__":
    main()
