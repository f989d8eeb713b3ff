#!/usr/bin/env python3
"""The report's two-car crash with this tree's railcrash against an earlier commit's, built side by side.

    bench/compare_commit.py [COMMIT] [--repeats 3] [--scratch DIR] [--t-end 0.25]

COMMIT (default cbce2b9, the commit issue 14 measured) is exported with `git archive` into
SCRATCH/railcrash-COMMIT (default /tmp), configured Release and its `railcrash` built there
(kept for the next call). Then both executables run the same cases, interleaved (old, new,
old, new, ...), REPEATS times each; the figure is the median CPU time of the process
(user + system, from the kernel's accounting of the child: other work on the machine does
not inflate it the way it inflates wall time). Cases: IDA at rtol 1e-3 and 1e-4, and
explicit Euler at the model's own dt (its stability limit, models/report/README.md), each
over T_END seconds with the model's output interval. Each case also prints steps, R1 (the crush
response) and R2 (the override response) of both runs, so a speed-up that changed the answer shows.

Both run one model: this tree's models/report/final_two_car.yaml, or, when the old
executable rejects it (keys added since), the old commit's copy of it (the table says
which); only when neither reads the other's does each run its own (then only roughly
comparable).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

from child_cpu import run_timed

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODEL = "models/report/final_two_car.yaml"


def build_commit(commit, scratch):
    source = os.path.join(scratch, "railcrash-" + commit)
    executable = os.path.join(source, "build", "railcrash")
    if os.path.exists(executable):
        return source, executable
    os.makedirs(source, exist_ok=True)
    archive = subprocess.run(["git", "-C", ROOT, "archive", commit], check=True, capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", source], input=archive, check=True)
    print(f"building {commit} in {source} (Release, railcrash only) ...", flush=True)
    subprocess.run(["cmake", "-S", source, "-B", os.path.join(source, "build"), "-G", "Ninja",
                    "-DCMAKE_BUILD_TYPE=Release"], check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", os.path.join(source, "build"), "--target", "railcrash",
                    "--parallel", str(os.cpu_count() or 1)], check=True, stdout=subprocess.DEVNULL)
    return source, executable


def accepts(executable, model):
    return subprocess.run([executable, "check", model], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode == 0


def timed_run(executable, model, options, out):
    """CPU seconds (user + system) of one `railcrash run`, and its summary.json."""
    usage = subprocess.run([executable, "run", "--help"], capture_output=True, text=True).stdout
    quiet = ["--quiet"] if "--quiet" in usage else []  # (older commits print no progress)
    cpu, _ = run_timed([executable, "run", model, "--out", out] + quiet + options)
    with open(os.path.join(out, "summary.json")) as f:
        return cpu, json.load(f)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("commit", nargs="?", default="cbce2b9")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--scratch", default=tempfile.gettempdir())
    parser.add_argument("--t-end", type=float, default=0.25)
    args = parser.parse_args()

    new_executable = os.path.join(ROOT, "build", "railcrash")
    old_source, old_executable = build_commit(args.commit, args.scratch)
    # One model for both: this tree's, or the old commit's when the old executable rejects
    # this tree's (keys added since) and the new one still reads the old.
    new_model = old_model = os.path.join(ROOT, MODEL)
    model_note = ""
    if not accepts(old_executable, new_model):
        new_model = old_model = os.path.join(old_source, MODEL)
        model_note = f"(the old executable rejects this tree's model: both run {args.commit}'s {MODEL})"
        if not accepts(new_executable, old_model):
            new_model = os.path.join(ROOT, MODEL)
            model_note = "(each executable runs its own commit's model: different models, only roughly comparable)"
    work = tempfile.mkdtemp(prefix="railcrash-compare-")
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()
    head += "+changes" if dirty else ""
    cases = [("IDA rtol 1e-3", ["--integrator", "ida", "--rtol", "1e-3"]),
             ("IDA rtol 1e-4", ["--integrator", "ida", "--rtol", "1e-4"]),
             ("Euler, the model's dt", ["--integrator", "euler"])]
    print(f"two-car crash ({MODEL}), {args.t_end} s; old = {args.commit}, new = {head}; "
          f"median of {args.repeats} interleaved runs, CPU s of the process; {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.1f} at the start")
    if model_note:
        print(model_note)
    print("\n| case | old CPU s | new CPU s | old / new | steps old / new | R1 old / new | R2 old / new |")
    print("|---|---|---|---|---|---|---|")
    for label, options in cases:
        options = options + ["--t-end", str(args.t_end)]
        times = {"old": [], "new": []}
        last = {}
        for repeat in range(args.repeats):
            for which, executable, model in (("old", old_executable, old_model), ("new", new_executable, new_model)):
                cpu, summary = timed_run(executable, model, options, os.path.join(work, which))
                times[which].append(cpu)
                last[which] = summary
        old, new = statistics.median(times["old"]), statistics.median(times["new"])
        o, n = last["old"], last["new"]
        print(f"| {label} | {old:.3f} | {new:.3f} | **{old / new:.2f}** | {o['stats']['steps']} / {n['stats']['steps']} | "
              f"{o['responses']['R1']:.4f} / {n['responses']['R1']:.4f} | {o['responses']['R2']:.4f} / {n['responses']['R2']:.4f} |",
              flush=True)
    print(f"\nload average at the end {os.getloadavg()[0]:.1f}; runs' output in {work}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
