#!/usr/bin/env python3
"""railcrash against Simbody 3.7 on the slider-crank, at equal accuracy, output included.

    bench/simbody/compare.py [--repeats 3] [--targets 1e-4,1e-6] [--intervals 0.4,0.001]

The mechanism is verification/cases/slider_crank.yaml (10 s); its Simbody twin is
bench/simbody/mechanisms.cpp (built here into build/bench-simbody when missing; needs
libsimbody-dev: scripts/install-deps.sh --bench). Each tool runs a ladder of tolerances
(railcrash IDA: --rtol R --atol R/10; Simbody Runge-Kutta-Merson: accuracy A), whole
processes timed by their CPU time (set-up, integration and the CSV output), medians of
REPEATS interleaved runs.

Error measure: the largest difference over the model's own output times (every 0.4 s) in
the crank angle [rad] or the slider position [m] (both of order 1), against a reference:
Simbody at accuracy 1e-12 (railcrash at rtol 1e-11 is printed against it, as a check of the
reference). For each target, each tool's cheapest setting whose error is within the target
(and every tighter setting's too) is compared. Run at the model's own output interval
(0.4 s) and at 1 ms (issue 14's other case: output-heavy).
"""
import argparse
import csv
import os
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))
from child_cpu import run_timed  # noqa: E402

MODEL = os.path.join(ROOT, "verification", "cases", "slider_crank.yaml")
T_END = 10.0
ERROR_GRID = 0.4  # [s] the model's own output interval: where errors are measured
LEVELS = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9]


def harness():
    build = os.path.join(ROOT, "build", "bench-simbody")
    executable = os.path.join(build, "simbody_mechanisms")
    if not os.path.exists(executable):
        subprocess.run(["cmake", "-S", HERE, "-B", build, "-DCMAKE_BUILD_TYPE=Release"], check=True, stdout=subprocess.DEVNULL)
        subprocess.run(["cmake", "--build", build], check=True, stdout=subprocess.DEVNULL)
    return executable


def on_grid(rows, time_key, columns):
    """{k: (values)} for the rows at t = k * ERROR_GRID."""
    samples = {}
    for row in rows:
        t = float(row[time_key])
        k = round(t / ERROR_GRID)
        if abs(t - k * ERROR_GRID) < 1e-9:
            samples[k] = tuple(float(row[c]) for c in columns)
    return samples


def railcrash_run(level, interval, work):
    out = os.path.join(work, "railcrash")
    cpu, _ = run_timed([os.path.join(ROOT, "build", "railcrash"), "run", MODEL, "--rtol", repr(level), "--atol",
                        repr(level / 10), "--output-interval", repr(interval), "--out", out, "--quiet"])
    with open(os.path.join(out, "timeseries.csv")) as f:
        return cpu, on_grid(csv.DictReader(f), "t", ["crank.theta", "rod.x"])


def simbody_run(executable, level, interval, work):
    out = os.path.join(work, "simbody.csv")
    cpu, _ = run_timed([executable, "slider_crank", "--accuracy", repr(level), "--t-end", repr(T_END),
                        "--output-interval", repr(interval), "--out", out])
    with open(out) as f:
        return cpu, on_grid(csv.DictReader(f), "t", ["crank.theta", "slider.x"])


def error(samples, reference):
    assert samples.keys() == reference.keys(), "output times differ from the reference's"
    return max(abs(a - b) for k in reference for a, b in zip(samples[k], reference[k]))


def cheapest_within(results, target):
    """(level, cpu, error) of the cheapest level whose error, and every tighter level's, is within target."""
    chosen = None
    for level in LEVELS:  # loosest first
        if all(results[tighter][1] <= target for tighter in LEVELS if tighter <= level):
            chosen = level
            break
    if chosen is None:
        return None
    return chosen, results[chosen][0], results[chosen][1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--targets", default="1e-4,1e-6")
    parser.add_argument("--intervals", default="0.4,0.001")
    args = parser.parse_args()
    targets = [float(x) for x in args.targets.split(",")]
    intervals = [float(x) for x in args.intervals.split(",")]
    executable = harness()
    work = tempfile.mkdtemp(prefix="railcrash-simbody-")
    _, reference = simbody_run(executable, 1e-12, ERROR_GRID, work)
    _, railcrash_tight = railcrash_run(1e-11, ERROR_GRID, work)
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    print(f"slider-crank ({os.path.relpath(MODEL, ROOT)}, {T_END} s), railcrash {head} against Simbody 3.7 "
          f"(Runge-Kutta-Merson); median CPU s of {args.repeats} interleaved runs per setting, output included; "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
    print(f"reference: Simbody at accuracy 1e-12; railcrash at rtol 1e-11 differs from it by {error(railcrash_tight, reference):.1e}")
    for interval in intervals:
        results = {"railcrash": {}, "simbody": {}}
        for level in LEVELS:
            times = {"railcrash": [], "simbody": []}
            samples = {}
            for _ in range(args.repeats):
                cpu, samples["railcrash"] = railcrash_run(level, interval, work)
                times["railcrash"].append(cpu)
                cpu, samples["simbody"] = simbody_run(executable, level, interval, work)
                times["simbody"].append(cpu)
            for tool in results:
                results[tool][level] = (statistics.median(times[tool]), error(samples[tool], reference))
        print(f"\noutput every {interval} s ({round(T_END / interval)} rows)\n")
        print("| tolerance | railcrash CPU s | railcrash error | Simbody CPU s | Simbody error |\n|---|---|---|---|---|")
        for level in LEVELS:
            r, s = results["railcrash"][level], results["simbody"][level]
            print(f"| {level:g} | {r[0]:.4f} | {r[1]:.1e} | {s[0]:.4f} | {s[1]:.1e} |")
        print("\n| error target | railcrash (rtol, CPU s) | Simbody (accuracy, CPU s) | railcrash / Simbody |\n|---|---|---|---|")
        for target in targets:
            r, s = cheapest_within(results["railcrash"], target), cheapest_within(results["simbody"], target)
            if r and s:
                print(f"| {target:g} | {r[0]:g}, {r[1]:.4f} | {s[0]:g}, {s[1]:.4f} | **{r[1] / s[1]:.2f}** |")
            else:
                print(f"| {target:g} | {'%g, %.4f' % r[:2] if r else 'not reached'} | {'%g, %.4f' % s[:2] if s else 'not reached'} | |")
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
