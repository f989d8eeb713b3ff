#!/usr/bin/env bash
# SIGINT / SIGTERM during a study (issue 12): the runs that finished are kept (the tables and CSV
# files are written with them, marked "interrupted after K of N runs"), the run in progress is
# stopped through the batch's stop flag, no other run starts, and the command exits 1 (as `run`
# and `sweep` do when interrupted). The signal is sent once the progress output shows finished
# runs (polled, with a time limit), so the test does not depend on the machine's speed.
# Usage: test_interrupt.sh RAILCRASH_BINARY SOURCE_DIR
set -u
bin=$1
src=$2
tmp=$(mktemp -d)
study_pid=""
trap '[ -n "$study_pid" ] && kill "$study_pid" 2> /dev/null; rm -rf "$tmp"' EXIT
failures=0
passes=0
model=$src/models/report/final_two_car.yaml

check() {  # description command...
  if "${@:2}"; then
    passes=$((passes + 1))
  else
    echo "FAIL: $1"
    failures=$((failures + 1))
  fi
}

# Waits (at most 120 s) until FILE has a line matching PATTERN while the study still runs.
wait_for_line() {  # file pattern
  for _ in $(seq 1 1200); do
    grep -q -- "$2" "$1" 2> /dev/null && return 0
    kill -0 "$study_pid" 2> /dev/null || return 1
    sleep 0.1
  done
  return 1
}

# Sends SIGNAL to the study once FILE shows PATTERN; sets $status to its exit status.
interrupt_when() {  # file pattern signal
  if wait_for_line "$1" "$2"; then
    kill "-$3" "$study_pid"
  else
    echo "FAIL: '$2' never appeared in $1 while the study ran"
    failures=$((failures + 1))
  fi
  wait "$study_pid"
  status=$?
  study_pid=""
}

# sensitivity: one job, SIGINT after the base run and the first parameter's run finished.
"$bin" sensitivity "$model" --jobs 1 --first-order --out "$tmp/sens" > "$tmp/sens.out" 2> "$tmp/sens.err" &
study_pid=$!
interrupt_when "$tmp/sens.err" '^\[2/' INT
check "sensitivity interrupted exits 1 (status $status)" [ "$status" -eq 1 ]
check "it says how many runs finished" grep -q "^interrupted after [0-9]* of 32 runs" "$tmp/sens.out"
check "sensitivity.csv keeps the finished base run" grep -q '^0,0,,,ok,[0-9]' "$tmp/sens/sensitivity.csv"
check "sensitivity.csv keeps the first parameter's run" grep -q '^1,1,P1,1.2,ok,[0-9]' "$tmp/sens/sensitivity.csv"
check "the runs not finished are marked, without responses" grep -q '^31,1,P31,1.2,interrupted,,,,0,0.00,"not run: the study was interrupted"' "$tmp/sens/sensitivity.csv"
check "sensitivity.md says it was interrupted" grep -q '^\*\*Interrupted after [0-9]* of 32 runs\*\*' "$tmp/sens/sensitivity.md"
check "so does comparison.md" grep -q '^\*\*Interrupted after [0-9]* of 32 runs\*\*' "$tmp/sens/comparison.md"
check "no run started after the signal (at most one was in progress)" \
  [ "$(grep -c ',interrupted,' "$tmp/sens/sensitivity.csv")" -ge 29 ]

# converge: SIGTERM once the reference run has finished (one job: the runs go one at a time).
"$bin" converge "$model" --euler-steps 0 --rtols 1e-3,1e-4,1e-5,1e-6 --reference-rtol 1e-7 --quantities max_crush --jobs 1 \
  --out "$tmp/conv" > "$tmp/conv.out" 2> "$tmp/conv.err" &
study_pid=$!
interrupt_when "$tmp/conv.out" '^  reference ' TERM
check "converge interrupted exits 1 (status $status)" [ "$status" -eq 1 ]
check "it says how many runs finished" grep -q "^interrupted after [1-4] of 5 runs" "$tmp/conv.out"
check "converge.csv keeps the reference" grep -q '^reference,.*,ok,' "$tmp/conv/converge.csv"
check "converge.md says it was interrupted" grep -q '^\*\*Interrupted after [1-4] of 5 runs\*\*' "$tmp/conv/converge.md"

echo "interrupt: $passes passed, $failures failed"
[ "$failures" -eq 0 ]
