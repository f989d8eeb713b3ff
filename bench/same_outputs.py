#!/usr/bin/python3
"""Do two railcrash executables write the same run folders? For refactors that must not change
behaviour (issue 41, "No behaviour change"; issue 37 item 5).

Runs every model of models/examples, models/scenarios, the report's cars, the barrier test and the
robustness model IDA fails on, under the model's own integrator and under Euler, with both
executables, and compares every file of the two folders byte for byte, apart from:
  - the provenance comment line of the CSV files ("# railcrash provenance ...");
  - summary.json's provenance, run_id and stats.wall_seconds (and any stats entry named *seconds*),
    and the stats entries named by --ignore-stat (a statistic the new build adds);
  - model.json's provenance, if any.
Exit codes and the first line of stderr must agree too (a failed run must fail the same way).

    bench/same_outputs.py OLD_BINARY NEW_BINARY [--jobs 2] [--extra "--format hdf5"] [--only PATTERN]
                          [--ignore-stat NAME ...]

Prints one line per run and a final count; exits 1 if any run differs.
"""
import argparse
import concurrent.futures
import filecmp
import glob
import json
import os
import shlex
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
IGNORED_STATS = []  # --ignore-stat


def models():
    names = sorted(glob.glob(os.path.join(ROOT, "models/examples/*.yaml")))
    names = [n for n in names if not n.endswith("_plan.yaml")]
    names += sorted(glob.glob(os.path.join(ROOT, "models/scenarios/*.yaml")))
    names += [os.path.join(ROOT, p) for p in ("models/report/final_two_car.yaml", "models/report/preliminary_car.yaml",
                                              "models/barrier/two_car_barrier.yaml",
                                              "tests/robustness/models/stiff_anticlimber_unit.yaml",
                                              "tests/robustness/models/crush_through_unit.yaml")]
    return [n for n in names if os.path.exists(n)]


def normalized(path):
    name = os.path.basename(path)
    if name.endswith(".json"):
        with open(path) as f:
            data = json.load(f)
        if isinstance(data, dict):
            for key in ("provenance", "run_id"):
                data.pop(key, None)
            stats = data.get("stats")
            if isinstance(stats, dict):
                for key in [k for k in stats if "seconds" in k or k in IGNORED_STATS]:
                    stats.pop(key)
        return json.dumps(data, sort_keys=True).encode()
    with open(path, "rb") as f:
        lines = f.read().split(b"\n")
    return b"\n".join(line for line in lines if not line.startswith(b"# railcrash provenance"))


def h5_contents(path):
    """Every dataset's values and every attribute of an HDF5 file, but the provenance (h5py)."""
    import h5py
    items = []
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            attrs = {k: repr(v) for k, v in obj.attrs.items() if "provenance" not in k and k != "run_id"}
            data = repr(obj[()].tolist()).encode() if isinstance(obj, h5py.Dataset) else b""  # strings: values, not pointers
            items.append((name, sorted(attrs.items()), data))
        f.visititems(visit)
        items.append(("/", sorted((k, repr(v)) for k, v in f.attrs.items() if "provenance" not in k and k != "run_id"), b""))
    return items


def run(binary, model, integrator, out, extra):
    cmd = [binary, "run", model, "--out", out, "--quiet"] + extra
    if integrator:
        cmd += ["--integrator", integrator]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    first_err = p.stderr.strip().split("\n")[0] if p.stderr.strip() else ""
    return p.returncode, first_err


def compare(old, new, model, integrator, extra, scratch):
    tag = os.path.relpath(model, ROOT) + (" --integrator " + integrator if integrator else "")
    base = os.path.join(scratch, tag.replace("/", "_").replace(" ", "_"))
    a, b = base + ".old", base + ".new"
    ra = run(old, model, integrator, a, extra)
    rb = run(new, model, integrator, b, extra)
    problems = []
    if ra[0] != rb[0]:
        problems.append(f"exit {ra[0]} vs {rb[0]}")
    if ra[1] != rb[1] and not ra[1].startswith("railcrash run") and "seconds" not in ra[1]:
        problems.append(f"stderr '{ra[1]}' vs '{rb[1]}'")
    fa = sorted(os.listdir(a)) if os.path.isdir(a) else []
    fb = sorted(os.listdir(b)) if os.path.isdir(b) else []
    if fa != fb:
        problems.append(f"files {fa} vs {fb}")
    files = 0
    for name in sorted(set(fa) & set(fb)):
        pa, pb = os.path.join(a, name), os.path.join(b, name)
        if os.path.isdir(pa) or name == ".railcrash.lock":  # the lock holds the writer's pid
            continue
        files += 1
        if filecmp.cmp(pa, pb, shallow=False):
            continue
        if name.endswith(".h5"):
            if h5_contents(pa) != h5_contents(pb):
                problems.append(f"{name} differs (datasets or attributes)")
            continue
        if normalized(pa) != normalized(pb):
            problems.append(f"{name} differs")
    return tag, files, problems


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--extra", default="", help="more arguments for every run, e.g. \"--format hdf5\"")
    ap.add_argument("--only", default="", help="only models whose path contains this")
    ap.add_argument("--ignore-stat", action="append", default=[], help="a summary.json stats entry left out of the comparison")
    args = ap.parse_args()
    IGNORED_STATS.extend(args.ignore_stat)
    old, new = os.path.abspath(args.old), os.path.abspath(args.new)
    extra = shlex.split(args.extra)
    cases = [(m, i) for m in models() if args.only in m for i in ("", "euler")]
    differ = 0
    total_files = 0
    with tempfile.TemporaryDirectory(prefix="same_outputs_") as scratch, \
            concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        for tag, files, problems in pool.map(lambda c: compare(old, new, c[0], c[1], extra, scratch), cases):
            total_files += files
            if problems:
                differ += 1
                print(f"DIFFERS {tag}: " + "; ".join(problems))
            else:
                print(f"same    {tag} ({files} files)")
    print(f"{len(cases) - differ} of {len(cases)} runs the same ({total_files} files compared); {differ} differ")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
