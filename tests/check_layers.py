#!/usr/bin/python3
"""The layers of design.md 4.1, checked: every source and header under src/<layer>/ and
include/railcrash/<layer>/ includes only its own layer and those before it in LAYERS.
Prints each include that runs back up (file:line, its layer, the included header's) and exits 1
if there is one; also when a file sits outside every layer folder (the public api.hpp/api.cpp
and the Python module's binding code, which use every layer, are the top).

    tests/check_layers.py [REPOSITORY]
"""
import os
import re
import sys

LAYERS = ["core", "model", "elements", "solver", "results", "studies", "scenarios", "report", "cli", "api"]
TOP_LEVEL = {"api.hpp": "api", "api.cpp": "api"}  # include/railcrash/api.hpp, src/api.cpp
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def layer_of(root, path):
    rel = os.path.relpath(path, root).split(os.sep)
    inner = rel[2:] if rel[0] == "include" else rel[1:]
    if len(inner) == 1:
        return TOP_LEVEL.get(inner[0])
    return inner[0] if inner[0] in LAYERS else None


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    problems = 0
    files = 0
    for top in ("src", os.path.join("include", "railcrash")):
        for folder, _, names in os.walk(os.path.join(root, top)):
            for name in sorted(names):
                if not name.endswith((".cpp", ".hpp")):
                    continue
                path = os.path.join(folder, name)
                files += 1
                own = layer_of(root, path)
                if own is None:
                    print(f"{os.path.relpath(path, root)}: in no layer folder ({', '.join(LAYERS[:-1])})")
                    problems += 1
                    continue
                with open(path, encoding="utf-8") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        target = m.group(1)
                        if target.startswith("railcrash/"):
                            included = os.path.join(root, "include", target)
                        else:
                            included = os.path.join(folder, target)
                            if not os.path.exists(included):
                                continue  # generated (build_commit.hpp) or the library's own
                        theirs = layer_of(root, included)
                        if theirs is None or LAYERS.index(theirs) > LAYERS.index(own):
                            print(f"{os.path.relpath(path, root)}:{number}: layer {own} includes {target} (layer {theirs})")
                            problems += 1
    print(f"{files} files in {len(LAYERS)} layers ({' < '.join(LAYERS)}): {problems} include(s) running back up")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
