"""The model file's JSON Schema (docs/railcrash-model.schema.json, README "Editor support").

Usage: python3 test_model_schema.py MODE RAILCRASH_BINARY SOURCE_DIR, MODE one of
  current   the committed schema equals what `railcrash schema` prints;
  models    every model file under models/ and verification/ (a YAML map with a top-level
            `railcrash` key; sweep plans, sensitivity designs and reading studies are other
            formats) is valid against the schema, and so is what `railcrash expand` writes from
            those with trains;
  agree     bad models (a misspelt parameter, a missing required one, a string for a number, an
            unknown element type, ...) are rejected by the schema AND by `railcrash check`, and
            their unbroken base by neither; a model with anchors and aliases is accepted by both,
            one with a merge key (<<: *anchor) rejected by both.

YAML is read as YAML 1.2 reads numbers (what railcrash and VS Code's YAML extension do):
PyYAML's YAML 1.1 rules read 1e6 (no dot) as a string. Anchors and aliases are resolved by the
YAML reader before validation, as in an editor; merge keys are not (railcrash has none).
"""
import copy
import difflib
import os
import re
import subprocess
import sys
import tempfile

import jsonschema
import yaml


class Yaml12Loader(yaml.SafeLoader):
    """SafeLoader with YAML 1.2's floats (1e6, 2E-3 without a dot)."""


Yaml12Loader.yaml_implicit_resolvers = {k: list(v) for k, v in yaml.SafeLoader.yaml_implicit_resolvers.items()}
Yaml12Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][-+]?[0-9]+)?$|^[-+]?\.(?:inf|Inf|INF)$|^\.(?:nan|NaN|NAN)$"),
    list("-+0123456789."),
)
# An integer-looking scalar stays an integer (the int resolver is tried first for it).
# No merge keys: railcrash's YAML reader (yaml-cpp 0.7) reads `<<: *anchor` as a key named '<<',
# which the loader rejects; so does the schema when '<<' stays a key (as in YAML 1.2 editors).
Yaml12Loader.yaml_implicit_resolvers["<"] = [
    (tag, regexp) for tag, regexp in Yaml12Loader.yaml_implicit_resolvers.get("<", []) if tag != "tag:yaml.org,2002:merge"]


def load_yaml(path):
    with open(path, encoding="utf-8") as f:
        return yaml.load(f, Loader=Yaml12Loader)


def schema_text(binary):
    return subprocess.run([binary, "schema"], check=True, capture_output=True, text=True).stdout


def validator(source_dir):
    import json
    with open(os.path.join(source_dir, "docs", "railcrash-model.schema.json"), encoding="utf-8") as f:
        schema = json.load(f)
    jsonschema.Draft7Validator.check_schema(schema)
    return jsonschema.Draft7Validator(schema)


def errors_of(v, document):
    return sorted(v.iter_errors(document), key=lambda e: list(e.absolute_path))


def describe(error):
    # The deepest cause of an if/then failure says what is wrong.
    path = "/".join(str(p) for p in error.absolute_path) or "(top)"
    return f"{path}: {error.message[:300]}"


def model_files(source_dir):
    out = []
    for top in ("models", "verification"):
        for folder, _, files in os.walk(os.path.join(source_dir, top)):
            for name in sorted(files):
                if name.endswith((".yaml", ".yml")):
                    path = os.path.join(folder, name)
                    document = load_yaml(path)
                    if isinstance(document, dict) and "railcrash" in document:
                        out.append((path, document))
    return sorted(out)


def mode_current(binary, source_dir):
    committed_path = os.path.join(source_dir, "docs", "railcrash-model.schema.json")
    with open(committed_path, encoding="utf-8") as f:
        committed = f.read()
    generated = schema_text(binary)
    if committed != generated:
        sys.stdout.writelines(difflib.unified_diff(committed.splitlines(True), generated.splitlines(True),
                                                   "docs/railcrash-model.schema.json (committed)", "railcrash schema"))
        print("FAIL: docs/railcrash-model.schema.json differs from `railcrash schema` (- committed, + generated).")
        print("Regenerate it from the source folder with: build/railcrash schema -o docs/railcrash-model.schema.json")
        return 1
    print("docs/railcrash-model.schema.json matches `railcrash schema`")
    return 0


