#!/usr/bin/python3
"""What a sweep run costs outside its integration, for two builds (a sweep's runs re-read the
model and read the run's summary back for the responses).

    /usr/bin/python3 bench/sweep_outside.py --executables OLD/railcrash,NEW/railcrash
        [--model models/examples/mu_3plus3_si.yaml] [--factor bodies.a1_body.mass]
        [--integrator euler] [--runs 16] [--repeats 5] [--all-responses]

Each build runs the same one-factor sweep (--factor scaled by 0.9 ... 1.1 in --runs levels,
simulation.integrator set to --integrator, responses R1-free: the largest crush of every car
and the zones' energy) with 1 job, --repeats times, the builds interleaved. Prints per build
the median CPU per run (user + system of the sweep process), the median over the runs of the
integration's share of a run (summary.json stats.wall_seconds against runs.csv's
wall_seconds), and NEW / OLD in CPU. The responses must be the same in both (checked).
--all-responses: instead, one sweep per build whose responses are every leaf of the model's
summary.json (from a run of the first build), and the columns whose values differ.
"""
import json
import argparse
import csv
import os
import resource
import statistics
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def plan_text(factor, integrator, runs, responses="crush_zones.total_absorbed, stats.steps, stats.wall_seconds"):
    levels = ", ".join(f"{0.9 + 0.2 * k / max(runs - 1, 1):.6g}" for k in range(runs))
    return (f"sweep: 1\ndesign: full_factorial\nset: [simulation.integrator={integrator}]\n"
            f"factors:\n  - {{key: {factor}, scale: true, levels: [{levels}]}}\n"
            f"responses: [{responses}]\n")


def summary_leaves(executable, model, integrator, scratch):
    """The dotted path of every leaf of the model's summary.json."""
    out = os.path.join(scratch, "leaves")
    subprocess.run([executable, "run", model, "--integrator", integrator, "--out", out, "--quiet"], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    paths = []

    def walk(node, path):
        if isinstance(node, dict):
            for key, value in node.items():
                walk(value, path + [key])
        elif path:
            paths.append(".".join(path))
    walk(summary, [])
    return paths


def compare_all(args, builds):
    with tempfile.TemporaryDirectory(prefix="railcrash_sweep_outside_") as scratch:
        paths = summary_leaves(builds[0], args.model, args.integrator, scratch)
        plan = os.path.join(scratch, "plan.yaml")
        with open(plan, "w") as f:
            f.write(plan_text(args.factor, args.integrator, 2, ", ".join(json.dumps(p) for p in paths)))
        rows = [sweep(build, args.model, plan, os.path.join(scratch, f"all_{k}"))[1] for k, build in enumerate(builds)]
    differing = {}
    for old, new in zip(*rows):
        for column in old:
            if column not in ("hash", "wall_seconds", "stats.wall_seconds") and old[column] != new.get(column):
                differing.setdefault(column, []).append(f"{old[column]} -> {new.get(column)}")
    print(f"{len(paths)} responses (every leaf of summary.json), 2 runs: {len(differing)} columns differ")
    for column, changes in differing.items():
        print(f"  {column}: {'; '.join(changes)}")


def sweep(executable, model, plan, out):
    """CPU seconds of the sweep process, and its runs.csv rows."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run([executable, "sweep", model, "--plan", plan, "--jobs", "1", "--out", out],
                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{executable} sweep {model}: exit {done.returncode}: {done.stderr.strip()}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    with open(os.path.join(out, "runs.csv")) as f:
        rows = list(csv.DictReader(f))
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime, rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--executables", required=True, help="OLD,NEW")
    parser.add_argument("--model", default=os.path.join(ROOT, "models/examples/mu_3plus3_si.yaml"))
    parser.add_argument("--factor", default="bodies.a1_body.mass")
    parser.add_argument("--integrator", default="euler")
    parser.add_argument("--runs", type=int, default=16)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--all-responses", action="store_true")
    args = parser.parse_args()
    builds = args.executables.split(",")
    if len(builds) != 2:
        parser.error("--executables takes two builds: OLD,NEW")
    if args.all_responses:
        compare_all(args, builds)
        return
    cpu = [[], []]  # per build, by position (OLD and NEW may be the same executable: a noise check)
    share = [[], []]
    responses = [None, None]
    with tempfile.TemporaryDirectory(prefix="railcrash_sweep_outside_") as scratch:
        plan = os.path.join(scratch, "plan.yaml")
        with open(plan, "w") as f:
            f.write(plan_text(args.factor, args.integrator, args.runs))
        for repeat in range(args.repeats):
            for k, build in enumerate(builds):
                seconds, rows = sweep(build, args.model, plan, os.path.join(scratch, f"out_{k}_{repeat}"))
                failed = [r for r in rows if r["status"] != "ok"]
                if failed:
                    raise SystemExit(f"{build}: run {failed[0]['run']} failed: {failed[0]['message']}")
                cpu[k].append(seconds / len(rows))
                share[k] += [float(r["stats.wall_seconds"]) / float(r["wall_seconds"]) for r in rows]
                if responses[k] is None:
                    responses[k] = [(r["crush_zones.total_absorbed"], r["stats.steps"]) for r in rows]
    if responses[0] != responses[1]:
        print("the two builds' responses differ")
    print(f"{os.path.relpath(args.model, ROOT)} under {args.integrator}: a sweep of {args.runs} runs ({args.factor} x 0.9 ... 1.1), "
          f"1 job, {args.repeats} repeats interleaved")
    print("| build | CPU per run [s], median | integration's share of a run's wall time, median |")
    print("|---|---|---|")
    for k, build in enumerate(builds):
        print(f"| {('OLD', 'NEW')[k]} {build} | {statistics.median(cpu[k]):.4f} | {100 * statistics.median(share[k]):.1f} % |")
    print(f"NEW / OLD in CPU per run: {statistics.median(cpu[1]) / statistics.median(cpu[0]):.3f}")


if __name__ == "__main__":
    main()
