#!/usr/bin/env bash
# Opens the report of a small two-car crash (tests/report/two_car.yaml) in headless Chromium
# and fails on any JavaScript error, any resource the page tries to load, an animation that
# draws the same picture at its first and last frame, or a plot without data. The page's
# own self-check (src/report/page/report.js) writes what it saw into #self-check; node reads it.
# Leaves the screenshot in OUTPUT_DIR/report_screenshot.png.
# Usage: test_report_browser.sh RAILCRASH_BINARY SOURCE_DIR CHROMIUM NODE OUTPUT_DIR
set -u
bin=$1 src=$2 chromium=$3 node=$4 out=$5
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$bin" run "$src/tests/report/two_car.yaml" --out "$tmp/run" --report > "$tmp/run.log" 2>&1 || { cat "$tmp/run.log"; fail "run --report"; }
[ -s "$tmp/run/report.html" ] || fail "no report.html"
# The page must need nothing from outside: no src= or href= to load.
if grep -Eq '<(script|link|img|iframe)[^>]* (src|href)=' "$tmp/run/report.html"; then fail "the page refers to an outside resource"; fi

flags=(--headless=new --no-sandbox --disable-gpu --no-first-run --disable-extensions --hide-scrollbars
       --user-data-dir="$tmp/profile" --enable-logging=stderr --v=0)
url="file://$tmp/run/report.html"
# open_page WHAT URL DOM BUDGET SCREENSHOT SIZE: the page's DOM after BUDGET ms of virtual time,
# failing on a script error or a failed load in Chromium's log, then its screenshot.
open_page() {
  local what=$1 page=$2 dom=$3 budget=$4 shot=$5 size=$6
  timeout 120 "$chromium" "${flags[@]}" --virtual-time-budget="$budget" --dump-dom "$page" > "$dom" 2> "$tmp/chromium.log" ||
    fail "chromium --dump-dom ($what)"
  if grep -E "Uncaught|net::ERR_|Failed to load resource" "$tmp/chromium.log"; then fail "JavaScript error in the $what (above)"; fi
  timeout 120 "$chromium" "${flags[@]}" --window-size="$size" --screenshot="$shot" "$page" > /dev/null 2>&1 ||
    fail "chromium --screenshot ($what)"
  [ -s "$shot" ] || fail "no screenshot of the $what"
}
timeout 120 "$chromium" "${flags[@]}" --virtual-time-budget=5000 --dump-dom "$url" > "$tmp/dom.html" 2> "$tmp/chromium.log" ||
  { tail -20 "$tmp/chromium.log"; fail "chromium --dump-dom"; }
# Console errors and failed loads show in Chromium's log.
if grep -E "Uncaught|net::ERR_|Failed to load resource" "$tmp/chromium.log"; then fail "JavaScript error or failed resource (above)"; fi
timeout 120 "$chromium" "${flags[@]}" --window-size=1400,1300 --screenshot="$out/report_screenshot.png" "$url" > /dev/null 2>&1 ||
  fail "chromium --screenshot"

