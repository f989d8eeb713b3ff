#!/usr/bin/env bash
# Writes the EN 15227 scenario models of the report's car (models/report/final_two_car.yaml)
# into DIR (default: this folder). Run from the repository root:
#   models/scenarios/make.sh build/railcrash [DIR]
# The limits and the buffer below are the values these examples were generated with, NOT values
# confirmed from the standard (README.md, "Collision scenarios", says which are and why):
#   offset 40 mm, mean deceleration 5 g, survival space 50 mm, override 100 mm, wheel lift 20 mm;
#   buffers: 105 mm stroke (EN 15551's freight-wagon stroke) storing 30 kJ (its category A
#   minimum) on a linear rise to 571.4 kN (5.442 kN/mm), then solid (544.2 kN/mm, 100 times
#   steeper), unloading at the solid slope (the buffer keeps its stroke: the work is dissipated);
#   buffer centre 1060 mm above the rail.
set -eu
bin=$1
dir=${2:-models/scenarios}
train=models/report/final_two_car.yaml
limits=(--deceleration-limit 5 --survival-space-limit 50 --override-limit 100 --wheel-lift-limit 20
        --passenger-bodies center_body --survival-gauge bolster_body,rear_body)
"$bin" scenario 1 --train "$train" --offset 40 "${limits[@]}" --out "$dir/scenario1_report_car.yaml"
"$bin" scenario 2 --train "$train" "${limits[@]}" --buffer-curve 0:0,105:571.4,115:6013.4 \
  --buffer-unloading-stiffness 544.2 --buffer-height 1060 --out "$dir/scenario2_report_car.yaml"
