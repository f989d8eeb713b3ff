#!/usr/bin/python3
"""Fails when a Catch2 test case has no CTest entry or a CTest entry runs no test case.

CTest learns the Catch2 test cases from `EXECUTABLE --list-test-names-only` (catch_discover_tests),
and runs each as `EXECUTABLE SPEC ...`. A test case whose name CMake or Catch2 mangles (a ';'
splits it into two CTest entries; '\\', '"', a trailing '*' or a leading '~' change what SPEC
selects) gets CTest entries that select no test case, and those pass without running anything.
This script compares, for each EXECUTABLE:
  1. Catch2's test names with the CTest entries that run EXECUTABLE (LABEL only): each name must
     have an entry of the same name, and each entry must be a test name;
  2. each entry's SPEC, given to EXECUTABLE --list-test-names-only, must select exactly the test
     case of the entry's name;
  3. EXECUTABLE must fail a SPEC that selects no test case, and the hidden test case tagged
     [.runner_self_check], which makes no assertion (tests/main.cpp turns on Catch2's warnings
     NoTests and NoAssertions), so that such an entry or test case fails when CTest runs it.
It prints each mismatch and exits 1 if there is one.

Usage: check_test_names.py CTEST BUILD_DIR LABEL EXECUTABLE...
"""
import json
import os
import subprocess
import sys

SELF_CHECK = "[.runner_self_check]"
NO_SUCH_TEST = "no test case has this name (check_test_names.py)"


def catch_names(executable, *spec):
    """The test names EXECUTABLE lists (for SPEC, or all), one per line as Catch2 prints them."""
    listed = subprocess.run([executable, *spec, "--list-test-names-only"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, check=False)
    if listed.returncode < 0:  # the exit status is the number of tests listed; negative is a signal
        sys.exit(f"{executable} --list-test-names-only ended with signal {-listed.returncode}: {listed.stderr}")
    return [line for line in listed.stdout.split("\n") if line]


def ctest_entries(ctest, build_dir, label):
    shown = subprocess.run([ctest, "--test-dir", build_dir, "-N", "-L", f"^{label}$", "--show-only=json-v1"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, check=False)
    if shown.returncode != 0:
        sys.exit(f"ctest --show-only=json-v1 in {build_dir} failed: {shown.stderr}")
    return json.loads(shown.stdout)["tests"]


def runner_problems(executable):
    """What EXECUTABLE lets pass that must fail: a spec that selects nothing, a test case that checks nothing."""
    problems = []
    for spec, expected, what in ((NO_SUCH_TEST, "No test cases matched", "a spec that selects no test case"),
                                 (SELF_CHECK, "No assertions in test case", "a test case that makes no assertion")):
        ran = subprocess.run([executable, spec], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, check=False)
        if ran.returncode == 0 or expected not in ran.stdout:
            problems.append(f"{os.path.basename(executable)} '{spec}' exited with {ran.returncode} without "
                            f"'{expected}': {what} passes (Catch2's warnings NoTests and NoAssertions, tests/main.cpp)")
    return problems


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    ctest, build_dir, label, executables = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
    entries = ctest_entries(ctest, build_dir, label)
    problems = []
    for entry in entries:
        if entry["name"].endswith("_NOT_BUILT"):
            problems.append(f"CTest entry '{entry['name']}': the test executable was not built when CTest read the tests")
    checked = 0
    for executable in executables:
        real = os.path.realpath(executable)
        names = catch_names(executable)
        if not names:
            problems.append(f"{executable} lists no test cases")
        mine = [e for e in entries if e.get("command") and os.path.realpath(e["command"][0]) == real]
        entry_names = [e["name"] for e in mine]
        for name in names:
            if name not in entry_names:
                problems.append(f"Catch2 test '{name}' ({os.path.basename(executable)}) has no CTest entry of that name")
        for name in sorted({n for n in entry_names if entry_names.count(n) > 1}):
            problems.append(f"CTest entry '{name}' is there {entry_names.count(name)} times")
        for entry in mine:
            name, command = entry["name"], entry["command"]
            if name not in names:
                problems.append(f"CTest entry '{name}' is not a Catch2 test of {os.path.basename(executable)} "
                                "(a name split at ';'?)")
                continue
            if len(command) < 2:
                problems.append(f"CTest entry '{name}' runs {os.path.basename(executable)} without a test spec")
                continue
            selected = catch_names(executable, command[1])
            if selected != [name]:
                problems.append(f"CTest entry '{name}' gives the spec '{command[1]}', which selects {selected} "
                                "instead of the test of that name (a character the spec reads specially?)")
            checked += 1
        problems += runner_problems(executable)
    for problem in problems:
        print(f"FAIL: {problem}")
    print(f"{checked} CTest entries (label {label}) each run exactly the Catch2 test case of their name; "
          f"{len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
