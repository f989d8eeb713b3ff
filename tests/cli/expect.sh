# Assertions shared by the command-line tests (sourced; the caller sets tmp, passes, failures).

expect_status() {  # description expected-status command...
  local description=$1 expected=$2
  shift 2
  "$@" > "$tmp/stdout" 2> "$tmp/stderr"
  local status=$?
  if [ "$status" -ne "$expected" ]; then
    echo "FAIL: $description: exit status $status, expected $expected"
    sed 's/^/  | /' "$tmp/stderr" "$tmp/stdout" | head -20
    failures=$((failures + 1))
  else
    passes=$((passes + 1))
  fi
}

expect_text() {  # description file pattern
  if grep -q -- "$3" "$2"; then
    passes=$((passes + 1))
  else
    echo "FAIL: $1: '$3' not found in $2"
    sed 's/^/  | /' "$2" | head -20
    failures=$((failures + 1))
  fi
}
