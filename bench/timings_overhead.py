#!/usr/bin/python3
"""What `railcrash run --timings` costs: each case with and without it, alternating, CPU of
the process (user + system), medians over the repeats (README.md, `--timings`). Usage: bench/timings_overhead.py [--executable build/railcrash] [--repeats 7]"""
import argparse
import pathlib
import statistics
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).parent))
from child_cpu import run_timed  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
CASES = [
    ("slider-crank, 10 s, rows every 1 ms", ["verification/cases/slider_crank.yaml", "--rtol", "1e-6", "--atol", "1e-7",
                                              "--output-interval", "1e-3"]),
    ("report two-car crash, 0.25 s", ["models/report/final_two_car.yaml"]),
]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executable", default=str(ROOT / "build/railcrash"))
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    print("| case | CPU s without | CPU s with --timings | ratio |\n|---|---|---|---|")
    with tempfile.TemporaryDirectory() as out:
        for name, case in CASES:
            times = {False: [], True: []}
            for _ in range(args.repeats):
                for timed in (False, True):
                    command = [args.executable, "run", str(ROOT / case[0]), *case[1:], "--out", out, "--quiet"]
                    cpu, _ = run_timed(command + (["--timings"] if timed else []))
                    times[timed].append(cpu)
            without, with_ = statistics.median(times[False]), statistics.median(times[True])
            print(f"| {name} | {without:.4f} | {with_:.4f} | {with_ / without:.3f} |", flush=True)


if __name__ == "__main__":
    main()
