#!/usr/bin/env python3
"""Euler against IDA on an EN 15227 scenario model: the criteria side by side, Euler's step refined.

Runs MODEL (default models/scenarios/scenario1_emu3.yaml) with IDA (the model's rtol and a tighter
one), auto, and explicit Euler at its own step and at finer steps, and prints one table of the
scenario criteria (summary.json's "scenario" section) with a column per run, then the rail
reactions the wheel-unloading criterion takes as its static load Q0 (the first non-zero sample of
each rail support's normal_reaction in timeseries.csv). Run from the repository root:

    /usr/bin/python3 bench/scenario_euler_convergence.py build/railcrash \
        [--model models/scenarios/scenario1_emu3.yaml] [--dts 1e-4,3e-5,1e-5,3e-6] [--out out/euler_convergence]

README "Collision scenarios (EN 15227)" quotes its output.
"""
import argparse
import csv
import json
import pathlib
import subprocess
import time


def run(binary, model, out, args):
    start = time.monotonic()
    subprocess.run([binary, "run", model, "--quiet", "--out", str(out)] + args, check=True, stdout=subprocess.DEVNULL)
    wall = time.monotonic() - start
    return json.loads((out / "summary.json").read_text()), wall


def first_reactions(folder, supports):
    """The first non-zero normal_reaction of each rail support in timeseries.csv, and its time."""
    out = {}
    with open(folder / "timeseries.csv") as f:
        rows = csv.reader(row for row in f if not row.startswith("#"))
        header = next(rows)
        columns = {s: header.index(s + ".normal_reaction") for s in supports if s + ".normal_reaction" in header}
        for row in rows:
            for s, c in columns.items():
                if s not in out and float(row[c]) != 0.0:
                    out[s] = (float(row[0]), float(row[c]))
            if len(out) == len(columns):
                break
    return out


def histories(folder, supports, interface):
    """Per rail support: the lowest reaction after the first non-zero one (and its time) and the
    largest; for the interface anticlimber: its vertical offset's largest and smallest value and
    their times. From timeseries.csv (the output rows)."""
    with open(folder / "timeseries.csv") as f:
        rows = list(csv.reader(row for row in f if not row.startswith("#")))
    header, rows = rows[0], rows[1:]
    t = [float(r[0]) for r in rows]
    out = {}
    for s in supports:
        c = header.index(s + ".normal_reaction")
        q = [float(r[c]) for r in rows]
        first = next(k for k, v in enumerate(q) if v != 0.0)
        sign = 1.0 if q[first] > 0 else -1.0
        later = [(sign * q[k], t[k]) for k in range(first + 1, len(q))]
        out[s] = (min(later), max(later))
    if interface and interface + ".vertical_offset" in header:
        c = header.index(interface + ".vertical_offset")
        v = [(float(r[c]), t[k]) for k, r in enumerate(rows)]
        out[interface] = (max(v), min(v))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("binary")
    parser.add_argument("--model", default="models/scenarios/scenario1_emu3.yaml")
    parser.add_argument("--dts", default="1e-4,3e-5,1e-5,3e-6", help="Euler steps [s] besides its own, comma-separated")
    parser.add_argument("--out", default="out/euler_convergence")
    parser.add_argument("--reuse", action="store_true", help="read the runs already in --out instead of running them")
    a = parser.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    runs = [("ida", ["--integrator", "ida"]), ("ida rtol 1e-8", ["--integrator", "ida", "--rtol", "1e-8"]),
            ("auto", ["--integrator", "auto"]), ("euler (own dt)", ["--integrator", "euler"])]
    runs += [("euler dt %s" % dt, ["--integrator", "euler", "--dt", dt]) for dt in a.dts.split(",")]
    results = []
    for k, (label, args) in enumerate(runs):
        folder = out / ("run%d" % k)
        if a.reuse and (folder / "summary.json").exists():
            summary, wall = json.loads((folder / "summary.json").read_text()), float("nan")
        else:
            summary, wall = run(a.binary, a.model, folder, args)
        results.append((label, folder, summary, wall))
    length = results[0][2]["units"]["length"]
    print("%s, criteria by run (%s):\n" % (a.model, "mean deceleration in g, wheel unloading (Q0 - Q) / Q0, lengths in " + length))
    print("| criterion | subject | " + " | ".join(label for label, *_ in results) + " |")
    print("|---|---|" + "---|" * len(results))
    rows = {}
    for _, _, summary, _ in results:
        for c in summary["scenario"]["criteria"]:
            rows.setdefault((c["criterion"], c["subject"]), None)
    for criterion, subject in rows:
        cells = []
        for _, _, summary, _ in results:
            c = next((c for c in summary["scenario"]["criteria"] if (c["criterion"], c["subject"]) == (criterion, subject)), None)
            cells.append("-" if c is None else "%.4g" % (c["value_g"] if criterion == "mean_deceleration" else c["value"]))
        print("| %s | %s | %s |" % (criterion, subject, " | ".join(cells)))
    print("| steps | | " + " | ".join(str(s["stats"]["steps"]) for _, _, s, _ in results) + " |")
    print("| Euler's stability limit [s] | | " + " | ".join("%.3g" % s["stats"]["stability_limit"] if s["stats"].get("stability_limit") else "-"
                                                      for _, _, s, _ in results) + " |")
    print("| last step [s] | | " + " | ".join("%.3g" % s["stats"]["last_step"] for _, _, s, _ in results) + " |")
    print("| integrator used | | " + " | ".join(s["integrator_used"]["method"] if s.get("integrator_used") else s["integrator"]
                                             for _, _, s, _ in results) + " |")
    print("| wall [s] | | " + " | ".join("%.2f" % w for *_, w in results) + " |")
    supports = [c["subject"] for c in results[0][2]["scenario"]["criteria"] if c["criterion"] == "wheel_unloading"]
    if supports:
        print("\nFirst non-zero rail reaction (the criterion's Q0), t [s] and Q [%s]:\n" % results[0][2]["units"]["force"])
        print("| support | " + " | ".join(label for label, *_ in results) + " |")
        print("|---|" + "---|" * len(results))
        firsts = [first_reactions(folder, supports) for _, folder, _, _ in results]
        for s in supports:
            print("| %s | %s |" % (s, " | ".join("%.3g: %.6g" % f[s] if s in f else "-" for f in firsts)))
        interface = next((c["subject"] for c in results[0][2]["scenario"]["criteria"] if c["criterion"] == "override"), "")
        print("\nAfter it, from the output rows: each support's lowest and largest reaction [%s] (t [s]), and the interface's "
              "vertical offset, largest and smallest [%s] (t [s]):\n" % (results[0][2]["units"]["force"], length))
        print("| quantity | " + " | ".join(label for label, *_ in results) + " |")
        print("|---|" + "---|" * len(results))
        h = [histories(folder, supports, interface) for _, folder, _, _ in results]
        for s in supports:
            print("| %s lowest | %s |" % (s, " | ".join("%.7g (%.3g)" % x[s][0] for x in h)))
            print("| %s largest | %s |" % (s, " | ".join("%.7g (%.3g)" % x[s][1] for x in h)))
        if interface and interface in h[0]:
            print("| %s vertical offset largest | %s |" % (interface, " | ".join("%.5g (%.3g)" % x[interface][0] for x in h)))
            print("| %s vertical offset smallest | %s |" % (interface, " | ".join("%.5g (%.3g)" % x[interface][1] for x in h)))


if __name__ == "__main__":
    main()