"$node" - "$tmp/dom.html" "$tmp/run/summary.json" <<'JS' || fail "self-check (above)"
const fs = require("fs");
const dom = fs.readFileSync(process.argv[2], "utf8");
const m = dom.match(/<div id="self-check"[^>]*data-status="([a-z]+)"[^>]*>([^<]*)<\/div>/);
const problems = [];
if (!m) { console.log("no self-check in the page: its script did not run to the end"); process.exit(1); }
const check = JSON.parse(m[2].replace(/&quot;/g, '"').replace(/&lt;/g, "<").replace(/&gt;/g, ">").replace(/&amp;/g, "&"));
if (m[1] !== "ran" || check.errors.length) problems.push("script errors: " + JSON.stringify(check.errors));
if (!check.library) problems.push("the plotting library is missing");
if (!check.frames || !check.frames.differ || check.frames.count < 100) problems.push("animation frames: " + JSON.stringify(check.frames));
const expected = ["displacement", "velocity", "acceleration_ax", "acceleration_ay", "forces", "loop:anticlimber", "energy", "energy_zones"];
for (const id of expected) {
  const p = check.plots.find((q) => q.id === id);
  if (!p) problems.push("plot " + id + " missing");
  else if (!(p.points > 0 && p.series > 0 && p.drawn)) problems.push("plot " + id + " has no data: " + JSON.stringify(p));
}
// The anticlimber's loop is drawn over its declared loading curve and unloading line.
const loop = check.plots.find((q) => q.id === "loop:anticlimber");
if (!loop || !(loop.design >= 2)) problems.push("the anticlimber's loop lacks its declared curve and unloading line: " + JSON.stringify(loop));
// Axes: SI prefixes (the forces of this crash are some 100 kN) and no tick label twice on an axis.
if (!check.axes || check.axes.length < 7) problems.push("no tick labels in the self-check: " + JSON.stringify(check.axes));
for (const a of check.axes || []) if (!a.distinct) problems.push("plot " + a.id + " repeats a tick label: " + JSON.stringify(a.labels));
const forceAxis = (check.axes || []).find((a) => a.id === "forces");
if (!forceAxis || forceAxis.y_label !== "kN") problems.push("the force plot's axis is not in kN: " + JSON.stringify(forceAxis));
// Follow a car (issue 39 item 4): the first car stays at the canvas centre at the first and the
// last frame, drawn larger than in the whole-model view.
const follow = check.follow;
if (!follow || follow.car !== "car1" || follow.cars !== 2 || follow.offsets_px.some((d) => Math.abs(d) > 1) || !(follow.zoom > 1.2))
  problems.push("following car1 does not keep it centred and larger: " + JSON.stringify(follow));
// Opened without a time asked: the middle of the run.
if (!check.opened || check.opened.asked !== null || Math.abs(check.opened.index - (check.frames.count - 1) / 2) > 1)
  problems.push("the page does not open at the middle frame: " + JSON.stringify(check.opened));
const jump = check.event_jump;
if (!jump || Math.abs(jump.frame_t - jump.event_t) > jump.spacing || jump.current !== "current")
  problems.push("a click on an event does not move the animation to it: " + JSON.stringify(jump));
if (check.problems !== 0) problems.push(check.problems + " problems listed at the top of a good run's report");
// The model name holds markup: it must be shown as text, never run.
if (!dom.includes("two cars &lt;script&gt;document.title=\"injected\"&lt;/script&gt; &amp; \"quotes\", commas")) problems.push("the model name is not shown as text");
if (/<title>[^<]*injected/.test(dom) && !/<title>railcrash report/.test(dom)) problems.push("the model name ran as a script");
// The provenance block: the run id and the model file's SHA-256 of summary.json, shown.
const provenance = JSON.parse(fs.readFileSync(process.argv[3], "utf8")).provenance;
const block = dom.match(/<details class="provenance" id="provenance"[^>]*>([\s\S]*?)<\/details>/);
if (!block) problems.push("no provenance block");
else if (!block[1].includes("<summary>Provenance: run " + provenance.run_id + "</summary>") ||
         !block[1].includes("sha256 " + provenance.model_files[0].sha256))
  problems.push("the provenance block lacks the run id or the model's SHA-256: " + block[1].slice(0, 400));
if (problems.length) { console.log(problems.join("\n")); process.exit(1); }
console.log("report ok: " + check.plots.length + " plots, " + check.frames.count + " frames");
JS
[ -s "$out/report_screenshot.png" ] || fail "no screenshot"

# report.html#t=last opens at the run's last frame (what `report --pdf` prints: the final
# deformed state), #t=SECONDS at the frame nearest to it.
for asked in last 0.1; do
  timeout 120 "$chromium" "${flags[@]}" --virtual-time-budget=5000 --dump-dom "$url#t=$asked" > "$tmp/dom_t.html" 2> "$tmp/chromium.log" ||
    fail "chromium --dump-dom (#t=$asked)"
  "$node" - "$tmp/dom_t.html" "$asked" <<'JS' || fail "the page opened at #t=$asked (above)"
