#!/usr/bin/python3
"""Where IDA's integration loses energy: per BDF order and per step after a restart.

    git worktree add /tmp/trace <commit> && cd /tmp/trace && \
        git apply <main>/bench/patches/ida_energy_trace.patch && scripts/build.sh
    RC_TRACE=1 /tmp/trace/build/railcrash run MODEL --integrator ida --rtol R [--set ...] --quiet 2> trace.txt
    /usr/bin/python3 bench/energy_by_order.py trace.txt

The patch (environment switches, none set: the build behaves as its commit) prints after each
IDA step "STEP t order h lost", lost being DaeSystem::work_balance's energy the integration has
lost since the start, and "RESTART t" at each restart; RC_FRAC=F sets the first step after a
restart to F times the step before (kRestartStepFraction, 0.3). This script sums each step's
change of `lost` by the step's BDF order and by how many steps it came after the last restart.
"""
import collections
import sys


def main():
    previous = None
    since = 99
    by_order, by_since = collections.defaultdict(float), collections.defaultdict(float)
    steps_order, steps_since = collections.Counter(), collections.Counter()
    with open(sys.argv[1]) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "RESTART":
                since = 0
                continue
            if p[0] != "STEP":
                continue
            order, lost = int(p[2]), float(p[4])
            if previous is not None:
                by_order[order] += lost - previous
                steps_order[order] += 1
                k = min(since, 10)
                by_since[k] += lost - previous
                steps_since[k] += 1
            previous = lost
            since += 1
    print(f"energy lost in all: {previous:.6g}")
    print("| BDF order | steps | energy lost |")
    print("|---|---|---|")
    for k in sorted(by_order):
        print(f"| {k} | {steps_order[k]} | {by_order[k]:.4g} |")
    print("\n| steps after the last restart | steps | energy lost |")
    print("|---|---|---|")
    for k in sorted(by_since):
        print(f"| {k if k < 10 else '10 or more'} | {steps_since[k]} | {by_since[k]:.4g} |")


if __name__ == "__main__":
    main()
