#!/usr/bin/env python3
"""railcrash against Simbody 3.7 on the slider-crank and Andrews' squeezer, at equal accuracy, output included.

    bench/simbody/compare.py [--repeats 3] [--targets 1e-4,1e-6] [--mechanisms slider_crank,andrews_squeezer]
                             [--executable build/railcrash]

The mechanisms are verification/cases/slider_crank.yaml (10 s) and
verification/cases/andrews_squeezer.yaml (0.03 s); their Simbody twins are in
bench/simbody/mechanisms.cpp (built here into build/bench-simbody when missing; needs
libsimbody-dev: scripts/install-deps.sh --bench). Each tool runs a ladder of tolerances
(railcrash IDA: --rtol R --atol R times the model file's atol/rtol; Simbody Runge-Kutta-Merson: accuracy A), whole
processes timed by their CPU time (set-up, integration and the CSV output), medians of
REPEATS interleaved runs (each repeat runs every level of both tools in turn).

Error measure: the largest difference over the model's own output times (slider-crank:
every 0.4 s, crank angle [rad] and slider position [m], both of order 1; Andrews: every
1 ms, the crank, rod and lever angles [rad]), against a reference: Simbody at accuracy
1e-12 (railcrash at rtol 1e-10 is printed against it, as a check of the reference). For
each target, each tool's cheapest setting whose error is within the target (and every
tighter setting's too) is compared. Run at the model's own output interval and at one 400
(slider-crank: 1 ms) or 100 (Andrews: 10 us) times denser: output-heavy.
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

# name: (model file, t_end [s], the model's output interval [s] = the error grid, a dense
# output interval [s], railcrash's columns, Simbody's columns (the same quantities),
# railcrash's atol / rtol (the model file's own ratio: atol is on lengths))
MECHANISMS = {
    "slider_crank": (os.path.join(ROOT, "verification", "cases", "slider_crank.yaml"), 10.0, 0.4, 0.001,
                     ["crank.theta", "rod.x"], ["crank.theta", "slider.x"], 0.1),
    "andrews_squeezer": (os.path.join(ROOT, "verification", "cases", "andrews_squeezer.yaml"), 0.03, 1e-3, 1e-5,
                         ["crank.theta", "rod.theta", "lever.theta"], ["crank.theta", "rod.theta", "lever.theta"], 1e-3),
}
RAILCRASH = [os.path.join(ROOT, "build", "railcrash")]  # --executable
LEVELS = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]


def harness():
    build = os.path.join(ROOT, "build", "bench-simbody")
    executable = os.path.join(build, "simbody_mechanisms")
    if not os.path.exists(executable):
        subprocess.run(["cmake", "-S", HERE, "-B", build, "-DCMAKE_BUILD_TYPE=Release"], check=True, stdout=subprocess.DEVNULL)
        subprocess.run(["cmake", "--build", build], check=True, stdout=subprocess.DEVNULL)
    return executable


def on_grid(rows, time_key, columns, grid):
    """{k: (values)} for the rows at t = k * grid."""
    samples = {}
    for row in rows:
        t = float(row[time_key])
        k = round(t / grid)
        if abs(t - k * grid) < 1e-9 * max(1.0, grid):
            samples[k] = tuple(float(row[c]) for c in columns)
    return samples


def railcrash_run(mechanism, level, interval, work):
    model, _, grid, _, columns, _, atol_ratio = MECHANISMS[mechanism]
    out = os.path.join(work, "railcrash")
    cpu, _ = run_timed([RAILCRASH[0], "run", model, "--rtol", repr(level), "--atol",
                        repr(level * atol_ratio), "--output-interval", repr(interval), "--out", out, "--quiet"])
    with open(os.path.join(out, "timeseries.csv")) as f:  # (its first line: the run's provenance)
        return cpu, on_grid(csv.DictReader(line for line in f if not line.startswith("#")), "t", columns, grid)


def simbody_run(executable, mechanism, level, interval, work):
    _, t_end, grid, _, _, columns, _ = MECHANISMS[mechanism]
    out = os.path.join(work, "simbody.csv")
    cpu, _ = run_timed([executable, mechanism, "--accuracy", repr(level), "--t-end", repr(t_end),
                        "--output-interval", repr(interval), "--out", out])
    with open(out) as f:
        return cpu, on_grid(csv.DictReader(f), "t", columns, grid)


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


def compare(mechanism, executable, args, targets, work):
    model, t_end, grid, dense, _, _, _ = MECHANISMS[mechanism]
    _, reference = simbody_run(executable, mechanism, 1e-12, grid, work)
    _, railcrash_tight = railcrash_run(mechanism, 1e-10, grid, work)
    print(f"\n## {mechanism} ({os.path.relpath(model, ROOT)}, {t_end} s)\n")
    print(f"reference: Simbody at accuracy 1e-12; railcrash at rtol 1e-10 differs from it by "
          f"{error(railcrash_tight, reference):.1e}")
    for interval in (grid, dense):
        # Every repeat runs every level of both tools, so that the settings a target pairs (two
        # different levels) are timed over the same stretch of the machine's load.
        times = {tool: {level: [] for level in LEVELS} for tool in ("railcrash", "simbody")}
        samples = {tool: {} for tool in times}
        for _ in range(args.repeats):
            for level in LEVELS:
                cpu, samples["railcrash"][level] = railcrash_run(mechanism, level, interval, work)
                times["railcrash"][level].append(cpu)
                cpu, samples["simbody"][level] = simbody_run(executable, mechanism, level, interval, work)
                times["simbody"][level].append(cpu)
        results = {tool: {level: (statistics.median(times[tool][level]), error(samples[tool][level], reference))
                          for level in LEVELS} for tool in times}
        print(f"\noutput every {interval} s ({round(t_end / interval)} rows)\n")
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


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--targets", default="1e-4,1e-6")
    parser.add_argument("--mechanisms", default=",".join(MECHANISMS))
    parser.add_argument("--executable", default=RAILCRASH[0], help="the railcrash to run (another build's, say)")
    args = parser.parse_args()
    RAILCRASH[0] = os.path.abspath(args.executable)
    targets = [float(x) for x in args.targets.split(",")]
    executable = harness()
    work = tempfile.mkdtemp(prefix="railcrash-simbody-")
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    print(f"railcrash {head} ({RAILCRASH[0]}) against Simbody 3.7 (Runge-Kutta-Merson); median CPU s of {args.repeats} interleaved runs "
          f"per setting, output included; {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
    for mechanism in args.mechanisms.split(","):
        compare(mechanism, executable, args, targets, work)
    return 0


if __name__ == "__main__":
    sys.exit(main())
