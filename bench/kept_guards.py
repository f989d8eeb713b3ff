#!/usr/bin/python3
"""Guards on the kept Jacobian, tried on a scratch build (bench/HISTORY.md, "Guards on the kept
Jacobian: tried, not adopted").

    git worktree add /tmp/guards <commit> && cd /tmp/guards && \
        git apply <main>/bench/patches/kept_jacobian_guards.patch && scripts/build.sh
    /usr/bin/python3 bench/kept_guards.py --executable /tmp/guards/build/railcrash

The patch adds two environment switches to IDA's Jacobian function (none set: the build
behaves as its commit): RC_LAMBDA=X evaluates afresh when a multiplier has moved by more than X
times the largest one the kept Jacobian was evaluated at; RC_ITERS=X when IDA took more than X
Newton iterations per step since the last setup. For each setting this prints whether the
N-four-bar (tests/robustness/models/n_four_bar.yaml) passes its singular configurations at
rtol 1e-3 ... 1e-9, and the energy the barrier cars' scenario 1 (joint and face friction)
creates at rtol 3e-3 and 1e-3, as summary.json's relative_balance_error (positive: created,
negative: lost; the friction test asks for no more than 1 % created).
"""
import argparse
import json
import os
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SETTINGS = [("", ""), ("RC_LAMBDA", "0.1"), ("RC_LAMBDA", "0.15"), ("RC_LAMBDA", "0.2"), ("RC_LAMBDA", "0.25"),
            ("RC_LAMBDA", "0.3"), ("RC_LAMBDA", "0.4"), ("RC_LAMBDA", "0.5"), ("RC_LAMBDA", "1.0"),
            ("RC_ITERS", "1.0"), ("RC_ITERS", "1.5"), ("RC_ITERS", "2.0")]


def run(executable, model, rtol, out, env):
    subprocess.run([executable, "run", os.path.join(ROOT, model), "--integrator", "ida", "--rtol", rtol, "--out", out,
                    "--quiet"], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executable", required=True)
    args = parser.parse_args()
    rtols = ["1e-3", "1e-4", "1e-5", "1e-6", "1e-7", "1e-8", "1e-9"]
    print("| setting | N-four-bar at rtol " + " / ".join(rtols) + " | barrier cars' scenario 1: balance error at rtol 3e-3 / 1e-3 |")
    print("|---|---|---|")
    with tempfile.TemporaryDirectory() as scratch:
        out = os.path.join(scratch, "out")
        for name, value in SETTINGS:
            env = {k: v for k, v in os.environ.items() if k not in ("RC_LAMBDA", "RC_ITERS")}
            if name:
                env[name] = value
            four_bar = [run(args.executable, "tests/robustness/models/n_four_bar.yaml", r, out, env)["status"] for r in rtols]
            energy = [run(args.executable, "models/scenarios/scenario1_barrier_cars.yaml", r, out, env)["energy"]["relative_balance_error"]
                      for r in ("3e-3", "1e-3")]
            label = f"{name}={value}" if name else "none (as main)"
            print(f"| {label} | {' '.join('pass' if s == 'ok' else 'FAIL' for s in four_bar)} | "
                  f"{energy[0]:+.4f} / {energy[1]:+.4f} |")


if __name__ == "__main__":
    main()