const fs = require("fs");
const m = fs.readFileSync(process.argv[2], "utf8").match(/<div id="self-check"[^>]*>([^<]*)<\/div>/);
const check = JSON.parse(m[1].replace(/&quot;/g, '"').replace(/&lt;/g, "<").replace(/&gt;/g, ">").replace(/&amp;/g, "&"));
const o = check.opened, asked = process.argv[3], count = check.frames.count;
const ok = asked === "last" ? o.index === count - 1 : Math.abs(o.t - Number(asked)) < 0.002 && o.index > 0 && o.index < count - 1;
if (!o || o.asked !== asked || !ok) { console.log("opened at " + JSON.stringify(o) + " of " + count + " frames"); process.exit(1); }
JS
done

# An EN 15227 scenario's criteria (issue 38's note): wheel unloading is a fraction of the static
# wheel load, (Q0 - Q) / Q0, never labelled with a length unit.
"$bin" run "$src/models/scenarios/scenario1_emu3.yaml" --out "$tmp/scenario" --report --quiet > /dev/null 2>&1 || fail "run scenario1_emu3"
timeout 120 "$chromium" "${flags[@]}" --virtual-time-budget=3000 --dump-dom "file://$tmp/scenario/report.html" > "$tmp/scenario.html" \
  2> /dev/null || fail "chromium --dump-dom (scenario)"
grep -Eq 'wheel unloading: [^<]*</th><td[^>]*>pass: [0-9.e+-]+ of the static wheel load \(limit 1 of the static wheel load' "$tmp/scenario.html" ||
  { grep -o 'wheel unloading[^<]*</th><td[^>]*>[^<]*' "$tmp/scenario.html" | head -2; fail "wheel unloading is not labelled as a fraction of the static wheel load"; }

# The study folders (issue 39 item 6, issue 40 item 5): a convergence study, a sweep across two
# branch changes of an SI model, and a sensitivity study of the report's model: each page's
# charts drawn with the plotting library, without a script error; a screenshot of each.
"$bin" converge "$src/verification/cases/damped_spring_mass.yaml" --t-end 0.5 --euler-dt 0.01 --euler-steps 3 --rtols 1e-3,1e-4 \
  --quantities displacement_rms --out "$tmp/converge" > /dev/null 2>&1 || fail "converge"
"$bin" sweep "$src/models/examples/draft_gear_branches_si.yaml" --plan "$src/tests/report/branch_sweep_plan.yaml" --out "$tmp/sweep" \
  > /dev/null 2>&1 || fail "sweep"
"$bin" sensitivity "$src/models/report/final_two_car.yaml" --only P7,P17 --first-order --out "$tmp/sensitivity" > /dev/null 2>&1 ||
  fail "sensitivity"
for study in converge sweep sensitivity; do
  "$bin" report "$tmp/$study" > /dev/null || fail "report of a $study folder"
  open_page "$study report" "file://$tmp/$study/report.html" "$tmp/$study.html" 3000 "$out/report_$study.png" 1200,1400
