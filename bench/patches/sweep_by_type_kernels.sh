#!/bin/bash
# Issue 14, item 1: the element kernels with the elements swept (and stored) by type, against
# model order. M: an unpatched Release build's railcrash_bench; X: the same commit with
# bench/patches/sweep_by_type.patch applied (bench/HISTORY.md, "Elements grouped by type").
#   bench/patches/sweep_by_type_kernels.sh [M] [X]
M=${1:-build/railcrash_bench}; X=${2:-/tmp/exp_sort/build/railcrash_bench}
for r in 1 2 3; do
  echo "== round $r"
  echo "-- A main"; $M --results /tmp/junk.md kernels --cars 20,100,200 | grep -E "^\| [0-9]"
  echo "-- B exp model order"; RAILCRASH_MODEL_ORDER=1 $X --results /tmp/junk.md kernels --cars 20,100,200 | grep -E "^\| [0-9]"
  echo "-- C exp type order"; $X --results /tmp/junk.md kernels --cars 20,100,200 | grep -E "^\| [0-9]"
  echo "-- D exp type order + pool by size"; RAILCRASH_POOL_BY_SIZE=1 $X --results /tmp/junk.md kernels --cars 20,100,200 | grep -E "^\| [0-9]"
done
