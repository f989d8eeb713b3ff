#!/usr/bin/env python3
"""Share of a run's CPU that goes to output rows (issue 14: "output <= 10 % of a run at 1 ms output").

    bench/output_share.py [--repeats 7] [--executable build/railcrash]

The two mechanisms of bench/simbody/compare.py at their models' tolerances (slider-crank
10 s, Andrews' squeezer 0.03 s), each run twice with every file written: with dense output
(slider-crank every 1 ms, 10,000 rows; Andrews every 10 us, 3,000 rows) and with output only
at t_end (one row). CPU of the whole process (start-up, run, files), medians of REPEATS
interleaved pairs. Output share = (dense - end) / dense; per row = (dense - end) / rows.
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


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--executable", default=os.path.join(ROOT, "build", "railcrash"))
    args = parser.parse_args()
    work = tempfile.mkdtemp(prefix="railcrash-output-share-")
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    print(f"railcrash {head} ({args.executable}); median CPU s of {args.repeats} interleaved pairs; "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}\n")
    print("| model | rows | CPU s, dense output | CPU s, output at t_end | output share | per row [us] |\n|---|---|---|---|---|---|")
    for model, t_end, dense, rtol, atol in CASES:
        times = {dense: [], t_end: []}
        for _ in range(args.repeats):
            for interval in times:
                cpu, _ = run_timed([args.executable, "run", os.path.join(ROOT, model), "--rtol", repr(rtol), "--atol", repr(atol),
                                    "--output-interval", repr(interval), "--out", os.path.join(work, "out"), "--quiet"])
                times[interval].append(cpu)
        rows = round(t_end / dense)
        with_rows, without = statistics.median(times[dense]), statistics.median(times[t_end])
        print(f"| {model} (every {dense:g} s) | {rows} | {with_rows:.4f} | {without:.4f} | "
              f"{100 * (with_rows - without) / with_rows:.0f} % | {1e6 * (with_rows - without) / rows:.1f} |")
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
