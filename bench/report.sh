#!/bin/sh
# How long the run report of an N + N-car consist (default 100 + 100, built from the report's
# final two-car model, T_END s simulated) takes to write and to open in headless Chromium
# (the page's own measure: navigation start to everything drawn). Not part of the test suite.
# Usage: bench/report.sh [CARS] [T_END]      e.g. bench/report.sh 100 0.05 (about 2 minutes)
set -eu
cd "$(dirname "$0")/.."
cars=${1:-100}
t_end=${2:-0.05}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
build/railcrash consist models/report/final_two_car.yaml --cars "$cars" --out "$out/consist.yaml" 2>/dev/null
build/railcrash run "$out/consist.yaml" --out "$out/run" --quiet --set simulation.t_end="$t_end" > /dev/null || true
start=$(date +%s.%N)
build/railcrash report "$out/run" > /dev/null
end=$(date +%s.%N)
size=$(stat -c %s "$out/run/report.html")
rows=$(($(grep -vc '^#' "$out/run/timeseries.csv") - 1))  # less the provenance line and the header
for attempt in 1 2 3; do
  ms=$(timeout 120 chromium --headless=new --no-sandbox --disable-gpu --user-data-dir="$out/profile" --dump-dom \
         "file://$out/run/report.html" 2>/dev/null | grep -o '"ms":[0-9]*' | cut -d: -f2)
  echo "$cars + $cars cars, $rows rows: report.html $size bytes written in $(awk "BEGIN { printf \"%.2f\", $end - $start }") s; opened in ${ms:-?} ms (attempt $attempt, $(nproc) cores, $(git rev-parse --short HEAD))"
done
