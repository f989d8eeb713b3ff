"""railcrash: planar rail-vehicle crash dynamics from Python.

    import railcrash
    m = railcrash.load("models/report/final_two_car.yaml",
                       set={"elements.anticlimber.horizontal_yield_deflection*": 1.2})
    r = railcrash.run(m, integrator="ida", rtol=1e-4)
    r.t, r.series("car1_center_body.x")      # numpy arrays (read-only views)
    r.summary["car_crush"]                     # summary.json as a dict
    r.events                                   # [(t, element, event, value), ...]
    r.dataframe()                              # every column, when pandas is installed

    b = railcrash.ModelBuilder("spring-mass", "SI")   # a model in code
    b.gravity(0, 0).body("cart", mass=2.0, inertia=0.1, position=(1.1, 0))
    b.element("spring", "linear_spring", [("ground", 0, 0), ("cart", 0, 0)],
              {"stiffness": 800.0, "free_length": 1.0})
    m = b.build()

    t = railcrash.sweep("model.yaml", "plan.yaml", jobs=2)   # `railcrash sweep`: runs.csv as a table

Settings (`set=`) are the command line's --set: {"simulation.t_end": 0.5} is
simulation.t_end=0.5; a key ending in "*" scales the model's number:
{"elements.k1.stiffness*": 1.2} is elements.k1.stiffness*=1.2.

Errors in a model or a setting raise railcrash.InputError (a ValueError) whose message
names the file, line, element or key and what to change. A run the solver cannot finish
does not raise: r.ok is False and r.message says why. Runs release the GIL: threads run
models in parallel.
"""

import json as _json
import math as _math
import numbers as _numbers
import os as _os
import warnings as _warnings

import numpy as _numpy

from ._railcrash import InputError, Model, ModelBuilder, Results, RunSettings, SolverError, __version__
from . import _railcrash

for _name in ("InputError", "SolverError", "Model", "ModelBuilder", "Results", "RunSettings"):
    getattr(_railcrash, _name).__module__ = "railcrash"

__all__ = ["load", "from_yaml", "run", "AccuracyWarning", "sensitivity", "sweep", "Model", "ModelBuilder", "Results", "InputError", "SolverError", "__version__"]


