#!/usr/bin/python3
"""IDA against Euler at equal accuracy on every car and every crush zone (issue 37).

    /usr/bin/python3 bench/equal_accuracy.py [--executable build/railcrash] [--models M1,M2]
                                             [--halvings 5] [--rtols 1e-3,1e-4,1e-5,1e-6,1e-7]
                                             [--repeats 1] [--ida-set KEY=VALUE ...]

For each model (default: the SI multiple-unit examples and the report's two-car crash), runs
an IDA reference (rtol 1e-9), then Euler at its own step (half the stability limit, or the
model's dt) and at that step halved --halvings times, and IDA at each rtol. For each run it
prints the process's CPU (user + system) and the largest relative errors against the
reference in (a) the largest car crush of the run, (b) every car's largest crush (the worst
car; relative to the car's own crush, or to 1 % of the largest when that is more), (c) the energy absorbed by all crush zones (summary.json crush_zones.total_absorbed),
and the run's integration drift as a share of the initial energy. Then, per accuracy level
(10 %, 1 %, 0.1 %), in (a) alone and in (b) and (c) together, the cheapest run of each
method that reaches it and their CPU ratio ("cheapest"), and the same for the loosest setting
from which every tighter setting of the method's grid reaches it too ("settled": a setting that
reaches a level by luck, a tighter one missing it again, does not count; give a grid that goes
well past the level, or the tightest setting settles trivially). A run that fails (say a zone crushed through at a
loose tolerance) reaches no level. --repeats takes the least CPU of that many runs.
"""
import argparse
import json
import os
import resource
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_MODELS = ["models/examples/emu_two_car_crush_zones.yaml", "models/examples/emu3_unit_collision.yaml",
                  "models/examples/emu3_wall.yaml", "models/examples/emu3_wagon.yaml",
                  "models/examples/mu_3plus3_si.yaml", "models/report/final_two_car.yaml"]


def run(executable, model, extra, out, repeats=1):
    """The least CPU of `repeats` runs, and the last run's summary (None when the run failed:
    a run that stops early, say crushed through, reaches no accuracy level)."""
    cpus = []
    for _ in range(repeats):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([executable, "run", model, "--out", out, "--quiet"] + extra, check=False,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    return min(cpus), (summary if summary.get("status") == "ok" else None)


def stability_step(executable, model, out):
    """Euler's own step for the model (summary.json stats.last_step of a short Euler run)."""
    subprocess.run([executable, "run", model, "--out", out, "--quiet", "--integrator", "euler", "--t-end", "1e-9"],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)["stats"]["last_step"]


def figures(summary):
    crush = {car: c["max_crush"] for car, c in summary.get("car_crush", {}).items()}
    zones = summary.get("crush_zones", {}).get("total_absorbed", float("nan"))
    energy = summary.get("energy", {})
    return crush, zones, energy


def relative(a, b):
    return abs(a - b) / abs(b) if b else abs(a - b)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executable", default=os.path.join(ROOT, "build/railcrash"))
    parser.add_argument("--models", default=",".join(DEFAULT_MODELS))
    parser.add_argument("--halvings", type=int, default=5)
    parser.add_argument("--rtols", default="1e-3,1e-4,1e-5,1e-6,1e-7")
    parser.add_argument("--repeats", type=int, default=1, help="runs per setting; the least CPU counts")
    parser.add_argument("--ida-set", action="append", default=[],
                        help="KEY=VALUE for the IDA runs at each rtol (as run --set), e.g. "
                             "simulation.position_tolerance=absolute; the reference keeps the model's settings")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        out = os.path.join(scratch, "out")
        for model in args.models.split(","):
            path = model if os.path.isabs(model) else os.path.join(ROOT, model)
            _, ref = run(args.executable, path, ["--integrator", "ida", "--rtol", "1e-9"], out)
            ref_crush, ref_zones, _ = figures(ref)
            ref_max = max(ref_crush.values())
            dt0 = stability_step(args.executable, path, out)
            jobs = [("euler", ["--integrator", "euler", "--dt", repr(dt0 / 2 ** k)], f"dt {dt0 / 2 ** k:.3g}")
                    for k in range(args.halvings + 1)]
            ida_set = [a for kv in args.ida_set for a in ("--set", kv)]
            rtols = sorted(args.rtols.split(","), key=float, reverse=True)  # loosest first, as Euler's steps
            jobs += [("ida", ["--integrator", "ida", "--rtol", r] + ida_set, f"rtol {r}") for r in rtols]
            jobs += [("auto", ["--integrator", "auto"], "default")]
            print(f"\n### {model} (reference: IDA rtol 1e-9; largest car crush {ref_max:.6g})\n")
            print("| method | setting | CPU s | largest crush err | worst car crush err | zones' energy err | drift / E0 |")
            print("|---|---|---|---|---|---|---|")
            rows = []
            for method, extra, label in jobs:
                cpu, s = run(args.executable, path, extra, out, args.repeats)
                if s is None:
                    print(f"| {method} | {label} | {cpu:.3f} | failed | failed | failed | |")
                    rows.append((method, label, cpu, float("inf"), float("inf"), float("inf")))
                    continue
                crush, zones, _ = figures(s)
                # Each car's error relative to its own crush, with a floor of 1 % of the run's
                # largest (a car that hardly crushes has no meaningful relative error).
                worst = max(abs(crush[c] - ref_crush[c]) / max(abs(ref_crush[c]), 0.01 * ref_max) for c in ref_crush)
                largest = relative(max(crush.values()), ref_max)
                zone_err = relative(zones, ref_zones)
                e = s.get("energy", {})
                drift = e.get("integration_drift", float("nan")) / e.get("initial_total", float("nan")) \
                    if e.get("initial_total") else float("nan")
                rows.append((method, label, cpu, largest, worst, zone_err))
                print(f"| {method} | {label} | {cpu:.3f} | {largest:.2e} | {worst:.2e} | {zone_err:.2e} | {drift:.2e} |")
            print()
            for measure in ("largest", "every"):
                for level in (0.1, 0.01, 0.001):
                    best = {}
                    for method, label, cpu, largest, worst, zone_err in rows:
                        reached = largest <= level if measure == "largest" else worst <= level and zone_err <= level
                        if method != "auto" and reached:
                            if method not in best or cpu < best[method][0]:
                                best[method] = (cpu, label)
                    # Settled: the loosest setting from which every tighter one of the grid reaches the
                    # level too (a setting that reaches it by luck, with tighter ones missing it again,
                    # does not count). Its CPU is that run's.
                    settled = {}
                    for method in ("euler", "ida"):
                        own = [r for r in rows if r[0] == method]  # loosest first
                        for k, (_, label, cpu, largest, worst, zone_err) in enumerate(own):
                            if all((r[3] <= level) if measure == "largest" else (r[4] <= level and r[5] <= level)
                                   for r in own[k:]):
                                settled[method] = (cpu, label)
                                break
                    what = "the largest car crush" if measure == "largest" else "every car's crush and the zones' energy"
                    for kind, chosen in (("cheapest", best), ("settled", settled)):
                        e, i = chosen.get("euler"), chosen.get("ida")
                        ratio = f"IDA / Euler {i[0] / e[0]:.2f}" if e and i else "one method does not reach it"
                        print(f"- {level:g} in {what}, {kind}: Euler {e[1] + f' {e[0]:.3f} s' if e else '-'}, "
                              f"IDA {i[1] + f' {i[0]:.3f} s' if i else '-'}: {ratio}")

if __name__ == "__main__":
    main()
