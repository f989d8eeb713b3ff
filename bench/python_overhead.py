#!/usr/bin/python3
"""Python module against the command line on the report's two-car crash (issue 15's goals:
a run through Python costs under 2 % more than through the CLI; loading the model and
starting a run from Python takes under 20 ms).

    PYTHONPATH=build/python bench/python_overhead.py [--repeats 5] [--model M]

Whole runs, alternated CLI / Python so that drifts of the machine's load hit both:
  CLI     build/railcrash run M --out TMP   (a process: start, load, run, CSV + summary.json)
  Python  railcrash.run(railcrash.load(M))   (in this process: load, run, results in memory)
Times: CPU of the process (children's rusage for the CLI, process_time for Python), which
other work on the machine inflates less than wall time, and wall time; medians. The
integration alone is summary.json's stats.wall_seconds in both.
Start-up: railcrash.load(M), then run(M, t_end=1e-5) (a reload, the DAE system, consistent
initial values, IDA's set-up and a first step), medians of 20.
"""

import argparse
import json
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import railcrash

ROOT = pathlib.Path(__file__).resolve().parents[1]


def children_cpu():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--model", default=str(ROOT / "models" / "report" / "final_two_car.yaml"))
    parser.add_argument("--cli", default=str(ROOT / "build" / "railcrash"))
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()

    cli = {"cpu": [], "wall": [], "integration": []}
    py = {"cpu": [], "wall": [], "integration": []}
    with tempfile.TemporaryDirectory() as out:
        for _ in range(args.repeats):
            cpu, wall = children_cpu(), time.perf_counter()
            subprocess.run([args.cli, "run", args.model, "--out", out], check=True, stdout=subprocess.DEVNULL)
            cli["wall"].append(time.perf_counter() - wall)
            cli["cpu"].append(children_cpu() - cpu)
            cli["integration"].append(json.loads(pathlib.Path(out, "summary.json").read_text())["stats"]["wall_seconds"])

            cpu, wall = time.process_time(), time.perf_counter()
            result = railcrash.run(railcrash.load(args.model))
            py["wall"].append(time.perf_counter() - wall)
            py["cpu"].append(time.process_time() - cpu)
            py["integration"].append(result.summary["stats"]["wall_seconds"])
            assert result.ok, result.message

    load = {"cpu": [], "wall": []}
    start = {"cpu": [], "wall": []}
    for _ in range(20):
        cpu, wall = time.process_time(), time.perf_counter()
        model = railcrash.load(args.model)
        load["wall"].append(time.perf_counter() - wall)
        load["cpu"].append(time.process_time() - cpu)
        cpu, wall = time.process_time(), time.perf_counter()
        first = railcrash.run(model, t_end=1e-5, output_interval=1e-5)
        start["wall"].append(time.perf_counter() - wall)
        start["cpu"].append(time.process_time() - cpu)
        assert first.ok, first.message

    print(f"model {args.model}, {args.repeats} runs each, railcrash {railcrash.__version__}, {os.cpu_count()} cores, "
          f"Python {sys.version.split()[0]}")
    print(f"{'':24} {'CLI':>10} {'Python':>10} {'Python - CLI':>14}")
    for key, label in (("cpu", "whole run, CPU [s]"), ("wall", "whole run, wall [s]"),
                       ("integration", "integration, wall [s]")):
        c, p = statistics.median(cli[key]), statistics.median(py[key])
        print(f"{label:24} {c:10.3f} {p:10.3f} {100.0 * (p - c) / c:+13.1f} %")
    for key in ("cpu", "wall"):
        load_ms, start_ms = 1e3 * statistics.median(load[key]), 1e3 * statistics.median(start[key])
        print(f"{key:>4}: load from Python {load_ms:5.1f} ms, start of a run (reload, set-up, first step) "
              f"{start_ms:5.1f} ms, together {load_ms + start_ms:5.1f} ms")
    print(f"load average {os.getloadavg()[0]:.2f} (1 min)")


if __name__ == "__main__":
    main()
