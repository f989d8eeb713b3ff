#!/usr/bin/env bash
# `railcrash sweep` from the command line: plan errors exit 2 before any run; 1 job, 2 jobs
# and (given MPIRUN) `mpirun -np 3` write the same runs.csv (wall_seconds aside); --resume
# after a SIGTERM mid-sweep (threads, and mpirun -np 2) writes the same file as an uninterrupted sweep.
# Usage: test_sweep.sh RAILCRASH_BINARY [MPIRUN]
set -u
bin=$1
mpirun=${2:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
passes=0

pass() { passes=$((passes + 1)); }
fail() { echo "FAIL: $1"; failures=$((failures + 1)); }
# runs.csv without the wall_seconds column (the sixth from the end, before message, outcomes, branch, integrator_used
# and euler_from_t; these hold no commas here).
untimed() { awk -F, 'BEGIN { OFS = "," } { $(NF - 5) = ""; print }' "$1"; }
same_rows() {  # description file expected-file
  if [ -f "$2" ] && diff <(untimed "$2") <(untimed "$3") > "$tmp/diff"; then pass; else fail "$1"; sed 's/^/  | /' "$tmp/diff" | head; fi
}

# A 1000 kg car at 2 m/s into an anticlimber against the ground (tests/models/anticlimber_r1.yaml, the R1
# model the C++ and Python tests read too), with a looser tolerance and sparser output.
sed 's/^simulation: .*/simulation: {t_end: 0.15, rtol: 1e-8, output_interval: 0.0005}/' \
  "$(dirname "$0")/../models/anticlimber_r1.yaml" > "$tmp/model.yaml"
cat > "$tmp/plan.yaml" <<'YAML'
sweep: 1
design: latin_hypercube
samples: 12
seed: 3
factors:
  - key: elements.ac.horizontal_yield_deflection
    distribution: {uniform: [0.006, 0.014]}
  - key: bodies.car.velocity[0]
    distribution: {normal: [-2, 0.2]}
responses: [R1, responses.max_anticlimber_crush, car.x@0.01]
YAML

# Plan errors: exit 2, file:line, before any run (no runs.csv).
printf 'sweep: 1\ndesign: full_factorial\nfactors:\n  - {key: elements.ac.stiffnes, levels: [1]}\n' > "$tmp/bad_key.yaml"
"$bin" sweep "$tmp/model.yaml" --plan "$tmp/bad_key.yaml" --out "$tmp/bad" > /dev/null 2> "$tmp/stderr"
status=$?
if [ $status -eq 2 ] && grep -q "bad_key.yaml:4: factor 'elements.ac.stiffnes'" "$tmp/stderr" && [ ! -e "$tmp/bad/runs.csv" ]; then pass
else fail "unknown key: status $status, $(cat "$tmp/stderr")"; fi
printf 'sweep: 1\ndesign: one_at_a_time\nfactors:\n  - key: simulation.t_end\n    levels: [0.1, fast]\n' > "$tmp/bad_level.yaml"
"$bin" sweep "$tmp/model.yaml" --plan "$tmp/bad_level.yaml" --out "$tmp/bad" > /dev/null 2> "$tmp/stderr"
status=$?
if [ $status -eq 2 ] && grep -q "bad_level.yaml:4: factor 'simulation.t_end' at level 'fast'" "$tmp/stderr"; then pass
else fail "wrong level type: status $status, $(cat "$tmp/stderr")"; fi
printf 'sweep: 1\ndesign: latin_hypercube\nsamples: 0\nfactors:\n  - {key: simulation.t_end, distribution: {uniform: [0.1, 0.2]}}\n' > "$tmp/empty.yaml"
"$bin" sweep "$tmp/model.yaml" --plan "$tmp/empty.yaml" --out "$tmp/bad" > /dev/null 2> "$tmp/stderr"
status=$?
if [ $status -eq 2 ] && grep -q "empty.yaml:3: .*the design is empty" "$tmp/stderr"; then pass
else fail "empty design: status $status, $(cat "$tmp/stderr")"; fi

# 1 job (the reference), 2 jobs.
if "$bin" sweep "$tmp/model.yaml" --plan "$tmp/plan.yaml" --jobs 1 --out "$tmp/one" > /dev/null 2>&1; then pass; else fail "sweep with 1 job"; fi
if [ "$(wc -l < "$tmp/one/runs.csv")" -eq 13 ] && ! grep -q ',failed,' "$tmp/one/runs.csv"; then pass; else fail "12 ok rows"; cat "$tmp/one/runs.csv"; fi
"$bin" sweep "$tmp/model.yaml" --plan "$tmp/plan.yaml" --jobs 2 --out "$tmp/two" > /dev/null 2>&1
same_rows "2 jobs give the rows of 1 job" "$tmp/two/runs.csv" "$tmp/one/runs.csv"
if grep -q "Main effects" "$tmp/one/summary.md"; then pass; else fail "summary.md has main effects"; fi

# SIGTERM mid-sweep keeps the finished rows; --resume runs the rest. Longer runs, and 200 of
# them, so that the signal comes mid-sweep: a run takes 0.02-0.03 s at 21b29fd (it took about
# 0.2 s when this was written), and 40 of them under mpirun -np 2 finished in under 0.75 s,
# before the loop below saw the third row.
sed -e 's/^samples: 12/samples: 200/' -e 's/^seed: 3/seed: 3\nset: [simulation.output_interval=0.000003, simulation.rtol=1e-10]/' \
  "$tmp/plan.yaml" > "$tmp/slow.yaml"
"$bin" sweep "$tmp/model.yaml" --plan "$tmp/slow.yaml" --jobs 2 --out "$tmp/whole" > /dev/null 2>&1
interrupt_and_resume() {  # description folder command-prefix...: SIGTERM once 3 rows are written, then --resume
  local description=$1 folder=$2
  shift 2
  "$@" "$bin" sweep "$tmp/model.yaml" --plan "$tmp/slow.yaml" --jobs 1 --out "$folder" > "$folder.out" 2>&1 &
  local pid=$!
  for _ in $(seq 1 400); do  # until 3 rows are written (header + 3)
    [ -f "$folder/runs.csv" ] && [ "$(wc -l < "$folder/runs.csv")" -ge 4 ] && break
    sleep 0.05
  done
  kill -TERM $pid
  wait $pid
  local status=$?
  local rows=$(($(wc -l < "$folder/runs.csv") - 1))
  if [ $status -ne 0 ] && [ $rows -ge 3 ] && [ $rows -lt 200 ]; then pass
  else fail "$description: SIGTERM: status $status with $rows rows (expected failure with 3-199)"; fi
  "$@" "$bin" sweep "$tmp/model.yaml" --plan "$tmp/slow.yaml" --jobs 2 --resume --out "$folder" > "$folder.resume" 2>&1
  if grep -q "($rows resumed)" "$folder.resume"; then pass; else fail "$description: resume keeps the $rows rows: $(cat "$folder.resume")"; fi
  same_rows "$description: --resume after SIGTERM gives the uninterrupted file" "$folder/runs.csv" "$tmp/whole/runs.csv"
}
interrupt_and_resume "threads" "$tmp/cut"

# A variant whose base model is edited between two sweeps: --resume runs every row again and says how many.
mkdir "$tmp/variant"
cp "$tmp/model.yaml" "$tmp/variant/base.yaml"
printf 'railcrash: 1\nvariant_of: base.yaml\nset:\n  name: r1 variant\n' > "$tmp/variant/model.yaml"
"$bin" sweep "$tmp/variant/model.yaml" --plan "$tmp/plan.yaml" --jobs 2 --out "$tmp/variant/out" > /dev/null 2>&1
sed -i 's/horizontal_elastic_stiffness: 1.0e7/horizontal_elastic_stiffness: 1.1e7/' "$tmp/variant/base.yaml"
"$bin" sweep "$tmp/variant/model.yaml" --plan "$tmp/plan.yaml" --jobs 2 --resume --out "$tmp/variant/out" > "$tmp/variant.out" 2>&1
if grep -q "^12 rows of $tmp/variant/out/runs.csv ran with other inputs" "$tmp/variant.out" && grep -q "(0 resumed)" "$tmp/variant.out"; then pass
else fail "--resume after an edit of the base model runs every row again: $(cat "$tmp/variant.out")"; fi

# An edited plan (6 other samples) with --keep-runs: the 12 old folders are removed, with a count.
"$bin" sweep "$tmp/model.yaml" --plan "$tmp/plan.yaml" --jobs 2 --keep-runs --out "$tmp/keep" > /dev/null 2>&1
sed -e 's/^samples: 12/samples: 6/' "$tmp/plan.yaml" > "$tmp/six.yaml"
"$bin" sweep "$tmp/model.yaml" --plan "$tmp/six.yaml" --jobs 2 --keep-runs --resume --out "$tmp/keep" > "$tmp/keep.out" 2>&1
if grep -q "^12 folders of $tmp/keep/runs/ belonged to no row of runs.csv" "$tmp/keep.out" && [ "$(ls "$tmp/keep/runs" | wc -l)" -eq 6 ]; then pass
else fail "an edited plan's --keep-runs folders: $(cat "$tmp/keep.out"; ls "$tmp/keep/runs")"; fi

# A plan of 10^7 runs (issue 36): counted without a list of its runs, run k's levels made from k
# alone, and run, stopped and resumed within 1.5 GB of address space (ulimit -v; a list of its
# runs, as railcrash made before, takes several GB and ends in bad_alloc before the first run).
# AddressSanitizer reserves terabytes of shadow address space at start, which ulimit -v forbids:
# a sanitizer build runs these without the limit (the release build's run of this test holds it).
address_limit=1500000  # [KiB]
if ldd "$bin" 2> /dev/null | grep -q libasan || nm "$bin" 2> /dev/null | grep -q __asan_init; then
  address_limit=unlimited
  echo "note: $bin is built with AddressSanitizer: the 10^7-run plan runs without ulimit -v"
fi
{
  printf 'sweep: 1\ndesign: full_factorial\nfactors:\n'
  for key in horizontal_elastic_stiffness horizontal_plastic_stiffness horizontal_yield_deflection vertical_elastic_stiffness \
             vertical_plastic_stiffness vertical_yield_deflection torsional_elastic_stiffness; do
    printf '  - {key: elements.ac.%s, scale: true, levels: [0.91, 0.92, 0.93, 0.94, 0.95, 0.96, 0.97, 0.98, 0.99, 1.0]}\n' "$key"
  done
  printf 'responses: [R1]\n'
} > "$tmp/huge.yaml"
"$bin" sweep "$tmp/model.yaml" --plan "$tmp/huge.yaml" --out "$tmp/huge" > /dev/null 2> "$tmp/stderr"
status=$?
if [ $status -eq 2 ] && grep -q "huge.yaml: the sweep's plan: 10000000 runs, more than the limit of 1000000 (--max-runs)" "$tmp/stderr"; then pass
else fail "10^7 runs over the default --max-runs: status $status, $(cat "$tmp/stderr")"; fi
# Run k's level of factor f (0-based): 0.91 + 0.01 d, d digit f of k in base 10 (the first factor the
# most significant of 7 digits), against the rows the dry run prints.
levels_right() {  # file with rows run,hash,7 levels: prints the rows whose levels are not the formula's
  awk -F, 'NR > 0 && $1 ~ /^[0-9]+$/ {
    for (f = 0; f < 7; ++f) {
      d = int($1 / 10 ^ (6 - f)) % 10
      if ((($(3 + f)) - (0.91 + 0.01 * d)) ^ 2 > 1e-24) { print "run " $1 " factor " f ": " $(3 + f) ", expected " 0.91 + 0.01 * d }
    }
  }' "$1"
}
(ulimit -v $address_limit; "$bin" sweep "$tmp/model.yaml" --plan "$tmp/huge.yaml" --max-runs 0 --dry-run --show-runs 0,1,10,1234567,9999999) \
  > "$tmp/dry" 2> "$tmp/stderr"
