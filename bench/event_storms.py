#!/usr/bin/python3
"""Event storms: every shipped model under IDA at each rtol, its steps, events and restarts.

    /usr/bin/python3 bench/event_storms.py [--executables build/railcrash[,OTHER]] [--rtols 1e-3,...]
                                           [--models M1,M2] [--limit 60]

A mode change that fires again and again at one instant (an element chattering on a boundary)
shows as a run with thousands of events and restarts where its neighbours on the rtol ladder
have hundreds, and as CPU seconds where they take a fraction of one. The table has one row per
model and rtol and one column group per executable; a run over --limit seconds of CPU is
stopped and shown as such. Found the draft gear's chatter at its reversal point (issue 37;
emu3_unit_collision at rtol 1e-3: 1,153,628 events, 30 s).
"""
import argparse
import glob
import json
import os
import resource
import shutil
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def shipped_models():
    models = []
    for pattern in ("models/examples/*.yaml", "models/report/*.yaml", "models/barrier/*.yaml",
                    "models/scenarios/*.yaml", "tests/robustness/models/*.yaml"):
        for path in sorted(glob.glob(os.path.join(ROOT, pattern))):
            with open(path) as f:
                text = f.read()
            # Models and variants of one (not plans, designs or sweeps).
            if any(line.startswith(("simulation:", "base:")) for line in text.splitlines()):
                models.append(path)
    return [os.path.relpath(m, ROOT) for m in models]


def run(executable, model, rtol, out, limit):
    shutil.rmtree(out, ignore_errors=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        done = subprocess.run([executable, "run", model, "--out", out, "--quiet", "--integrator", "ida", "--rtol", rtol],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=limit, cwd=ROOT)
        code = done.returncode
    except subprocess.TimeoutExpired:
        code = None
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    if code is None:
        return f"over {limit:g} s", cpu
    if code != 0:
        return f"exit {code}", cpu
    try:
        with open(os.path.join(out, "summary.json")) as f:
            stats = json.load(f)["stats"]
    except (OSError, ValueError, KeyError):
        return f"exit {code}, no summary", cpu
    return f"{stats['steps']} / {stats['events']} / {stats['reinitializations']}", cpu


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executables", default=os.path.join(ROOT, "build/railcrash"))
    parser.add_argument("--rtols", default="1e-3,1e-4,1e-5,1e-6,1e-7")
    parser.add_argument("--models", default="")
    parser.add_argument("--limit", type=float, default=60.0, help="CPU seconds before a run is stopped")
    args = parser.parse_args()
    executables = args.executables.split(",")
    models = args.models.split(",") if args.models else shipped_models()
    print("| model | rtol | " + " | ".join(f"{os.path.basename(os.path.dirname(os.path.abspath(e)))}/"
                                            f"{os.path.basename(e)}: steps / events / restarts, CPU s" for e in executables) + " |")
    print("|---|---|" + "---|" * len(executables))
    worst = [(0.0, "") for _ in executables]
    with tempfile.TemporaryDirectory() as scratch:
        for model in models:
            for rtol in args.rtols.split(","):
                cells = []
                for k, executable in enumerate(executables):
                    text, cpu = run(executable, model, rtol, os.path.join(scratch, str(k)), args.limit)
                    cells.append(f"{text}, {cpu:.3f}")
                    worst[k] = max(worst[k], (cpu, f"{model} rtol {rtol}"))
                print(f"| {model} | {rtol} | " + " | ".join(cells) + " |", flush=True)
    for executable, (cpu, where) in zip(executables, worst):
        print(f"{executable}: costliest run {cpu:.3f} s CPU ({where})")


if __name__ == "__main__":
    main()
