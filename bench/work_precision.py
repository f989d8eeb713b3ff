#!/usr/bin/env python3
"""CPU at equal accuracy: the two-car crash's work-precision lines for this tree and an earlier commit.

    bench/work_precision.py [COMMIT] [--rtols 1e-3,...,1e-5] [--repeats 3] [--reference-rtol 1e-7]
                            [--executable E] [--t-end 0.25]

Issue 14's goal for the two-car crash is CPU "at equal accuracy in every engineering
quantity". Comparing two builds at one rtol each does not settle that: the same build's
errors scatter by up to 10x between neighbouring rtols (bench/HISTORY.md), and two builds
at the same rtol need not be equally accurate. Here both executables (this tree's
build/railcrash, or --executable, and COMMIT's, built by compare_commit.py) run the same
model (compare_commit.py's choice) at every rtol of a grid, interleaved, REPEATS times each;
a run's cost is its process's median CPU (user + system), its errors those of
compare_accuracy.py (max crush, peak coupler force, R2, CFC-60 car body) and two event times
(the struck car's draft-gear pin shear and the anticlimbers' first contact), each against the
same executable's own run at REFERENCE_RTOL.

For each quantity and build a straight line is fitted to log10(error) against log10(CPU)
over the grid (least squares): the build's work-precision line. The figure is the ratio of
the two lines' CPU at the same error, taken at the geometric mean of all the grid's errors
of that quantity (both builds): old CPU / new CPU, above 1 when the new build is cheaper.
The lines' slopes and their scatter (the root-mean-square distance of the points from the
line, in decades of error) are printed with it; where either line's error falls by less than
one decade per decade of CPU (R2 on this model: the rail hangers' bifurcation, bench/r2_jumps.py)
no ratio is read off it. The points themselves are printed too.

A second table reads the same runs as an engineer would: for an error target (1 % and 0.1 %)
and quantity, each build's cheapest rtol of the grid at which that rtol and every tighter one
meet the target (`railcrash converge`'s rule), and the ratio of their CPU. One unlucky point
at a loose rtol moves it (the rule is strict); a line does not.
"""
import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile

from child_cpu import run_timed
from compare_accuracy import quantities
from compare_commit import MODEL, ROOT, accepts, build_commit

NAMES = ["max crush", "peak coupler force", "R2", "CFC-60 car body", "pin shear time", "anticlimber contact time"]
# Event timing (issue 14's fifth quantity): the first occurrence of these (element, event) pairs
# in events.csv, as in the IDA-against-Euler table of bench/HISTORY.md (the struck car's
# draft-gear pin shear near 4.76 ms, the anticlimbers' first contact near 6.19 ms); relative
# errors over those times.
EVENTS = {"pin shear time": ("car2_draft_gear", "pin shear"), "anticlimber contact time": ("anticlimber", "contact")}


def with_events(found):
    """compare_accuracy's quantities with the event times of EVENTS added as quantities."""
    for name, key in EVENTS.items():
        found[name] = found["events"].get(key, math.nan)
    return found


DEFAULT_RTOLS = "1e-3,7e-4,5e-4,3e-4,2e-4,1e-4,7e-5,5e-5,3e-5,2e-5,1e-5"
# A line whose error falls by less than this many decades per decade of CPU says little about
# the cost of an error: a small shift of its points moves the cost read off it by decades.
FLATTEST_SLOPE = 1.0
# Error targets of the second table (issue 14's IDA-against-Euler table uses the same two).
TARGETS = [1e-2, 1e-3]


def run(executable, model, rtol, t_end, out):
    """CPU seconds of one run and its quantities."""
    usage = subprocess.run([executable, "run", "--help"], capture_output=True, text=True).stdout
    quiet = ["--quiet"] if "--quiet" in usage else []
    cpu, _ = run_timed([executable, "run", model, "--integrator", "ida", "--rtol", rtol, "--t-end", str(t_end),
                        "--out", out] + quiet)
    return cpu, with_events(quantities(out))


