#!/usr/bin/env bash
# The command line's contract: exit status 0 (success), 1 (run failed, results kept),
# 2 (bad input, one-line message with file and line); files written by `run`.
# Usage: test_cli.sh RAILCRASH_BINARY SOURCE_DIR
set -u
bin=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
passes=0

. "$(dirname "$0")/expect.sh"

crank=$src/verification/cases/slider_crank.yaml

expect_status "check a valid model" 0 "$bin" check "$crank"
expect_text "check prints degrees of freedom" "$tmp/stdout" "degrees of freedom  1"

expect_status "run a valid model" 0 "$bin" run "$crank" --out "$tmp/crank" --t-end 1
expect_text "summary status" "$tmp/crank/summary.json" '"status": "ok"'
expect_text "summary t_reached" "$tmp/crank/summary.json" '"t_reached": 1,'
expect_text "timeseries header" "$tmp/crank/timeseries.csv" '^t,crank.x,crank.y,crank.theta,crank.vx,crank.vy,crank.omega,rod.x'
expect_text "events header" "$tmp/crank/events.csv" '^t,element,event,value$'

expect_status "euler run" 0 "$bin" run "$crank" --integrator euler --dt 1e-3 --t-end 0.5 --out "$tmp/euler"
expect_text "euler prints its step and limit" "$tmp/stdout" "euler step 0.001, stability limit"
expect_text "summary integrator" "$tmp/euler/summary.json" '"integrator": "euler"'

expect_status "run --timings" 0 "$bin" run "$crank" --t-end 1 --timings --out "$tmp/timed"
expect_text "--timings prints the phases" "$tmp/stdout" "^wall time by phase \[s\]: other [0-9.e-]* ([0-9]* %) start .* residual .* linear_solve .* output "
expect_text "--timings: summary.json has them" "$tmp/timed/summary.json" '"seconds": {"other": [0-9.e-]*, "start": '
if grep -q '"seconds"' "$tmp/crank/summary.json"; then echo "FAIL: an untimed run's summary has seconds"; failures=$((failures + 1)); else passes=$((passes + 1)); fi

expect_status "--set changes a model key" 0 "$bin" run "$crank" --set simulation.t_end=0.25 --out "$tmp/set"
expect_text "--set took effect" "$tmp/set/summary.json" '"t_reached": 0.25,'

printf 'railcrash: 1\nname: bad\nunits: SI\nbodies:\n  - {name: b, mass: -1, inertia: 1, position: [0, 0]}\nsimulation: {t_end: 1}\n' > "$tmp/bad.yaml"
expect_status "bad input exits 2" 2 "$bin" run "$tmp/bad.yaml" --out "$tmp/bad"
expect_text "bad input names file, line and what to change" "$tmp/stderr" "bad.yaml:5: body 'b': mass must be positive"
[ ! -e "$tmp/bad/summary.json" ] && passes=$((passes + 1)) || { echo "FAIL: bad input wrote results"; failures=$((failures + 1)); }

expect_status "missing model file exits 2" 2 "$bin" check "$tmp/nothing.yaml"
expect_status "unknown option exits 2" 2 "$bin" run "$crank" --no-such-option
expect_status "bad command-line value exits 2" 2 "$bin" run "$crank" --t-end -1
expect_text "bad --t-end says so, naming the option" "$tmp/stderr" "slider_crank.yaml: --t-end -1: simulation: t_end must be positive"

