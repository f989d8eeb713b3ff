"""CSV against HDF5 output (`railcrash run --format csv|hdf5`): CPU and bytes written per case.

Each case runs with both formats, interleaved, REPEATS times; the medians of the CPU time
(user + system of the run's process, bench/child_cpu.py) and the per-row files' sizes are
printed, with the HDF5/CSV ratios. Cases:
  two-car  models/report/final_two_car.yaml to 0.25 s with 0.1 ms rows (2,501 rows x 390 columns)
  consist  a 20-car consist (`railcrash consist ... --cars 20`) to 0.05 s with 0.1 ms rows
Usage: bench/run.sh formats [--repeats N] (or /usr/bin/python3 bench/output_format.py BINARY COMMIT)."""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_cpu import run_timed  # noqa: E402

ROW_FILES = {"csv": ["timeseries.csv", "events.csv", "accelerations.csv", "energy.csv"], "hdf5": ["timeseries.h5"]}


def folder_bytes(folder, fmt):
    return sum(os.path.getsize(os.path.join(folder, name)) for name in ROW_FILES[fmt])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("binary")
    parser.add_argument("commit")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    source = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    two_car = os.path.join(source, "models/report/final_two_car.yaml")
    with tempfile.TemporaryDirectory() as work:
        consist = os.path.join(work, "consist20.yaml")
        subprocess.run([args.binary, "consist", two_car, "--cars", "20", "--out", consist], check=True,
                       stdout=subprocess.DEVNULL)
        cases = [("two-car, 0.25 s, 0.1 ms rows", [two_car, "--t-end", "0.25", "--output-interval", "1e-4"]),
                 ("20-car consist, 0.05 s, 0.1 ms rows", [consist, "--t-end", "0.05", "--output-interval", "1e-4"])]
        for title, run_args in cases:
            cpu = {"csv": [], "hdf5": []}
            size = {}
            for _ in range(args.repeats):
                for fmt in ("csv", "hdf5"):
                    out = os.path.join(work, fmt)
                    seconds, _ = run_timed([args.binary, "run", *run_args, "--format", fmt, "--out", out, "--quiet"])
                    cpu[fmt].append(seconds)
                    size[fmt] = folder_bytes(out, fmt)
            with open(os.path.join(work, "csv", "timeseries.csv")) as header:
                lines = [line for line in header if not line.startswith("#")]  # (the provenance line)
                columns, rows = lines[0].count(",") + 1, len(lines) - 1
            csv_cpu, hdf5_cpu = statistics.median(cpu["csv"]), statistics.median(cpu["hdf5"])
            print(f"{title}: {rows} rows x {columns} timeseries columns; median of {args.repeats} CPU [s]: "
                  f"csv {csv_cpu:.2f}, hdf5 {hdf5_cpu:.2f} (hdf5/csv {hdf5_cpu / csv_cpu:.2f}); per-row files [MB]: "
                  f"csv {size['csv'] / 1e6:.1f}, hdf5 {size['hdf5'] / 1e6:.1f} (hdf5/csv {size['hdf5'] / size['csv']:.2f}); "
                  f"commit {args.commit}, {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
