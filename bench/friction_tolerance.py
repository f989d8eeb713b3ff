#!/usr/bin/env python3
"""IDA at loose tolerances on models with regularized Coulomb friction (F = -mu N tanh(v / v_f)):
each run's status, steps, integration drift and every car's crush against the model's run at
rtol 1e-7, with this build and (--base) another.

    /usr/bin/python3 bench/friction_tolerance.py [--executable build/railcrash] [--base OTHER]

The models: the barrier cars' EN 15227 scenario 1 (face friction 0.3, v_f 0.01 in/s between the
leading cars), and models/examples/emu3_wall.yaml with friction 0.2 (v_f 0.01 m/s, slider_length
0.6 m) on its end bodies' guides, written to a temporary file (the shipped example has no joint
friction). bench/HISTORY.md, "Velocities held to the friction's slip speed".
"""
import argparse
import json
import os
import re
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RTOLS = ["1e-2", "3e-3", "1e-3", "1e-4"]


def guide_friction_variant(path):
    with open(os.path.join(ROOT, "models/examples/emu3_wall.yaml")) as f:
        text = f.read()
    text, count = re.subn(r"(name: (?:front|rear)_guide, type: slider_joint,)", r"\1 friction: 0.2, friction_velocity: 0.01, slider_length: 0.6,", text)
    assert count == 4, count
    with open(path, "w") as f:
        f.write(text)


def run(executable, model, out, rtol):
    summary = os.path.join(out, "summary.json")
    if os.path.exists(summary):
        os.remove(summary)  # (a run that writes none must not be read as the last one)
    subprocess.run([executable, "run", model, "--integrator", "ida", "--quiet", "--out", out, "--rtol", rtol],
                   cwd=ROOT, capture_output=True, text=True)
    with open(summary) as f:
        return json.load(f)


def crushes(summary):
    return [c["max_crush"] for c in summary.get("car_crush", {}).values()]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executable", default=os.path.join(ROOT, "build", "railcrash"))
    parser.add_argument("--base", help="another build to compare with")
    args = parser.parse_args()
    builds = [("this", args.executable)] + ([("base", args.base)] if args.base else [])
    with tempfile.TemporaryDirectory() as tmp:
        variant = os.path.join(tmp, "emu3_wall_guide_friction.yaml")
        guide_friction_variant(variant)
        out = os.path.join(tmp, "run")
        for model in ["models/scenarios/scenario1_barrier_cars.yaml", variant]:
            reference = crushes(run(args.executable, model, out, "1e-7"))
            name = os.path.basename(model)
            print(f"{name}: every car's crush at rtol 1e-7 {', '.join(f'{c:.4g}' for c in reference)}")
            for label, executable in builds:
                for rtol in RTOLS:
                    s = run(executable, model, out, rtol)
                    energy = s["energy"]
                    drift = energy["integration_drift"] / energy["initial_total"]
                    worst = max((abs(c - r) / r for c, r in zip(crushes(s), reference) if r > 0), default=0.0)
                    print(f"  [{label}] rtol {rtol}: {s['status']}, {s['stats']['steps']} steps, drift / E0 {drift:+.3g}, "
                          f"crush {', '.join(f'{c:.4g}' for c in crushes(s))} (worst car {worst:.1e})", flush=True)


if __name__ == "__main__":
    main()
