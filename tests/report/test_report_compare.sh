#!/usr/bin/env bash
# `railcrash report RUN_A RUN_B` (issue 39 item 5): two runs of an SI model (the 3-car EMU
# collision, t_end shortened), the second with the striking unit faster (--set); the page's
# tables must give each run's summary.json values and the differences b - a and 100 (b - a) / |a|
# that this test computes itself from the two summary.json files; runs of different models are
# refused (exit 2, nothing written); --out with one run folder is refused.
# Usage: test_report_compare.sh RAILCRASH_BINARY SOURCE_DIR PYTHON
set -u
bin=$1 src=$2 python=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
model="$src/models/examples/emu3_unit_collision.yaml"

"$bin" run "$model" --t-end 0.12 --out "$tmp/base" --quiet > "$tmp/base.log" 2>&1 || { cat "$tmp/base.log"; fail "run base"; }
"$bin" run "$model" --t-end 0.12 --set trains.unitA.speed=12000 --out "$tmp/faster" --quiet > "$tmp/faster.log" 2>&1 ||
  { cat "$tmp/faster.log"; fail "run faster"; }

# The default path: compare_<A>_<B>.html beside the first run folder.
"$bin" report "$tmp/base" "$tmp/faster" > "$tmp/report.log" 2>&1 || { cat "$tmp/report.log"; fail "report base faster"; }
[ -s "$tmp/compare_base_faster.html" ] || { cat "$tmp/report.log"; fail "no $tmp/compare_base_faster.html"; }
grep -q "2 runs side by side written to $tmp/compare_base_faster.html" "$tmp/report.log" || { cat "$tmp/report.log"; fail "report's message"; }
# --out, and the page needs nothing from outside.
"$bin" report "$tmp/base" "$tmp/faster" --out "$tmp/pages/side.html" > "$tmp/missing.log" 2>&1
status=$?
[ $status -eq 2 ] && grep -q "the folder of the page '$tmp/pages/side.html' does not exist" "$tmp/missing.log" ||
  { cat "$tmp/missing.log"; fail "--out into a missing folder: exit $status, expected 2 and the folder named"; }
mkdir -p "$tmp/pages"
"$bin" report "$tmp/base" "$tmp/faster" --out "$tmp/pages/side.html" > /dev/null 2>&1 || fail "report --out"
if grep -Eq '<(script|link|img|iframe)[^>]* (src|href)=' "$tmp/pages/side.html"; then fail "the page refers to an outside resource"; fi

"$python" - "$tmp/pages/side.html" "$tmp/base" "$tmp/faster" <<'PY' || fail "the page's tables (above)"
import csv, json, math, re, sys
page, base_dir, faster_dir = sys.argv[1:4]
html = open(page, encoding="utf-8").read()
m = re.search(r'<script type="application/json" id="report-data">(.*?)</script>', html, re.S)
data = json.loads(m.group(1))
a = json.load(open(base_dir + "/summary.json"))
b = json.load(open(faster_dir + "/summary.json"))
problems = []
tables = {t["id"]: {r["name"]: r for r in t["rows"]} for t in data["tables"]}

def expect(table, row, va, vb):
    r = tables.get(table, {}).get(row)
    if r is None:
        problems.append(f"{table}: no row {row}")
        return
    d = vb - va
    p = 100.0 * d / abs(va) if va != 0 else None
    close = lambda x, y: x is not None and y is not None and abs(x - y) <= 1e-9 * max(1.0, abs(y))
    if not (close(r["values"][0], va) and close(r["values"][1], vb)):
        problems.append(f"{table} {row}: values {r['values']}, summary.json {va}, {vb}")
    if not close(r["difference"][1], d) or r["difference"][0] is not None:
        problems.append(f"{table} {row}: difference {r['difference']}, expected {d}")
    if (p is None) != (r["percent"][1] is None) or (p is not None and not close(r["percent"][1], p)):
        problems.append(f"{table} {row}: percent {r['percent']}, expected {p}")

for car in a["car_crush"]:
    expect("car_crush", car, a["car_crush"][car]["max_crush"], b["car_crush"][car]["max_crush"])
zones_b = {z["element"]: z for z in b["crush_zones"]["zones"]}
for z in a["crush_zones"]["zones"]:
    expect("zone_energy", z["element"], z["absorbed"], zones_b[z["element"]]["absorbed"])
expect("zone_energy", "total", a["crush_zones"]["total_absorbed"], b["crush_zones"]["total_absorbed"])
# energy_zones.csv holds the same per-zone energies (the files a user opens).
with open(faster_dir + "/energy_zones.csv") as f:
    rows = [r for r in csv.DictReader(line for line in f if not line.startswith("#")) if r["kind"] == "zone"]
for r in rows:
    got = tables["zone_energy"][r["name"]]["values"][1]
    if abs(got - float(r["absorbed"])) > 1e-6 * max(1.0, abs(got)):
        problems.append(f"zone {r['name']}: page {got}, energy_zones.csv {r['absorbed']}")
for car in a["crush_zones"]["cars"]:
    expect("car_energy", car, a["crush_zones"]["cars"][car]["absorbed"], b["crush_zones"]["cars"][car]["absorbed"])
for key in ("kinetic", "elastic", "dissipated", "initial_total"):
    expect("energy", key, a["energy"][key], b["energy"][key])