# Euler above its stability limit: refused (2) unless forced; forced, it diverges (1) and
# still leaves its results.
printf 'railcrash: 1\nname: stiff\nunits: SI\ngravity: [0, 0]\nbodies:\n  - {name: m, mass: 2, inertia: 0.1, position: [1.1, 0]}\nelements:\n  - {name: k, type: linear_spring, stiffness: 200, free_length: 1, points: [{body: ground, at: [0, 0]}, {body: m, at: [0, 0]}]}\nsimulation: {t_end: 300, integrator: euler, dt: 0.3, output_interval: 1}\n' > "$tmp/stiff.yaml"
expect_status "euler step above the limit exits 2" 2 "$bin" run "$tmp/stiff.yaml" --out "$tmp/stiff"
expect_text "the refusal gives the limit" "$tmp/stderr" "above the stability limit 0.2"
expect_status "forced euler divergence exits 1" 1 "$bin" run "$tmp/stiff.yaml" --force-dt --out "$tmp/stiff"
expect_text "failed summary" "$tmp/stiff/summary.json" '"status": "failed"'
expect_text "failed summary says why" "$tmp/stiff/summary.json" 'diverged'
expect_status "the failed run's summary.json is valid JSON" 0 python3 -m json.tool "$tmp/stiff/summary.json"
expect_status "no temporary summary left" 1 test -e "$tmp/stiff/summary.json.tmp"
# A failed static settle (before the first step) still writes summary.json, status failed.
expect_status "failed static settle exits 1" 1 "$bin" run "$src/tests/robustness/models/no_static_equilibrium.yaml" --out "$tmp/settle"
expect_text "its summary says failed" "$tmp/settle/summary.json" '"status": "failed"'
expect_text "and why" "$tmp/settle/summary.json" 'no static equilibrium found'
# A model path that is not UTF-8 (a Latin-1 e-acute): summary.json stays strict UTF-8 JSON.
# The failure message names the file, so the path is in summary.json.
latin1_model="$tmp/caf$(printf '\351').yaml"
cp "$src/tests/robustness/models/tiny_mass.yaml" "$latin1_model"
expect_status "a Latin-1 model path that fails at t = 0 exits 2" 2 "$bin" run "$latin1_model" --out "$tmp/latin1" --quiet
expect_text "its summary.json holds the message" "$tmp/latin1/summary.json" "vx changes at"
expect_status "its summary.json is strict UTF-8 JSON" 0 python3 -c 'import json, sys; json.loads(open(sys.argv[1], "rb").read().decode("utf-8", "strict"))' "$tmp/latin1/summary.json"

# sensitivity: the default design is sensitivity_design.yaml beside the model; none there -> input error.
expect_status "sensitivity without a design beside the model exits 2" 2 "$bin" sensitivity "$crank" --out "$tmp/sens"
expect_text "it says to pass --design" "$tmp/stderr" "sensitivity_design.yaml does not exist; pass --design FILE"

# converge: a small study writes its CSV, plot and summary; an unknown quantity is an input error.
spring=$src/verification/cases/damped_spring_mass.yaml
expect_status "converge runs" 0 "$bin" converge "$spring" --t-end 0.5 --euler-dt 0.01 --euler-steps 3 --rtols 1e-3,1e-4 --quantities displacement_rms,R1 --out "$tmp/conv"
expect_text "converge prints the observed orders" "$tmp/stdout" "Observed orders"
expect_text "converge says what does not apply" "$tmp/stdout" "R1 .*not applicable: the model has no responses section"
expect_text "converge CSV header" "$tmp/conv/converge.csv" '^method,step,rtol,status,wall_s,steps,residual_evaluations,jacobian_evaluations,events,displacement_rms'
[ -s "$tmp/conv/converge.svg" ] && passes=$((passes + 1)) || { echo "FAIL: converge wrote no plot"; failures=$((failures + 1)); }
expect_status "converge with an unknown quantity exits 2" 2 "$bin" converge "$spring" --quantities max_crunch
expect_text "it names the quantity" "$tmp/stderr" "unknown quantity 'max_crunch'"

# The studies' shared options are declared once (src/cli/common.cpp): every study's --help gives
# each the same help text, and converge takes --run-limit as the others do (and --run-timeout,
# its former name).
same_help() {  # description option command...: the option's help text (the line after its name) alike in each
  local description=$1 option=$2 first="" text command
  shift 2
  for command in "$@"; do
    text=$("$bin" "$command" --help | grep -A1 -- "^  $option[ ,]" | sed -n 2p | sed 's/^ *//')
    if [ -z "$text" ]; then echo "FAIL: $description: $command --help has no $option"; failures=$((failures + 1)); return; fi
    [ -z "$first" ] && first=$text
    if [ "$text" != "$first" ]; then
      echo "FAIL: $description: $command --help says '$text', $1 --help '$first'"; failures=$((failures + 1)); return
    fi
  done
  passes=$((passes + 1))
}
same_help "--run-limit: one help text" --run-limit sensitivity readings sweep converge
same_help "--max-runs: one help text" --max-runs sensitivity readings sweep
same_help "--jobs: one help text" --jobs sensitivity readings sweep
expect_status "converge takes --run-limit" 0 "$bin" converge "$spring" --t-end 0.5 --euler-steps 0 --rtols 1e-3 --quantities displacement_rms --run-limit 600 --out "$tmp/conv_limit"
expect_status "converge still takes --run-timeout" 0 "$bin" converge "$spring" --t-end 0.5 --euler-steps 0 --rtols 1e-3 --quantities displacement_rms --run-timeout 600 --out "$tmp/conv_timeout"
expect_status "converge --run-limit -1 exits 2" 2 "$bin" converge "$spring" --run-limit -1
expect_text "it gives the range" "$tmp/stderr" "'-1' is not in range: give a finite number of at least 0 \[s\]"

