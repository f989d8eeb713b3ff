#!/bin/sh
# Builds railcrash (Release) and runs the benchmarks; figures are printed and appended to
# bench/results.md with the core count and the commit. Usage:
#   bench/run.sh [ab|consist|consist-ab|kernels|memory|numbers|sensitivity|converge|compare|accuracy-compare|work-precision|simbody|outcost|startup|readings|python|sweep|formats|all] [extra options]
# e.g. bench/run.sh consist --cars 2,5,10 --t-end 0.05
set -eu
cd "$(dirname "$0")/.."
what=${1:-all}
[ $# -gt 0 ] && shift
scripts/build.sh >/dev/null
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
if [ -n "$(git status --porcelain 2>/dev/null | grep -v '^??' || true)" ]; then commit="$commit+changes"; fi
bench=build/railcrash_bench
case $what in
  consist|sensitivity|kernels|memory|numbers) $bench --commit "$commit" "$what" "$@" ;;
  # The two-car crash (IDA rtol 1e-3 and 1e-4, Euler at the model's dt) against an older
  # commit built side by side: bench/run.sh compare [COMMIT] (default cbce2b9) [--repeats 3]
  compare) /usr/bin/python3 bench/compare_commit.py "$@" ;;
  # The same crash's engineering-quantity errors, both commits against their own rtol 1e-7 run:
  # bench/run.sh accuracy-compare [COMMIT] [--rtols 1e-3,1e-4]
  accuracy-compare) /usr/bin/python3 bench/compare_accuracy.py "$@" ;;
  # CPU at equal accuracy: both commits' work-precision lines over an rtol grid, the CPU
  # ratio at equal error per quantity: bench/run.sh work-precision [COMMIT] [--repeats 3]
  work-precision) /usr/bin/python3 bench/work_precision.py "$@" ;;
  # A consist against another build, interleaved size by size, phase by phase, and the change of
  # the cost exponent: bench/run.sh consist-ab BASE [--cars 10,20,50,100,200] [--repeats 5]
  consist-ab) /usr/bin/python3 bench/consist_ab.py "$@" ;;
  # Whole runs of given models against another build's executable, interleaved, with a
  # byte-for-byte comparison of the outputs: bench/run.sh ab BASE/railcrash [--models A,B] [--repeats 9]
  ab) /usr/bin/python3 bench/ab_models.py "$@" ;;
  # The slider-crank and Andrews' squeezer against Simbody 3.7 at equal accuracy (install-deps.sh --bench)
  simbody) /usr/bin/python3 bench/simbody/compare.py "$@" ;;
  # Share of a run's CPU that goes to output rows (slider-crank at 1 ms, Andrews at 10 us output;
  # --cases crash: the two crash models at 1 ms)
  outcost) /usr/bin/python3 bench/output_share.py "$@" ;;
  # Start-up (--version, the slider-crank at 0.4 s output) against a base build: bench/run.sh startup --base BASE/railcrash
  startup) /usr/bin/python3 bench/startup.py "$@" ;;
  python) PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py "$@" ;;
  sweep) /usr/bin/python3 bench/sweep_bench.py "$@" ;;   # runs/s of `railcrash sweep`, 1 and 2 jobs, 2 MPI ranks
  formats) /usr/bin/python3 bench/output_format.py build/railcrash "$commit" "$@" ;;  # CPU and bytes, --format csv vs hdf5
  converge) build/railcrash converge models/report/final_two_car.yaml --t-end 0.5 --levels 1e-2,1e-3,1e-4 \
              --out bench/converge_final_two_car_0.5s "$@" ;;
  readings)
    # The report's reading study: 64 combinations x 40 runs (issue 10's goal: under 30 min on 2 cores).
    start=$(date +%s)
    mkdir -p out  # a study's --out must have an existing parent folder
    build/railcrash readings models/report/final_two_car.yaml --readings models/report/readings.yaml --jobs "$(nproc)" \
        --out out/readings "$@" > /dev/null
    seconds=$(( $(date +%s) - start ))
    load=$(cut -d' ' -f1-3 /proc/loadavg)
    line="readings (models/report/readings.yaml, 64 combinations x 40 runs, --jobs $(nproc)): ${seconds} s wall; load average at the end ${load}; commit $commit, $(nproc) cores"
    echo "$line"
    printf -- '- %s: %s\n' "$(date -u +%Y-%m-%d)" "$line" >> bench/results.md ;;
  all)
    $bench --commit "$commit" consist --t-end 0.05
    $bench --commit "$commit" kernels --cars 2,10,20,50,100
    $bench --commit "$commit" sensitivity
    build/railcrash converge models/report/final_two_car.yaml --t-end 0.5 --levels 1e-2,1e-3,1e-4 \
        --out bench/converge_final_two_car_0.5s ;;
  *) echo "usage: bench/run.sh [consist|kernels|memory|numbers|sensitivity|converge|compare|accuracy-compare|work-precision|simbody|outcost|startup|readings|python|sweep|formats|all] [options]" >&2; exit 2 ;;
esac