def mode_models(binary, source_dir):
    v = validator(source_dir)
    files = model_files(source_dir)
    failed = 0
    for path, document in files:
        errors = errors_of(v, document)
        if errors:
            failed += 1
            print(f"FAIL: {os.path.relpath(path, source_dir)} is not valid against the schema:")
            for e in errors[:10]:
                print("   ", describe(e))
    # What `railcrash expand` writes from a model with trains is a flat model: valid too.
    expanded = 0
    for path, document in files:
        if "trains" not in document:
            continue
        result = subprocess.run([binary, "expand", path], capture_output=True, text=True)
        errors = errors_of(v, yaml.load(result.stdout, Loader=Yaml12Loader)) if result.returncode == 0 else []
        if result.returncode != 0 or errors:
            failed += 1
            print(f"FAIL: railcrash expand {os.path.relpath(path, source_dir)}: exit {result.returncode} {result.stderr.strip()[:300]}")
            for e in errors[:10]:
                print("   ", describe(e))
        expanded += 1
    if expanded == 0:
        print("FAIL: no model with trains to expand")
        return 1
    if len(files) < 20:
        print(f"FAIL: only {len(files)} model files found under models/ and verification/")
        return 1
    print(f"{len(files)} model files and {expanded} expanded train models checked against the schema, {failed} invalid")
    return 1 if failed else 0


def first_element(document, type_name):
    for e in document["elements"]:
        if e["type"] == type_name:
            return e
    raise AssertionError(f"no {type_name} element in the base model")


def bad_models(source_dir):
    """(what, base path, edit, what the loader's message must contain) for each case."""
    spring_mass = os.path.join(source_dir, "verification", "cases", "spring_mass.yaml")
    emu = os.path.join(source_dir, "models", "examples", "emu3_wall.yaml")
    anticlimber = os.path.join(source_dir, "models", "report", "final_two_car.yaml")
    scenario = os.path.join(source_dir, "models", "scenarios", "scenario1_report_car.yaml")

    def rename(key, new):
        def edit(d):
            e = first_element(d, "linear_spring")
            e[new] = e.pop(key)
        return edit

    def spring(key, value):
        def edit(d):
            first_element(d, "linear_spring")[key] = value
        return edit

    def drop(key):
        def edit(d):
            del first_element(d, "linear_spring")[key]
        return edit

    def set_path(*path_and_value):
        *path, value = path_and_value

        def edit(d):
            node = d
            for step in path[:-1]:
                node = node[step]
            node[path[-1]] = value
        return edit

    def anticlimber_word(d):
        first_element(d, "anticlimber")["interlock_while_unloading"] = "loosen"

    return [
        ("a misspelt parameter", spring_mass, rename("stiffness", "stifness"), "unknown key 'stifness'"),
        ("a missing required parameter", spring_mass, drop("stiffness"), "missing required parameter 'stiffness'"),
        ("a string where a number belongs", spring_mass, spring("stiffness", "stiff"), "must be a number"),
        ("a list where a number belongs", spring_mass, spring("free_length", [1.0, 2.0]), "must be a number"),
        ("a negative value where it must not be", spring_mass, spring("stiffness", -5.0), "must not be negative"),
        ("an unknown element type", spring_mass, spring("type", "linear_sprung"), "unknown element type 'linear_sprung'"),
        ("a name above the loader's 256 characters", spring_mass, spring("name", "s" * 300), "more than the limit of 256"),
        ("a misspelt body key", spring_mass, set_path("bodies", 0, "intertia", 0.1), "unknown key 'intertia'"),
        ("an unknown integrator", spring_mass, set_path("simulation", "integrator", "rk4"), "integrator must be auto, ida or euler"),
        ("an unknown unit system", spring_mass, set_path("units", "furlongs"), "units must be"),
        ("an unknown top-level key", spring_mass, set_path("simulaton", {"t_end": 1.0}), "unknown key 'simulaton'"),
        ("a choice outside its values", anticlimber, anticlimber_word, "interlock_while_unloading"),
        ("a third point on a two-point element", spring_mass,
         lambda d: first_element(d, "linear_spring")["points"].append({"body": "mass"}), "needs exactly 2 points"),
        ("a fractional max_steps", spring_mass, set_path("simulation", "max_steps", 10.5), "max_steps must be a whole number"),
        ("a misspelt key of the scenario section", scenario, set_path("scenario", "override", "wheel_lift_limt", 1.0),
         "unknown key 'wheel_lift_limt'"),
        ("an unknown design category", scenario, set_path("scenario", "category", "C-V"), "category must be"),
        ("a misspelt key of a train's car", emu, set_path("trains", 0, "cars", 0, "reverse", True), "unknown key 'reverse'"),
        ("a train facing neither way", emu, set_path("trains", 0, "facing", "up"), "facing must be +x or -x"),
        ("a misspelt parameter in a car type", emu,
         lambda d: next(iter(d["car_types"].values()))["elements"][0].update({"stifnes": 1.0}), "unknown key 'stifnes'"),
    ]


def railcrash_check(binary, document):
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
        yaml.safe_dump(document, f, sort_keys=False)
        path = f.name
    try:
        return subprocess.run([binary, "check", path], capture_output=True, text=True)
    finally:
        os.unlink(path)


