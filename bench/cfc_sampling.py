#!/usr/bin/python3
"""CFC-60 peaks from a model's own output rows against fine rows: how much sampling moves them.

Runs MODEL at --rtol twice: with its own output interval and with --fine rows (10 us). For
every body it prints the CFC-60 peak of the acceleration magnitude before the filter's end
zone (summary.json's magnitude_cfc) from
  * the fine rows (the reference: the filter's input resolves the pulse),
  * the model's rows, instantaneous accelerations (accelerations.csv: what summary.json
    filters),
  * the model's rows, the mean acceleration over each output interval (velocity differences
    of timeseries.csv, at the intervals' midpoints): an anti-alias box in front of the filter,
each with its error against the reference. summary.json gives the interval means' peak
beside the rows' one (magnitude_cfc_interval_mean) where the two differ by more than 5 %. The filter is bench/cfc_end_zone.py's (SAE J211-1
Appendix C, the end reflection of src/results/cfc_filter.cpp). Standard gravity 386.088 in/s^2
(the crash models' units).

Usage, from the repository root (about half a minute per model):
  /usr/bin/python3 bench/cfc_sampling.py MODEL [--rtol 1e-9] [--fine 1e-5] [--executable build/railcrash]
"""
import argparse
import math
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cfc_end_zone import cfc_filter, run, table  # noqa: E402

G = 386.088


def run_tables(executable, model, rtol, interval, out):
    """The run's summary.json, timeseries.csv and accelerations.csv (rows every `interval`, or the model's)."""
    summary = run(executable, model, rtol, out, ["--output-interval", interval] if interval else [])
    return summary, table(os.path.join(out, "timeseries.csv")), table(os.path.join(out, "accelerations.csv"))


def peak(times, ax, ay, interval, t_max):
    fx, fy = cfc_filter(ax, interval), cfc_filter(ay, interval)
    return max(math.hypot(a, b) for t, a, b in zip(times, fx, fy) if t <= t_max) / G


def peaks(series, body, t_max):
    _, (th, ts), (ah, acc) = series
    times = [r[0] for r in acc]
    interval = times[1] - times[0]
    instantaneous = peak(times, [r[ah.index(body + ".ax")] for r in acc], [r[ah.index(body + ".ay")] for r in acc],
                         interval, t_max)
    vx, vy = [r[th.index(body + ".vx")] for r in ts], [r[th.index(body + ".vy")] for r in ts]
    mid = [0.5 * (a[0] + b[0]) for a, b in zip(ts, ts[1:])]
    mean = peak(mid, [(b - a) / interval for a, b in zip(vx, vx[1:])], [(b - a) / interval for a, b in zip(vy, vy[1:])],
                interval, t_max)
    return instantaneous, mean


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("model")
    parser.add_argument("--rtol", default="1e-9")
    parser.add_argument("--fine", default="1e-5")
    parser.add_argument("--executable", default="build/railcrash")
    args = parser.parse_args()
    work = tempfile.mkdtemp(prefix="railcrash-cfc-sampling-")
    own = run_tables(args.executable, args.model, args.rtol, None, os.path.join(work, "own"))
    fine = run_tables(args.executable, args.model, args.rtol, args.fine, os.path.join(work, "fine"))
    summary, _, (acceleration_header, accelerations) = own
    t_max = summary["t_reached"] - summary["peak_accelerations"]["filter"]["end_zone"]  # before the end zone
    bodies = [c[:-3] for c in acceleration_header if c.endswith(".ax")]
    print(f"{args.model} at rtol {args.rtol}: own rows every {accelerations[1][0] - accelerations[0][0]:g} s against {args.fine} s rows; "
          f"CFC-60 peaks of |a| before t = {t_max:g} s [g]\n")
    print("| body | fine rows | own rows, instantaneous | error | own rows, interval mean | error |\n|---|---|---|---|---|---|")
    errors = ([], [])
    for body in bodies:
        reference = peaks(fine, body, t_max)[0]
        instantaneous, mean = peaks(own, body, t_max)
        errors[0].append(abs(instantaneous / reference - 1.0))
        errors[1].append(abs(mean / reference - 1.0))
        print(f"| {body} | {reference:.4g} | {instantaneous:.4g} | {100 * (instantaneous / reference - 1):+.2f} % | "
              f"{mean:.4g} | {100 * (mean / reference - 1):+.2f} % |")
    for name, e in zip(("instantaneous", "interval mean"), errors):
        print(f"\n{name}: largest |error| {100 * max(e):.2f} %, median {100 * sorted(e)[len(e) // 2]:.2f} %", end="")
    print()


if __name__ == "__main__":
    main()
