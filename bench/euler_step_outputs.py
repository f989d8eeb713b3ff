#!/usr/bin/env python3
"""What Euler's per-step output evaluation costs, with and without a result writer (issue 37 item 6).

    bench/euler_step_outputs.py --base OTHER_RAILCRASH [--executable build/railcrash] [--repeats 5]

The report's two-car crash (models/report/final_two_car.yaml) under explicit Euler at its dt
1e-6 s (250,000 steps over its 0.25 s), two ways, each with the executable and the base
interleaved (CPU of the process, user + system, medians of REPEATS):

  run          `railcrash run --integrator euler`: the result writer takes every output
               column's per-step extremes (summary.json's peaks), so every element's outputs
               are evaluated at every step.
  sensitivity  `railcrash sensitivity --only P1 --first-order` on a copy of the model with
               `integrator: euler` (two runs, no result writer): only the response tracker
               reads outputs per step, the anticlimber's; since issue 37 item 6 the other
               elements' outputs are evaluated at the output rows alone.

Prints the medians, the executable's change against the base, and whether the two builds'
sensitivity.csv R1-R3 columns (and run's summary.json peaks) are the same. --callgrind: counts
the instructions each case executes instead (valgrind --tool=callgrind, once per build: the same
count on every run, whatever the load on the machine; about 80x slower than a run).
"""
import argparse
import csv
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from child_cpu import run_timed  # noqa: E402

MODEL = os.path.join(ROOT, "models", "report", "final_two_car.yaml")
DESIGN = os.path.join(ROOT, "models", "report", "sensitivity_design.yaml")


def responses(folder):
    with open(os.path.join(folder, "sensitivity.csv"), newline="") as f:
        return [(row["run"], row["R1"], row["R2"], row["R3"]) for row in csv.DictReader(f)]


def peaks(folder):
    with open(os.path.join(folder, "summary.json")) as f:
        return json.load(f)["peaks"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--executable", default=os.path.join(ROOT, "build", "railcrash"))
    parser.add_argument("--base", required=True, help="a second railcrash executable, run interleaved with --executable")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--callgrind", action="store_true", help="instructions executed (valgrind) in place of CPU time")
    args = parser.parse_args()
    work = tempfile.mkdtemp(prefix="railcrash-euler-step-outputs-")
    euler_model = os.path.join(work, "final_two_car.yaml")
    with open(MODEL) as source, open(euler_model, "w") as copy:
        text = source.read()
        if "\n  integrator: ida\n" not in text:
            sys.exit(f"{MODEL}: no 'integrator: ida' line under simulation to replace")
        copy.write(text.replace("\n  integrator: ida\n", "\n  integrator: euler\n"))
    shutil.copy(DESIGN, os.path.join(work, "sensitivity_design.yaml"))
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    measure = "instructions (valgrind callgrind, millions)" if args.callgrind else f"median CPU s of {args.repeats} interleaved runs"
    print(f"railcrash {head} ({args.executable}; base {args.base}); {measure}; "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}\n")
    cases = {
        "run": lambda exe, out: [exe, "run", MODEL, "--integrator", "euler", "--out", out, "--quiet"],
        "sensitivity": lambda exe, out: [exe, "sensitivity", euler_model, "--only", "P1", "--first-order", "--jobs", "1",
                                         "--bisect", "0", "--out", out],
    }
    unit = "instructions, M" if args.callgrind else "CPU s"
    print(f"| case | base {unit} | executable {unit} | change | results |\n|---|---|---|---|---|")
    for case, command in cases.items():
        times = {args.executable: [], args.base: []}
        for _ in range(1 if args.callgrind else args.repeats):
            for exe in times:
                out = os.path.join(work, case + ("_base" if exe == args.base else "_exe"))
                if args.callgrind:
                    finished = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=" + os.devnull] + command(exe, out),
                                              capture_output=True, text=True, check=True)
                    times[exe].append(int(re.search(r"Collected : (\d+)", finished.stderr).group(1)) / 1e6)
                else:
                    cpu, _ = run_timed(command(exe, out))
                    times[exe].append(cpu)
        read = responses if case == "sensitivity" else peaks
        same = read(os.path.join(work, case + "_exe")) == read(os.path.join(work, case + "_base"))
        base, exe = statistics.median(times[args.base]), statistics.median(times[args.executable])
        what = "R1-R3" if case == "sensitivity" else "peaks"
        digits = 0 if args.callgrind else 3
        print(f"| {case} | {base:.{digits}f} | {exe:.{digits}f} | {100 * (exe - base) / base:+.1f} % | {what} {'same' if same else 'DIFFER'} |")
        sys.stdout.flush()
    shutil.rmtree(work)


if __name__ == "__main__":
    main()
