#!/usr/bin/env bash
# Runs the flagship (models/report/final_two_car.yaml) with --report and saves a screenshot of
# its report, docs/report.png, shown in the README; and the SI example with crush zones
# (models/examples/emu_two_car_crush_zones.yaml): docs/report_crush_zones.png, its report from
# the force-deformation loops over their declared curves to the energy per crush zone.
# Needs build/railcrash, chromium and (for the PDF page) poppler-utils.
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
build/railcrash run models/report/final_two_car.yaml --out "$out/final_two_car" --report > /dev/null
chromium --headless=new --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$out/profile" \
  --window-size=1280,1500 --screenshot="$PWD/docs/report.png" "file://$out/final_two_car/report.html" > /dev/null 2>&1
echo "docs/report.png: $(stat -c %s docs/report.png) bytes"

build/railcrash run models/examples/emu_two_car_crush_zones.yaml --out "$out/emu" --report > /dev/null
chromium --headless=new --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$out/profile" \
  --window-size=1400,1550 --screenshot="$PWD/docs/report_crush_zones.png" "file://$out/emu/report.html#crush-zones" > /dev/null 2>&1
echo "docs/report_crush_zones.png: $(stat -c %s docs/report_crush_zones.png) bytes"

# `railcrash report --pdf` (headless Chromium): the flagship's PDF, its first page as PNG
# (pdftoppm, Debian's poppler-utils), docs/report_pdf_page1.png.
build/railcrash report "$out/final_two_car" --pdf > /dev/null
pdftoppm -png -r 60 -f 1 -l 1 -singlefile "$out/final_two_car/report.pdf" "$PWD/docs/report_pdf_page1"
echo "docs/report_pdf_page1.png: $(stat -c %s docs/report_pdf_page1.png) bytes"

# The study pages (issue 39 item 6): a sweep of the SI draft-gear example across two branch
# changes, the report's first-order sensitivity study, a convergence study.
build/railcrash sweep models/examples/draft_gear_branches_si.yaml --plan tests/report/branch_sweep_plan.yaml --out "$out/sweep" > /dev/null
build/railcrash sensitivity models/report/final_two_car.yaml --first-order --jobs 2 --out "$out/sensitivity" > /dev/null
build/railcrash converge verification/cases/damped_spring_mass.yaml --t-end 0.5 --euler-dt 0.01 --euler-steps 3 --rtols 1e-3,1e-4,1e-5 \
  --quantities displacement_rms --out "$out/converge" > /dev/null
for study in sweep sensitivity converge; do
  build/railcrash report "$out/$study" > /dev/null
  chromium --headless=new --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$out/profile" \
    --window-size=1200,1250 --screenshot="$PWD/docs/report_$study.png" "file://$out/$study/report.html" > /dev/null 2>&1
  echo "docs/report_$study.png: $(stat -c %s docs/report_$study.png) bytes"
done

# Runs side by side (issue 39 item 5): the SI EMU collision at 36 km/h and with the striking unit
# at 43.2 km/h (--set trains.unitA.speed=12000 mm/s), t_end 0.12 s: docs/report_compare.png.
build/railcrash run models/examples/emu3_unit_collision.yaml --t-end 0.12 --out "$out/36kmh" --quiet > /dev/null
build/railcrash run models/examples/emu3_unit_collision.yaml --t-end 0.12 --set trains.unitA.speed=12000 --out "$out/43kmh" --quiet > /dev/null
build/railcrash report "$out/36kmh" "$out/43kmh" --out "$out/compare.html" > /dev/null
chromium --headless=new --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$out/profile" \
  --window-size=1300,2900 --screenshot="$PWD/docs/report_compare.png" "file://$out/compare.html" > /dev/null 2>&1
echo "docs/report_compare.png: $(stat -c %s docs/report_compare.png) bytes"

# Walls (issue 39 item 4): the SI unit into a rigid wall, its cab followed (#follow=unitA.car1),
# at the middle frame (t = 0.2 s): docs/report_wall.png, the animation part of the page.
build/railcrash run models/examples/emu3_wall.yaml --out "$out/wall" --report --quiet > /dev/null
chromium --headless=new --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$out/profile" \
  --window-size=1300,1100 --screenshot="$PWD/docs/report_wall.png" "file://$out/wall/report.html#follow=unitA.car1" > /dev/null 2>&1
echo "docs/report_wall.png: $(stat -c %s docs/report_wall.png) bytes"
