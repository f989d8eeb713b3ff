#!/usr/bin/env python3
"""Share of a run's CPU that goes to output rows (issue 14: "output <= 10 % of a run at 1 ms output").

    bench/output_share.py [--repeats 7] [--executable build/railcrash] [--base OTHER_RAILCRASH] [--format csv|hdf5]
                          [--cases mechanisms|crash|all]

The two mechanisms of bench/simbody/compare.py at their models' tolerances (slider-crank
10 s, Andrews' squeezer 0.03 s), each run twice with every file written: with dense output
(slider-crank every 1 ms, 10,000 rows; Andrews every 10 us, 3,000 rows) and with output only
at t_end (one row). CPU of the whole process (start-up, run, files), medians of REPEATS
interleaved pairs. Output share = (dense - end) / dense of the medians; per row = (dense - end)
/ rows. "Pairwise" is the median over the REPEATS pairs of each pair's own share, (dense - end)
/ dense of one dense run and the end run right after it: a run disturbed by other work moves
one pair's share, not the medians' balance (steadier when the VM's speed changes mid-run).
With --base (another build, e.g. of an older commit), its runs alternate with the
executable's (dense and end of one, then of the other, REPEATS times) and both are printed:
an A/B comparison in one run, with the same load on both. --format hdf5: the runs write
timeseries.h5 in place of the four CSV files (railcrash run --format).

--cases crash runs the two crash models instead, at their own rtol (1e-5) with 1 ms rows
(the report's two-car crash over its 0.25 s, 250 rows; the barrier test over its 0.8 s,
800 rows): what an output row costs in the runs railcrash is for. --cases all runs both sets.
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from child_cpu import run_timed  # noqa: E402

# model, t_end [s], dense output interval [s], rtol, atol (the model files' own)
CASES = [
    ("verification/cases/slider_crank.yaml", 10.0, 1e-3, 1e-6, 1e-7),
    ("verification/cases/andrews_squeezer.yaml", 0.03, 1e-5, 1e-6, 1e-9),
]
# the crash models at their own tolerances (no atol given: the run's scaled default)
CRASH_CASES = [
    ("models/report/final_two_car.yaml", 0.25, 1e-3, 1e-5, None),
    ("models/barrier/two_car_barrier.yaml", 0.8, 1e-3, 1e-5, None),
]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--executable", default=os.path.join(ROOT, "build", "railcrash"))
    parser.add_argument("--base", help="a second railcrash executable, run interleaved with --executable")
    parser.add_argument("--format", choices=["csv", "hdf5"], default="csv", help="railcrash run --format")
    parser.add_argument("--cases", choices=["mechanisms", "crash", "all"], default="mechanisms")
    args = parser.parse_args()
    cases = {"mechanisms": CASES, "crash": CRASH_CASES, "all": CASES + CRASH_CASES}[args.cases]
    work = tempfile.mkdtemp(prefix="railcrash-output-share-")
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    executables = [args.executable] + ([args.base] if args.base else [])
    print(f"railcrash {head} ({args.executable}{'; base ' + args.base if args.base else ''}); --format {args.format}; median CPU s of "
          f"{args.repeats} interleaved pairs; {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}\n")
    print("| model | executable | rows | CPU s, dense output | CPU s, output at t_end | output share | pairwise | per row [us] |\n"
          "|---|---|---|---|---|---|---|---|")
    for model, t_end, dense, rtol, atol in cases:
        times = {(exe, interval): [] for exe in executables for interval in (dense, t_end)}
        for _ in range(args.repeats):
            for exe, interval in times:
                tolerances = ["--rtol", repr(rtol)] + (["--atol", repr(atol)] if atol is not None else [])
                cpu, _ = run_timed([exe, "run", os.path.join(ROOT, model)] + tolerances + [
                                    "--output-interval", repr(interval), "--out", os.path.join(work, "out"), "--format", args.format, "--quiet"])
                times[(exe, interval)].append(cpu)
        rows = round(t_end / dense)
        for exe in executables:
            with_rows, without = statistics.median(times[(exe, dense)]), statistics.median(times[(exe, t_end)])
            pairwise = statistics.median((d - e) / d for d, e in zip(times[(exe, dense)], times[(exe, t_end)]))
            label = "base" if exe == args.base else "executable"
            print(f"| {model} (every {dense:g} s) | {label} | {rows} | {with_rows:.4f} | {without:.4f} | "
                  f"{100 * (with_rows - without) / with_rows:.1f} % | {100 * pairwise:.1f} % | "
                  f"{1e6 * (with_rows - without) / rows:.1f} |")
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
