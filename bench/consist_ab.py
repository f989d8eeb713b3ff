#!/usr/bin/env python3
"""A consist's cost against another build, interleaved, size by size and phase by phase.

    bench/consist_ab.py BASE [--executable build/railcrash] [--cars 10,20,50,100,200]
                        [--repeats 5] [--t-end 0.05]

BASE is a commit (built by compare_commit.py, railcrash only) or a railcrash executable. For
each size the report's two-car model is made into N + N coupled cars (`railcrash consist`),
then both builds run it with `--timings` (0.5 ms rows, as `railcrash_bench consist`), one
after the other, REPEATS times. Printed per size: the medians of each build's process CPU
and of its solver's wall time (the sum of the `--timings` phases: no model loading), the
median of the per-pair ratios of the latter (new / base: a pair runs seconds apart, so this
VM's slow and fast phases fall on both), and each phase's ratio of medians.

A single round of `bench/run.sh consist` scatters by +-0.1 in its fitted exponent on this VM
(bench/HISTORY.md); the ratio of two builds measured side by side does not. Its slope against
log N is the change of the exponent: printed last.
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile

from child_cpu import run_timed
from compare_commit import ROOT, build_commit

PHASES = ["other", "start", "residual", "jacobian", "linear_setup", "linear_solve", "step_sweep", "events", "restarts",
          "output"]


def slope(xs, ys):
    mx, my = statistics.fmean(xs), statistics.fmean(ys)
    return sum((a - mx) * (b - my) for a, b in zip(xs, ys)) / sum((a - mx) ** 2 for a in xs)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("base", help="a commit, or the path of another railcrash executable")
    parser.add_argument("--executable", default=os.path.join(ROOT, "build", "railcrash"))
    parser.add_argument("--cars", default="10,20,50,100,200")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--t-end", type=float, default=0.05)
    args = parser.parse_args()
    work = tempfile.mkdtemp(prefix="railcrash-consist-ab-")
    base = args.base if os.path.isfile(args.base) else build_commit(args.base, tempfile.gettempdir())[1]
    new = args.executable
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    print(f"consist A/B: new = {new} (tree at {head}), base = {base}; {args.repeats} interleaved pairs per size, "
          f"t_end {args.t_end} s; {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}\n")
    print("| cars per consist | base process CPU s | new process CPU s | base solver s | new solver s | "
          "new / base solver (median of pairs) | " + " | ".join(PHASES) + " |")
    print("|---" * (6 + len(PHASES)) + "|")
    sizes, ratios = [], []
    for cars in [int(c) for c in args.cars.split(",")]:
        model = os.path.join(work, f"consist{cars}.yaml")
        subprocess.run([new, "consist", os.path.join(ROOT, "models/report/final_two_car.yaml"), "--cars", str(cars),
                        "--out", model], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        cpu = {base: [], new: []}
        phases = {base: {p: [] for p in PHASES}, new: {p: [] for p in PHASES}}
        solver = {base: [], new: []}
        for _ in range(args.repeats):
            for exe in (base, new):
                out = os.path.join(work, "out")
                seconds, _ = run_timed([exe, "run", model, "--t-end", str(args.t_end), "--output-interval", "5e-4",
                                        "--timings", "--quiet", "--out", out])
                with open(os.path.join(out, "summary.json")) as f:
                    split = json.load(f)["stats"]["seconds"]
                cpu[exe].append(seconds)
                solver[exe].append(sum(split.values()))
                for p in PHASES:
                    phases[exe][p].append(split.get(p, 0.0))
        pair = statistics.median([b / a for a, b in zip(solver[base], solver[new])])
        sizes.append(cars)
        ratios.append(pair)
        cells = []
        for p in PHASES:
            a, b = statistics.median(phases[base][p]), statistics.median(phases[new][p])
            cells.append(f"{b / a:.2f}" if a > 0 else "-")
        print(f"| {cars} | {statistics.median(cpu[base]):.2f} | {statistics.median(cpu[new]):.2f} | "
              f"{statistics.median(solver[base]):.2f} | {statistics.median(solver[new]):.2f} | **{pair:.3f}** | "
              + " | ".join(cells) + " |", flush=True)
    if len(sizes) > 1:
        change = slope([math.log(n) for n in sizes], [math.log(r) for r in ratios])
        print(f"\nthe solver's cost exponent changes by {change:+.3f} (slope of log(new / base) against log N, "
              f"{sizes[0]} to {sizes[-1]} cars per consist)")


if __name__ == "__main__":
    sys.exit(main())
