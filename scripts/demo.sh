#!/usr/bin/env bash
# One command: install dependencies, build, and run the flagship crash: the report's final
# two-car model, a loaded transit car at 35 mph into a standing unloaded car.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
model=models/report/final_two_car.yaml
echo "== railcrash check $model"
build/railcrash check "$model"
echo "== railcrash run $model --out results/final_two_car --report"
build/railcrash run "$model" --out results/final_two_car --report