# readings: bad readings files exit 2 naming the file and line, before any run starts (the
# report model's study would take minutes, so an exit within seconds shows nothing ran).
report_model=$src/models/report/final_two_car.yaml
printf 'reading_study: 1\nreadings:\n  - name: a\n    levels:\n      - {name: x, set: {elements.nothing.stiffness: 2}}\n' > "$tmp/missing_key.yaml"
expect_status "readings naming a missing model key exits 2" 2 "$bin" readings "$report_model" --readings "$tmp/missing_key.yaml" --out "$tmp/r1"
expect_text "it names the readings file's line and the key" "$tmp/stderr" "missing_key.yaml:5: reading 'a', level 'x'.*no element named 'nothing'"
printf 'reading_study: 1\nreadings: []\n' > "$tmp/empty.yaml"
expect_status "an empty readings list exits 2" 2 "$bin" readings "$report_model" --readings "$tmp/empty.yaml" --out "$tmp/r2"
expect_text "it says what to give" "$tmp/stderr" "empty.yaml:2: .*at least one reading"
printf 'reading_study: 1\nreadings:\n  - {name: a, levelz: []}\n' > "$tmp/unknown_key.yaml"
expect_status "an unknown reading key exits 2" 2 "$bin" readings "$report_model" --readings "$tmp/unknown_key.yaml" --out "$tmp/r3"
expect_text "it names the key" "$tmp/stderr" "unknown_key.yaml:3: reading: unknown key 'levelz'"
[ ! -e "$tmp/r1" ] && [ ! -e "$tmp/r2" ] && [ ! -e "$tmp/r3" ] && passes=$((passes + 1)) || { echo "FAIL: a rejected readings study wrote output"; failures=$((failures + 1)); }
sed '/^reference:/,$d' "$src/models/report/sensitivity_design.yaml" > "$tmp/no_reference.yaml"
expect_status "readings with a design without a reference exits 2" 2 "$bin" readings "$report_model" --readings "$src/models/report/readings.yaml" --design "$tmp/no_reference.yaml" --out "$tmp/r4"
expect_text "it says the reference is missing" "$tmp/stderr" "no 'reference' section"

# report: a run folder gives report.html (exit 0); a missing folder or one without a timeseries exits 2.
expect_status "run a small crash" 0 "$bin" run "$src/tests/report/two_car.yaml" --out "$tmp/two"
expect_status "report of a run folder" 0 "$bin" report "$tmp/two"
[ -s "$tmp/two/report.html" ] && passes=$((passes + 1)) || { echo "FAIL: report wrote no report.html"; failures=$((failures + 1)); }
expect_text "report says where" "$tmp/stdout" "report of 1501 output rows written to $tmp/two/report.html"
expect_text "the summary has CFC 60 peaks" "$tmp/two/summary.json" '"x_cfc": {"abs_max"'
expect_text "and mean decelerations" "$tmp/two/summary.json" '"mean_deceleration": '
expect_text "run writes the model geometry" "$tmp/crank/model.json" '"name": "crank", "mass"'
expect_text "run writes the accelerations" "$tmp/crank/accelerations.csv" '^t,crank.ax,crank.ay,crank.alpha,rod.ax'
expect_status "report of a missing folder exits 2" 2 "$bin" report "$tmp/nowhere"
expect_text "it says the folder does not exist" "$tmp/stderr" "run folder '$tmp/nowhere' does not exist"
mkdir -p "$tmp/not_a_run"
expect_status "report of a folder without timeseries exits 2" 2 "$bin" report "$tmp/not_a_run"
expect_text "it says it is not a run folder" "$tmp/stderr" "has no timeseries.csv: it is not a run folder"
head -c 200000 "$tmp/two/timeseries.csv" > "$tmp/two/cut.csv" && mv "$tmp/two/cut.csv" "$tmp/two/timeseries.csv"
rm "$tmp/two/summary.json"
expect_status "report of a truncated run folder" 0 "$bin" report "$tmp/two"
expect_text "it lists the truncated row" "$tmp/stderr" "report: timeseries.csv line [0-9]*: .*the file ends mid-row"
expect_text "and the missing summary" "$tmp/stderr" "report: no summary.json: the run did not finish"

