#!/usr/bin/python3
"""Experiments on IDA's cost on mu_3plus3_si at equal accuracy in its largest crush (issue 37).

    git worktree add /tmp/exp d92063a && cd /tmp/exp && \
        git apply <main>/bench/patches/ida_step_experiments.patch && scripts/build.sh
    /usr/bin/python3 bench/ida_step_experiments.py --executable /tmp/exp/build/railcrash [--repeats 3]

The patch adds environment switches to IDA (none set: the build behaves as d92063a):
  RC_LAND=m [RC_MINF=f]   end a step just past the first root crossing predicted on IDA's
                          polynomial extrapolated over its next step (IDASetStopTime), for
                          crossings at least f of the step ahead, never on two steps in a row
  RC_NOKINK=1             every located mode change restarts IDA (no kink goes on across)
  RC_VSCALE=s, RC_PSCALE=s  velocities' / positions' tolerances times s
  RC_MSCALE=p             each body's velocity tolerance times (heaviest mass / its mass)^p
Every run uses position_tolerance: absolute. For each variant and rtol it prints CPU (least of
--repeats), IDA's steps, Jacobians and restarts, and the largest car crush's relative error
against an IDA rtol 1e-9 run; then Euler at its own step as the line to beat (2x its CPU).
"""
import argparse
import json
import os
import resource
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODEL = os.path.join(ROOT, "models/examples/mu_3plus3_si.yaml")
VARIANTS = [
    ("as d92063a", {}),
    ("every event restarts", {"RC_NOKINK": "1"}),
    ("land on predicted crossings (0.2, 0.1)", {"RC_LAND": "0.2", "RC_MINF": "0.1"}),
    ("land on predicted crossings (0.05, 0.5)", {"RC_LAND": "0.05", "RC_MINF": "0.5"}),
    ("velocity tolerance x (M/m)^0.5", {"RC_MSCALE": "0.5"}),
    ("velocity tolerance x M/m", {"RC_MSCALE": "1"}),
    ("velocities x 0.1", {"RC_VSCALE": "0.1"}),
    ("positions x 0.3", {"RC_PSCALE": "0.3"}),
    ("positions x 0.1", {"RC_PSCALE": "0.1"}),
    ("positions x 0.03", {"RC_PSCALE": "0.03"}),
]


def run(executable, extra, env, out, repeats):
    cpus = []
    for _ in range(repeats):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([executable, "run", MODEL, "--out", out, "--quiet"] + extra, check=False,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env={**os.environ, **env})
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    with open(os.path.join(out, "summary.json")) as f:
        return min(cpus), json.load(f)


def largest(summary):
    return max(c["max_crush"] for c in summary["car_crush"].values())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executable", required=True)
    parser.add_argument("--rtols", default="3e-3,1e-3,3e-4,1e-4")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        out = os.path.join(scratch, "out")
        _, ref = run(args.executable, ["--integrator", "ida", "--rtol", "1e-9"], {}, out, 1)
        reference = largest(ref)
        euler_cpu, euler = run(args.executable, ["--integrator", "euler"], {}, out, args.repeats)
        print(f"reference (IDA rtol 1e-9): largest car crush {reference:.6g}")
        print(f"Euler at its own step: CPU {euler_cpu:.3f} s, error {abs(largest(euler) / reference - 1):.2e}; "
              f"twice its CPU {2 * euler_cpu:.3f} s\n")
        print("| variant | rtol | CPU s | steps | Jacobians | restarts | status | largest crush err |")
        print("|---|---|---|---|---|---|---|---|")
        for name, env in VARIANTS:
            for rtol in args.rtols.split(","):
                cpu, s = run(args.executable, ["--integrator", "ida", "--rtol", rtol, "--set",
                                               "simulation.position_tolerance=absolute"], env, out, args.repeats)
                st = s["stats"]
                err = abs(largest(s) / reference - 1)
                print(f"| {name} | {rtol} | {cpu:.3f} | {st['steps']} | {st['jacobian_evaluations']} | "
                      f"{st['reinitializations']} | {s['status']} | {err:.2e} |")


if __name__ == "__main__":
    main()
