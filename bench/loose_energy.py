#!/usr/bin/python3
"""Every shipped model under IDA at loose tolerances, positions in either form (relative, the
default, and `position_tolerance: absolute`), run by one or more builds: which runs fail, how
much energy each creates, and where IDA held its BDF order to 2 (summary.json
stats.bdf_order_held_at; bench/HISTORY.md, "BDF order held where the integration creates
energy"). Prints every row where the builds differ, then per build the failures and the runs
that created more than 1 % (the accuracy warning's limit).

Usage: bench/loose_energy.py [--executables OLD/railcrash,build/railcrash] [--forms relative,absolute]
                             [--rtols 1e-2,5e-3,3e-3,1e-3]
"""
import argparse
import glob
import json
import os
import pathlib
import subprocess
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
NOT_MODELS = ("readings", "sensitivity_design", "_plan")  # study and plan files under models/ (as loose_tolerances)


def run(executable, model, rtol, form, out):
    summary = out / "summary.json"
    summary.unlink(missing_ok=True)
    done = subprocess.run([executable, "run", model, "--integrator", "ida", "--rtol", rtol, "--set",
                           f"simulation.position_tolerance={form}", "--out", str(out), "--quiet"],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    if not summary.exists():
        return {"text": f"no summary (exit {done.returncode})", "failed": True, "created": 0.0}
    s = json.loads(summary.read_text())
    created = s["energy"]["relative_balance_error"]  # [-] energy created (< 0: lost), of the energy turned over
    held = s["stats"].get("bdf_order_held_at")
    failed = s["status"] != "ok"
    text = f"{s['stats']['steps']:6d} steps {100 * created:+8.2f} %" + (f" held at {held:.4g} s" if held is not None else "")
    return {"text": text + (" FAILED" if failed else ""), "failed": failed, "created": created}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--executables", default=str(ROOT / "build" / "railcrash"))
    parser.add_argument("--forms", default="relative,absolute")
    parser.add_argument("--rtols", default="1e-2,5e-3,3e-3,1e-3")
    args = parser.parse_args()
    executables = args.executables.split(",")
    models = sorted(m for m in glob.glob(str(ROOT / "models" / "*" / "*.yaml"))
                    if not any(word in os.path.basename(m) for word in NOT_MODELS))
    results = {e: [] for e in executables}
    print(f"{len(models)} models x {args.forms} x rtol {args.rtols}; executables: {', '.join(executables)}")
    print("rows where the executables differ (energy created > 0, lost < 0, of the energy turned over):")
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(tmp) / "run"
        for model in models:
            for form in args.forms.split(","):
                for rtol in args.rtols.split(","):
                    row = [run(e, model, rtol, form, out) for e in executables]
                    name = f"{os.path.relpath(model, ROOT)} {form} rtol {rtol}"
                    for e, r in zip(executables, row):
                        results[e].append((name, r))
                    if len({r["text"] for r in row}) > 1:
                        print(f"  {name}: " + " | ".join(r["text"] for r in row))
    for e in executables:
        failed = [n for n, r in results[e] if r["failed"]]
        created = [(n, r["created"]) for n, r in results[e] if r["created"] > 0.01]
        print(f"{e}: {len(results[e])} runs, {len(failed)} failed" + (f" ({'; '.join(failed)})" if failed else "") +
              f", {len(created)} created more than 1 %" +
              (" (" + "; ".join(f"{n} {100 * c:.2f} %" for n, c in created) + ")" if created else ""))


if __name__ == "__main__":
    main()