def _setting_value(key, value):
    """The YAML text of one setting's value; TypeError names the key for anything else."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, _numbers.Real):
        number = float(value)
        if not _math.isfinite(number):
            raise InputError(f"set: '{key}' must be a finite number, not {value!r}")
        return repr(number)
    if isinstance(value, str):
        return value
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_setting_value(key, item) for item in value) + "]"
    raise TypeError(f"set: the value of '{key}' must be a number, a bool, a string or a list, "
                    f"not {type(value).__name__}")


def _settings(values):
    """{"KEY": value, "KEY*": factor} -> ["KEY=value", "KEY*=factor"] (a list of strings passes through)."""
    if values is None:
        return []
    if isinstance(values, (list, tuple)):
        for item in values:
            if not isinstance(item, str):
                raise TypeError(f"set: a list of settings holds 'KEY=VALUE' strings, not {type(item).__name__}")
        return list(values)
    if not isinstance(values, dict):
        raise TypeError(f"set must be a dict {{key: value}} or a list of 'KEY=VALUE' strings, not {type(values).__name__}")
    out = []
    for key, value in values.items():
        if not isinstance(key, str) or not key:
            raise TypeError(f"set: keys are strings such as 'simulation.t_end', not {key!r}")
        if key.endswith("*"):
            if isinstance(value, bool) or not isinstance(value, _numbers.Real):
                raise TypeError(f"set: '{key}' scales a number; its factor must be a number, not {type(value).__name__}")
            out.append(f"{key}={_setting_value(key, value)}")
        else:
            out.append(f"{key}={_setting_value(key, value)}")
    return out


def load(path, set=None):
    """Reads and checks a model file; `set` applies settings (see the module help)."""
    return Model.load(str(path), _settings(set))


def from_yaml(text, set=None, source="<string>"):
    """A model from YAML text; `source` names it in error messages."""
    return Model.from_yaml(text, source, _settings(set))


_with_settings = Model.with_settings


def _with(self, set):
    """A copy of the model with more settings applied (a dict as for load, or 'KEY=VALUE' strings)."""
    return _with_settings(self, _settings(set))


Model.with_settings = _with


class AccuracyWarning(UserWarning):
    """A run's own energy balance or constraint residual says its numbers carry an integration
    error past the stated limits (README "Accuracy warnings"); the message says what to change."""


def run(model, integrator=None, t_end=None, rtol=None, atol=None, dt=None, output_interval=None, force_dt=False,
        set=None, timings=False):
    """Runs a model (a Model, or a model file's path) and returns its Results, in memory.

    Unset arguments keep the model's simulation section. integrator: "auto", "ida" or "euler"
    (auto: results.summary["integrator_used"] says which ran when, and why). atol is in the model
    file's length unit (mm for an mm-t-s-N model), as its simulation.atol and --atol.
    timings: split the run's wall time by phase, as `railcrash run --timings`:
    results.summary["stats"]["seconds"] (residual, jacobian, linear_solve, ..., adding up to
    results.summary["stats"]["wall_seconds"]).
    """
    if isinstance(model, (str, _os.PathLike)):
        model = load(model, set)
    elif not isinstance(model, Model):
        raise TypeError(f"run takes a railcrash.Model or a model file's path, not {type(model).__name__}")
    elif set:
        model = model.with_settings(set)
    settings = RunSettings()
    if integrator is not None:
        if integrator not in ("auto", "ida", "euler"):
            raise InputError(f"integrator must be 'auto', 'ida' or 'euler', not {integrator!r}")
        settings.integrator = integrator
    for name, value in (("t_end", t_end), ("rtol", rtol), ("atol", atol), ("dt", dt),
                        ("output_interval", output_interval)):
        if value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, _numbers.Real):
            raise TypeError(f"{name} must be a number, not {type(value).__name__}")
        setattr(settings, name, float(value))
    settings.force_dt = bool(force_dt)
    settings.timings = bool(timings)
    results = _railcrash._run(model, settings)
    for text in results.accuracy_warnings:  # (as `railcrash run` prints them: README "Accuracy warnings")
        _warnings.warn(text, AccuracyWarning, stacklevel=2)
    return results


def _summary(self):
    """summary.json of the run as a dict (status, stats, energy, peaks, peak_accelerations, car_crush, ...)."""
    return _json.loads(self.summary_json)


def _dataframe(self):
    """Every column as a pandas DataFrame indexed by t (needs pandas)."""
    try:
        import pandas
    except ImportError as error:
        raise ImportError("Results.dataframe() needs pandas (Debian: apt install python3-pandas); "
                          "Results.series(name) gives numpy arrays without it") from error
    columns = self.columns
    frame = pandas.DataFrame({name: self.series(name) for name in columns[1:]}, index=self.series("t"))
    frame.index.name = "t"
    return frame


def _outcomes(self):
    """The run's discrete outcome (summary.json's "outcomes"): "signature" (fractures, shears,
    overrides, bottoming with their times), "branch" (the order only; runs with equal ones are on
    one branch) and "events" [{t, element, what}, ...]."""
    return self.summary["outcomes"]


Results.summary = property(_summary)
Results.outcomes = property(_outcomes)
Results.dataframe = _dataframe


def sensitivity(model_path, design="report", jobs=0, only=None, second_order=True, central=0.0, run_limit=0.0,
                bisect=4):
    """The report's parameter study of R1-R3 (`railcrash sensitivity`), returned as tables.

    design: a design file, or "report" for sensitivity_design.yaml beside the model.
    Returns a dict: "runs" (one row per run: parameter, variation, factor, ok, R1-R3, and its
    discrete outcome: "outcomes" with times, "branch" order only, and the method it used:
    "integrator_used" "ida", "euler", "ida+euler" or "ida+euler+ida" (IDA took it back),
    "euler_from_t" the time integrator auto handed the run to Euler, NaN when it did not), "first_order" (A_i per
    parameter), "constant" (A0 for R1-R3), "branch_changes" (each first-order run whose branch
    differs from run 0's, its step bisected `bisect` times: the values of P on and off run 0's
    branch, A_i, the effect within the branch and the jump) and, with a second-order design,
    "second_order" (fitted constants per term). Rows are dicts: pandas.DataFrame(rows) makes a
    table of them.
    """
    only = list(only) if only else []
    return _railcrash._sensitivity(str(model_path), str(design), int(jobs), only, bool(second_order), float(central),
                                   float(run_limit), int(bisect))


def _sweep_column(name, values):
    """A runs.csv column: integers for "run", floats (NaN where empty) where every value is a
    number, else the texts."""
    if name == "run":
        return _numpy.array([int(v) for v in values], dtype=int)
    try:
        return _numpy.array([float(v) if v != "" else _math.nan for v in values], dtype=float)
    except ValueError:
        return list(values)


def sweep(model_path, plan, jobs=0, out=None, resume=False, run_limit=0.0):
    """A study over model keys (`railcrash sweep`; README "Sweeps"), returned as a table.

    plan: a plan file, or a dict of the same content (written to a JSON file for the run,
    so error messages name that file and its line). out: the folder for runs.csv and
    summary.md (default: a temporary folder, removed afterwards). Returns a
    pandas.DataFrame when pandas is installed, else a dict of columns (numpy arrays for
    numbers, lists of text): run, hash, one column per factor, status, one per response,
    wall_seconds, message, outcomes, branch, integrator_used ("ida", "euler", "ida+euler" or
    "ida+euler+ida": IDA took the run back), euler_from_t (when integrator auto handed the run to Euler; NaN when it did not). Runs not
    done (interrupted) are left out.
    """
    import tempfile
    with tempfile.TemporaryDirectory(prefix="railcrash_sweep_") as scratch:
        plan_path = plan
        if isinstance(plan, dict):
            plan_path = _os.path.join(scratch, "plan.json")
            with open(plan_path, "w") as f:
                _json.dump(plan, f, indent=1)
        directory = str(out) if out is not None else _os.path.join(scratch, "out")
        columns, rows = _railcrash._sweep(str(model_path), str(plan_path), int(jobs), directory, bool(resume),
                                          float(run_limit))
    table = {name: _sweep_column(name, [row[k] for row in rows]) for k, name in enumerate(columns)}
    try:
        import pandas
    except ImportError:
        return table
    return pandas.DataFrame(table, columns=columns)
