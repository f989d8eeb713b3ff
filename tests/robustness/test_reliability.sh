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
  mountpoint -q "$tmp/full2" 2> /dev/null && umount "$tmp/full2"
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

# ============ issue 36, second part: the sweep's runs.csv, HDF5, the folder lock, planted links
# in a run folder, a full-disk CSV run's closing message, the output memory estimate.
plan64=$models/sweep_64_runs.yaml
count_csv_rows() {  # file: the records a CSV reader finds (header included), or "unparsable"
  python3 -c 'import csv,sys
try:
    rows=list(csv.reader(open(sys.argv[1], newline=""), strict=True))
    print(len(rows), sum(1 for r in rows[1:] if len(r) == len(rows[0]) and r[4] == "ok"))
except Exception as e:
    print("unparsable", e)' "$1"
}
same_value() {  # description actual expected
  if [ "$2" = "$3" ]; then passes=$((passes + 1)); else echo "FAIL: $1: '$2', expected '$3'"; failures=$((failures + 1)); fi
}

# --- A resumed runs.csv whose last row was cut inside its quoted message: the row is dropped
# and its run runs again, and the file stays CSV.
expect_status "a 64-run sweep" 0 "$bin" sweep "$oscillator" --plan "$plan64" --jobs 2 --out "$tmp/sweep"
size=$(stat -c %s "$tmp/sweep/runs.csv")
truncate -s $((size - 2)) "$tmp/sweep/runs.csv"  # the last row ends inside its message's quotes
expect_status "resume after a torn last row" 0 "$bin" sweep "$oscillator" --plan "$plan64" --jobs 2 --resume --out "$tmp/sweep"
expect_text "the torn row is named" "$tmp/stdout" "runs.csv (line 65) was cut short"
expect_text "and run again" "$tmp/stdout" "64 of 64 runs done (63 resumed), 0 failed"
same_value "runs.csv parses: 65 records, 64 ok" "$(count_csv_rows "$tmp/sweep/runs.csv")" "65 64"

# --- Garbage in a resumed runs.csv: refused at the start with its line and column.
sed -i '3s/^\([^,]*,[^,]*,[^,]*,[^,]*,ok,\)[^,]*/\1oops/' "$tmp/sweep/runs.csv"
expect_status "resume with garbage in runs.csv" 2 "$bin" sweep "$oscillator" --plan "$plan64" --jobs 2 --resume --out "$tmp/sweep"
expect_text "line and column named" "$tmp/stderr" "runs.csv:3:[0-9]*: bob.x@0.5 'oops' is not a number"

# --- A sweep plan too big: counted without overflow and refused before a run is generated.
python3 - "$tmp" << 'PY'
import sys
tmp = sys.argv[1]
# full factorials of 2^65 and 2^21 runs over the stiffnesses of 65 springs on one body
def plan(name, factors):
    with open(f"{tmp}/{name}", "w") as f:
        f.write("sweep: 1\ndesign: full_factorial\nfactors:\n")
        for k in range(factors):
            f.write(f"  - {{key: elements.s{k}.stiffness, levels: [100, 110]}}\n")
        f.write("responses: [t_reached]\n")
def model(name, springs):
    with open(f"{tmp}/{name}", "w") as f:
        f.write("railcrash: 1\nname: many springs\nunits: SI\ngravity: [0, 0]\nbodies:\n")
        f.write("  - {name: bob, mass: 2, inertia: 0.1, position: [1.1, 0], angle: 0}\nelements:\n")
        for k in range(springs):
            f.write(f"  - {{name: s{k}, type: linear_spring, stiffness: 200, free_length: 1, points: [{{body: ground, at: [0, 0]}}, {{body: bob, at: [0, 0]}}]}}\n")
        f.write("simulation: {t_end: 0.01, output_interval: 0.01}\n")
