#!/usr/bin/env bash
# One command: install dependencies, build, run the whole test suite (unit tests,
# verification cases, the Python module's tests and example, the installed package used from
# an outside project, the Debian packages), then build the unit tests with AddressSanitizer
# and UndefinedBehaviorSanitizer and run them again, then fuzz the model loader (clang,
# libFuzzer) for a fixed number of executions.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs="$(nproc)"

echo "== Release build, unit tests and verification"
scripts/build.sh
ctest --test-dir build --output-on-failure -j "$jobs"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build, unit tests"
# -O1 -g1 (line tables), as the sanitizers' own documentation suggests: half the compile time of
# -O2 -g (initial_conditions.cpp: 27 s against 58 s of CPU), the same checks. The browser tests
# (label "browser": Chromium drawing the report's page) ran in the release stage; here the
# report's C++ runs under the sanitizers in report_compare, cli and the Catch2 report tests.
cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" \
  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DRAILCRASH_SANITIZE=ON > /dev/null
cmake --build build-sanitize --parallel "$jobs" --target railcrash_tests railcrash railcrash_fuzz_replay
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-sanitize --output-on-failure -j "$jobs" -L unit -LE browser

echo "== Fuzzing the model loader and assembly (libFuzzer, ASan + UBSan; README \"Fuzzing\")"
if ! command -v clang++ > /dev/null; then
  echo "no clang++: the fuzzer is not run (scripts/install-deps.sh installs clang and libclang-rt-14-dev)"
  exit 1
fi
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=None "-DCMAKE_CXX_FLAGS=-O1 -gline-tables-only" \
  -DRAILCRASH_FUZZ=ON -DRAILCRASH_REPORT_PLOTS=OFF -DRAILCRASH_MPI=OFF > /dev/null
cmake --build build-fuzz --parallel "$jobs" --target railcrash_fuzz railcrash_fuzz_dict
tests/fuzz/run_fuzzer.sh build-fuzz 100000 "$jobs"