status=$?
if [ $status -eq 0 ] && [ "$(head -1 "$tmp/dry")" = "$tmp/huge.yaml: 10000000 runs" ] && [ "$(grep -c '^[0-9]' "$tmp/dry")" -eq 5 ] &&
   grep -q '^1234567,[0-9a-f]\{16\},0.92,0.93,0.94,0.95,0.96,0.97,0.98$' "$tmp/dry" && [ -z "$(levels_right "$tmp/dry")" ]; then pass
else fail "--dry-run of 10^7 runs: status $status, $(cat "$tmp/dry" "$tmp/stderr"; levels_right "$tmp/dry")"; fi
# The sweep itself, stopped by SIGTERM once runs.csv holds a few rows, then resumed and stopped again.
huge_launcher=()
huge_rows() { local n; n=$( { wc -l < "$tmp/huge/runs.csv"; } 2> /dev/null || echo 1); echo $((n - 1)); }
run_huge_until() {  # ROWS [--resume]: starts the sweep, stops it once runs.csv holds ROWS rows (60 s at most)
  local rows=$1 waited=0
  shift
  if [ ${#huge_launcher[@]} -gt 0 ]; then  # (OpenMPI maps more address space than ulimit -v leaves: no limit)
    "${huge_launcher[@]}" "$bin" sweep "$tmp/model.yaml" --plan "$tmp/huge.yaml" --max-runs 0 --out "$tmp/huge" "$@" \
      > "$tmp/huge.out" 2> "$tmp/huge.err" &
  else
    (ulimit -v $address_limit; exec "$bin" sweep "$tmp/model.yaml" --plan "$tmp/huge.yaml" --max-runs 0 --jobs 2 --out "$tmp/huge" "$@") \
      > "$tmp/huge.out" 2> "$tmp/huge.err" &
  fi
  local pid=$!
  while kill -0 $pid 2> /dev/null && [ "$(huge_rows)" -lt "$rows" ] && [ $waited -lt 600 ]; do sleep 0.1; waited=$((waited + 1)); done
  kill -TERM $pid 2> /dev/null
  wait $pid
  huge_status=$?
}
run_huge_until 4
first_rows=$(huge_rows)
if [ $huge_status -eq 1 ] && [ "$first_rows" -ge 4 ] && grep -q "^$first_rows of 10000000 runs done (0 resumed)" "$tmp/huge.out" &&
   [ -z "$(levels_right "$tmp/huge/runs.csv")" ] && [ "$(awk -F, 'NR == 2 { print $1 "," $10 }' "$tmp/huge/runs.csv")" = "0,ok" ]; then pass
else fail "10^7 runs stopped after $first_rows rows: status $huge_status, $(head -c 600 "$tmp/huge.out" "$tmp/huge.err"; levels_right "$tmp/huge/runs.csv")"; fi
run_huge_until $((first_rows + 4)) --resume
if [ $huge_status -eq 1 ] && [ "$(huge_rows)" -ge $((first_rows + 4)) ] &&
   grep -q "^$(huge_rows) of 10000000 runs done ($first_rows resumed)" "$tmp/huge.out" && [ -z "$(levels_right "$tmp/huge/runs.csv")" ] &&
   [ "$(cut -d, -f1 "$tmp/huge/runs.csv" | sort -u | wc -l)" -eq $(($(huge_rows) + 1)) ]; then pass
else fail "10^7 runs resumed: status $huge_status, $(huge_rows) rows, $(head -c 600 "$tmp/huge.out" "$tmp/huge.err")"; fi

if [ -n "$mpirun" ]; then
  # CI runs as root on 2 cores: allow root, oversubscribe, and yield when idle.
  # OpenMPI keeps some allocations to the end of the process: no leak report in a sanitizer build.
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_mpi_yield_when_idle=1 ASAN_OPTIONS=detect_leaks=0
  interrupt_and_resume "mpirun -np 2" "$tmp/mpi_cut" "$mpirun" --oversubscribe -np 2
  if "$mpirun" --oversubscribe -np 3 "$bin" sweep "$tmp/model.yaml" --plan "$tmp/plan.yaml" --out "$tmp/mpi" > "$tmp/mpi.out" 2>&1; then pass
  else fail "mpirun -np 3: $(tail -5 "$tmp/mpi.out")"; fi
  same_rows "mpirun -np 3 gives the rows of 1 job" "$tmp/mpi/runs.csv" "$tmp/one/runs.csv"
  "$mpirun" --oversubscribe -np 2 "$bin" sweep "$tmp/model.yaml" --plan "$tmp/bad_key.yaml" --out "$tmp/bad" > /dev/null 2> "$tmp/stderr"
  status=$?
  if [ $status -eq 2 ] && [ "$(grep -c "bad_key.yaml:4:" "$tmp/stderr")" -eq 1 ]; then pass
  else fail "mpirun with a bad plan: status $status, $(cat "$tmp/stderr")"; fi
  # The 10^7-run plan over 2 ranks: rank 0 hands out run numbers from a cursor, each rank makes its run from the number.
  rm -rf "$tmp/huge"
  huge_launcher=("$mpirun" --oversubscribe -np 2)
  run_huge_until 4
  first_rows=$(huge_rows)
  if [ $huge_status -ne 0 ] && [ "$first_rows" -ge 4 ] && [ -z "$(levels_right "$tmp/huge/runs.csv")" ]; then pass
  else fail "mpirun: 10^7 runs stopped after $first_rows rows: status $huge_status, $(head -c 600 "$tmp/huge.out" "$tmp/huge.err")"; fi
  run_huge_until $((first_rows + 4)) --resume
  if [ $huge_status -ne 0 ] && [ "$(huge_rows)" -ge $((first_rows + 4)) ] && [ -z "$(levels_right "$tmp/huge/runs.csv")" ] &&
     [ "$(cut -d, -f1 "$tmp/huge/runs.csv" | sort -u | wc -l)" -eq $(($(huge_rows) + 1)) ]; then pass
  else fail "mpirun: 10^7 runs resumed: status $huge_status, $(huge_rows) rows, $(head -c 600 "$tmp/huge.out" "$tmp/huge.err")"; fi
  # --dry-run under a launcher: the plan printed once, by the first process, not once per rank.
  "$mpirun" --oversubscribe -np 2 "$bin" sweep "$tmp/model.yaml" --plan "$tmp/plan.yaml" --dry-run > "$tmp/mpi_dry" 2> "$tmp/stderr"
  status=$?
  "$bin" sweep "$tmp/model.yaml" --plan "$tmp/plan.yaml" --dry-run > "$tmp/dry_alone"
  if [ $status -eq 0 ] && cmp -s "$tmp/mpi_dry" "$tmp/dry_alone"; then pass
  else fail "mpirun -np 2 --dry-run: status $status, printed $(grep -c 'runs$' "$tmp/mpi_dry") time(s): $(head -c 400 "$tmp/mpi_dry" "$tmp/stderr")"; fi
  # railcrash links no MPI and runs railcrash-mpi beside it under a launcher: without it, exit 2 saying so.
  mkdir "$tmp/alone" && cp "$bin" "$tmp/alone/railcrash"
  PMIX_RANK=0 "$tmp/alone/railcrash" sweep "$tmp/model.yaml" --plan "$tmp/plan.yaml" --out "$tmp/alone/out" > /dev/null 2> "$tmp/stderr"
  status=$?
  if [ $status -eq 2 ] && grep -q "cannot start $tmp/alone/railcrash-mpi" "$tmp/stderr" && [ ! -e "$tmp/alone/out" ]; then pass
  else fail "under a launcher without railcrash-mpi: status $status, $(cat "$tmp/stderr")"; fi
fi

echo "$passes passed, $failures failed"
[ $failures -eq 0 ]