ALIASES = """railcrash: 1
name: anchors and aliases
units: SI
gravity: [0, 0]
bodies:
  - &mass {name: mass, mass: 2.0, inertia: 0.1, position: [1.1, 0.0]}
  - {name: mass2, mass: 2.0, inertia: 0.1, position: &p2 [2.2, 0.0]}
elements:
  - {name: spring, type: linear_spring, stiffness: &k 2e2, points: &ends [{body: ground}, {body: mass}]}
  - {name: dashpot, type: linear_dashpot, damping: *k, points: *ends}
  - {name: spring2, type: linear_spring, stiffness: *k, points: [{body: mass}, {body: mass2}]}
simulation: {t_end: 1.0}
"""
MERGE = ALIASES.replace("{name: mass2, mass: 2.0, inertia: 0.1, position: &p2 [2.2, 0.0]}", "{<<: *mass, name: mass2, position: [2.2, 0.0]}")


def agree_on_text(binary, v, what, text, accepted, message=""):
    """Whether the schema and `railcrash check` both accept (or both reject) the model `text`."""
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
        f.write(text)
        path = f.name
    try:
        schema_errors = errors_of(v, load_yaml(path))
        result = subprocess.run([binary, "check", path], capture_output=True, text=True)
    finally:
        os.unlink(path)
    loader_ok = result.returncode == 0 if accepted else (result.returncode == 2 and message in result.stderr)
    if bool(schema_errors) == accepted or not loader_ok:
        print(f"FAIL: {what}: expected both to {'accept' if accepted else 'reject'} it; schema: "
              f"{[describe(e) for e in schema_errors[:3]]}; railcrash check exits {result.returncode}: {result.stderr.strip()[:300]}")
        return False
    print(f"ok: {what}: both {'accept' if accepted else 'reject'} it")
    return True


def scenario_keys_agree(v, source_dir):
    """The scenario section's keys are described by hand in src/model/model_schema.cpp: they must be
    the lists read_scenario_section (src/results/scenario_criteria.cpp) passes to check_map_keys."""
    with open(os.path.join(source_dir, "src", "results", "scenario_criteria.cpp"), encoding="utf-8") as f:
        text = f.read()
    lists = re.findall(r'check_map_keys\(\w+,\s*\{([^}]*)\},\s*"([^"]*)"\)', text)
    scenario = v.schema["definitions"]["scenario"]
    where = {"the section": scenario, "mean_deceleration": scenario["properties"]["mean_deceleration"],
             "survival_space": scenario["properties"]["survival_space"],
             "survival_space: gauge": scenario["properties"]["survival_space"]["properties"]["gauges"]["items"],
             "survival_space: zone": scenario["properties"]["survival_space"]["properties"]["zones"]["items"],
             "override": scenario["properties"]["override"]}
    ok = len(lists) == len(where)
    for keys, context in lists:
        loader = set(re.findall(r'"([^"]+)"', keys))
        schema = set(where[context]["properties"]) if context in where else set()
        if loader != schema:
            ok = False
            print(f"FAIL: scenario section '{context}': criteria.cpp allows {sorted(loader)}, the schema {sorted(schema)}")
    if len(lists) != len(where):
        print(f"FAIL: criteria.cpp has {len(lists)} check_map_keys lists, the schema describes {len(where)} maps of the scenario section")
    if ok:
        print(f"ok: the scenario section's {len(lists)} key lists are the schema's")
    return ok


def mode_agree(binary, source_dir):
    v = validator(source_dir)
    failed = 0
    failed += not scenario_keys_agree(v, source_dir)
    failed += not agree_on_text(binary, v, "anchors and aliases", ALIASES, True)
    failed += not agree_on_text(binary, v, "a merge key", MERGE, False, "unknown key '<<'")
    checked_bases = set()
    for what, base_path, edit, message in bad_models(source_dir):
        base = load_yaml(base_path)
        if base_path not in checked_bases:  # the unbroken base passes both
            checked_bases.add(base_path)
            result = railcrash_check(binary, base)
            if result.returncode != 0 or errors_of(v, base):
                print(f"FAIL: the base model {base_path} is rejected (railcrash check: {result.stderr.strip()})")
                failed += 1
        document = copy.deepcopy(base)
        edit(document)
        schema_errors = errors_of(v, document)
        result = railcrash_check(binary, document)
        loader_ok = result.returncode == 2 and message in result.stderr
        if not schema_errors or not loader_ok:
            failed += 1
            print(f"FAIL: {what}: schema {'rejects' if schema_errors else 'ACCEPTS'} it; railcrash check exits "
                  f"{result.returncode} with: {result.stderr.strip()[:400]} (expected a message with '{message}')")
        else:
            print(f"ok: {what}: schema: {describe(schema_errors[0])}; railcrash check: {result.stderr.strip()[:200]}")
    return 1 if failed else 0


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in ("current", "models", "agree"):
        print(__doc__)
        return 2
    mode, binary, source_dir = sys.argv[1:]
    return {"current": mode_current, "models": mode_models, "agree": mode_agree}[mode](binary, source_dir)


if __name__ == "__main__":
    sys.exit(main())
