#!/usr/bin/python3
"""IDA with its Jacobian kept between setups (the default, simulation: jacobian_kept_steps 20)
against one evaluated at every setup (jacobian_kept_steps 0), one build, interleaved.

    /usr/bin/python3 bench/kept_jacobian.py [--executable build/railcrash] [--repeats 5] [--models M1,M2]

Each model runs under IDA at its own settings, REPEATS times with each setting in turn. Per model
it prints the median CPU of the process (user + system) with each and their ratio, IDA's steps,
Jacobian evaluations and Newton matrices factored (summary.json stats) with each, and the
largest car crush with each (bench/HISTORY.md, "The Jacobian kept between setups"). The report's
models name jacobian_kept_steps 0 in their files; here both settings are set explicitly.
"""
import argparse
import json
import os
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from child_cpu import run_timed  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODELS = ["models/examples/mu_3plus3_si.yaml", "models/examples/emu3_unit_collision.yaml", "models/examples/emu3_wall.yaml",
          "models/examples/emu3_wagon.yaml", "models/examples/emu_two_car_crush_zones.yaml",
          "models/scenarios/scenario1_emu3.yaml", "models/scenarios/scenario2_emu3.yaml", "models/barrier/two_car_barrier.yaml",
          "models/scenarios/scenario1_barrier_cars.yaml", "models/scenarios/scenario2_barrier_cars.yaml",
          "models/report/final_two_car.yaml", "models/report/preliminary_car.yaml", "models/scenarios/scenario1_report_car.yaml",
          "models/scenarios/scenario2_report_car.yaml", "verification/cases/slider_crank.yaml"]
SETTINGS = (0, 20)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--executable", default=os.path.join(ROOT, "build", "railcrash"))
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--models", default=",".join(MODELS))
    args = parser.parse_args()
    print("| model | CPU s, every setup | CPU s, kept | kept / every | steps | Jacobians | Newton matrices | largest crush |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for model in args.models.split(","):
            cpu = {k: [] for k in SETTINGS}
            summary = {}
            for _ in range(args.repeats):
                for kept in SETTINGS:
                    out = os.path.join(tmp, str(kept))
                    path = os.path.join(out, "summary.json")
                    if os.path.exists(path):
                        os.remove(path)
                    seconds, _ = run_timed([args.executable, "run", os.path.join(ROOT, model), "--integrator", "ida", "--quiet",
                                         "--out", out, "--set", f"simulation.jacobian_kept_steps={kept}"])
                    cpu[kept].append(seconds)
                    with open(path) as f:
                        summary[kept] = json.load(f)
            median = {k: statistics.median(v) for k, v in cpu.items()}

            def pair(key):
                return " / ".join(str(summary[k]["stats"][key]) for k in SETTINGS)

            def crush(s):
                values = [c["max_crush"] for c in s.get("car_crush", {}).values()]
                return f"{max(values):.6g}" if values else "-"
            status = "" if all(summary[k]["status"] == "ok" for k in SETTINGS) else " (" + " / ".join(summary[k]["status"] for k in SETTINGS) + ")"
            print(f"| {os.path.basename(model)}{status} | {median[0]:.3f} | {median[20]:.3f} | {median[20] / median[0]:.3f} | "
                  f"{pair('steps')} | {pair('jacobian_evaluations')} | {pair('linear_setups')} | "
                  f"{crush(summary[0])} / {crush(summary[20])} |", flush=True)


if __name__ == "__main__":
    main()
