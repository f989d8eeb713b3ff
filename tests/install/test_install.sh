#!/usr/bin/env bash
# Installs the build into a temporary prefix, builds examples/cpp as an outside project
# against the installed CMake package (shared, then static library), and runs it: the
# example checks a spring-mass period against its closed form and runs a report model.
# Usage: test_install.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
source=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" > "$work/install.log"
for f in bin/railcrash include/railcrash/api.hpp include/railcrash/core/error.hpp lib/cmake/railcrash/railcrashConfig.cmake; do
  [ -e "$prefix/$f" ] || { echo "not installed: $f"; exit 1; }
done
ls "$prefix"/lib*/librailcrash.a "$prefix"/lib*/librailcrash.so > /dev/null
# Only the public headers are installed.
[ "$(ls "$prefix/include/railcrash" | wc -l)" -eq 2 ] || { echo "unexpected headers:"; ls "$prefix/include/railcrash"; exit 1; }
"$prefix/bin/railcrash" check "$source/models/report/final_two_car.yaml" > /dev/null

for kind in shared static; do
  flag=OFF
  [ "$kind" = static ] && flag=ON
  cmake -S "$source/examples/cpp" -B "$work/example-$kind" -G Ninja -DCMAKE_BUILD_TYPE=Release \
        -DCMAKE_PREFIX_PATH="$prefix" -DRAILCRASH_EXAMPLE_STATIC=$flag > "$work/configure-$kind.log" \
    || { cat "$work/configure-$kind.log"; exit 1; }
  cmake --build "$work/example-$kind" > "$work/build-$kind.log" || { cat "$work/build-$kind.log"; exit 1; }
  echo "== $kind library"
  "$work/example-$kind/spring_mass" "$source/models/report/final_two_car.yaml" "simulation.t_end=0.05"
done
if [ -n "$(ldd "$work/example-shared/spring_mass" | grep librailcrash)" ]; then
  echo "shared example links $(ldd "$work/example-shared/spring_mass" | grep -o 'librailcrash[^ ]*' | head -1)"
else
  echo "the shared example does not link librailcrash.so"; exit 1
fi
