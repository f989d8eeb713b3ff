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

# A convergence study's folder: its tables and chart.
"$bin" converge "$src/verification/cases/damped_spring_mass.yaml" --t-end 0.5 --euler-dt 0.01 --euler-steps 3 --rtols 1e-3,1e-4 \
  --quantities displacement_rms --out "$tmp/converge" > /dev/null 2>&1 || fail "converge"
"$bin" report "$tmp/converge" > /dev/null || fail "report of a converge folder"
timeout 120 "$chromium" "${flags[@]}" --virtual-time-budget=3000 --dump-dom "file://$tmp/converge/report.html" > "$tmp/study.html" 2> "$tmp/chromium.log" ||
  fail "chromium --dump-dom (study)"
if grep -E "Uncaught|net::ERR_|Failed to load resource" "$tmp/chromium.log"; then fail "JavaScript error in the study report (above)"; fi
grep -q 'data-status="ran"' "$tmp/study.html" || fail "the study report's script did not run"
grep -Eq '&quot;tables&quot;:[1-9][0-9]*,&quot;chart&quot;:true' "$tmp/study.html" || grep -Eq '"tables":[1-9][0-9]*,"chart":true' "$tmp/study.html" ||
  { grep -o '<div id="self-check"[^<]*' "$tmp/study.html"; fail "the study report has no tables or no chart"; }
echo "PASS: report opens in Chromium without errors; screenshot in $out/report_screenshot.png"
