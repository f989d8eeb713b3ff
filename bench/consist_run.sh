#!/bin/bash
# The consist through `railcrash run` against `railcrash_bench consist` (issue 14; bench/HISTORY.md,
# "The run path on a long consist"), and optionally against another railcrash build:
#   bench/consist_run.sh [--cars "20 100 200"] [--rounds 2] [--base OLD/railcrash]
# Per round and size: the bench's process CPU (user + system) and its solver's CPU, `railcrash
# run` on the same model with the bench's rows (t_end / 100) and its run_model wall time, a run
# to 1e-6 s (start-up), and with --base the old build's `run` CPU. Then, over all rounds, each
# executable's `run` CPU median per size and its least-squares exponent.
set -eu
cd "$(dirname "$0")/.."
cars="20 100 200"; rounds=2; base=""; t_end=0.05
while [ $# -gt 0 ]; do
  case $1 in
    --cars) cars=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --base) base=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
work=$(mktemp -d)
cpu() { { /usr/bin/time -f "%U %S" "$@" > /dev/null; } 2>&1 | tail -1 | awk '{print $1 + $2}'; }
for n in $cars; do build/railcrash consist models/report/final_two_car.yaml --cars "$n" --out "$work/c$n.yaml" > /dev/null; done
rows=$(/usr/bin/python3 -c "print($t_end / 100)")
for r in $(seq "$rounds"); do
  for n in $cars; do
    b=$(cpu build/railcrash_bench --results "$work/results.md" consist --cars "$n" --t-end "$t_end")
    solver=$(grep -E "^\| $n \|" "$work/results.md" | tail -1 | awk -F'|' '{print $6}' | tr -d ' ')
    echo "round $r cars $n bench $b solver $solver"
    x=$(cpu build/railcrash run "$work/c$n.yaml" --t-end "$t_end" --output-interval "$rows" --out "$work/o" --quiet)
    echo "round $r cars $n run $x run_model_wall $(/usr/bin/python3 -c "import json;print(json.load(open('$work/o/summary.json'))['stats']['wall_seconds'])")"
    echo "round $r cars $n startup $(cpu build/railcrash run "$work/c$n.yaml" --t-end 1e-6 --output-interval 1e-6 --out "$work/o" --quiet)"
    [ -n "$base" ] && echo "round $r cars $n base_run $(cpu "$base" run "$work/c$n.yaml" --t-end "$t_end" --output-interval "$rows" --out "$work/o" --quiet)"
  done
done | tee "$work/log.txt"
/usr/bin/python3 - "$work/log.txt" <<'PY'
import collections, math, statistics, sys
runs = collections.defaultdict(list)
for line in open(sys.argv[1]):
    f = line.split()
    if f[4] in ("run", "base_run", "bench"):
        runs[(f[4], int(f[3]))].append(float(f[5]))
for what in ("bench", "run", "base_run"):
    sizes = sorted(n for (w, n) in runs if w == what)
    if len(sizes) < 2:
        continue
    med = [statistics.median(runs[(what, n)]) for n in sizes]
    lx = [math.log(n) for n in sizes]; ly = [math.log(c) for c in med]
    mx, my = statistics.fmean(lx), statistics.fmean(ly)
    slope = sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)
    print(f"{what}: median CPU s per size {dict(zip(sizes, [round(c, 2) for c in med]))}, exponent N^{slope:.2f}")
PY
