#!/usr/bin/env bash
# Prints the two physical checks of the scenario models over longer runs than the unit tests
# (README.md, "Collision scenarios"). Run from the repository root:
#   models/scenarios/verify.sh build/railcrash [OUT_DIR]
#  1. zero-offset scenario 1 (report car, 20 ms, IDA): largest |vx(s body) + vx(mirrored t body)|
#     over the closing speed up to each millisecond, the first sample where it exceeds 1e-9 with
#     the events just before it and the anticlimber's vertical offset there (the element measures
#     it in body 1's axes, so it is not zero for mirrored faces), and how far apart in time IDA
#     located the mirrored pairs of mode changes (events.csv); the same run at rtol 1e-9;
#  2. zero-offset scenario 1 of the barrier cars (50 ms, IDA and Euler): the same asymmetry, and
#     the mirrored crush springs' mode changes that IDA commits more than once at one time;
#  3. scenario 2 (models/scenarios/scenario2_report_car.yaml, whole run, IDA and Euler): the
#     change of the total longitudinal momentum over its initial value, and the energy balance.
set -eu
bin=$1
out=${2:-out/scenario_checks}
mkdir -p "$out"
"$bin" scenario 1 --train models/report/final_two_car.yaml --offset 0 --deceleration-limit 5 --survival-space-limit 50 \
  --override-limit 100 --wheel-lift-limit 20 --passenger-bodies center_body --survival-gauge bolster_body,rear_body \
  --t-end 0.02 --out "$out/symmetric.yaml" 2> /dev/null
"$bin" run "$out/symmetric.yaml" --output-interval 0.0005 --quiet --out "$out/symmetric" > /dev/null
"$bin" run "$out/symmetric.yaml" --output-interval 0.0005 --set simulation.rtol=1e-9 --quiet --out "$out/symmetric_rtol_1e-9" > /dev/null
"$bin" scenario 1 --train models/barrier/two_car_barrier.yaml --offset 0 --deceleration-limit 5 --survival-space-limit 50 \
  --override-limit 100 --wheel-lift-limit 20 --passenger-bodies lead_body,trail_body --face-stiffness 875.6 --face-height 304.8 \
  --t-end 0.05 --out "$out/symmetric_barrier.yaml" 2> /dev/null
for integrator in ida euler; do
  "$bin" run "$out/symmetric_barrier.yaml" --integrator "$integrator" --output-interval 0.0005 --quiet --out "$out/symmetric_barrier_$integrator" > /dev/null
done
for integrator in ida euler; do
  "$bin" run models/scenarios/scenario2_report_car.yaml --integrator "$integrator" --quiet --out "$out/momentum_$integrator" > /dev/null
done
/usr/bin/python3 - "$out" <<'PY'
import csv, json, pathlib, sys


def rows_of(path):  # a run's CSV file without its first line, the run's provenance ("# railcrash provenance ...")
    return [line for line in open(path) if not line.startswith("#")]

out = pathlib.Path(sys.argv[1])
rows = list(csv.DictReader(rows_of(out / "symmetric/timeseries.csv")))
closing = json.loads((out / "symmetric/summary.json").read_text())["scenario"]["closing_speed"]
print("scenario 1, zero offset: largest |vx_s + vx_t| / closing speed up to t")
largest = 0.0
for r in rows:
    largest = max([largest] + [abs(float(r[k]) + float(r["t" + k[1:]])) / closing for k in r if k.startswith("s") and k.endswith(".vx")])
    if round(float(r["t"]) * 1e4) % 10 == 0:
        print("  t = %5.1f ms  %.3g" % (1e3 * float(r["t"]), largest))
previous, first = 0.0, None
for r in rows:
    worst = max(abs(float(r[k]) + float(r["t" + k[1:]])) / closing for k in r if k.startswith("s") and k.endswith(".vx"))
    if worst > 1e-9:
        first = r
        break
    previous = float(r["t"])
if first:
    t_first = float(first["t"])
    print("first sample above 1e-9: t = %.2f ms; events after the sample before it (%.2f ms):" % (1e3 * t_first, 1e3 * previous))
    for e in csv.DictReader(rows_of(out / "symmetric/events.csv")):
        if previous < float(e["t"]) <= t_first:
            print("  t = %.5f ms  %s  %s" % (1e3 * float(e["t"]), e["element"], e["event"]))
    print("  there: front ends' heights differ by %.3g in, the anticlimber's vertical_offset is %.3g in, its vertical force %.3g"
          % (abs(float(first["s1_front_end.y"]) - float(first["t1_front_end.y"])), float(first["anticlimber.vertical_offset"]),
             float(first["anticlimber.vertical_force"])))
