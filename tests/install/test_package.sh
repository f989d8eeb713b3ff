#!/usr/bin/env bash
# Builds the Debian packages with CPack and checks them: each declares its Debian
# dependencies (shared libraries found by dpkg-shlibdeps, the -dev packages the CMake package
# finds again), holds the files it should, and works unpacked (the program checks a model,
# the Python module imports and runs one). Usage: test_package.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
source=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cpack --config "$build/CPackConfig.cmake" -B "$work" > "$work/cpack.log" || { cat "$work/cpack.log"; exit 1; }

depends() { dpkg-deb -f "$1" Depends; }
require() {  # require PACKAGE-FILE WORD...: the Depends field names every WORD
  local deb=$1; shift
  for word in "$@"; do
    depends "$deb" | grep -q "$word" || { echo "$(basename "$deb"): Depends lacks $word: $(depends "$deb")"; exit 1; }
  done
  echo "$(basename "$deb"): Depends: $(depends "$deb")"
}
runtime=$(ls "$work"/railcrash_*.deb)
dev=$(ls "$work"/railcrash-dev_*.deb)
require "$runtime" libsundials-idas libklu libyaml-cpp libstdc++6  # KLU directly: railcrash's own linear solver
require "$dev" "railcrash (=" libsundials-dev libsuitesparse-dev libyaml-cpp-dev libeigen3-dev
contains() {  # contains PACKAGE-FILE PATTERN
  dpkg-deb -c "$1" > "$work/contents"
  grep -q "$2" "$work/contents" || { echo "$(basename "$1") has no $2"; exit 1; }
}
contains "$runtime" "usr/bin/railcrash$"
contains "$runtime" "usr/lib/.*librailcrash.so.0.1"
if [ -x "$build/railcrash-mpi" ]; then contains "$runtime" "usr/bin/railcrash-mpi$"; fi  # what railcrash runs under mpirun
if grep -q "^RAILCRASH_HDF5:BOOL=ON" "$build/CMakeCache.txt"; then  # loaded only for --format hdf5, so not a Depends
  dpkg-deb -f "$runtime" Recommends | grep -q libhdf5 || { echo "$(basename "$runtime"): Recommends lacks libhdf5"; exit 1; }
fi
contains "$dev" "usr/include/railcrash/api.hpp"
contains "$dev" "usr/lib/.*cmake/railcrash/railcrashConfig.cmake"
contains "$dev" "usr/lib/.*librailcrash.a"

dpkg-deb -x "$runtime" "$work/root"
LD_LIBRARY_PATH="$work/root/usr/lib" "$work/root/usr/bin/railcrash" check "$source/models/report/final_two_car.yaml" > "$work/check.txt"
head -1 "$work/check.txt"

if ls "$work"/python3-railcrash_*.deb > /dev/null 2>&1; then
  python=$(ls "$work"/python3-railcrash_*.deb)
  require "$python" python3-numpy "python3 (>=" libsundials-idas
  dpkg-deb -x "$python" "$work/root"
  PYTHONPATH="$work/root/usr/lib/python3/dist-packages" /usr/bin/python3 -c "
import railcrash, sys
m = railcrash.load(sys.argv[1], set={'simulation.t_end': 0.01})
r = railcrash.run(m, rtol=1e-4)
assert r.ok and railcrash.__file__.startswith(sys.argv[2]), railcrash.__file__
print('python3-railcrash', railcrash.__version__, 'ran', m.name, 'to t =', r.t[-1])
" "$source/models/report/final_two_car.yaml" "$work/root"
fi
