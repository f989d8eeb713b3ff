#!/bin/sh
# Errors against rtol on the two crash models (issue 14, item 3): IDA at rtol 1e-3 ... 1e-7
# against an IDA reference at 1e-9, per engineering quantity, with the cost of each run.
# Prints railcrash converge's tables (files in out/accuracy_*). Usage, from the repository root:
#   bench/accuracy.sh [RAILCRASH_BINARY]      (default build/railcrash; about 1 minute)
set -eu
bin=${1:-build/railcrash}
mkdir -p out
for model in models/barrier/two_car_barrier.yaml models/report/final_two_car.yaml; do
  name=$(basename "$model" .yaml)
  case $name in
    two_car_barrier) quantities=max_crush,peak_coupler_force,element.wall.normal_force,element.lead_crush.force,element.climb_limit.normal_force,displacement_rms,acceleration.lead_body,acceleration.trail_body,event.end_beams ;;
    *) quantities="max_crush,peak_anticlimber_force,peak_coupler_force,R1,R2,displacement_rms,acceleration.car1_center_body,acceleration.car2_center_body,event.car2_draft_gear:pin shear,event.anticlimber:contact" ;;
  esac
  echo "== $model"
  "$bin" converge "$model" --euler-steps 0 --rtols 1e-3,1e-4,1e-5,1e-6,1e-7 --reference-rtol 1e-9 \
      --quantities "$quantities" --out "out/accuracy_$name" | sed -n '/^Relative errors/,/^Observed/p' | grep '^|'
done