model("springs.yaml", 65)
plan("plan_2e64.yaml", 65)
plan("plan_2e21.yaml", 21)
# 300 bodies on springs: 1e6 output rows keep about 6 GB for the CFC filter
with open(f"{tmp}/bodies_300.yaml", "w") as f:
    f.write("railcrash: 1\nname: 300 oscillators\nunits: SI\ngravity: [0, 0]\nbodies:\n")
    for k in range(300):
        f.write(f"  - {{name: b{k}, mass: 2, inertia: 0.1, position: [1.1, {k}], angle: 0}}\n")
    f.write("elements:\n")
    for k in range(300):
        f.write(f"  - {{name: s{k}, type: linear_spring, stiffness: 200, free_length: 1, points: [{{body: ground, at: [0, {k}]}}, {{body: b{k}, at: [0, 0]}}]}}\n")
    f.write("simulation: {t_end: 1, output_interval: 1.0e-6}\n")
PY
expect_status "a 2^65-run sweep refused" 2 timeout -k 5 60 "$bin" sweep "$tmp/springs.yaml" --plan "$tmp/plan_2e64.yaml" --out "$tmp/huge"
expect_text "as more than 2^64" "$tmp/stderr" "more than 18446744073709551615"
expect_status "a 2^21-run sweep refused" 2 timeout -k 5 60 "$bin" sweep "$tmp/springs.yaml" --plan "$tmp/plan_2e21.yaml" --out "$tmp/huge"
expect_text "with its count and the limit" "$tmp/stderr" "2097152 runs, more than the limit of 1000000 (--max-runs)"

# --- Two writers, one folder: the second is refused, naming the folder and the first's pid.
"$bin" run "$oscillator" --t-end 100000 --output-interval 0.1 --quiet --out "$tmp/busy" > /dev/null 2>&1 &
first=$!
for _ in $(seq 100); do [ -s "$tmp/busy/summary.json" ] && break; sleep 0.1; done
expect_status "a second run into a busy folder" 2 "$bin" run "$oscillator" --out "$tmp/busy"
expect_text "is refused with the folder and the pid" "$tmp/stderr" "the output folder '$tmp/busy' is being written by another railcrash process (pid $first)"
expect_status "a sweep into it too" 2 "$bin" sweep "$oscillator" --plan "$plan64" --out "$tmp/busy"
kill -KILL "$first"; wait "$first" 2> /dev/null
expect_status "after the first is gone, the folder is free" 0 "$bin" run "$oscillator" --out "$tmp/busy"

# --- kill -9 during an HDF5 run: the file opens without h5clear and holds the rows summary.json
# says are valid.
h5python=""
for candidate in python3 /usr/bin/python3; do
  if "$candidate" -c 'import h5py' 2> /dev/null; then h5python=$candidate; break; fi
done
if "$bin" run "$oscillator" --format hdf5 --out "$tmp/h5probe" > /dev/null 2>&1 && [ -n "$h5python" ]; then
  "$bin" run "$oscillator" --format hdf5 --t-end 100000 --output-interval 0.1 --quiet --out "$tmp/h5" > /dev/null 2>&1 &
  pid=$!
  for _ in $(seq 200); do grep -q '"valid_rows": [1-9]' "$tmp/h5/summary.json" 2> /dev/null && break; sleep 0.1; done
  kill -KILL "$pid"; wait "$pid" 2> /dev/null
  same_value "a killed run's timeseries.h5 opens and holds its valid rows" "$("$h5python" -c '
import h5py, json, sys
summary = json.load(open(sys.argv[1] + "/summary.json"))
valid, t = summary["output"]["valid_rows"], summary["output"]["valid_to_t"]
with h5py.File(sys.argv[1] + "/timeseries.h5", "r") as f:
    times = f["timeseries"]["t"][:valid]
    ok = valid > 0 and len(times) == valid and all(b > a for a, b in zip(times, times[1:])) and abs(times[-1] - t) <= 1e-9 * max(1, abs(t))
    print("ok" if ok else "rows %d, valid %d, last t %g, valid_to_t %g" % (len(times), valid, times[-1] if len(times) else -1, t))
