#!/usr/bin/python3
"""IDA's sparse LU ordering: the default (fewest_entries) against COLAMD alone, per model.

    /usr/bin/python3 bench/linear_ordering.py [--executable build/railcrash] [--models M1,M2]
                                              [--repeats 9] [--options "--rtol 1e-4 ..."]

Each model runs under IDA with `simulation.linear_ordering` fewest_entries and colamd in turn
(colamd, default, colamd, default, ...), REPEATS times each, with the model's own settings plus
OPTIONS. Prints per model: the ordering the default kept, each ordering's factor entries and
steps, the median CPU (user + system of the process) of each and the ratio default / colamd
with the range of the per-pair ratios, and the largest relative difference between the two
runs' car crushes (round-off: the ordering changes nothing else). README "Sparse LU ordering";
bench/HISTORY.md, "KLU's ordering chosen by fill".
"""
import argparse
import json
import os
import shlex
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_cpu import run_timed  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_MODELS = ["models/examples/mu_3plus3_si.yaml", "models/examples/emu3_unit_collision.yaml",
                  "models/examples/emu3_wall.yaml", "models/examples/emu3_wagon.yaml",
                  "models/examples/emu_two_car_crush_zones.yaml", "models/barrier/two_car_barrier.yaml",
                  "models/scenarios/scenario2_barrier_cars.yaml"]


def run(executable, model, ordering, options, out):
    command = [executable, "run", model, "--integrator", "ida", "--quiet", "--out", out,
               "--set", f"simulation.linear_ordering={ordering}"] + options
    cpu, _ = run_timed(command)
    with open(os.path.join(out, "summary.json")) as f:
        return cpu, json.load(f)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executable", default=os.path.join(ROOT, "build/railcrash"))
    parser.add_argument("--models", default=",".join(DEFAULT_MODELS))
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--options", default="", help="extra `railcrash run` options")
    args = parser.parse_args()
    options = shlex.split(args.options)
    print("| model | default keeps | factor entries default / COLAMD | steps default / COLAMD | "
          "CPU s default / COLAMD (medians) | ratio (pairs) | car crush, largest relative difference |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as scratch:
        for model in args.models.split(","):
            path = model if os.path.isabs(model) else os.path.join(ROOT, model)
            cpus = {"fewest_entries": [], "colamd": []}
            summaries = {}
            for _ in range(args.repeats):
                for ordering in ("colamd", "fewest_entries"):
                    out = os.path.join(scratch, ordering)
                    cpu, summaries[ordering] = run(args.executable, path, ordering, options, out)
                    cpus[ordering].append(cpu)
            new, old = summaries["fewest_entries"], summaries["colamd"]
            crush_new = {car: c["max_crush"] for car, c in new.get("car_crush", {}).items()}
            crush_old = {car: c["max_crush"] for car, c in old.get("car_crush", {}).items()}
            largest = max((crush_old[car] for car in crush_old), default=0.0)
            difference = max((abs(crush_new[car] - crush_old[car]) / largest for car in crush_old if largest > 0.0),
                             default=0.0)
            pairs = [n / o for n, o in zip(cpus["fewest_entries"], cpus["colamd"])]
            median_new, median_old = statistics.median(cpus["fewest_entries"]), statistics.median(cpus["colamd"])
            print(f"| {model} | {new['stats'].get('factor_ordering', '?')} | "
                  f"{new['stats'].get('factor_nonzeros')} / {old['stats'].get('factor_nonzeros')} | "
                  f"{new['stats']['steps']} / {old['stats']['steps']} | {median_new:.3f} / {median_old:.3f} | "
                  f"{median_new / median_old:.3f} ({min(pairs):.2f}-{max(pairs):.2f}) | {difference:.1e} |", flush=True)


if __name__ == "__main__":
    main()
