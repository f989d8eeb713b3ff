#!/usr/bin/python3
"""What the CFC filter's end zone hides: a run's filtered end against the same instant in a longer run.

Runs MODEL to its own t_end and to t_end + --more, and prints per body (summary.json of the
first run) the filtered peak before the end zone (magnitude_cfc), the larger value within it
(magnitude_cfc_end_zone, if any) and, from the longer run's accelerations.csv filtered here
(SAE J211-1 Appendix C, the same two-pass Butterworth and end reflection as
src/results/cfc_filter.cpp, written again), the filtered magnitude at the first run's end
instant: what the end value would have been had the record gone on.

Usage, from the repository root (a few seconds):
  /usr/bin/python3 bench/cfc_end_zone.py [MODEL] [--rtol 1e-9] [--more 0.05]
      [--bodies car1_front_end,car2_bolster_body,car1_draft_housing] [--executable build/railcrash]
"""
import argparse
import csv
import json
import math
import os
import subprocess
import tempfile


def coefficients(cfc, interval):
    wa = math.tan(math.pi * 2.0775 * cfc * interval)
    d = 1.0 + math.sqrt(2.0) * wa + wa * wa
    a0 = wa * wa / d
    return a0, 2.0 * a0, a0, -2.0 * (wa * wa - 1.0) / d, (-1.0 + math.sqrt(2.0) * wa - wa * wa) / d


def one_pass(c, x):
    a0, a1, a2, b1, b2 = c
    x1 = x2 = y1 = y2 = x[0]
    for i, value in enumerate(x):
        y = a0 * value + a1 * x1 + a2 * x2 + b1 * y1 + b2 * y2
        x2, x1, y2, y1 = x1, value, y1, y
        x[i] = y


def cfc_filter(samples, interval, cfc=60.0):
    n = len(samples)
    pad = min(n - 1, math.ceil(4.0 / (2.0775 * cfc * interval)))
    x = [2 * samples[0] - samples[k] for k in range(pad, 0, -1)] + list(samples) + \
        [2 * samples[-1] - samples[n - 1 - k] for k in range(1, pad + 1)]
    c = coefficients(cfc, interval)
    one_pass(c, x)
    x.reverse()
    one_pass(c, x)
    x.reverse()
    return x[pad:pad + n]


def run(executable, model, rtol, out, extra=()):
    """railcrash run MODEL at rtol into out, with extra options; its summary.json."""
    command = [executable, "run", model, "--rtol", rtol, "--out", out, "--quiet", *extra]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def table(path):
    """A CSV file's header and its rows as numbers."""
    with open(path) as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    return rows[0], [[float(v) for v in r] for r in rows[1:]]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("model", nargs="?", default="models/report/final_two_car.yaml")
    parser.add_argument("--rtol", default="1e-9")
    parser.add_argument("--more", type=float, default=0.05)
    parser.add_argument("--bodies", default="car1_front_end,car2_bolster_body,car1_draft_housing")
    parser.add_argument("--executable", default="build/railcrash")
    args = parser.parse_args()
    work = tempfile.mkdtemp(prefix="railcrash-cfc-end-")
    short = run(args.executable, args.model, args.rtol, os.path.join(work, "short"))
    t_end = short["t_reached"]
    run(args.executable, args.model, args.rtol, os.path.join(work, "long"), ["--set", f"simulation.t_end={t_end + args.more!r}"])
    head, data = table(os.path.join(work, "long", "accelerations.csv"))
    times = [r[0] for r in data]
    interval = times[1] - times[0]
    at_end = min(range(len(times)), key=lambda k: abs(times[k] - t_end))
    peaks = short["peak_accelerations"]
    g = peaks["standard_gravity"]
    print(f"{args.model} at rtol {args.rtol}: end zone {1e3 * peaks['filter']['end_zone']:.2f} ms before t_end = {t_end:g} s; "
          f"the longer run to {t_end + args.more:g} s\n")
    print("| body | magnitude_cfc [g] (t) | magnitude_cfc_end_zone [g] (t) | longer run, filtered at t_end [g] |\n|---|---|---|---|")
    for body in args.bodies.split(","):
        p = peaks["bodies"][body]
        ax = cfc_filter([r[head.index(body + ".ax")] for r in data], interval)
        ay = cfc_filter([r[head.index(body + ".ay")] for r in data], interval)
        zone = p.get("magnitude_cfc_end_zone")
        print(f"| {body} | {p['magnitude_cfc']['g']:.3g} ({p['magnitude_cfc']['t']:g}) | "
              f"{'%.4g (%g)' % (zone['g'], zone['t']) if zone else '-'} | {math.hypot(ax[at_end], ay[at_end]) / g:.3g} |")


if __name__ == "__main__":
    main()