' "$tmp/h5" 2>&1 | tail -1)" "ok"
else
  skipped="$skipped hdf5-kill (no HDF5 in this build or no h5py)"
fi

# --- Planted links in a run folder: never written through.
mkdir "$tmp/links"
printf 'precious\n' > "$tmp/victim_csv"
printf 'precious\n' > "$tmp/victim_tmp"
ln -s "$tmp/victim_csv" "$tmp/links/timeseries.csv"
ln -s "$tmp/victim_tmp" "$tmp/links/summary.json.tmp"
"$bin" run "$oscillator" --out "$tmp/links" > /dev/null 2>&1
same_text "a link named timeseries.csv is not followed" "$tmp/victim_csv" "precious"
same_text "a link named summary.json.tmp is not followed" "$tmp/victim_tmp" "precious"
rm "$tmp/links/timeseries.csv"
expect_status "a run beside a planted summary.json.tmp link" 0 "$bin" run "$oscillator" --out "$tmp/links"
same_text "whose target stays" "$tmp/victim_tmp" "precious"

# --- Output memory: estimated at the start and refused above the limit, with the figures.
expect_status "300 bodies x 1e6 rows refused" 2 timeout -k 5 60 "$bin" run "$tmp/bodies_300.yaml" --quiet --out "$tmp/memory"
expect_text "with the estimate and what lowers it" "$tmp/stderr" "would keep about 6.0[0-9]* GB in memory until its end (300 bodies x 1000002 output rows x 20 B"
expect_text "and the option that raises the limit" "$tmp/stderr" "--max-output-memory GB"

# --- Full disk: a sweep's runs.csv, a CSV run's closing message, HDF5's summary.
full2=$tmp/full2
mkdir -p "$full2"
if mount -t tmpfs -o size=1m tmpfs "$full2" 2> /dev/null; then
  # Two free pages: the lock file's pid takes one, runs.csv's header and its first rows the
  # other; the rest of the 160 rows (about 55 bytes each) does not fit.
  printf 'sweep: 1\ndesign: full_factorial\nfactors:\n  - {key: elements.spring.stiffness, levels: [%s]}\n  - {key: bodies.bob.mass, levels: [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]}\nresponses: [bob.x@0.5]\n' \
    "$(seq -s ', ' 100 10 250)" > "$tmp/sweep_160_runs.yaml"
  mkdir "$full2/sweep"
  dd if=/dev/zero of="$full2/reserve" bs=4096 count=2 2> /dev/null
  dd if=/dev/zero of="$full2/filler" bs=4k 2> /dev/null
  dd if=/dev/zero of="$full2/filler_tail" bs=512 2> /dev/null
  rm "$full2/reserve"
  expect_status "a sweep that fills the disk exits 1" 1 "$bin" sweep "$oscillator" --plan "$tmp/sweep_160_runs.yaml" --jobs 2 --out "$full2/sweep"
  expect_text "naming runs.csv and the reason" "$tmp/stderr" "cannot write '$full2/sweep/runs.csv': No space left on device"
  rows_before=$(grep -c ',ok,' "$full2/sweep/runs.csv")
  if [ "$rows_before" -ge 20 ] && [ "$rows_before" -lt 160 ]; then passes=$((passes + 1)); else
    echo "FAIL: the rows appended before the disk was full: $rows_before, expected 20 to 159"; failures=$((failures + 1)); fi
  rm "$full2/filler"
  expect_status "resumed with room again" 0 "$bin" sweep "$oscillator" --plan "$tmp/sweep_160_runs.yaml" --jobs 2 --resume --out "$full2/sweep"
  expect_text "every run done, the rows on disk resumed" "$tmp/stdout" "160 of 160 runs done ([0-9]* resumed), 0 failed"
  same_value "its runs.csv parses: 161 records, 160 ok" "$(count_csv_rows "$full2/sweep/runs.csv")" "161 160"
  rm -rf "$full2/sweep"

  # A CSV run on a disk with room for a few hundred rows: the message says what the files hold.
  dd if=/dev/zero of="$full2/filler" bs=4k count=40 2> /dev/null
  expect_status "a CSV run that fills the disk" 1 "$bin" run "$oscillator" --t-end 100 --output-interval 0.001 --quiet --out "$full2/csv"
  expect_text "says what timeseries.csv holds" "$tmp/stdout" "timeseries.csv holds the first [0-9]* rows whole, up to t = "
  rows=$(grep -o 'the first [0-9]* rows' "$tmp/stdout" | grep -o '[0-9]*')
  t_held=$(grep -o 'rows whole, up to t = [0-9.e+-]*' "$tmp/stdout" | grep -o '[0-9.e+-]*$')
  # after the provenance comment and the header, at least that many whole rows, the last of them at t_held
  row=$(grep -v '^#' "$full2/csv/timeseries.csv" | sed -n "$((rows + 1))p" | cut -d, -f1)
  same_value "timeseries.csv's row $rows is at that t" "$(python3 -c "print(abs($row - $t_held) <= 1e-9 * max(1, abs($t_held)))")" "True"
  expect_text "summary.json says failed even so" "$full2/csv/summary.json" '"status": "failed"'
  umount "$full2"
