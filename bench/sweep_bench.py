#!/usr/bin/env python3
"""Throughput of `railcrash sweep` (issue 13): a Latin-hypercube sweep of the report's two-car
crash (models/report/final_two_car.yaml) with 1 and 2 jobs and, in an MPI build, 2 MPI ranks;
the batch runner's overhead per run; the scaling efficiency; and a paper estimate of a
10,000-run study on 64 ranks. Prints the figures and appends a line to bench/results.md.

    /usr/bin/python3 bench/sweep_bench.py [--runs 200] [--build build]     (bench/run.sh sweep)

Figures per configuration: wall time, runs per second (wall), CPU time of all processes
(user + system, which other work on the machine does not inflate). From the 1-job sweep's
runs.csv: the mean wall time of a run inside the runner (model read + run + responses:
wall_seconds) and of its integration alone (summary.json's stats.wall_seconds). The batch
runner's overhead per run is the sweep's wall time / runs - the mean wall_seconds (thread
pool, hashing, runs.csv); the sweep's overhead outside the integration adds the model's
set-up and the responses.
"""
import argparse
import csv
import datetime
import math
import os
import pathlib
import resource
import shutil
import subprocess
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
PLAN = """sweep: 1
design: latin_hypercube
samples: {runs}
seed: 13
factors:
  - key: elements.anticlimber.horizontal_yield_deflection
    scale: true
    distribution: {{uniform: [0.8, 1.2]}}
  - key: elements.anticlimber.vertical_yield_deflection
    scale: true
    distribution: {{uniform: [0.8, 1.2]}}
responses: [R1, R2, R3, car_crush.car1.max_crush, stats.wall_seconds]
"""
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1", "OMPI_MCA_mpi_yield_when_idle": "1"}


def timed(command, env=None):
    """(wall seconds, CPU seconds of the child processes) of one command, which must succeed."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   env=dict(os.environ, **(env or {})))
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def column(rows, name):
    return [float(r[name]) for r in rows if r["status"] == "ok" and r[name] != ""]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=200)
    parser.add_argument("--build", default=str(ROOT / "build"))
    args = parser.parse_args()
    binary = pathlib.Path(args.build) / "railcrash"
    model = ROOT / "models" / "report" / "final_two_car.yaml"
    mpirun = shutil.which("mpirun")
    # `railcrash sweep` under mpirun execs railcrash-mpi, built beside it when CMake found MPI
    # (railcrash itself links no MPI since the start-up work: bench/HISTORY.md, "Start-up").
    with_mpi = mpirun is not None and (binary.parent / "railcrash-mpi").exists()
    with tempfile.TemporaryDirectory(prefix="railcrash_sweep_bench_") as scratch:
        plan = pathlib.Path(scratch) / "plan.yaml"
        plan.write_text(PLAN.format(runs=args.runs))
        sweep = [str(binary), "sweep", str(model), "--plan", str(plan)]
        configurations = [("1 job", sweep + ["--jobs", "1", "--out", f"{scratch}/j1"], None, 1),
                          ("2 jobs", sweep + ["--jobs", "2", "--out", f"{scratch}/j2"], None, 2)]
        if with_mpi:
            configurations.append(("2 MPI ranks", [mpirun, "--oversubscribe", "-np", "2"] + sweep + ["--out", f"{scratch}/mpi"],
                                   MPI_ENV, 2))
        results = []
        for label, command, env, workers in configurations:
            wall, cpu = timed(command, env)
            results.append((label, wall, cpu, workers))
            print(f"{label:12s} {args.runs} runs in {wall:7.1f} s wall: {args.runs / wall:.3f} runs/s; CPU {cpu:.1f} s",
                  flush=True)
        with open(f"{scratch}/j1/runs.csv") as f:
            rows = list(csv.DictReader(f))
    failed = sum(1 for r in rows if r["status"] != "ok")
    run_wall = column(rows, "wall_seconds")
    integration = column(rows, "stats.wall_seconds")
    mean_run = sum(run_wall) / len(run_wall)
    mean_integration = sum(integration) / len(integration)
    longest = max(run_wall)
    wall_1 = results[0][1]
    batch_overhead = wall_1 / args.runs - mean_run
    outside = wall_1 / args.runs - mean_integration
    print(f"\n1-job sweep: {failed} failed runs; mean run {mean_run:.3f} s (longest {longest:.3f} s), of which "
          f"integration {mean_integration:.3f} s")
    print(f"batch runner overhead per run: {1e3 * batch_overhead:.2f} ms = {100 * batch_overhead / mean_run:.2f} % of a run "
          f"(goal < 1 %); outside the integration (model set-up, responses, runner): {1e3 * outside:.1f} ms "
          f"= {100 * outside / mean_run:.1f} %")
    print(f"CPU per run (all processes): " + ", ".join(f"{label} {cpu / args.runs:.3f} s" for label, _, cpu, _ in results)
          + " (wall times on a loaded machine wait for the other work; CPU does not)")
    for label, wall, cpu, workers in results[1:]:
        efficiency = wall_1 / (workers * wall)
        print(f"scaling efficiency, {label}: {100 * efficiency:.0f} % (runs/s against {workers} x the 1-job rate)")
    # Paper estimate: 10,000 runs over 64 ranks (rank 0 runs too), one run per core at a time.
    total, ranks = 10000, 64
    best_efficiency = max(wall_1 / (w * wall) for _, wall, _, w in results[1:]) if len(results) > 1 else 1.0
    estimate = math.ceil(total / ranks) * mean_run + longest
    print(f"\npaper estimate, {total} runs on {ranks} ranks: ceil({total}/{ranks}) x {mean_run:.2f} s + the longest run "
          f"{longest:.2f} s (the dynamic distribution's tail) = {estimate / 60:.1f} min at full efficiency; "
          f"{estimate / best_efficiency / 60:.1f} min at the {100 * best_efficiency:.0f} % measured here.")
    cpu_run = results[0][2] / args.runs
    cpu_estimate = math.ceil(total / ranks) * cpu_run + longest * cpu_run / mean_run
    print(f"from the CPU per run instead ({cpu_run:.3f} s, the cost on an idle core): {cpu_estimate / 60:.1f} min")
    print("assumptions: 64 cores as fast per core as this machine, one rank per core, every run costing what this "
          "sweep's runs cost (same model, same tolerances), rank 0's coordination negligible (one 300-byte message per "
          "run), runs.csv on a shared file system written by rank 0 only.")
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    load = open("/proc/loadavg").read().split()[:3]
    rates = ", ".join(f"{label} {args.runs / wall:.3f} runs/s ({wall:.0f} s)" for label, wall, _, _ in results)
    line = (f"sweep of final_two_car.yaml, {args.runs} runs: {rates}; runner overhead {1e3 * batch_overhead:.2f} ms/run "
            f"({100 * batch_overhead / mean_run:.2f} %); mean run {mean_run:.2f} s; load average at the end {' '.join(load)}; "
            f"commit {commit}, {os.cpu_count()} cores")
    with open(ROOT / "bench" / "results.md", "a") as f:
        f.write(f"- {datetime.date.today().isoformat()}: {line}\n")


if __name__ == "__main__":
    main()
