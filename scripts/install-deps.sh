#!/usr/bin/env bash
# Installs what railcrash needs to build and test, from Debian 12's packages (as root, or
# through sudo). Does nothing that is already installed. Usage: scripts/install-deps.sh [--bench]
set -euo pipefail
# file + dpkg-dev: CPack's Debian packages (their dependencies come from dpkg-shlibdeps).
# pybind11 + numpy + python3-dev: the Python module; pandas and matplotlib: its dataframe()
# and the Python example (all from Debian, for /usr/bin/python3; no pip).
# nodejs + npm: the build fetches the run report's plotting library (uPlot, pinned in
# src/report/js/package-lock.json) from the npm registry; chromium: the report's browser test
# and `report --pdf`; poppler-utils: the PDF test turns its pages into images (pdftoppm).
# libopenmpi-dev + openmpi-bin: `railcrash sweep` across ranks (mpirun/srun) and its test.
# clang + libclang-rt-14-dev: the libFuzzer target (README "Fuzzing"; libFuzzer and the
# sanitizer runtimes are in libclang-rt-14-dev).
# libhdf5-dev: `run --format hdf5` (the serial library, pkg-config hdf5-serial); python3-h5py:
# its CLI test reads the file as users would, with h5py and pandas.
# python3-jsonschema + python3-yaml: the test that every model is valid against the model
# file's JSON Schema (docs/railcrash-model.schema.json).
# nlohmann-json3-dev: the report reads a run folder's JSON files with it (header-only).
packages=(build-essential cmake ninja-build pkg-config file dpkg-dev
          libeigen3-dev libsuitesparse-dev libsundials-dev libyaml-cpp-dev libcli11-dev catch2 chromium poppler-utils
          python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pandas python3-matplotlib
          libopenmpi-dev openmpi-bin clang libclang-rt-14-dev libhdf5-dev python3-h5py
          python3-jsonschema python3-yaml nlohmann-json3-dev)
# --bench: also the benchmarks' own (not needed to build or test): libsimbody-dev for the
# Simbody 3.7 comparison in bench/simbody.
[ "${1:-}" = "--bench" ] && packages+=(libsimbody-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# A node.js from elsewhere (e.g. NodeSource, which bundles npm) is fine too.
command -v node > /dev/null || missing+=(nodejs)
command -v npm > /dev/null || missing+=(npm)
if [ ${#missing[@]} -eq 0 ]; then
  echo "railcrash: all build dependencies are installed"
  exit 0
fi
echo "railcrash: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