done
"$node" - "$tmp" <<'JS' || fail "study pages (above)"
const fs = require("fs");
const tmp = process.argv[2];
const problems = [];
function selfCheck(study) {
  const dom = fs.readFileSync(tmp + "/" + study + ".html", "utf8");
  const m = dom.match(/<div id="self-check"[^>]*data-status="([a-z]+)"[^>]*>([^<]*)<\/div>/);
  if (!m) { problems.push(study + ": the page's script did not run to the end"); return null; }
  const check = JSON.parse(m[2].replace(/&quot;/g, '"').replace(/&lt;/g, "<").replace(/&gt;/g, ">").replace(/&amp;/g, "&"));
  if (m[1] !== "ran" || check.errors.length) problems.push(study + ": script errors " + JSON.stringify(check.errors));
  for (const c of check.charts || []) if (!(c.drawn && c.points > 0)) problems.push(study + ": chart " + c.id + " not drawn: " + JSON.stringify(c));
  return check;
}
function csv(text) { return text.trim().split("\n").map((line) => line.match(/("([^"]|"")*"|[^,]*)(,|$)/g).map((f) => f.replace(/,$/, "").replace(/^"|"$/g, ""))); }
// Converge: the SVG and the error against cost of displacement_rms, Euler's 3 runs and IDA's 2.
const converge = selfCheck("converge");
if (converge) {
  if (!converge.chart || !(converge.tables > 0)) problems.push("converge: no tables or no converge.svg");
  const c = converge.charts.find((q) => q.id === "converge:displacement_rms_error");
  if (!c || c.series !== 2 || c.points !== 5) problems.push("converge: error against cost should have 2 methods and 5 runs: " + JSON.stringify(c));
}
// Sweep: each response against each factor (2 x 2), three branches, the two changes along the
// fracture load at the midpoints of the levels between which runs.csv's branch changes, none along the mass.
const sweep = selfCheck("sweep");
if (sweep) {
  const rows = csv(fs.readFileSync(tmp + "/sweep/runs.csv", "utf8"));
  const h = rows[0], load = h.indexOf("elements.car2_draft_gear.fracture_load"), branch = h.indexOf("branch");
  const branchAt = {};
  for (const r of rows.slice(1)) (branchAt[r[load]] = branchAt[r[load]] || new Set()).add(r[branch]);
  const expected = [];
  const keys = Object.keys(branchAt).sort((a, b) => Number(a) - Number(b));
  for (let k = 1; k < keys.length; ++k)
    if ([...branchAt[keys[k]]].join() !== [...branchAt[keys[k - 1]]].join()) expected.push((Number(keys[k]) + Number(keys[k - 1])) / 2);
  if (JSON.stringify(expected) !== JSON.stringify([1.1e6, 1.25e6])) problems.push("sweep: runs.csv's branches are not the plan's: " + JSON.stringify([...Object.entries(branchAt)].map(([k, v]) => [k, [...v]])));
  if (!sweep.found || sweep.found.branches !== 3) problems.push("sweep: 3 branches expected: " + JSON.stringify(sweep.found));
  if (sweep.charts.length !== 4) problems.push("sweep: 4 charts expected (R1, R2 against 2 factors): " + sweep.charts.map((c) => c.id));
  for (const response of ["R1", "R2"]) {
    const along = sweep.charts.find((c) => c.id === "sweep:" + response + ":elements.car2_draft_gear.fracture_load");
    const mass = sweep.charts.find((c) => c.id === "sweep:" + response + ":bodies.car1.mass");
    if (!along || JSON.stringify(along.marks) !== JSON.stringify(expected)) problems.push("sweep: branch changes along the load " + JSON.stringify(along && along.marks));
    if (!along || along.series !== 4 || along.points !== 8 + 4) problems.push("sweep: a point per run on 3 branch series plus 4 means: " + JSON.stringify(along));
    if (!mass || mass.marks.length !== 0) problems.push("sweep: a branch change along the mass: " + JSON.stringify(mass));
  }
  // R2 is 0 in every run (the model has no anticlimber): its axis runs 0..1, not uPlot's 0..100.
  const r2Values = rows.slice(1).map((r) => Number(r[h.indexOf("R2")]));
  const r2 = sweep.charts.find((c) => c.id === "sweep:R2:bodies.car1.mass");
  if (r2Values.some((v) => v !== 0) || !r2 || JSON.stringify(r2.y) !== "[0,1]") problems.push("sweep: R2 (all 0) axis " + JSON.stringify(r2 && r2.y) + ", expected [0,1]");
  // R1 varies: its axis covers every run's R1 with 5 % to spare.
  const r1Values = rows.slice(1).map((r) => Number(r[h.indexOf("R1")]));
  const r1 = sweep.charts.find((c) => c.id === "sweep:R1:bodies.car1.mass");
  const r1Low = Math.min(...r1Values), r1High = Math.max(...r1Values), r1Pad = 0.05 * (r1High - r1Low);
  if (!r1 || !r1.y || Math.abs(r1.y[0] - (r1Low - r1Pad)) > 1e-9 * r1High || Math.abs(r1.y[1] - (r1High + r1Pad)) > 1e-9 * r1High)
    problems.push("sweep: R1 axis " + JSON.stringify(r1 && r1.y) + ", expected " + JSON.stringify([r1Low - r1Pad, r1High + r1Pad]));
  if (!(sweep.headings >= 3)) problems.push("sweep: summary.md's headings not rendered as headings: " + sweep.headings);
}
// Sensitivity: a tornado chart per response, its bars in the order of |first-order coefficient|.
const sensitivity = selfCheck("sensitivity");
if (sensitivity) {
  const rows = csv(fs.readFileSync(tmp + "/sensitivity/sensitivity_first_order.csv", "utf8"));
  const flagged = new Set(csv(fs.readFileSync(tmp + "/sensitivity/sensitivity_branches.csv", "utf8")).slice(1).map((r) => r[1]));
  for (const [c, response] of [[2, "R1"], [3, "R2"], [4, "R3"]]) {
    const terms = rows.slice(1).filter((r) => r[0] !== "1").sort((a, b) => Math.abs(Number(b[c])) - Math.abs(Number(a[c])));
    const order = terms.map((r) => r[0] + (flagged.has(r[0]) ? " *" : ""));
    const chart = sensitivity.charts.find((q) => q.id === "tornado:" + response);
    if (!chart || JSON.stringify(chart.order) !== JSON.stringify(order)) problems.push("sensitivity: tornado " + response + " order " + JSON.stringify(chart && chart.order) + ", expected " + JSON.stringify(order));
  }
  if (!(sensitivity.headings >= 3)) problems.push("sensitivity: sensitivity.md's headings not rendered: " + sensitivity.headings);
}
if (problems.length) { console.log(problems.join("\n")); process.exit(1); }
console.log("study pages ok: converge, sweep (" + sweep.charts.length + " charts), sensitivity (" + sensitivity.charts.length + " tornado charts)");
JS

# Runs side by side (issue 39 item 5): two runs of the SI EMU collision, the second faster and,
# when this build writes HDF5, as timeseries.h5; the page opens without a script error, every
# chart is drawn with a line per run, and the car crush table's % difference shown for the
# striking cab is the one computed here from the two summary.json files.
emu="$src/models/examples/emu3_unit_collision.yaml"
"$bin" run "$emu" --t-end 0.1 --out "$tmp/base" --quiet > /dev/null 2>&1 || fail "run base"
format=csv
"$bin" run "$emu" --t-end 0.001 --format hdf5 --out "$tmp/probe" --quiet > /dev/null 2>&1 && format=hdf5
"$bin" run "$emu" --t-end 0.1 --set trains.unitA.speed=12000 --format $format --out "$tmp/faster" --quiet > /dev/null 2>&1 ||
  fail "run faster ($format)"
"$bin" report "$tmp/base" "$tmp/faster" --out "$tmp/compare.html" > /dev/null || fail "report base faster"
open_page "side-by-side page" "file://$tmp/compare.html" "$tmp/compare_dom.html" 5000 "$out/report_compare.png" 1400,1800
"$node" - "$tmp" <<'JS' || fail "side-by-side page (above)"
const fs = require("fs");
const tmp = process.argv[2];
const dom = fs.readFileSync(tmp + "/compare_dom.html", "utf8");
const problems = [];
const m = dom.match(/<div id="self-check"[^>]*data-status="([a-z]+)"[^>]*>([^<]*)<\/div>/);
if (!m) { console.log("compare: the page's script did not run to the end"); process.exit(1); }
const check = JSON.parse(m[2].replace(/&quot;/g, '"').replace(/&lt;/g, "<").replace(/&gt;/g, ">").replace(/&amp;/g, "&"));
if (m[1] !== "ran" || check.errors.length) problems.push("compare: script errors " + JSON.stringify(check.errors));
const data = JSON.parse(fs.readFileSync(tmp + "/compare.html", "utf8").match(/<script type="application\/json" id="report-data">([\s\S]*?)<\/script>/)[1]);
if (check.charts.length !== data.charts.length || check.charts.length < 20) problems.push("compare: " + check.charts.length + " of " + data.charts.length + " charts drawn");
for (const c of check.charts) if (!(c.drawn && c.series === 2 && c.points > 0)) problems.push("compare: chart " + c.id + " not drawn with 2 lines: " + JSON.stringify(c));
for (const id of ["car_crush", "zone_energy", "car_energy", "energy", "accelerations", "peaks"])
  if (!check.tables.find((t) => t.id === id && t.rows > 0)) problems.push("compare: no table " + id);
const a = JSON.parse(fs.readFileSync(tmp + "/base/summary.json", "utf8")), b = JSON.parse(fs.readFileSync(tmp + "/faster/summary.json", "utf8"));
const ca = a.car_crush["unitA.car1"].max_crush, cb = b.car_crush["unitA.car1"].max_crush;
const percent = (100 * (cb - ca) / Math.abs(ca)).toFixed(2);
const row = dom.match(/<table class="compare" id="compare-car_crush">[\s\S]*?<tr><th>unitA\.car1<\/th>((?:<td[^>]*>[^<]*<\/td>)+)<\/tr>/);
const cells = row ? [...row[1].matchAll(/<td[^>]*>([^<]*)<\/td>/g)].map((c) => c[1]) : [];
if (cells.length !== 4 || cells[3] !== (Number(percent) > 0 ? "+" : "") + percent) problems.push("compare: unitA.car1's crush cells " + JSON.stringify(cells) + ", expected the % difference " + percent);
if (problems.length) { console.log(problems.join("\n")); process.exit(1); }
console.log("side-by-side page ok: " + check.charts.length + " charts, " + check.tables.length + " tables, unitA.car1 crush " + cells[3] + " %");
JS
# Walls (issue 39 item 4): the SI unit into a rigid wall; model.json carries the contact's line
# (x = 0.05 m, normal -x) and the animation draws it on the canvas, to the right of the cab's
# front (the wall's solid side), at every frame.
"$bin" run "$src/models/examples/emu3_wall.yaml" --t-end 0.05 --out "$tmp/wall" --report --quiet > /dev/null 2>&1 || fail "run emu3_wall"
open_page "wall run's report" "file://$tmp/wall/report.html" "$tmp/wall.html" 5000 "$out/report_wall.png" 1400,1300
"$node" - "$tmp" <<'JS' || fail "wall drawn (above)"
const fs = require("fs");
const tmp = process.argv[2];
const model = JSON.parse(fs.readFileSync(tmp + "/wall/model.json", "utf8"));
const problems = [];
const wall = model.elements.find((e) => e.name === "wall");
if (!wall || !wall.surface || wall.surface.kind !== "line" || JSON.stringify(wall.surface.point) !== "[0.05,0]" ||
    JSON.stringify(wall.surface.normal) !== "[-1,0]")
  problems.push("model.json: the wall's surface " + JSON.stringify(wall && wall.surface));
if (model.elements.some((e) => e.surface && e.name !== "wall")) problems.push("model.json: a surface on another element");
const dom = fs.readFileSync(tmp + "/wall.html", "utf8");
const m = dom.match(/<div id="self-check"[^>]*data-status="([a-z]+)"[^>]*>([^<]*)<\/div>/);
if (!m) { console.log("wall: the page's script did not run to the end"); process.exit(1); }
const check = JSON.parse(m[2].replace(/&quot;/g, '"').replace(/&lt;/g, "<").replace(/&gt;/g, ">").replace(/&amp;/g, "&"));
if (m[1] !== "ran" || check.errors.length) problems.push("wall: script errors " + JSON.stringify(check.errors));
const drawn = check.surfaces || [];
if (drawn.length !== 1 || drawn[0].element !== "wall" || drawn[0].kind !== "line" || !drawn[0].on_canvas)
  problems.push("wall: not drawn on the canvas: " + JSON.stringify(drawn));
// The unit's car bodies (points along the underframe and at the bogie pivots: 0.9 m over 24.4 m)
// are drawn as boxes 0.15 of their length high, not as slivers; every body at least that.
const outlines = check.body_outlines;
if (!outlines || !(outlines.drawn_as_boxes >= 3) || !(outlines.thinnest_height_per_length >= 0.15 - 1e-12))
  problems.push("wall: bodies drawn as slivers: " + JSON.stringify(outlines));
if (problems.length) { console.log(problems.join("\n")); process.exit(1); }
console.log("wall ok: drawn at " + JSON.stringify(drawn[0].point_px) + " px");
JS
echo "PASS: report and study pages open in Chromium without errors; screenshots in $out/report_*.png"
