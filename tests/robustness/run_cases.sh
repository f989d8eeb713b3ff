#!/bin/bash
# Runs every hostile input of cases.txt and checks its exit status and message: each must end
# with exit 0, 1 or 2 (never a signal or a timeout) and print the expected fragment.
# usage: run_cases.sh RAILCRASH SOURCE_DIR
set -u
railcrash=$1
source_dir=$2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
seconds_per_case=20
cases=0
failures=0
while IFS= read -r line; do
  [[ -z "$line" || "$line" == \#* ]] && continue
  cases=$((cases + 1))
  expected=$(echo "$line" | cut -d'|' -f1 | xargs)
  fragment=$(echo "$line" | cut -d'|' -f2 | sed 's/^ //; s/ $//')
  arguments=$(echo "$line" | cut -d'|' -f3- | sed 's/^ //')
  touch "$work/file$cases"
  mkdir -p "$work/dir$cases"
  for placeholder in arguments fragment; do
    text=${!placeholder}
    text=${text//@M@/$here/models}
    text=${text//@SRC@/$source_dir}
    text=${text//@OUT@/$work/out$cases}
    text=${text//@FILE@/$work/file$cases}
    text=${text//@DIR@/$work/dir$cases}
    printf -v "$placeholder" '%s' "$text"
  done
  # Words split on spaces, except that a --set value keeps its spaces (the rest of the line).
  if [[ "$arguments" == *"--set "* ]]; then
    read -r -a words <<< "${arguments%%--set *}"
    words+=(--set "${arguments#*--set }")
  else
    read -r -a words <<< "$arguments"
    [[ "$arguments" == *"--out " ]] && words+=("")
  fi
  output=$(timeout -k 5 "$seconds_per_case" "$railcrash" "${words[@]}" 2>&1)
  status=$?
  problem=""
  if [[ $status -gt 2 ]]; then
    problem="ended with status $status (a crash, a signal or the $seconds_per_case s timeout)"
  elif [[ "$status" != "$expected" ]]; then
    problem="exit $status, expected $expected"
  elif [[ "$output" != *"$fragment"* ]]; then
    problem="the message lacks '$fragment'"
  fi
  if [[ -n "$problem" ]]; then
    failures=$((failures + 1))
    echo "FAIL case $cases (railcrash $arguments): $problem"
    echo "$output" | head -5 | sed 's/^/    /'
  fi
done < "$here/cases.txt"
echo "robustness: $cases cases, $((cases - failures)) ended with the expected exit status (0, 1 or 2) and message, $failures did not"
[[ $cases -gt 0 && $failures -eq 0 ]]  # no cases read is a failure too