# A run owns its folder: it removes what an earlier run left (the names railcrash writes, no
# others) and says so; every file carries the run's id and provenance (results/provenance.hpp).
mkdir -p "$tmp/owned" && echo "my notes" > "$tmp/owned/notes.txt" && echo "stale" > "$tmp/owned/report.html"
expect_status "a run into a folder with a report of an earlier run" 0 "$bin" run "$crank" --t-end 0.1 --out "$tmp/owned" --quiet
expect_text "it says which files of an earlier run it removed" "$tmp/stdout" "^removed the files of an earlier run from $tmp/owned/: report.html$"
[ -f "$tmp/owned/notes.txt" ] && [ ! -f "$tmp/owned/report.html" ] && passes=$((passes + 1)) ||
  { echo "FAIL: the run removed notes.txt or kept report.html"; failures=$((failures + 1)); }
cp "$tmp/owned/summary.json" "$tmp/first_summary.json"
expect_status "a second run into the same folder" 0 "$bin" run "$crank" --t-end 0.2 --out "$tmp/owned" --quiet
expect_text "it names the earlier run's files it removed" "$tmp/stdout" \
  "^removed the files of an earlier run from $tmp/owned/: timeseries.csv, events.csv, accelerations.csv, energy.csv, summary.json, model.json, energy_zones.csv$"
