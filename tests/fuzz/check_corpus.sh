#!/bin/bash
# `railcrash check` on every input of the fuzzer's seed corpus (models/**/*.yaml,
# tests/robustness/models/) and on every regression input (tests/fuzz/regressions/): each must
# end with exit 0, 1 or 2 (never a signal or a timeout), and on 1 or 2 print a message that
# names the file; on 2 (an input error) also the line ("FILE:LINE: "), unless the mistake is
# the file as a whole (cannot be read, not a model: "FILE: ").
# usage: check_corpus.sh RAILCRASH SOURCE_DIR
set -u
railcrash=$1
source_dir=$2
seconds_per_input=20
inputs=0
failures=0
declare -A by_status=([0]=0 [1]=0 [2]=0)
with_line=0
while IFS= read -r -d '' input; do
  inputs=$((inputs + 1))
  output=$(timeout "$seconds_per_input" "$railcrash" check "$input" 2>&1)
  status=$?
  problem=""
  if [[ $status -gt 2 ]]; then
    problem="ended with status $status (a crash, a signal or the $seconds_per_input s timeout)"
  elif [[ $status -ne 0 && "$output" != *"$input"* ]]; then
    problem="exit $status with a message that does not name the file"
  elif [[ $status -eq 2 ]]; then
    if [[ "$output" =~ $(printf '%q' "$input"):[0-9]+:\  ]]; then
      with_line=$((with_line + 1))
    elif [[ "$output" != *"$input: "* ]]; then
      problem="exit 2 without 'FILE:LINE: ' or 'FILE: ' in the message"
    fi
  fi
  [[ $status -le 2 ]] && by_status[$status]=$((by_status[$status] + 1))
  if [[ -n "$problem" ]]; then
    failures=$((failures + 1))
    echo "FAIL $input: $problem"
    echo "$output" | head -5 | sed 's/^/    /'
  fi
done < <(find "$source_dir/models" "$source_dir/tests/robustness/models" -name '*.yaml' -print0 | sort -z
         find "$source_dir/tests/fuzz/regressions" -type f -print0 | sort -z)
echo "fuzz corpus: $inputs inputs checked: ${by_status[0]} exit 0, ${by_status[1]} exit 1, ${by_status[2]} exit 2" \
     "($with_line naming file and line); $failures failed (a signal, a timeout or a message without the file)"
[[ $inputs -gt 0 && $failures -eq 0 ]]
