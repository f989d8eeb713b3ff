#!/usr/bin/env bash
# Writes the EN 15227 scenario models of the report's car (models/report/final_two_car.yaml),
# of the barrier test's two cars (models/barrier/two_car_barrier.yaml) and of the illustrative
# 3-car EMU (models/examples/emu3_unit_collision.yaml, emu3_wall.yaml) into DIR (default:
# this folder). Run from the repository root:
#   models/scenarios/make.sh build/railcrash [DIR]
# The limits and the buffer below are the values these examples were generated with, NOT values
# confirmed from the standard (README.md, "Collision scenarios", says which are and why):
#   offset 40 mm, mean deceleration 5 g, survival space 50 mm, override 100 mm, wheel lift 20 mm;
#   buffers: 105 mm stroke (EN 15551's freight-wagon stroke) storing 30 kJ (its category A
#   minimum) on a linear rise to 571.4 kN (5.442 kN/mm), then solid (544.2 kN/mm, 100 times
#   steeper), unloading at the solid slope (the buffer keeps its stroke: the work is dissipated);
#   buffer centre 1060 mm above the rail.
# The barrier cars' front faces in scenario 1 (the test met a wall, not a second train) take the
# barrier model's own values: 875.6 kN/mm per face = its wall stiffness 5e6 lbf/in (its reading
# 11), 304.8 mm high = its end beams' 12 in depth (its reading 4); their friction coefficient
# 0.3 (illustrative, a dry steel-on-steel value: no source) lets the 40 mm offset act.
set -eu
bin=$1
dir=${2:-models/scenarios}
limits=(--deceleration-limit 5 --survival-space-limit 50 --override-limit 100 --wheel-lift-limit 20)
buffers=(--buffer-curve 0:0,105:571.4,115:6013.4 --buffer-unloading-stiffness 544.2 --buffer-height 1060)
train=models/report/final_two_car.yaml
report_car=(--passenger-bodies center_body --survival-gauge bolster_body,rear_body)
"$bin" scenario 1 --train "$train" --offset 40 "${limits[@]}" "${report_car[@]}" --out "$dir/scenario1_report_car.yaml"
"$bin" scenario 2 --train "$train" "${limits[@]}" "${report_car[@]}" "${buffers[@]}" --out "$dir/scenario2_report_car.yaml"
train=models/barrier/two_car_barrier.yaml
barrier_cars=(--passenger-bodies lead_body,trail_body)
"$bin" scenario 1 --train "$train" --offset 40 "${limits[@]}" "${barrier_cars[@]}" --face-stiffness 875.6 --face-height 304.8 --face-friction 0.3 \
  --out "$dir/scenario1_barrier_cars.yaml"
"$bin" scenario 2 --train "$train" "${limits[@]}" "${barrier_cars[@]}" "${buffers[@]}" --out "$dir/scenario2_barrier_cars.yaml"
# The illustrative 3-car EMU built from car types (models/examples/emu3_*.yaml): its cab front's
# curve reaches the 60 kN/mm survival-space segment at 900 mm, the intermediate car's and every
# rear end's at 200 mm; those are the declared crush zones' strokes.
emu3=(--passenger-bodies body --crush-zones cab_car.front_crush:900,intermediate_car.front_crush:200,rear_crush:200)
"$bin" scenario 1 --train models/examples/emu3_unit_collision.yaml --offset 40 "${limits[@]}" "${emu3[@]}" \
  --out "$dir/scenario1_emu3.yaml"
"$bin" scenario 2 --train models/examples/emu3_wall.yaml "${limits[@]}" "${emu3[@]}" "${buffers[@]}" --out "$dir/scenario2_emu3.yaml"
