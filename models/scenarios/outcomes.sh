#!/usr/bin/env bash
# Runs the scenario models of this folder with IDA and with explicit Euler and prints the
# README's outcome table (criteria from each run's summary.json). Run from the repository root:
#   models/scenarios/outcomes.sh build/railcrash [OUT_DIR]
set -eu
bin=$1
out=${2:-out/scenarios}
mkdir -p "$out"
for model in models/scenarios/scenario*.yaml; do
  name=$(basename "$model" .yaml)
  for integrator in ida euler; do
    "$bin" run "$model" --integrator "$integrator" --quiet --out "$out/${name}_$integrator" > /dev/null || true
  done
done
/usr/bin/python3 - "$out" <<'PY'
import json, pathlib, sys
out = pathlib.Path(sys.argv[1])
print("| model | integrator | status | criterion | subject | value | limit | pass |")
print("|---|---|---|---|---|---|---|---|")
for summary in sorted(out.glob("*/summary.json")):
    s = json.loads(summary.read_text())
    run = summary.parent.name
    model, integrator = run.rsplit("_", 1)
    status = s["status"] + (" at t = %.4g s" % s["t_reached"] if s["status"] != "ok" else "")
    for c in s.get("scenario", {}).get("criteria", []):
        g = c["criterion"] == "mean_deceleration"
        unit = " g" if g else "" if c["criterion"] == "wheel_unloading" else " " + s["units"]["length"]
        value, limit = (c["value_g"], c["limit_g"]) if g else (c["value"], c["limit"])
        note = " (%s)" % c["note"] if c["note"] else ""
        print("| %s | %s | %s | %s | %s | %.4g%s | %.4g%s | %s%s |" % (model, integrator, status, c["criterion"], c["subject"],
              value, unit, limit, unit, "yes" if c["pass"] else "NO", note))
PY