events = {}
for e in csv.DictReader(rows_of(out / "symmetric/events.csv")):
    name = e["element"]
    key = (name[0], name[1:], e["event"]) if name[0] in "st" and name[1:2].isdigit() else None
    if key: events.setdefault(key[1:], {}).setdefault(key[0], []).append(float(e["t"]))
print("mirrored mode changes located apart (first of each pair):")
for (element, event), times in sorted(events.items(), key=lambda kv: min(min(v) for v in kv[1].values())):
    if "s" in times and "t" in times:
        print("  %-28s %-40s t = %.5f s, apart %.2g s" % ("*" + element, event, times["s"][0], abs(times["s"][0] - times["t"][0])))
tight = list(csv.DictReader(rows_of(out / "symmetric_rtol_1e-9/timeseries.csv")))
print("the same at rtol 1e-9: largest |vx_s + vx_t| / closing speed up to t")
largest = 0.0
for r in tight:
    largest = max([largest] + [abs(float(r[k]) + float(r["t" + k[1:]])) / closing for k in r if k.startswith("s") and k.endswith(".vx")])
    if 9.0 <= round(float(r["t"]) * 1e3, 1) <= 10.0:
        print("  t = %5.1f ms  %.3g" % (1e3 * float(r["t"]), largest))
gear = {}
for e in csv.DictReader(rows_of(out / "symmetric_rtol_1e-9/events.csv")):
    if e["element"] in ("s1_draft_gear", "t1_draft_gear") and e["event"] == "back on the loading curve (buff)":
        gear.setdefault(e["element"], float(e["t"]))
if len(gear) == 2:
    print("  the draft gears' 'back on the loading curve' at %.5f ms, apart %.2g s" % (1e3 * min(gear.values()), abs(gear["s1_draft_gear"] - gear["t1_draft_gear"])))
print("scenario 1 of the barrier cars, zero offset: largest |vx_s + vx_t| / closing speed up to t (IDA, Euler)")
largest = {}
series = {i: list(csv.DictReader(rows_of(out / ("symmetric_barrier_%s/timeseries.csv" % i)))) for i in ("ida", "euler")}
for k in range(len(series["ida"])):
    line = []
    for i in ("ida", "euler"):
        r = series[i][k]
        largest[i] = max([largest.get(i, 0.0)] + [abs(float(r[c]) + float(r["t_" + c[2:]])) / closing for c in r if c.startswith("s_") and c.endswith(".vx")])
        line.append("%.3g" % largest[i])
    if round(float(series["ida"][k]["t"]) * 1e4) % 50 == 0:
        print("  t = %5.1f ms  %s" % (1e3 * float(series["ida"][k]["t"]), "  ".join(line)))
print("  IDA's mode changes of the mirrored lead_crush springs logged more than once at one time:")
counts = {}
for e in csv.DictReader(rows_of(out / "symmetric_barrier_ida/events.csv")):
    if e["element"] in ("s_lead_crush", "t_lead_crush"):
        counts.setdefault((e["t"], e["element"]), []).append(e["event"])
for (t, element), logged in sorted(counts.items(), key=lambda kv: float(kv[0][0])):
    mirror = ("t" if element[0] == "s" else "s") + element[1:]
    if len(logged) > 1:
        print("    t = %.6f ms  %s: %d commits (%s), %s: %d" % (1e3 * float(t), element, len(logged), ", ".join(sorted(set(logged))),
              mirror, len(counts.get((t, mirror), []))))
for integrator in ("ida", "euler"):
    run = out / ("momentum_" + integrator)
    masses = {b["name"]: b["mass"] for b in json.loads((run / "model.json").read_text())["bodies"]}
    rows = list(csv.DictReader(rows_of(run / "timeseries.csv")))
    momentum = [sum(m * float(r[b + ".vx"]) for b, m in masses.items()) for r in rows]
    change = max(abs(p - momentum[0]) for p in momentum) / abs(momentum[0])
    energy = json.loads((run / "summary.json").read_text())["energy"]["relative_balance_error"]
    print("scenario 2, %s: largest momentum change %.3g of the initial, relative energy balance error %.3g" % (integrator, change, energy))
PY
