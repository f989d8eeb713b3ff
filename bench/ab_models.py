#!/usr/bin/env python3
"""This tree's railcrash against another build on whole runs of given models, interleaved.

    bench/run.sh ab BASE_EXECUTABLE [--models M1,M2,...] [--repeats 9] [--options "..."]
                                    [--new EXECUTABLE] [--new-env NAME=VALUE ...]

Each model runs with BASE_EXECUTABLE and with build/railcrash in turn (base, new, base, new,
...), REPEATS times each, with the model's own settings (plus OPTIONS). The figure is the
median CPU time of the process (user + system, the kernel's accounting of the child) and the
ratio new / base of the medians, with the range of the per-pair ratios beside it. Each line
also says whether the two builds' outputs were the same, byte for byte (every output file;
summary.json without its wall time and phase seconds; every file without the run's id and
provenance, which name the run and the build), so a change meant to leave results alone can
be shown to.

Default models: the barrier test, the report's two-car crash and the slider-crank.
"""
import argparse
import filecmp
import os
import re
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_cpu import run_timed  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_MODELS = ["models/barrier/two_car_barrier.yaml", "models/report/final_two_car.yaml",
                  "verification/cases/slider_crank.yaml"]


def without_wall_time(path):
    with open(path) as f:
        text = f.read()
    text = re.sub(r'"wall_seconds": [^,]*,', "", text)
    return re.sub(r'"seconds": \{[^}]*\}', "", text)


def without_provenance(text):
    """The text without the run's id and provenance (results/provenance.hpp): a CSV file's first
    line, model.json's and summary.json's "run_id" and "provenance" lines."""
    return "".join(line for line in text.splitlines(keepends=True)
                   if not line.startswith(("# railcrash provenance ", '  "run_id": ', '  "provenance": ')))


def same_outputs(first, second):
    names = sorted(os.listdir(first))
    if names != sorted(os.listdir(second)):
        return False
    for name in names:
        a, b = os.path.join(first, name), os.path.join(second, name)
        if name == ".railcrash.lock":  # the output folder's lock: the writer's process id
            continue
        if name == "summary.json":
            if without_provenance(without_wall_time(a)) != without_provenance(without_wall_time(b)):
                return False
        elif name.endswith((".csv", ".json")):
            with open(a) as fa, open(b) as fb:
                if without_provenance(fa.read()) != without_provenance(fb.read()):
                    return False
        elif not filecmp.cmp(a, b, shallow=False):
            return False
    return True


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("base", help="the other build's railcrash executable")
    parser.add_argument("--models", default=",".join(DEFAULT_MODELS))
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--options", default="", help="extra `railcrash run` options, e.g. \"--rtol 1e-4\"")
    parser.add_argument("--new", default=os.path.join(ROOT, "build", "railcrash"),
                        help="the new executable (default: this tree's build/railcrash)")
    parser.add_argument("--new-env", action="append", default=[],
                        help="NAME=VALUE set in the new runs' environment only (a scratch build's switch; "
                             "with --new the same as the base, the switch alone is compared)")
    args = parser.parse_args()
    new = args.new
    new_env = dict(os.environ)
    for assignment in args.new_env:
        name, equals, value = assignment.partition("=")
        if not name or not equals:
            parser.error(f"--new-env {assignment!r}: give NAME=VALUE")
        new_env[name] = value
    extra = args.options.split()
    scratch = tempfile.mkdtemp(prefix="railcrash-ab-")
    print(f"new {new}{' with ' + ' '.join(args.new_env) if args.new_env else ''} against base {args.base}; "
          f"{args.repeats} interleaved pairs per model; "
          f"load average before: {os.getloadavg()[0]:.2f}")
    print("| model | base CPU s (median) | new CPU s (median) | new / base | per-pair range | outputs |")
    print("|---|---|---|---|---|---|")
    for model in args.models.split(","):
        path = os.path.join(ROOT, model) if not os.path.isabs(model) else model
        times = {"base": [], "new": []}
        outs = {which: os.path.join(scratch, which) for which in times}
        for _ in range(args.repeats):
            for which, executable in (("base", args.base), ("new", new)):
                cpu, _ = run_timed([executable, "run", path, "--out", outs[which], "--quiet"] + extra,
                                   env=new_env if which == "new" else None)
                times[which].append(cpu)
        ratios = sorted(n / b for b, n in zip(times["base"], times["new"]))
        base, new_median = statistics.median(times["base"]), statistics.median(times["new"])
        same = "identical" if same_outputs(outs["base"], outs["new"]) else "DIFFER"
        print(f"| {model} | {base:.4f} | {new_median:.4f} | {new_median / base:.3f} | "
              f"{ratios[0]:.3f}-{ratios[-1]:.3f} | {same} |", flush=True)
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