else
  skipped="$skipped full-disk-2 (mount -t tmpfs is not permitted: not root)"
fi

# ============ issue 36, third part: the report and hostile run folders, long names, stale
# temporary files.

# --- A 20,000-character element name: refused at load (check and run) with the file, the line,
# the name's start, its length and the limit; nothing is run.
long_name=$(head -c 20000 /dev/zero | tr '\0' 'e')
sed "s/name: spring,/name: $long_name,/" "$oscillator" > "$tmp/long_name.yaml"
for command in check "run --out $tmp/long_name"; do
  expect_status "$command of a model with a 20000-character element name" 2 timeout -k 5 60 "$bin" $command "$tmp/long_name.yaml"
  expect_text "is refused with file, line, start, length and limit" "$tmp/stderr" \
    "long_name.yaml:8: element name 'eeeeeeeeeeeeeeeeeeeeeeeeeeeeeeeeeeeeeeee...' (its first 40 characters) is 20000 characters long, more than the limit of 256"
done

# --- The report of a failed run whose summary.json holds a 100,000-character message, and whose
# model.json names an element with 20,000 characters (std::regex recursion crashed both): the
# report is written and leads with the message.
"$bin" run "$oscillator" --quiet --out "$tmp/long_message" > /dev/null 2>&1
python3 - "$tmp/long_message" <<'PY'
import json, sys
folder = sys.argv[1]
summary = json.load(open(folder + "/summary.json"))
summary["status"], summary["message"] = "failed", "m" * 100000 + ' "quoted" \\ end'
json.dump(summary, open(folder + "/summary.json", "w"), indent=2)
model = json.load(open(folder + "/model.json"))
model["elements"][0]["name"] = "e" * 20000
json.dump(model, open(folder + "/model.json", "w"), indent=2)
PY
expect_status "report with a 100k-character message and a 20k-character element name" 0 timeout -k 5 60 "$bin" report "$tmp/long_message"
expect_text "leads with the failure and its whole message" "$tmp/stderr" "The run FAILED at t = 1 s: mmmmmmmmmm.*mmmm \"quoted\" \\\\ end"
expect_text "and is written" "$tmp/stdout" "written to $tmp/long_message/report.html"

