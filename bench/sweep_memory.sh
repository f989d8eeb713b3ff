#!/usr/bin/env bash
# Peak memory of a sweep over a large plan, until its first runs are written (issue 36: runs
# generated one at a time). Writes a full-factorial plan of 10^FACTORS runs over the masses of
# the SI 3+3-car multiple unit (models/examples/mu_3plus3_si.yaml, t_end 0.02 s), starts
# `railcrash sweep --jobs 1 --max-runs 0` under /usr/bin/time -v, stops it with SIGTERM once
# runs.csv holds ROWS rows (or after LIMIT seconds), and prints the peak RSS, the seconds to the
# first row and the rows written.
# Usage: bench/sweep_memory.sh RAILCRASH_BINARY [FACTORS=7] [ROWS=3] [LIMIT=300]
set -u
bin=$1
factors=${2:-7}
rows=${3:-3}
limit=${4:-300}
here=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
{
  printf 'sweep: 1\ndesign: full_factorial\nset: [simulation.t_end=0.02]\nfactors:\n'
  for body in a1_body a2_body a3_body b1_body b2_body b3_body a1_end_front a1_end_rear a2_end_front; do
    [ "$factors" -gt 0 ] || break
    printf '  - {key: bodies.%s.mass, scale: true, levels: [0.91, 0.92, 0.93, 0.94, 0.95, 0.96, 0.97, 0.98, 0.99, 1.0]}\n' "$body"
    factors=$((factors - 1))
  done
  printf 'responses: [energy.relative_balance_error]\n'
} > "$tmp/plan.yaml"
start=$(date +%s.%N)
/usr/bin/time -v -o "$tmp/time" "$bin" sweep "$here/models/examples/mu_3plus3_si.yaml" --plan "$tmp/plan.yaml" \
  --jobs 1 --max-runs 0 --out "$tmp/out" > "$tmp/stdout" 2> "$tmp/stderr" &
timer=$!
first=""
while kill -0 $timer 2> /dev/null; do
  written=$(($( { wc -l < "$tmp/out/runs.csv"; } 2> /dev/null || echo 1) - 1))
  [ "$written" -ge 1 ] && [ -z "$first" ] && first=$(echo "$(date +%s.%N) - $start" | bc)
  if [ "$written" -ge "$rows" ] || [ "$(echo "$(date +%s.%N) - $start > $limit" | bc)" = 1 ]; then
    kill -TERM $(pgrep -P $timer) 2> /dev/null  # the sweep: the child of this /usr/bin/time
    break
  fi
  sleep 0.2
done
wait $timer
written=$(($( { wc -l < "$tmp/out/runs.csv"; } 2> /dev/null || echo 1) - 1))
echo "plan: $(grep -c 'key:' "$tmp/plan.yaml") factors x 10 levels; $written rows written; first row after ${first:-never} s"
grep -E "Maximum resident set size|Elapsed" "$tmp/time"
tail -n 2 "$tmp/stderr" | sed 's/^/stderr: /'