def fit(points):
    """Least-squares line log10(error) = a + b log10(cpu); returns (a, b, rms distance in decades)."""
    xs = [math.log10(c) for c, _ in points]
    ys = [math.log10(e) for _, e in points]
    mx, my = statistics.fmean(xs), statistics.fmean(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    a = my - b * mx
    rms = math.sqrt(statistics.fmean([(y - a - b * x) ** 2 for x, y in zip(xs, ys)]))
    return a, b, rms


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("commit", nargs="?", default="cbce2b9")
    parser.add_argument("--rtols", default=DEFAULT_RTOLS)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--reference-rtol", default="1e-7")
    parser.add_argument("--executable", default=os.path.join(ROOT, "build", "railcrash"))
    parser.add_argument("--scratch", default=tempfile.gettempdir())
    parser.add_argument("--t-end", type=float, default=0.25)
    args = parser.parse_args()

    old_source, old_executable = build_commit(args.commit, args.scratch)
    executables = {"old": old_executable, "new": args.executable}
    model = os.path.join(ROOT, MODEL)
    if not accepts(old_executable, model):
        model = os.path.join(old_source, MODEL)
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    labels = {"old": args.commit, "new": f"{head} ({args.executable})"}
    work = tempfile.mkdtemp(prefix="railcrash-work-precision-")
    rtols = args.rtols.split(",")

    references = {w: run(executables[w], model, args.reference_rtol, args.t_end, os.path.join(work, "reference_" + w))[1]
                  for w in executables}
    cpu = {(w, r): [] for w in executables for r in rtols}
    found = {}
    for repeat in range(args.repeats):
        for r in rtols:
            for w in ("old", "new"):
                seconds, q = run(executables[w], model, r, args.t_end, os.path.join(work, f"{w}_{r}"))
                cpu[(w, r)].append(seconds)
                found[(w, r)] = q

    def error(w, r, name):
        return abs(found[(w, r)][name] - references[w][name]) / abs(references[w][name])

    print(f"{model}, {args.t_end} s, IDA; each executable against its own run at rtol {args.reference_rtol}; "
          f"CPU: median of {args.repeats} interleaved runs")
    print(f"old: {labels['old']}   new: {labels['new']}\n")
    print("| rtol | build | CPU s | steps | " + " | ".join(NAMES) + " |")
    print("|---|---|---|---|" + "---|" * len(NAMES))
    for r in rtols:
        for w in ("old", "new"):
            print(f"| {r} | {w} | {statistics.median(cpu[(w, r)]):.3f} | {found[(w, r)]['steps']} | " +
                  " | ".join(f"{error(w, r, n):.2e}" for n in NAMES) + " |")

    print("\n| quantity | error where compared | old: slope, scatter [decades] | new: slope, scatter | "
          "old CPU / new CPU at that error |")
    print("|---|---|---|---|---|")
    for name in NAMES:
        lines = {}
        all_errors = []
        for w in ("old", "new"):
            points = [(statistics.median(cpu[(w, r)]), error(w, r, name)) for r in rtols if error(w, r, name) > 0.0]
            all_errors += [e for _, e in points]
            lines[w] = fit(points) if len(points) >= 3 else None
        if lines["old"] is None or lines["new"] is None or lines["old"][1] >= 0.0 or lines["new"][1] >= 0.0:
            print(f"| {name} | - | - | - | no falling line to compare |")
            continue
        if max(lines["old"][1], lines["new"][1]) > -FLATTEST_SLOPE:
            print(f"| {name} | - | {lines['old'][1]:.2f}, {lines['old'][2]:.2f} | {lines['new'][1]:.2f}, {lines['new'][2]:.2f} | "
                  f"a line too flat to read a cost off (error falls less than {FLATTEST_SLOPE:g} decades per decade of CPU) |")
            continue
        target = statistics.fmean([math.log10(e) for e in all_errors])
        cost = {w: 10.0 ** ((target - lines[w][0]) / lines[w][1]) for w in lines}
        print(f"| {name} | {10.0 ** target:.2e} | {lines['old'][1]:.2f}, {lines['old'][2]:.2f} | "
              f"{lines['new'][1]:.2f}, {lines['new'][2]:.2f} | **{cost['old'] / cost['new']:.2f}** |")

    # The engineer's reading: for an error target, the cheapest rtol of the grid at which this
    # and every tighter rtol of the grid meet it (converge's rule), and its CPU.
    print("\n| quantity | target | old: rtol, CPU s | new: rtol, CPU s | old CPU / new CPU |")
    print("|---|---|---|---|---|")
    loosest_first = sorted(rtols, key=float, reverse=True)
    for target in TARGETS:
        for name in NAMES:
            cheapest = {}
            for w in ("old", "new"):
                cheapest[w] = None
                for i, r in enumerate(loosest_first):
                    if all(error(w, tighter, name) <= target for tighter in loosest_first[i:]):
                        cheapest[w] = (r, statistics.median(cpu[(w, r)]))
                        break
            cells = [f"{c[0]}, {c[1]:.3f}" if c else "none in the grid" for c in (cheapest["old"], cheapest["new"])]
            ratio = f"**{cheapest['old'][1] / cheapest['new'][1]:.2f}**" if cheapest["old"] and cheapest["new"] else "-"
            print(f"| {name} | {target:g} | {cells[0]} | {cells[1]} | {ratio} |")
    print(f"\nruns' output in {work}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