# --- Files that are not regular in a run folder: refused at once (timeout: a hang fails), exit 2,
# the message names the file and what it is.
"$bin" run "$oscillator" --quiet --out "$tmp/hostile" > /dev/null 2>&1
cp -r "$tmp/hostile" "$tmp/hostile_good"
rm "$tmp/hostile/summary.json" && mkfifo "$tmp/hostile/summary.json"
expect_status "report with summary.json a FIFO" 2 timeout -k 2 10 "$bin" report "$tmp/hostile"
expect_text "is refused, naming it" "$tmp/stderr" "'$tmp/hostile/summary.json' is a FIFO (named pipe), not a regular file"
rm "$tmp/hostile/summary.json" && ln -s /dev/zero "$tmp/hostile/summary.json"
expect_status "report with summary.json a link to /dev/zero" 2 timeout -k 2 10 "$bin" report "$tmp/hostile"
expect_text "is refused, naming it" "$tmp/stderr" "'$tmp/hostile/summary.json' is a symbolic link"
rm "$tmp/hostile/summary.json" && cp "$tmp/hostile_good/summary.json" "$tmp/hostile/"  # (rm: cp writes through a link)
rm "$tmp/hostile/timeseries.csv" && mkfifo "$tmp/hostile/timeseries.csv"
expect_status "report with timeseries.csv a FIFO" 2 timeout -k 2 10 "$bin" report "$tmp/hostile"
expect_text "is refused, naming it" "$tmp/stderr" "'$tmp/hostile/timeseries.csv' is a FIFO (named pipe)"
rm "$tmp/hostile/timeseries.csv" && cp "$tmp/hostile_good/timeseries.csv" "$tmp/hostile/"  # (rm: cp into a FIFO blocks)
rm "$tmp/hostile/model.json" && ln -s /dev/zero "$tmp/hostile/model.json"
expect_status "report with model.json a link to /dev/zero" 2 timeout -k 2 10 "$bin" report "$tmp/hostile"
expect_text "is refused, naming it" "$tmp/stderr" "'$tmp/hostile/model.json' is a symbolic link"
rm "$tmp/hostile/model.json"
head -c 70000000 /dev/zero | tr '\0' ' ' > "$tmp/hostile/summary.json"
expect_status "report with a 70 MB summary.json" 2 timeout -k 2 30 "$bin" report "$tmp/hostile"
expect_text "is refused with its size and the limit" "$tmp/stderr" "'$tmp/hostile/summary.json' is 70.0 MB (70000000 bytes), more than the report's limit of 67.1 MB"

# --- Temporary files a killed writer left: the next run or sweep into the folder removes them
# (only the names whole_file.cpp gives, whose writer no longer runs) and says how many.
"$bin" run "$oscillator" --t-end 100000 --output-interval 0.1 --quiet --out "$tmp/killed" > /dev/null 2>&1 &
victim=$!
for _ in $(seq 100); do [ -s "$tmp/killed/summary.json" ] && break; sleep 0.1; done
kill -KILL "$victim"; wait "$victim" 2> /dev/null
# what a kill between a whole file's creation and its rename leaves (the victim's own names)
touch "$tmp/killed/.summary.json.tmp-$victim-7-3fa2c1-0" "$tmp/killed/.converge.md.tmp-$victim-0-1b-0" "$tmp/killed/.notes.tmp-keep"
expect_status "a run into the killed run's folder" 0 "$bin" run "$oscillator" --quiet --out "$tmp/killed"
expect_text "says it removed the killed writer's 2 temporary files" "$tmp/stdout" \
  "removed 2 temporary files of an interrupted railcrash from $tmp/killed/"
same_value "and leaves other files" "$(ls -A "$tmp/killed" | grep -c 'tmp')" "1"
mkdir -p "$tmp/killed_sweep"
touch "$tmp/killed_sweep/.runs.csv.tmp-$victim-0-1b-0"
expect_status "a sweep into a folder with a killed writer's temporary file" 0 "$bin" sweep "$oscillator" --plan "$plan64" --out "$tmp/killed_sweep"
expect_text "says it removed it" "$tmp/stdout" "removed 1 temporary file of an interrupted railcrash from $tmp/killed_sweep/"
no_temporary_files "the sweep's folder" "$tmp/killed_sweep"

echo "reliability: $passes checks passed, $failures failed${skipped:+; skipped:$skipped}"
[ "$failures" -eq 0 ]
