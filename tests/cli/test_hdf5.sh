#!/usr/bin/env bash
# `railcrash run --format hdf5` as a user meets it: the option's errors (exit 2), and
# DIR/timeseries.h5 read with h5py and pandas (Debian's python3-h5py, python3-pandas) against
# the CSV files of the same run; an interrupted run's file readable with the rows up to then.
# Without HDF5 in the build: the input error that says how to get it.
# Usage: test_hdf5.sh RAILCRASH_BINARY SOURCE_DIR
set -u
bin=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
passes=0
python=/usr/bin/python3

. "$(dirname "$0")/expect.sh"

model=$src/models/report/final_two_car.yaml

expect_status "an unknown format" 2 "$bin" run "$model" --format parquet --out "$tmp/bad"
expect_text "the unknown format's message names the choices" "$tmp/stderr" "csv"

"$bin" run "$model" --t-end 0.001 --format hdf5 --out "$tmp/probe" --quiet > "$tmp/stdout" 2> "$tmp/stderr"
if grep -q "built without HDF5" "$tmp/stderr"; then
  expect_status "hdf5 in a build without it" 2 "$bin" run "$model" --t-end 0.001 --format hdf5 --out "$tmp/probe"
  expect_text "the message says how to get it" "$tmp/stderr" "install Debian's libhdf5-dev"
  echo "$passes passed, $failures failed"
  [ "$failures" -eq 0 ]
  exit
fi

# --version names the HDF5 it was built with: the one h5py (Debian's, on the same library) reports.
hdf5_version=$($python -c "import h5py; print(h5py.version.hdf5_version)")
expect_status "--version" 0 "$bin" --version
expect_text "it names HDF5 and its version" "$tmp/stdout" "^HDF5 $hdf5_version (--format hdf5"

expect_status "run with csv" 0 "$bin" run "$model" --t-end 0.02 --output-interval 0.001 --out "$tmp/csv" --quiet
expect_status "run with hdf5" 0 "$bin" run "$model" --t-end 0.02 --output-interval 0.001 --format hdf5 --out "$tmp/h5" --quiet
expect_text "run names the file" "$tmp/stdout" "timeseries.h5"
expect_text "summary.json names the format" "$tmp/h5/summary.json" '"format": "hdf5"'
expect_status "report of an hdf5 run folder" 0 "$bin" report "$tmp/h5"
expect_text "the report reads timeseries.h5's 21 rows" "$tmp/stdout" "^report of 21 output rows written to $tmp/h5/report.html"
expect_status "run --format hdf5 --report" 0 "$bin" run "$model" --t-end 0.02 --output-interval 0.001 --format hdf5 --report \
  --out "$tmp/h5_report" --quiet
expect_text "it writes the report" "$tmp/stdout" "^report of 21 output rows written to $tmp/h5_report/report.html"

# The issue's case: an HDF5 run into the folder of a CSV run. The run removes the CSV run's
# files and says so; the report then shows the HDF5 run's rows, not the old ones.
cp -r "$tmp/csv" "$tmp/csv_then_h5"
expect_status "an hdf5 run into a csv run's folder" 0 "$bin" run "$model" --t-end 0.02 --output-interval 0.001 --format hdf5 \
  --out "$tmp/csv_then_h5" --quiet
expect_text "it says which files of the csv run it removed" "$tmp/stdout" \
  "^removed the files of an earlier run from $tmp/csv_then_h5/: timeseries.csv, events.csv, accelerations.csv, energy.csv, summary.json, model.json, energy_zones.csv$"
left=$(ls "$tmp/csv_then_h5" | grep -c '\.csv$')
[ "$left" -eq 0 ] && passes=$((passes + 1)) || { echo "FAIL: $left CSV files of the earlier run left"; failures=$((failures + 1)); }
expect_status "report of that folder" 0 "$bin" report "$tmp/csv_then_h5"
expect_text "it reports the hdf5 run" "$tmp/stdout" "^report of 21 output rows written to $tmp/csv_then_h5/report.html"

# A write failing mid-run (files limited to 200 kB, SIGXFSZ ignored: the write fails with EFBIG):
# exit 1 with the file and the reason, not a crash.
expect_status "a write failing mid-run" 1 bash -c "trap '' XFSZ; ulimit -f 200; exec \"\$0\" \"\$@\"" \
    "$bin" run "$model" --t-end 0.1 --output-interval 0.0001 --format hdf5 --out "$tmp/too_large" --quiet
expect_text "it names the file and the reason" "$tmp/stdout" "cannot write $tmp/too_large/timeseries.h5: File too large"

# A consist of 5 + 5 cars: its timeseries (some 1,900 columns) is too wide for one compound
# type, so it is written as a matrix with its column names beside it.
"$bin" consist "$model" --cars 5 --out "$tmp/consist.yaml" > /dev/null
expect_status "consist with csv" 0 "$bin" run "$tmp/consist.yaml" --t-end 0.002 --output-interval 0.001 --out "$tmp/consist_csv" --quiet
expect_status "consist with hdf5" 0 "$bin" run "$tmp/consist.yaml" --t-end 0.002 --output-interval 0.001 --format hdf5 \
    --out "$tmp/consist_h5" --quiet
