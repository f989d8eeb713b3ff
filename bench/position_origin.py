#!/usr/bin/python3
"""mu_3plus3_si under IDA at its own rtol, moved along the track (every body position and
ground point shifted in x): how far it sits from its origin in its own size
(summary.json stats.origin_distance_in_sizes), its largest car crush against the rtol 1e-9
run at the origin, and whether the run warns about the relative position tolerance
(README "Position tolerances"; results/accuracy_check.hpp, kOriginDistanceLimit).

Usage: bench/position_origin.py [--executable build/railcrash] [--shifts 0,1000,10000,100000]
                                [--forms relative,absolute]
"""
import argparse
import json
import pathlib
import subprocess
import tempfile

from joint_opening_origin import MODEL, ROOT, shifted


def run(executable, model, out, extra):
    subprocess.run([executable, "run", str(model), "--integrator", "ida", "--out", str(out), "--quiet"] + extra,
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(out / "summary.json") as f:
        summary = json.load(f)
    largest = max(car["max_crush"] for car in summary["car_crush"].values())
    return summary, largest


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executable", default=str(ROOT / "build" / "railcrash"))
    parser.add_argument("--shifts", default="0,1000,10000,100000")
    parser.add_argument("--forms", default="relative,absolute")
    args = parser.parse_args()
    text = MODEL.read_text()
    with tempfile.TemporaryDirectory() as scratch:
        scratch = pathlib.Path(scratch)
        _, reference = run(args.executable, MODEL, scratch / "reference", ["--rtol", "1e-9"])
        print(f"reference (rtol 1e-9, at the origin): largest crush {reference:.6f} m")
        print("| shift [m] | position tolerance | origin distance [sizes] | steps | largest crush [m] | error | origin warning |")
        print("|---|---|---|---|---|---|---|")
        for shift in [float(s) for s in args.shifts.split(",")]:
            model = scratch / f"shifted_{shift:g}.yaml"
            model.write_text(shifted(text, shift))
            for form in args.forms.split(","):
                summary, largest = run(args.executable, model, scratch / f"out_{shift:g}_{form}",
                                       ["--set", f"simulation.position_tolerance={form}"])
                distance = summary["stats"].get("origin_distance_in_sizes", 0.0)
                warned = any("from its origin" in w for w in summary.get("accuracy_warnings", []))
                print(f"| {shift:g} | {form} | {distance:.3g} | {summary['stats']['steps']} | {largest:.6f} | "
                      f"{largest / reference - 1:+.2e} | {'yes' if warned else 'no'} |")


if __name__ == "__main__":
    main()
