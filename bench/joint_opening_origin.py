#!/usr/bin/python3
"""The largest joint opening Euler reports on mu_3plus3_si, moved along the track by 0, 1 and
10 km (every body's position and every ground point shifted in x): it must not depend on where
the model sits (bench/HISTORY.md, "Joint openings at the bodies' own size").

Usage: bench/joint_opening_origin.py [--executable build/railcrash] [--shifts 0,1000,10000]
"""
import argparse
import json
import pathlib
import re
import subprocess
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
MODEL = ROOT / "models" / "examples" / "mu_3plus3_si.yaml"


def shifted(text, dx):
    """The model's text with every body position and ground point moved by dx along x."""
    def position(m):
        return f"position: [{float(m.group(1)) + dx:.10g}, {m.group(2)}]"

    def ground(m):
        return f"{{body: ground, at: [{float(m.group(1)) + dx:.10g}, {m.group(2)}]}}"

    text, bodies = re.subn(r"position: \[([-0-9.e+]+), ([-0-9.e+]+)\]", position, text)
    text, points = re.subn(r"\{body: ground, at: \[([-0-9.e+]+), ([-0-9.e+]+)\]\}", ground, text)
    assert bodies > 0 and points > 0, "the model's positions or ground points were not found"
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executable", default=str(ROOT / "build" / "railcrash"))
    parser.add_argument("--shifts", default="0,1000,10000", help="metres along x")
    args = parser.parse_args()
    text = MODEL.read_text()
    print(f"{'shift [m]':>10} {'method':6} {'joint opening [mm]':>18} {'a1 max crush [m]':>16} warnings")
    with tempfile.TemporaryDirectory() as tmp:
        for dx in (float(s) for s in args.shifts.split(",")):
            model = pathlib.Path(tmp) / f"mu_{dx:g}.yaml"
            model.write_text(shifted(text, dx))
            for method in ("euler", "ida"):
                out = pathlib.Path(tmp) / "run"
                (out / "summary.json").unlink(missing_ok=True)
                done = subprocess.run([args.executable, "run", str(model), "--integrator", method, "--out", str(out),
                                       "--quiet"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                if done.returncode != 0 or not (out / "summary.json").exists():
                    print(f"{dx:>10g} {method:6} FAILED (exit {done.returncode}): {done.stderr.strip()[:120]}")
                    continue
                s = json.loads((out / "summary.json").read_text())
                crush = s["car_crush"]["a1"]["max_crush"]
                print(f"{dx:>10g} {method:6} {1000 * s['constraint_residual_max']:>18.4g} {crush:>16.6g} "
                      f"{len(s['accuracy_warnings'])}")


if __name__ == "__main__":
    main()
