#!/usr/bin/env bash
# One command: install dependencies, build, and run the flagship model.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
model=models/examples/coupled_cars.yaml
echo "== railcrash check $model"
build/railcrash check "$model"
echo "== railcrash run $model --out results/coupled_cars"
build/railcrash run "$model" --out results/coupled_cars