run_id=$(sed -n 's/^  "run_id": "\([0-9a-f]*\)",$/\1/p' "$tmp/owned/summary.json")
first_id=$(sed -n 's/^  "run_id": "\([0-9a-f]*\)",$/\1/p' "$tmp/first_summary.json")
[ ${#run_id} -eq 32 ] && [ ${#first_id} -eq 32 ] && [ "$run_id" != "$first_id" ] && passes=$((passes + 1)) ||
  { echo "FAIL: run ids '$first_id', '$run_id': not two different 32-digit ids"; failures=$((failures + 1)); }
expect_text "stdout names the run id" "$tmp/stdout" "run id $run_id$"
for name in timeseries events accelerations energy; do
  expect_text "$name.csv's first line is the run's provenance" "$tmp/owned/$name.csv" \
    "^# railcrash provenance {\"run_id\": \"$run_id\", \"version\": \"[0-9.]*\", \"commit\": "
done
expect_text "model.json carries the run id" "$tmp/owned/model.json" "^  \"run_id\": \"$run_id\",$"
# The provenance in summary.json: the model's SHA-256 as sha256sum computes it, the command line, the settings.
crank_sha=$(sha256sum "$crank" | cut -d' ' -f1)
expect_text "summary.json has the model file's SHA-256" "$tmp/owned/summary.json" \
  "\"model_files\": \[{\"path\": \"$crank\", \"sha256\": \"$crank_sha\"}\]"
expect_text "and the command line" "$tmp/owned/summary.json" "\"command_line\": \"$bin run $crank --t-end 0.2 --out $tmp/owned --quiet\""
expect_text "and the settings" "$tmp/owned/summary.json" \
  '"settings": \["simulation.t_end=0.2"\], "simulation": {"integrator": "ida", "t_end": 0.2, "output_interval": 0.4, "max_steps": 10000000, "rtol": 1e-06, "atol": 1e-07,'
expect_text "the timeseries' provenance line has them too" "$tmp/owned/timeseries.csv" "^# railcrash provenance .*\"sha256\": \"$crank_sha\""
# A variant: both files read, each with its digest.
variant=$src/models/report/final_two_car_corrected.yaml
expect_status "a run of a model variant" 0 "$bin" run "$variant" --t-end 0.01 --set "simulation.rtol=1e-7" --out "$tmp/variant" --quiet
expect_text "its provenance has the variant's and the base's SHA-256" "$tmp/variant/summary.json" \
  "\"model_files\": \[{\"path\": \"$variant\", \"sha256\": \"$(sha256sum "$variant" | cut -d' ' -f1)\"}, {\"path\": \"$src/models/report/final_two_car.yaml\", \"sha256\": \"$(sha256sum "$src/models/report/final_two_car.yaml" | cut -d' ' -f1)\"}\]"
expect_text "and the --set before the run options" "$tmp/variant/summary.json" '"settings": \["simulation.rtol=1e-7", "simulation.t_end=0.01"\]'
# report refuses a folder whose files are of two runs, naming them.
cp "$tmp/first_summary.json" "$tmp/owned/summary.json"
expect_status "report of a folder with the summary.json of another run exits 2" 2 "$bin" report "$tmp/owned"
expect_text "it names the two files and their runs" "$tmp/stderr" \
  "'$tmp/owned/timeseries.csv' is of run $run_id but '$tmp/owned/summary.json' is of run $first_id: the folder holds the files of two runs"
[ ! -f "$tmp/owned/report.html" ] && passes=$((passes + 1)) || { echo "FAIL: report wrote a page of two runs"; failures=$((failures + 1)); }
expect_status "a run again" 0 "$bin" run "$crank" --t-end 0.1 --out "$tmp/owned" --quiet --report
expect_text "its report carries the provenance" "$tmp/owned/report.html" "\"provenance\": {\"run_id\": \"$(sed -n 's/^  "run_id": "\([0-9a-f]*\)",$/\1/p' "$tmp/owned/summary.json")\""

expect_status "--version" 0 "$bin" --version
if git -C "$src" rev-parse HEAD > /dev/null 2>&1; then  # built from a checkout: a commit of it (the one built)
  commit=$(sed -n 's/^railcrash [0-9.]* (commit \([0-9a-f]\{12\}\)\(-dirty\)\?)$/\1/p' "$tmp/stdout")
  [ -n "$commit" ] && git -C "$src" cat-file -e "$commit^{commit}" 2> /dev/null && passes=$((passes + 1)) ||
    { echo "FAIL: --version names no commit of $src: $(head -1 "$tmp/stdout")"; failures=$((failures + 1)); }
fi
expect_text "it names SUNDIALS" "$tmp/stdout" "^SUNDIALS 6"
expect_text "and SuiteSparse" "$tmp/stdout" "^SuiteSparse [0-9.]* (KLU"
expect_status "--quiet run" 0 "$bin" run "$src/tests/report/two_car.yaml" --quiet --out "$tmp/quiet"
[ ! -s "$tmp/stderr" ] && passes=$((passes + 1)) || { echo "FAIL: --quiet printed to stderr"; failures=$((failures + 1)); }

# elements: the reference written from the element declarations.
expect_status "elements lists the types" 0 "$bin" elements
expect_text "one line per type" "$tmp/stdout" "^linear_spring  *(IITRAIN report type 1)  *Linear spring along P1-P2"
expect_status "elements TYPE prints one type" 0 "$bin" elements linear_spring
expect_text "its parameters with unit kind, both unit systems, presence and range" "$tmp/stdout" \
  "stiffness  *force/length (in-lbf-s: lbf/in, SI: N/m); required; >= 0"
expect_status "an unknown element type exits 2" 2 "$bin" elements linear_sprign
expect_text "with the nearest type" "$tmp/stderr" "unknown element type 'linear_sprign' (did you mean 'linear_spring'?)"
# EN 15227 scenarios: the model is written, runs, and summary.json carries the criteria;
# a missing required value, a category or scenario the standard does not define, or a train
# model without the interface the scenario needs exits 2 naming what is missing.
train=$src/models/report/final_two_car.yaml
limits=(--deceleration-limit 5 --survival-space-limit 50 --override-limit 100 --wheel-lift-limit 20
        --passenger-bodies center_body --survival-gauge bolster_body,rear_body)
expect_status "scenario 2 model" 0 "$bin" scenario 2 --train "$train" "${limits[@]}" --buffer-curve 0:0,105:1000,150:2000 \
  --buffer-unloading-stiffness 50 --buffer-height 1060 --t-end 0.005 --out "$tmp/scenario2.yaml"
expect_text "the wagon's weight is 80 t in lbf" "$tmp/scenario2.yaml" "weight: 176369"
expect_status "scenario 2 runs" 0 "$bin" run "$tmp/scenario2.yaml" --quiet --out "$tmp/scenario2"
expect_text "summary.json has the criteria" "$tmp/scenario2/summary.json" '"criterion": "wheel_lift", "subject": "s1_front_truck_wheel_1"'
expect_status "scenario 1 without --offset" 2 "$bin" scenario 1 --train "$train" "${limits[@]}"
expect_text "it names the option" "$tmp/stderr" "missing --offset: the vertical offset between the two units"
expect_status "category C-V" 2 "$bin" scenario 1 --train "$train" "${limits[@]}" --offset 40 --category C-V
expect_text "it names the categories" "$tmp/stderr" "use C-I, C-II, C-III or C-IV"
expect_status "scenario 4" 2 "$bin" scenario 4 --train "$train" "${limits[@]}"
expect_text "it says why" "$tmp/stderr" "out of the longitudinal-vertical plane"
expect_status "a train without the interface" 2 "$bin" scenario 1 --train "$src/models/examples/coupled_cars.yaml" "${limits[@]}" --offset 40
expect_text "it names the train file" "$tmp/stderr" "coupled_cars.yaml"
expect_status "a bad buffer curve" 2 "$bin" scenario 2 --train "$train" "${limits[@]}" --buffer-curve 0:0,105 \
  --buffer-unloading-stiffness 50 --buffer-height 1060
expect_text "it names the point" "$tmp/stderr" "--buffer-curve: '105' is not a point stroke:force"
barrier=$src/models/barrier/two_car_barrier.yaml
barrier_limits=(--deceleration-limit 5 --survival-space-limit 50 --override-limit 100 --wheel-lift-limit 20 --passenger-bodies lead_body,trail_body)
expect_status "scenario 1 from the barrier cars without the face stiffness" 2 "$bin" scenario 1 --train "$barrier" "${barrier_limits[@]}" --offset 40
expect_text "it names the option" "$tmp/stderr" "missing --face-stiffness"
expect_status "scenario 3 without the obstacle" 2 "$bin" scenario 3 --train "$barrier" "${barrier_limits[@]}" --speed 110
expect_text "it names the option" "$tmp/stderr" "missing --obstacle-curve"
expect_status "scenario 3 model" 0 "$bin" scenario 3 --train "$barrier" "${barrier_limits[@]}" --speed 110 --obstacle-curve 0:0,100:500,1000:800 \
  --obstacle-unloading-stiffness 50 --obstacle-height 1000 --t-end 0.005 --out "$tmp/scenario3.yaml"
expect_status "scenario 3 runs" 0 "$bin" run "$tmp/scenario3.yaml" --quiet --out "$tmp/scenario3"
expect_text "summary.json has the survival space of the lead car" "$tmp/scenario3/summary.json" '"criterion": "survival_space", "subject": "s_lead"'
# The shipped scenario models are what models/scenarios/make.sh generates, and they run
# (10 ms, both integrators) with their criteria in summary.json.
mkdir -p "$tmp/scenarios"
cd "$src"
expect_status "make.sh regenerates the scenario models" 0 models/scenarios/make.sh "$bin" "$tmp/scenarios"
cd - > /dev/null
for name in scenario1_report_car scenario2_report_car scenario1_barrier_cars scenario2_barrier_cars scenario1_emu3 scenario2_emu3; do
  if cmp -s "$tmp/scenarios/$name.yaml" "$src/models/scenarios/$name.yaml"; then passes=$((passes + 1));
  else echo "FAIL: models/scenarios/$name.yaml differs from what make.sh writes now"; failures=$((failures + 1)); fi
  for integrator in ida euler; do
    expect_status "$name runs with $integrator" 0 "$bin" run "$src/models/scenarios/$name.yaml" --integrator "$integrator" \
      --t-end 0.01 --quiet --out "$tmp/$name.$integrator"
    expect_text "$name has its criteria" "$tmp/$name.$integrator/summary.json" '"criterion": "override"'
  done
done

echo "$passes passed, $failures failed"
[ "$failures" -eq 0 ]