expect_status "report of the consist's hdf5 folder (a matrix table)" 0 "$bin" report "$tmp/consist_h5"
expect_text "it reads the matrix's 3 rows" "$tmp/stdout" "^report of 3 output rows written to $tmp/consist_h5/report.html"

if ! "$python" -c "import h5py, pandas" 2> /dev/null; then
  echo "h5py or pandas missing for $python (Debian: python3-h5py python3-pandas): the file is not read back here"
else
  # The README's recipe, table by table, against pandas.read_csv of the CSV run.
  if "$python" - "$tmp/h5" "$tmp/csv" "$tmp/consist_h5" "$tmp/consist_csv" > "$tmp/compare" 2>&1 <<'EOF'
import json
import sys
import h5py
import pandas as pd


def table(f, name):  # README "Binary output": a compound dataset, or a matrix and its names
    d = f[name]
    if d.attrs["layout"] == "matrix":
        return pd.DataFrame(d[:], columns=f[name + "_columns"].asstr()[:])
    return pd.DataFrame(d[:])


for h5_dir, csv_dir in [(sys.argv[1], sys.argv[2]), (sys.argv[3], sys.argv[4])]:
    with h5py.File(f"{h5_dir}/timeseries.h5", "r") as f:
        assert f.attrs["railcrash_version"], "no version attribute"
        # The run's id and provenance, as summary.json has them.
        summary = json.load(open(f"{h5_dir}/summary.json"))
        assert f.attrs["run_id"] == summary["run_id"] and len(summary["run_id"]) == 32, (f.attrs["run_id"], summary["run_id"])
        assert json.loads(f.attrs["provenance"]) == summary["provenance"], f.attrs["provenance"]
        for name in ["timeseries", "accelerations", "energy", "events"]:
            frame = table(f, name)
            if name == "events":
                for column in ["element", "event"]:
                    frame[column] = frame[column].str.decode("utf-8")
            csv = pd.read_csv(f"{csv_dir}/{name}.csv", skiprows=1)  # README: the first line is the provenance
            assert list(frame.columns) == list(csv.columns), name
            # The CSV holds 12 significant digits, the file every bit.
            pd.testing.assert_frame_equal(frame, csv, rtol=1e-11, atol=0, check_dtype=False)
            print(h5_dir, name, f[name].attrs["layout"], frame.shape)
EOF
  then
    passes=$((passes + 1))
  else
    echo "FAIL: h5py + pandas read of timeseries.h5 differs from the CSV files"
    sed 's/^/  | /' "$tmp/compare"
    failures=$((failures + 1))
  fi
  expect_text "the timeseries table has the CSV's 21 rows and 390 columns" "$tmp/compare" "h5 timeseries compound (21, 390)"
  expect_text "the consist's timeseries is a matrix" "$tmp/compare" "consist_h5 timeseries matrix (3, "

  # SIGINT mid-run: exit 1, and the file closed with the rows up to the summary's t_reached.
  "$bin" run "$model" --t-end 5 --format hdf5 --out "$tmp/stopped" --quiet > "$tmp/stdout" 2> "$tmp/stderr" &
  pid=$!
  for _ in $(seq 1 100); do  # until the first rows are on disk
    [ -s "$tmp/stopped/timeseries.h5" ] && grep -q '"status": "running"' "$tmp/stopped/summary.json" 2> /dev/null && break
    sleep 0.1
  done
  sleep 0.5
  kill -INT "$pid"
  wait "$pid"
  status=$?
  if [ "$status" -eq 1 ]; then passes=$((passes + 1)); else echo "FAIL: interrupted run: exit $status, expected 1"; failures=$((failures + 1)); fi
  if "$python" - "$tmp/stopped" > "$tmp/compare" 2>&1 <<'EOF'
import json, sys
import h5py
import pandas as pd
folder = sys.argv[1]
summary = json.load(open(f"{folder}/summary.json"))
with h5py.File(f"{folder}/timeseries.h5", "r") as f:
    table = pd.DataFrame(f["timeseries"][:])
assert summary["status"] == "failed" and "interrupted" in summary["message"], summary["message"]
assert len(table) > 1, len(table)
assert abs(table["t"].iloc[-1] - summary["t_reached"]) < 1e-12, (table["t"].iloc[-1], summary["t_reached"])
print("rows", len(table), "up to t =", summary["t_reached"])
EOF
  then
    passes=$((passes + 1))
  else
    echo "FAIL: the interrupted run's timeseries.h5"
    sed 's/^/  | /' "$tmp/compare"
    failures=$((failures + 1))
  fi
fi

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
