#!/usr/bin/env bash
# docs/elements.md is generated from the element declarations: this test fails (with the
# difference and the command to regenerate it) when the committed file is out of date.
# Usage: test_element_reference.sh RAILCRASH_BINARY SOURCE_DIR
set -u
bin=$1
src=$2
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
if ! "$bin" elements --markdown > "$tmp"; then
  echo "FAIL: '$bin elements --markdown' exited with status $?"
  exit 1
fi
if ! diff -u "$src/docs/elements.md" "$tmp"; then
  echo "FAIL: docs/elements.md differs from the element declarations (- committed, + generated)."
  echo "Regenerate it from the source folder with: build/railcrash elements --markdown > docs/elements.md"
  exit 1
fi
echo "docs/elements.md matches 'railcrash elements --markdown'"