for body, peak in a["peak_accelerations"]["bodies"].items():
    if "body" in body:
        expect("accelerations", body, peak["x_cfc"]["g"], b["peak_accelerations"]["bodies"][body]["x_cfc"]["g"])
for name, peak in a["peaks"].items():
    expect("peaks", name + " max", peak["max"], b["peaks"][name]["max"])
    expect("peaks", name + " min", peak["min"], b["peaks"][name]["min"])
# The change must show: the faster unit's striking cab crushes more, and the initial energy
# grows by the striking unit's kinetic energy 0.5 m (12^2 - 10^2) (m/s; m from model.json).
if not tables["car_crush"]["unitA.car1"]["percent"][1] > 5:
    problems.append("unitA.car1's crush does not grow with the speed: " + json.dumps(tables["car_crush"]["unitA.car1"]))
mass = sum(body["mass"] for body in json.load(open(base_dir + "/model.json"))["bodies"] if body["name"].startswith("unitA."))
if abs(tables["energy"]["initial_total"]["difference"][1] - 0.5 * mass * (12.0**2 - 10.0**2)) > 1e-6 * 0.5 * mass * 44.0:
    problems.append(f"initial energy difference is not 0.5 m (12^2 - 10^2) with m = {mass} kg: " + json.dumps(tables["energy"]["initial_total"]))
# Identity and outcomes.
runs = data["runs"]
if [r["label"] for r in runs] != ["base", "faster"]: problems.append("labels " + str([r["label"] for r in runs]))
if runs[1]["settings"] != b["provenance"]["settings"] or "trains.unitA.speed=12000" not in runs[1]["settings"]:
    problems.append("settings " + str(runs[1]["settings"]))
for r, s in zip(runs, (a, b)):
    if r["t_reached"] != s["t_reached"] or r["status"] != s["status"] or r["integrator"] != s["integrator"] or r["run_id"] != s["run_id"]:
        problems.append("identity " + json.dumps(r))
if [o["signature"] for o in data["outcomes"]] != [a["outcomes"]["signature"], b["outcomes"]["signature"]]:
    problems.append("outcomes " + json.dumps(data["outcomes"]))
# The charts: a line per run; run b's displacement of unitA.car1.body at its last row is that of timeseries.csv.
charts = {c["id"]: c for c in data["charts"]}
chart = charts.get("displacement:unitA.car1.body")
with open(faster_dir + "/timeseries.csv") as f:
    series = list(csv.DictReader(line for line in f if not line.startswith("#")))
if not chart or len(chart["series"]) != 2:
    problems.append("no displacement chart of unitA.car1.body with 2 lines")
else:
    last = [v for v in chart["series"][1]["values"] if v is not None][-1]
    want = float(series[-1]["unitA.car1.body.x"]) - float(series[0]["unitA.car1.body.x"])
    if abs(last - want) > 1e-5 * abs(want): problems.append(f"displacement chart ends at {last}, timeseries.csv {want}")
for kind in ("velocity:unitB.car3.body", "force:impact.anticlimber", "energy:kinetic"):
    if kind not in charts: problems.append("no chart " + kind)
if data["unshared"]: problems.append("columns not shared between runs of one model: " + str(data["unshared"][:5]))
if problems:
    print("\n".join(problems)); sys.exit(1)
print(f"compare ok: {sum(len(t) for t in tables.values())} rows, {len(charts)} charts")
PY

# Runs of different models: nothing to overlay, refused with both named.
"$bin" run "$src/tests/report/two_car.yaml" --t-end 0.02 --out "$tmp/other" --quiet > /dev/null 2>&1 || fail "run two_car"
"$bin" report "$tmp/base" "$tmp/other" --out "$tmp/refused.html" > "$tmp/refused.log" 2>&1
status=$?
[ $status -eq 2 ] || { cat "$tmp/refused.log"; fail "runs of different models: exit $status, expected 2"; }
grep -q "share no column but t: they are runs of different models" "$tmp/refused.log" || { cat "$tmp/refused.log"; fail "refusal's message"; }
[ -e "$tmp/refused.html" ] && fail "a page was written for runs of different models"
# --out with one run folder; a folder that is not a run.
"$bin" report "$tmp/base" --out "$tmp/one.html" > "$tmp/one.log" 2>&1 && fail "--out with one run folder was accepted"
grep -q "report --out names the page of runs side by side" "$tmp/one.log" || { cat "$tmp/one.log"; fail "--out message"; }
# --cfc sets one run's acceleration plots; the side-by-side page has none: refused, not ignored.
"$bin" report "$tmp/base" "$tmp/faster" --cfc 180 --out "$tmp/cfc.html" > "$tmp/cfc.log" 2>&1
status=$?
[ $status -eq 2 ] || { cat "$tmp/cfc.log"; fail "--cfc with runs side by side: exit $status, expected 2"; }
grep -q "report --cfc sets the acceleration plots of one run's report" "$tmp/cfc.log" || { cat "$tmp/cfc.log"; fail "--cfc message"; }
[ -e "$tmp/cfc.html" ] && fail "a page was written with --cfc for runs side by side"
mkdir "$tmp/empty"
"$bin" report "$tmp/base" "$tmp/empty" > "$tmp/empty.log" 2>&1 && fail "a folder without results was accepted"
grep -q "empty' has no timeseries.csv nor timeseries.h5" "$tmp/empty.log" || { cat "$tmp/empty.log"; fail "empty folder message"; }
echo "report compare ok"
