#!/usr/bin/python3
"""Each shipped model run by Euler at its default step and by IDA: the energy share the
integration created or lost and the largest joint opening, against the accuracy warnings'
limits (include/railcrash/results/accuracy_check.hpp, README "Accuracy warnings").

Usage: bench/accuracy_warnings.py [BUILD_DIR]   (default: build)
"""
import json
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
BUILD = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ROOT / "build")
MODELS = ["report/final_two_car", "report/preliminary_car", "barrier/two_car_barrier", "examples/coupled_cars",
          "examples/crush_zone_cars", "examples/emu_two_car_crush_zones", "examples/mu_3plus3_si",
          "examples/emu3_unit_collision", "examples/emu3_wall", "examples/emu3_wagon"]

print(f"{'model':34} {'method':6} {'energy share %':>14} {'joint opening':>16} warnings")
with tempfile.TemporaryDirectory() as tmp:
    for name in MODELS:
        for method in ("euler", "ida"):
            out = pathlib.Path(tmp) / "run"
            subprocess.run([str(BUILD / "railcrash"), "run", str(ROOT / "models" / f"{name}.yaml"), "--integrator", method,
                            "--out", str(out), "--quiet"], stdout=subprocess.DEVNULL)  # a failed run: said below
            s = json.loads((out / "summary.json").read_text())
            unit = s["units"]["length"]
            residual = s["constraint_residual_max"]
            opening = f"{residual * 1000:.3g} mm" if unit == "m" else f"{residual * 25.4:.3g} mm"
            print(f"{name:34} {method:6} {100 * s['energy']['relative_balance_error']:>14.3g} {opening:>16} "
                  f"{len(s['accuracy_warnings'])}" + ("" if s["status"] == "ok" else f"  FAILED: {s['message'][:110]}"))
