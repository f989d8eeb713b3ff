#!/usr/bin/python3
"""A parameter study from Python: the report's final two-car crash (a loaded car at 35 mph
into a standing car) with the anticlimber's horizontal yield force scaled from 0.6 to 1.4,
run in parallel threads (runs release the GIL) and plotted with matplotlib.

    PYTHONPATH=build/python examples/python/parameter_study.py [--t-end 0.25] [--out study.png]

Prints one row per run (largest crush of each car, peak acceleration of the striking car's
centre body) and writes a figure: the striking car's speed against time for every factor,
and the largest crush against the factor. The yield force is scaled through the yield
deflection, as the report's P7 does (yield force = elastic slope x yield deflection).
"""

import argparse
import concurrent.futures
import os
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import railcrash  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", default=str(ROOT / "models" / "report" / "final_two_car.yaml"))
    parser.add_argument("--factors", default="0.6,0.8,1.0,1.2,1.4", help="comma list of yield force factors")
    parser.add_argument("--t-end", type=float, default=None, help="end time [s] (default: the model's)")
    parser.add_argument("--rtol", type=float, default=1e-4)
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--out", default="parameter_study.png")
    args = parser.parse_args()

    base = railcrash.load(args.model)
    factors = [float(f) for f in args.factors.split(",")]
    models = [base.with_settings({"elements.anticlimber.horizontal_yield_deflection*": f}) for f in factors]

    def run(model):
        return railcrash.run(model, integrator="ida", rtol=args.rtol, t_end=args.t_end)

    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        results = list(pool.map(run, models))

    units = base.units
    length, speed = ("in", "in/s") if units == "in-lbf-s" else ("m", "m/s")
    print(f"{base.name}: anticlimber horizontal yield force x factor, {len(factors)} runs")
    print(f"{'factor':>7} {'status':>7} {'car1 crush':>12} {'car2 crush':>12} {'car1 body peak':>15}")
    crush = []
    for factor, result in zip(factors, results):
        cars = result.summary["car_crush"]
        peak = result.summary["peak_accelerations"]["bodies"]["car1_center_body"]["magnitude"]["g"]
        crush.append(cars["car1"]["max_crush"])
        print(f"{factor:7.2f} {('ok' if result.ok else 'FAILED'):>7} {cars['car1']['max_crush']:9.3f} {length:<2}"
              f" {cars['car2']['max_crush']:9.3f} {length:<2} {peak:12.2f} g")

    figure, (speed_axes, crush_axes) = plt.subplots(1, 2, figsize=(11, 4.2))
    for factor, result in zip(factors, results):
        speed_axes.plot(result.t, result.series("car1_center_body.vx"), label=f"x {factor:g}")
    speed_axes.set_xlabel("t [s]")
    speed_axes.set_ylabel(f"striking car speed [{speed}]")
    speed_axes.legend(title="yield force")
    speed_axes.grid(True, alpha=0.3)
    crush_axes.plot(factors, crush, "o-")
    crush_axes.set_xlabel("anticlimber horizontal yield force factor")
    crush_axes.set_ylabel(f"largest crush of each car [{length}]")
    crush_axes.grid(True, alpha=0.3)
    figure.suptitle(base.name, fontsize=9)
    figure.tight_layout()
    figure.savefig(args.out, dpi=120)
    print(f"figure: {args.out}")
    return 0 if all(r.ok for r in results) else 1


if __name__ == "__main__":
    raise SystemExit(main())
