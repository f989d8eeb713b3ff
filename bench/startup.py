#!/usr/bin/env python3
"""Start-up of the railcrash process: this build against a base build, interleaved (issue 14).

    bench/startup.py --base BASE_EXECUTABLE [--executable build/railcrash] [--repeats 21]
                     [--base-python BASE/python [--python build/python]]

Runs `railcrash --version` and the slider-crank at its own 0.4 s output (the case where
start-up dominates the Simbody comparison, bench/simbody/compare.py: rtol 1e-6 and 1e-8, atol
a tenth of rtol), alternately with the base and this executable (the order swapped every
repeat), and prints per case the median CPU time of the process (user + system) and the
median wall time, both in ms, the number of shared libraries each executable loads (`ldd`)
and, for scale, the cost of a process that does nothing (/bin/true). With --base-python, also
`python3 -c "import railcrash"` with either build's module. Build the base once, e.g. `git archive 2f93f14 | tar -x -C /tmp/startup-base/src`,
configure /tmp/startup-base/build from it (Release) and build its target railcrash.
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from child_cpu import run_timed  # noqa: E402

SLIDER_CRANK = os.path.join(ROOT, "verification", "cases", "slider_crank.yaml")


def cases(work):
    run = ["run", SLIDER_CRANK, "--output-interval", "0.4", "--out", os.path.join(work, "out"), "--quiet"]
    return [("--version", ["--version"]),
            ("slider-crank, rtol 1e-6, 0.4 s output", run + ["--rtol", "1e-6", "--atol", "1e-7"]),
            ("slider-crank, rtol 1e-8, 0.4 s output", run + ["--rtol", "1e-8", "--atol", "1e-9"])]


def timed(executable, arguments):
    """(CPU ms, wall ms) of one run of executable with arguments."""
    start = time.perf_counter()
    cpu, _ = run_timed([executable] + arguments)
    return 1e3 * cpu, 1e3 * (time.perf_counter() - start)


def libraries(executable):
    listing = subprocess.run(["ldd", executable], capture_output=True, text=True, check=True).stdout
    return sum(1 for line in listing.splitlines() if "=>" in line)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--base", required=True, help="the base build's railcrash executable")
    parser.add_argument("--executable", default=os.path.join(ROOT, "build", "railcrash"))
    parser.add_argument("--repeats", type=int, default=21)
    parser.add_argument("--base-python", help="the base build's python folder (BASE/python): also time `import railcrash`")
    parser.add_argument("--python", default=os.path.join(ROOT, "build", "python"), help="this build's python folder")
    args = parser.parse_args()
    tools = {"base": args.base, "this": args.executable}
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    print(f"railcrash start-up: {args.executable} (HEAD {head}) against {args.base}; medians of {args.repeats} "
          f"interleaved runs; {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
    print(f"shared libraries loaded (ldd): base {libraries(args.base)}, this {libraries(args.executable)}")
    floor = [timed("/bin/true", []) for _ in range(args.repeats)]
    print(f"a process that does nothing (/bin/true, libc only): median CPU {statistics.median(s[0] for s in floor):.1f} ms, "
          f"wall {statistics.median(s[1] for s in floor):.1f} ms\n")
    print("| case | base CPU ms | this CPU ms | this/base CPU | base wall ms | this wall ms | this/base wall |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="railcrash-startup-") as work:
        for name, arguments in cases(work):
            samples = {tool: [] for tool in tools}
            for repeat in range(args.repeats):
                for tool in (("base", "this") if repeat % 2 == 0 else ("this", "base")):
                    samples[tool].append(timed(tools[tool], arguments))
            cpu = {tool: statistics.median(s[0] for s in samples[tool]) for tool in tools}
            wall = {tool: statistics.median(s[1] for s in samples[tool]) for tool in tools}
            print(f"| {name} | {cpu['base']:.1f} | {cpu['this']:.1f} | **{cpu['this'] / cpu['base']:.2f}** | "
                  f"{wall['base']:.1f} | {wall['this']:.1f} | {wall['this'] / wall['base']:.2f} |")
            sys.stdout.flush()
    if args.base_python:  # `import railcrash`: the module links the library and its dependencies
        folders = {"base": args.base_python, "this": args.python}
        samples = {tool: [] for tool in folders}
        for repeat in range(args.repeats):
            for tool in (("base", "this") if repeat % 2 == 0 else ("this", "base")):
                os.environ["PYTHONPATH"] = folders[tool]
                samples[tool].append(timed("/usr/bin/python3", ["-c", "import railcrash"]))
        cpu = {tool: statistics.median(s[0] for s in samples[tool]) for tool in folders}
        wall = {tool: statistics.median(s[1] for s in samples[tool]) for tool in folders}
        print(f"| python3 -c 'import railcrash' | {cpu['base']:.1f} | {cpu['this']:.1f} | **{cpu['this'] / cpu['base']:.2f}** | "
              f"{wall['base']:.1f} | {wall['this']:.1f} | {wall['this'] / wall['base']:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
