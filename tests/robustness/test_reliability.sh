#!/bin/bash
# What the study writers, the plan limits and the job count guarantee (issue 36; README
# "Reliability"), each staged for real:
#   full disk     a 64 KiB tmpfs filled to the last byte (mount needs root: CI runs as root;
#                 without it those checks are skipped and the test says so)
#   planted link  converge.md a symbolic link to another file; converge.svg a FIFO
#   huge plans    a readings plan of 2^22 combinations, stopped by SIGTERM while it is checked
#   thread limit  --jobs 64 under `ulimit -u 6` as an unprivileged user (setpriv; root only)
# usage: test_reliability.sh RAILCRASH SOURCE_DIR
set -u
bin=$1
src=$2
models=$src/tests/robustness/models
oscillator=$models/oscillator.yaml
two_car=$src/models/report/final_two_car.yaml
tmp=$(mktemp -d)
full=$tmp/full
mounted=0
cleanup() {
  [ "$mounted" = 1 ] && umount "$full"
  rm -rf "$tmp"
}
trap cleanup EXIT
passes=0
failures=0
skipped=""
source "$src/tests/cli/expect.sh"

no_temporary_files() {  # description folder: the writer left no temporary file behind
  if ls -A "$2" | grep -q '\.tmp-'; then
    echo "FAIL: $1: temporary files left in $2: $(ls -A "$2" | grep '\.tmp-' | tr '\n' ' ')"
    failures=$((failures + 1))
  else
    passes=$((passes + 1))
  fi
}

same_text() {  # description file text: the file holds exactly this text
  if [ -f "$2" ] && [ "$(cat "$2")" = "$3" ]; then
    passes=$((passes + 1))
  else
    echo "FAIL: $1: $2 does not hold '$3' (it holds '$(head -c 200 "$2" 2>/dev/null)')"
    failures=$((failures + 1))
  fi
}

converge_quick=(--euler-steps 2 --rtols 1e-3 --quantities displacement_rms)

# --- A full disk: every writer exits non-zero naming the file and the reason, and a file it
# could not write keeps its old content (the new one goes to a temporary file and a rename).
mkdir -p "$full"
if mount -t tmpfs -o size=64k tmpfs "$full" 2> /dev/null; then
  mounted=1
  mkdir "$full/converge" "$full/sensitivity"
  printf 'old table\n' > "$full/converge/converge.csv"
  printf 'old model\n' > "$full/consist.yaml"
  dd if=/dev/zero of="$full/filler" bs=4k 2> /dev/null  # until the disk is full (ENOSPC)
  dd if=/dev/zero of="$full/filler_tail" bs=512 2> /dev/null

  expect_status "converge on a full disk exits 1" 1 "$bin" converge "$oscillator" "${converge_quick[@]}" --out "$full/converge"
  expect_text "it names the file and the reason" "$tmp/stderr" "cannot write '$full/converge/converge.csv': No space left on device"
  same_text "the old converge.csv is whole" "$full/converge/converge.csv" "old table"
  no_temporary_files "converge on a full disk" "$full/converge"

  expect_status "sensitivity on a full disk exits 1" 1 "$bin" sensitivity "$two_car" --only P1 --first-order --jobs 2 \
    --out "$full/sensitivity"
  expect_text "it names the file and the reason" "$tmp/stderr" "cannot write '$full/sensitivity/sensitivity.csv': No space left on device"
  no_temporary_files "sensitivity on a full disk" "$full/sensitivity"

  expect_status "consist to a full disk exits 1" 1 "$bin" consist "$two_car" --cars 2 --out "$full/consist.yaml"
  expect_text "it names the file and the reason" "$tmp/stderr" "cannot write '$full/consist.yaml': No space left on device"
  same_text "the old consist.yaml is whole" "$full/consist.yaml" "old model"
  no_temporary_files "consist on a full disk" "$full"
else
  skipped="$skipped full-disk (mount -t tmpfs is not permitted: not root)"
fi

