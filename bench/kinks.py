#!/usr/bin/python3
"""IDA's counts and CPU on the crash models for one or more builds (issue 37, "Kinks are not jumps").

    /usr/bin/python3 bench/kinks.py [--executables build/railcrash,OLD/railcrash] [--rtols 1e-5]
                                    [--repeats 3] [--consist-cars 10]

For each model (the report's two-car crash, the barrier test, models/examples/mu_3plus3_si.yaml
and a consist of --consist-cars + --consist-cars cars built from the two-car crash, run to
0.05 s) and rtol, each executable runs it REPEATS times, interleaved; printed: the median CPU
of the run's process (user + system), IDA's steps, residual and Jacobian evaluations, events,
restarts (reinitializations) and the largest car crush, from summary.json.
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(executable, model, rtol, extra, out):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([executable, "run", model, "--rtol", rtol, "--out", out, "--quiet"] + extra, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executables", default="build/railcrash")
    parser.add_argument("--rtols", default="1e-5")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--consist-cars", type=int, default=10)
    args = parser.parse_args()
    executables = args.executables.split(",")
    with tempfile.TemporaryDirectory() as scratch:
        consist = os.path.join(scratch, "consist.yaml")
        subprocess.run([executables[0], "consist", os.path.join(ROOT, "models/report/final_two_car.yaml"),
                        "--cars", str(args.consist_cars), "--out", consist], check=True, stdout=subprocess.DEVNULL)
        models = [("two-car crash", os.path.join(ROOT, "models/report/final_two_car.yaml"), []),
                  ("barrier test", os.path.join(ROOT, "models/barrier/two_car_barrier.yaml"), []),
                  ("mu_3plus3_si", os.path.join(ROOT, "models/examples/mu_3plus3_si.yaml"), []),
                  (f"{args.consist_cars} + {args.consist_cars} cars, 0.05 s", consist, ["--t-end", "0.05"])]
        print("| model | rtol | executable | CPU s (median) | steps | residuals | Jacobians | events | restarts | max car crush |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for name, model, extra in models:
            for rtol in args.rtols.split(","):
                cpu = {e: [] for e in executables}
                for _ in range(args.repeats):
                    for e in executables:
                        cpu[e].append(run(e, model, rtol, extra, os.path.join(scratch, "out")))
                for e in executables:
                    run(e, model, rtol, extra, os.path.join(scratch, "out"))
                    summary = json.load(open(os.path.join(scratch, "out", "summary.json")))
                    s = summary["stats"]
                    crush = max((c.get("max_crush", 0.0) for c in summary.get("car_crush", {}).values()), default=float("nan"))
                    print(f"| {name} | {rtol} | {e} | {statistics.median(cpu[e]):.3f} | {s['steps']} | "
                          f"{s['residual_evaluations']} | {s['jacobian_evaluations']} | {s['events']} | "
                          f"{s['reinitializations']} | {crush:.6g} |", flush=True)


if __name__ == "__main__":
    main()
