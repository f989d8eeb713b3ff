#!/usr/bin/env bash
# One command: install dependencies, build, run the whole test suite (unit tests,
# verification cases, the Python module's tests and example, the installed package used from
# an outside project, the Debian packages), then build the unit tests with AddressSanitizer
# and UndefinedBehaviorSanitizer and run them again.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs="$(nproc)"

echo "== Release build, unit tests and verification"
scripts/build.sh
ctest --test-dir build --output-on-failure -j "$jobs"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build, unit tests"
cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRAILCRASH_SANITIZE=ON > /dev/null
cmake --build build-sanitize --parallel "$jobs" --target railcrash_tests railcrash
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-sanitize --output-on-failure -j "$jobs" -L unit