# --- Planted files: a link is replaced, not written through; a FIFO is replaced, not opened
# (opened for writing, it would block the writer until a reader came).
mkdir "$tmp/planted"
printf 'precious\n' > "$tmp/victim"
ln -s "$tmp/victim" "$tmp/planted/converge.md"
mkfifo "$tmp/planted/converge.svg"
expect_status "converge with a planted link and FIFO" 0 timeout -k 5 20 "$bin" converge "$oscillator" "${converge_quick[@]}" --out "$tmp/planted"
same_text "the link's target is untouched" "$tmp/victim" "precious"
if [ -f "$tmp/planted/converge.md" ] && [ ! -L "$tmp/planted/converge.md" ] && [ -f "$tmp/planted/converge.svg" ] &&
   [ ! -p "$tmp/planted/converge.svg" ]; then
  passes=$((passes + 1))
else
  echo "FAIL: converge.md and converge.svg are not regular files after the run"
  ls -l "$tmp/planted"
  failures=$((failures + 1))
fi
expect_text "converge.md is the study's" "$tmp/planted/converge.md" "displacement_rms"

# --- A plan too big to hold: refused before any model is loaded, in well under a second.
start=$(date +%s%N)
expect_status "2^22 combinations refused" 2 timeout -k 5 20 "$bin" readings "$two_car" --readings "$models/readings_4m.yaml" --out "$tmp/readings"
elapsed_ms=$((($(date +%s%N) - start) / 1000000))
expect_text "with the count and the limit" "$tmp/stderr" "4194304 combinations of the readings x 40 runs each: 167772160 runs, more than the limit of 1000000 (--max-runs)"
if [ "$elapsed_ms" -lt 5000 ]; then passes=$((passes + 1)); else echo "FAIL: refusing took $elapsed_ms ms"; failures=$((failures + 1)); fi

# --- SIGTERM while a large plan is checked (--max-runs 0 lifts the limit): the checks stop,
# nothing runs, the tables say so, exit 1 within seconds.
"$bin" readings "$two_car" --readings "$models/readings_4m.yaml" --max-runs 0 --out "$tmp/stopped" > "$tmp/stopped.out" 2>&1 &
pid=$!
sleep 1
kill -TERM "$pid"
for _ in $(seq 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
if kill -0 "$pid" 2> /dev/null; then
  echo "FAIL: readings still checks 5 s after SIGTERM"
  kill -KILL "$pid"
  failures=$((failures + 1))
fi
wait "$pid"
status=$?
if [ "$status" -eq 1 ]; then passes=$((passes + 1)); else echo "FAIL: readings after SIGTERM: exit $status, expected 1"; failures=$((failures + 1)); fi
expect_text "it says how far it came" "$tmp/stopped.out" "interrupted after 0 of 4194304 combinations"
expect_text "readings.md says so too" "$tmp/stopped/readings.md" "Interrupted after 0 of 4194304 combinations"

# --- --jobs above the process limit: the sweep runs on the threads it can have and says so.
if [ "$(id -u)" = 0 ] && command -v setpriv > /dev/null; then
  jail=$tmp/jail
  chmod 711 "$tmp"  # (mktemp -d's folder is the owner's alone)
  mkdir "$jail"
  cp "$bin" "$oscillator" "$models/sweep_64_runs.yaml" "$jail/"
  chmod 777 "$jail"
  chmod 755 "$jail/$(basename "$bin")"
  chmod 644 "$jail/oscillator.yaml" "$jail/sweep_64_runs.yaml"
  # 6 tasks for uid 65534: this process, the supervisor and four workers.
  expect_status "sweep --jobs 64 under ulimit -u 6 exits 0" 0 setpriv --reuid=65534 --regid=65534 --clear-groups \
    bash -c "ulimit -u 6 && exec '$jail/$(basename "$bin")' sweep '$jail/oscillator.yaml' --plan '$jail/sweep_64_runs.yaml' --jobs 64 --out '$jail/out'"
  expect_text "it says how many threads it runs with" "$tmp/stderr" "railcrash: --jobs 64: only [0-9]* threads\? could be started"
  expect_text "every run is done" "$tmp/stdout" "64 of 64 runs done (0 resumed), 0 failed"
else
  skipped="$skipped thread-limit (needs root and setpriv)"
fi

echo "reliability: $passes checks passed, $failures failed${skipped:+; skipped:$skipped}"
[ "$failures" -eq 0 ]
