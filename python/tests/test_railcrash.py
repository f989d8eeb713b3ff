"""Tests of the Python module (run by CTest: `ctest -R python`, with PYTHONPATH=build/python).

Values are checked against closed forms: the period of a spring-mass oscillator, the crush of
a mass stopped by an anticlimber (energy balance), and against the same runs done alone.
"""

import math
import os
import pathlib
import tempfile
import sys
import threading
import time
import unittest
from unittest import mock

import numpy

import railcrash

SOURCE = pathlib.Path(os.environ.get("RAILCRASH_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
TWO_CAR = SOURCE / "models" / "report" / "final_two_car.yaml"

MASS = 2.0          # [kg]
STIFFNESS = 800.0   # [N/m]
OSCILLATOR = f"""railcrash: 1
name: oscillator
units: SI
gravity: [0, 0]
bodies:
  - {{name: cart, mass: {MASS}, inertia: 0.1, position: [1.1, 0]}}
elements:
  - name: spring
    type: linear_spring
    stiffness: {STIFFNESS}
    free_length: 1.0
    points: [{{body: ground, at: [0, 0]}}, {{body: cart, at: [0, 0]}}]
simulation: {{t_end: 1.0, output_interval: 1.0e-4, rtol: 1.0e-9}}
"""

# A 1000 kg car at 2 m/s into an anticlimber against the ground: elastic 1e7 N/m up to the
# yield deflection, then 1e5 N/m (the R1 test model the C++ and shell tests read too).
ANTICLIMBER = (SOURCE / "tests" / "models" / "anticlimber_r1.yaml").read_text()


def crush_for(yield_deflection, elastic=1e7, plastic=1e5, energy=2000.0):
    """Largest crush [m] from the energy balance k d_y^2/2 + F_y u + k_p u^2/2 = E."""
    force = elastic * yield_deflection
    rest = energy - 0.5 * elastic * yield_deflection ** 2
    u = (-force + math.sqrt(force ** 2 + 2.0 * plastic * rest)) / plastic
    return yield_deflection + u


def mean_period(t, x, level):
    """Mean period from the upward crossings of `level` (linear interpolation)."""
    below = x[:-1] < level
    k = numpy.nonzero(below & (x[1:] >= level))[0]
    crossings = t[k] + (level - x[k]) / (x[k + 1] - x[k]) * (t[k + 1] - t[k])
    return (crossings[-1] - crossings[0]) / (len(crossings) - 1)


class RunTest(unittest.TestCase):
    def test_spring_mass_period_against_the_closed_form(self):
        model = railcrash.from_yaml(OSCILLATOR)
        self.assertEqual(model.name, "oscillator")
        self.assertEqual(model.bodies, ["cart"])
        self.assertEqual(model.elements, [("spring", "linear_spring")])
        result = railcrash.run(model, integrator="ida")
        self.assertTrue(result.ok, result.message)
        self.assertIsInstance(result.t, numpy.ndarray)
        self.assertEqual(result.t.shape, (10001,))
        self.assertAlmostEqual(result.t[-1], 1.0, places=12)
        x = result.series("cart.x")
        self.assertEqual(x.shape, result.t.shape)
        self.assertFalse(x.flags.writeable)
        exact = 2.0 * math.pi * math.sqrt(MASS / STIFFNESS)
        self.assertLess(abs(mean_period(result.t, x, 1.0) - exact) / exact, 1e-6)
        # Amplitude 0.1 m about the free length; energy k A^2 / 2 = 4 J is kept.
        self.assertAlmostEqual(x.max(), 1.1, places=6)
        self.assertAlmostEqual(x.min(), 0.9, places=6)
        summary = result.summary
        self.assertEqual(summary["status"], "ok")
        self.assertEqual(summary["integrator"], "ida")
        self.assertNotIn("integrator_used", summary)
        # auto on a smooth motion without mode changes keeps IDA throughout, with IDA's result.
        auto = railcrash.run(model, integrator="auto")
        self.assertEqual(auto.summary["integrator"], "auto")
        self.assertEqual(auto.summary["integrator_used"]["method"], "ida")
        self.assertIsNone(auto.summary["integrator_used"]["euler_from_t"])
        self.assertTrue(auto.summary["integrator_used"]["reason"].startswith("IDA kept the run"))
        self.assertTrue(numpy.array_equal(auto.series("cart.x"), x))
        self.assertLess(abs(summary["energy"]["balance_error"]), 1e-5)
        # Signed extremes of the spring force (tension positive): +k A at x = 1.1, -k A at x = 0.9.
        self.assertAlmostEqual(summary["peaks"]["spring.force"]["max"], STIFFNESS * 0.1, places=3)
        self.assertAlmostEqual(summary["peaks"]["spring.force"]["min"], -STIFFNESS * 0.1, places=3)
        self.assertEqual(result.events, [])

    def test_model_built_in_code(self):
        builder = railcrash.ModelBuilder("oscillator", "SI")
        builder.gravity(0.0, 0.0).body("cart", mass=MASS, inertia=0.1, position=(1.1, 0.0))
        builder.element("spring", "linear_spring", [("ground", 0, 0), ("cart", 0, 0)],
                        {"stiffness": STIFFNESS, "free_length": 1.0})
        settings = railcrash.RunSettings()
        settings.t_end = 1.0
        settings.output_interval = 1e-4
        builder.simulation(settings)
        model = builder.build()
        self.assertIn("linear_spring", builder.yaml())
        result = railcrash.run(model, rtol=1e-9)
        exact = 2.0 * math.pi * math.sqrt(MASS / STIFFNESS)
        self.assertLess(abs(mean_period(result.t, result.series("cart.x"), 1.0) - exact) / exact, 1e-6)
        # A constant force F moves the equilibrium by F / k.
        pushed = railcrash.ModelBuilder("pushed", "SI")
        pushed.gravity(0, 0).body("cart", mass=MASS, inertia=0.1, position=(1.0, 0.0))
        pushed.element("spring", "linear_spring", [("ground", 0, 0), ("cart", 0, 0)],
                       {"stiffness": STIFFNESS, "free_length": 1.0})
        pushed.element("damper", "linear_dashpot", [("ground", 0, 0), ("cart", 0, 0)], {"damping": 80.0})  # critical: 2 sqrt(k m)
        pushed.force("cart", at=(0, 0), value=(40.0, 0.0))
        settled = railcrash.run(pushed.build(), t_end=2.0)
        self.assertAlmostEqual(settled.series("cart.x")[-1], 1.0 + 40.0 / STIFFNESS, places=6)

    def test_built_body_declares_its_car(self):
        builder = railcrash.ModelBuilder("cars")
        builder.gravity(0, 0).body("cart", mass=1.0, inertia=0.1, position=(1, 0), car="train")
        builder.body("post", mass=1.0, inertia=0.1, position=(3, 0))
        self.assertIn('car: "train"', builder.yaml())
        self.assertEqual(builder.yaml().count("car:"), 1)
        empty = railcrash.ModelBuilder("empty car")
        empty.body("cart", mass=1.0, inertia=0.1, position=(1, 0), car=" train")
        with self.assertRaisesRegex(railcrash.InputError, "body 'cart': car ' train' starts or ends with a space"):
            empty.build()

    def test_built_model_errors_name_the_element(self):
        builder = railcrash.ModelBuilder("dangling")
        builder.body("cart", mass=1.0, inertia=0.1, position=(1, 0))
        builder.element("spring", "linear_spring", [("ground", 0, 0), ("crat", 0, 0)], {"stiffness": 10.0})
        with self.assertRaisesRegex(railcrash.InputError, "element 'spring'.*unknown body 'crat' \\(did you mean 'cart'\\?\\)"):
            builder.build()
        typo = railcrash.ModelBuilder("typo")
        typo.body("cart", mass=1.0, inertia=0.1, position=(1, 0))
        typo.element("spring", "linear_sprung", [("ground", 0, 0), ("cart", 0, 0)], {"stiffness": 10.0})
        with self.assertRaisesRegex(railcrash.InputError, "did you mean 'linear_spring'"):
            typo.build()
        negative = railcrash.ModelBuilder("negative")
        negative.body("cart", mass=-1.0, inertia=0.1, position=(1, 0))
        with self.assertRaisesRegex(railcrash.InputError, "body 'cart': mass must be positive"):
            negative.build()
        with self.assertRaises(TypeError):
            negative.element("spring", "linear_spring", [("ground", 0, 0)], {"stiffness": "stiff"})

    def test_settings_scale_and_set_values(self):
        model = railcrash.from_yaml(OSCILLATOR)
        base = railcrash.run(model)
        stiffer = railcrash.run(model, set={"elements.spring.stiffness*": 4})
        ratio = mean_period(stiffer.t, stiffer.series("cart.x"), 1.0) / mean_period(base.t, base.series("cart.x"), 1.0)
        self.assertAlmostEqual(ratio, 0.5, places=6)
        heavier = model.with_settings({"bodies.cart.mass": 4 * MASS, "simulation.t_end": 0.5})
        self.assertEqual(heavier.settings, ["bodies.cart.mass=8.0", "simulation.t_end=0.5"])
        self.assertEqual(heavier.t_end, 0.5)
        result = railcrash.run(heavier, t_end=0.75, output_interval=1e-3)
        self.assertAlmostEqual(result.t[-1], 0.75, places=12)
        self.assertEqual(len(result.t), 751)
        # Euler from Python too, at a fixed step.
        euler = railcrash.run(model, integrator="euler", dt=1e-5, t_end=0.2)
        self.assertTrue(euler.ok, euler.message)
        self.assertEqual(euler.summary["integrator"], "euler")

    def test_events_and_responses_of_an_anticlimber_crush(self):
        result = railcrash.run(railcrash.from_yaml(ANTICLIMBER))
        self.assertTrue(result.ok, result.message)
        crush = crush_for(0.01)
        self.assertAlmostEqual(result.summary["responses"]["R1"], crush / 0.02, delta=1e-5 * crush / 0.02)
        self.assertAlmostEqual(result.series("ac.horizontal_deformation").max(), crush, delta=1e-4 * crush)
        kinds = [event for _, element, event, _ in result.events if element == "ac"]
        self.assertIn("contact", " ".join(kinds))
        self.assertIn("yield", " ".join(kinds))
        for t, element, event, value in result.events:
            self.assertIsInstance(t, float)
            self.assertTrue(0.0 <= t <= 0.15)

    def test_discrete_outcome_of_a_gear_that_fractures_or_not(self):
        # A 500 kg probe at 2 m/s into a draft gear: peak force sqrt(H^2 + 2 k (E - stick corner)),
        # about 49.2 kN (tests/studies/test_sensitivity.cpp gear_peak_force): a fracture load below it
        # fractures, one above does not.
        def gear(fracture_load):
            return railcrash.from_yaml(
                "railcrash: 1\nname: gear\nunits: SI\ngravity: [0, 0]\nbodies:\n"
                "  - {name: probe, mass: 500, inertia: 1, position: [0, 0], velocity: [-2, 0]}\nelements:\n"
                "  - {name: gear, type: draft_gear, initial_stiffness: 1.0e6, travel: 0.05, stiffness_after_bottoming: 2.0e7,\n"
                "     hysteresis_load: 2.0e4, transition_stiffness: 2.0e7, fracture_load: %g,\n"
                "     points: [{body: ground, at: [-1, 0]}, {body: probe, at: [0, 0]}]}\n"
                "simulation: {t_end: 0.06, rtol: 1e-8}\n" % fracture_load)
        broken = railcrash.run(gear(45000.0))
        self.assertTrue(broken.ok, broken.message)
        self.assertEqual(broken.outcomes["branch"], "gear:fracture")
        self.assertEqual(len(broken.outcomes["events"]), 1)
        self.assertTrue(broken.outcomes["signature"].startswith("gear:fracture@"))
        fracture_time = broken.outcomes["events"][0]["t"]
        located = [t for t, element, event, _ in broken.events if (element, event) == ("gear", "fracture")]
        self.assertEqual(len(located), 1)
        self.assertAlmostEqual(fracture_time, located[0], delta=1e-9)  # summary.json keeps 12 digits
        intact = railcrash.run(gear(54000.0))
        self.assertTrue(intact.ok, intact.message)
        self.assertEqual(intact.outcomes["branch"], "none")
        self.assertEqual(intact.outcomes["events"], [])

    @unittest.skipUnless(TWO_CAR.exists(), "the report's two-car model")
    def test_report_model_from_file(self):
        model = railcrash.load(TWO_CAR, set={"elements.anticlimber.horizontal_yield_deflection*": 1.2,
                                            "simulation.t_end": 0.05})
        self.assertEqual(len(model.bodies), 18)
        self.assertIn("car1_center_body.x", model.columns)
        result = railcrash.run(model, integrator="ida", rtol=1e-4)
        self.assertTrue(result.ok, result.message)
        self.assertEqual(result.columns, model.columns)
        x = result.series("car1_center_body.x")
        # The striking car enters at 616 in/s (35 mph) and slows down.
        self.assertAlmostEqual((x[1] - x[0]) / (result.t[1] - result.t[0]), 616.0, delta=1.0)
        self.assertLess(result.series("car1_center_body.vx")[-1], 616.0)
        self.assertGreater(len(result.events), 0)
        self.assertEqual(set(result.summary["car_crush"]), {"car1", "car2"})

    @unittest.skipUnless(TWO_CAR.exists(), "the report's two-car model")
    def test_same_results_as_the_command_line_settings(self):
        """A KEY*=FACTOR setting from Python and its KEY=VALUE spelling give the same run."""
        scaled = railcrash.load(TWO_CAR, set={"elements.anticlimber.horizontal_yield_deflection*": 1.5,
                                             "simulation.t_end": 0.02})
        valued = railcrash.load(TWO_CAR, set=["elements.anticlimber.horizontal_yield_deflection=0.159",
                                              "simulation.t_end=0.02"])
        a = railcrash.run(scaled, rtol=1e-5).series("anticlimber.horizontal_force")
        b = railcrash.run(valued, rtol=1e-5).series("anticlimber.horizontal_force")
        numpy.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-6)

    def test_euler_default_step_on_an_si_unit_warns_and_ida_does_not(self):
        """A user's SI unit under Euler's default step loses its energy balance (README "Accuracy
        warnings"): run() warns with AccuracyWarning, as `railcrash run` prints it; IDA does not."""
        unit = SOURCE / "models" / "examples" / "emu3_unit_collision.yaml"
        with self.assertWarns(railcrash.AccuracyWarning) as caught:
            euler = railcrash.run(unit, integrator="euler")
        self.assertTrue(euler.ok, euler.message)
        self.assertIn("of the energy turned over", str(caught.warning))
        self.assertEqual(euler.accuracy_warnings, euler.summary["accuracy_warnings"])
        self.assertEqual(len(euler.accuracy_warnings), 2)
        self.assertGreater(abs(euler.summary["energy"]["relative_balance_error"]), 0.01)
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter("error", railcrash.AccuracyWarning)
            ida = railcrash.run(unit, integrator="ida")
        self.assertEqual(ida.accuracy_warnings, [])

    def test_timings_split_the_wall_time_by_phase(self):
        timed = railcrash.run(railcrash.from_yaml(ANTICLIMBER), timings=True)
        self.assertTrue(timed.ok, timed.message)
        stats = timed.summary["stats"]
        seconds = stats["seconds"]
        self.assertEqual(list(seconds), ["other", "start", "residual", "jacobian", "linear_setup", "linear_solve",
                                         "step_sweep", "events", "restarts", "output"])
        self.assertAlmostEqual(sum(seconds.values()), stats["wall_seconds"], delta=1e-3 * stats["wall_seconds"] + 1e-4)
        self.assertGreater(seconds["residual"], 0.0)
        self.assertGreater(seconds["linear_solve"], 0.0)
        self.assertNotIn("seconds", railcrash.run(railcrash.from_yaml(ANTICLIMBER)).summary["stats"])

    @unittest.skipUnless(__import__("importlib").util.find_spec("pandas"), "pandas is not installed")
    def test_dataframe(self):
        result = railcrash.run(railcrash.from_yaml(OSCILLATOR), t_end=0.1)
        frame = result.dataframe()
        self.assertEqual(frame.index.name, "t")
        self.assertEqual(len(frame), len(result.t))
        self.assertEqual(list(frame.columns), result.columns[1:])
        numpy.testing.assert_array_equal(frame["cart.x"].to_numpy(), result.series("cart.x"))


class ErrorTest(unittest.TestCase):
    def test_model_file_error_names_file_and_line(self):
        with tempfile.TemporaryDirectory() as folder:
            path = pathlib.Path(folder) / "model.yaml"
            path.write_text(OSCILLATOR.replace("stiffness: 800.0", "stifness: 800.0"))
            with self.assertRaises(railcrash.InputError) as caught:
                railcrash.load(path)
            message = str(caught.exception)
            self.assertIn(f"{path}:10:", message)  # the stiffness line
            self.assertIn("stifness", message)
            self.assertIn("did you mean 'stiffness'", message)
            self.assertIsInstance(caught.exception, ValueError)

    def test_missing_file(self):
        with self.assertRaisesRegex(railcrash.InputError, "cannot open the model file"):
            railcrash.load("/no/such/model.yaml")

    def test_settings_change_exactly_the_key_they_name(self):
        """set= goes through --set's path: a value two bodies share through a YAML alias (as PyYAML
        writes a list a generator reuses) changes for the body named only, and KEY[i] is one entry."""
        shared = """railcrash: 1
name: two 40 t cars with one velocity
units: SI
gravity: [0, 0]
bodies:
  - {name: car_a, mass: 40000, inertia: 1.0e6, position: [0, 0], velocity: &speed [-5, 0]}
  - {name: car_b, mass: 40000, inertia: 1.0e6, position: [0, 10], velocity: *speed}
simulation: {t_end: 0.01, output_interval: 1.0e-3}
"""
        for settings, expected in (({"bodies.car_a.velocity": [-6, 0]}, (-6.0, -5.0)),
                                   ({"bodies.car_b.velocity[0]": -4}, (-5.0, -4.0)),
                                   ({"bodies.car_b.velocity[0]*": 0.5}, (-5.0, -2.5))):
            result = railcrash.run(railcrash.from_yaml(shared, set=settings))
            self.assertTrue(result.ok, result.message)
            self.assertEqual((result.series("car_a.vx")[0], result.series("car_b.vx")[0]), expected, settings)

    def test_bad_settings(self):
        with self.assertRaisesRegex(railcrash.InputError, "no element named 'sprung'"):
            railcrash.from_yaml(OSCILLATOR, set={"elements.sprung.stiffness": 1.0})
        with self.assertRaisesRegex(railcrash.InputError, "stiffnes"):
            railcrash.from_yaml(OSCILLATOR, set={"elements.spring.stiffnes": 1.0})
        with self.assertRaisesRegex(railcrash.InputError, "stiffness"):
            railcrash.from_yaml(OSCILLATOR, set={"elements.spring.stiffness": "stiff"})
        with self.assertRaisesRegex(TypeError, "elements.spring.stiffness"):
            railcrash.from_yaml(OSCILLATOR, set={"elements.spring.stiffness": object()})
        with self.assertRaisesRegex(TypeError, "factor must be a number"):
            railcrash.from_yaml(OSCILLATOR, set={"elements.spring.stiffness*": "2"})
        with self.assertRaisesRegex(railcrash.InputError, "finite"):
            railcrash.from_yaml(OSCILLATOR, set={"simulation.t_end": float("nan")})
        with self.assertRaises(TypeError):
            railcrash.from_yaml(OSCILLATOR, set=42)

    def test_bad_run_arguments(self):
        model = railcrash.from_yaml(OSCILLATOR)
        with self.assertRaisesRegex(TypeError, "rtol must be a number"):
            railcrash.run(model, rtol="tight")
        with self.assertRaisesRegex(railcrash.InputError, "integrator"):
            railcrash.run(model, integrator="rk4")
        with self.assertRaisesRegex(railcrash.InputError, r"RunSettings.rtol = -1: simulation: rtol must be a positive number"):
            railcrash.run(model, rtol=-1.0)
        with self.assertRaises(TypeError):
            railcrash.run(42)
        result = railcrash.run(model, t_end=0.01)
        with self.assertRaisesRegex(railcrash.InputError, "did you mean 'cart.x'"):
            result.series("cart.xx")


class ThreadTest(unittest.TestCase):
    @unittest.skipUnless(TWO_CAR.exists(), "the report's two-car model")
    def test_two_threads_run_while_python_goes_on(self):
        """Two runs in two threads give what they give alone, and the GIL is free meanwhile."""
        first = railcrash.load(TWO_CAR, set={"simulation.t_end": 0.1})
        second = first.with_settings({"elements.anticlimber.horizontal_yield_deflection*": 1.2})
        alone = [railcrash.run(model, rtol=1e-4) for model in (first, second)]
        together = [None, None]
        spans = [None, None]  # (start, end) of each threaded run [s]

        def work(index, model):
            start = time.perf_counter()
            together[index] = railcrash.run(model, rtol=1e-4)
            spans[index] = (start, time.perf_counter())

        threads = [threading.Thread(target=work, args=(k, m)) for k, m in enumerate((first, second))]
        for thread in threads:
            thread.start()
        # Heartbeat of the main thread while the runs go. A run that held the GIL would leave
        # no beat inside its span: Python cannot run any other thread meanwhile.
        beats = []
        while any(thread.is_alive() for thread in threads):
            beats.append(time.perf_counter())
            time.sleep(0.001)
        for thread in threads:
            thread.join()
        for a, b in zip(alone, together):
            self.assertTrue(b.ok, b.message)
            numpy.testing.assert_array_equal(a.series("anticlimber.horizontal_force"),
                                             b.series("anticlimber.horizontal_force"))
            self.assertEqual(a.events, b.events)
        self.assertFalse(numpy.array_equal(together[0].series("anticlimber.horizontal_force"),
                                           together[1].series("anticlimber.horizontal_force")))
        for start, end in spans:
            inside = sum(1 for beat in beats if start < beat < end)
            self.assertGreaterEqual(inside, 5, f"{inside} heartbeats during a run of {end - start:.3f} s: "
                                               "the run held the GIL")


class SweepTest(unittest.TestCase):
    PLAN = {"sweep": 1, "design": "full_factorial",
            "factors": [{"key": "elements.ac.horizontal_yield_deflection", "levels": [0.008, 0.012]},
                        {"key": "simulation.t_end", "levels": [0.15]}],
            "responses": ["R1", "responses.max_anticlimber_crush"]}

    def test_rows_against_the_closed_form_and_the_same_with_two_jobs(self):
        with tempfile.TemporaryDirectory() as folder:
            model = pathlib.Path(folder) / "model.yaml"
            model.write_text(ANTICLIMBER)
            table = railcrash.sweep(model, self.PLAN, jobs=1)
            plan_file = pathlib.Path(folder) / "plan.yaml"
            plan_file.write_text("sweep: 1\ndesign: runs\nfactors:\n"
                                 "  - {key: elements.ac.horizontal_yield_deflection}\n"
                                 "runs:\n  - {elements.ac.horizontal_yield_deflection: 0.012}\n  - {elements.ac.horizontal_yield_deflection: 0.008}\n"
                                 "responses: [R1, responses.max_anticlimber_crush]\n")
            explicit = railcrash.sweep(model, plan_file, jobs=2, out=pathlib.Path(folder) / "out")
            self.assertTrue((pathlib.Path(folder) / "out" / "runs.csv").exists())
        column = lambda t, name: numpy.asarray(t[name])
        self.assertEqual(list(column(table, "run")), [0, 1])
        self.assertEqual(list(column(table, "status")), ["ok", "ok"])
        yields = column(table, "elements.ac.horizontal_yield_deflection")
        self.assertEqual(list(yields), [0.008, 0.012])
        for d_y, r1, crush in zip(yields, column(table, "R1"), column(table, "responses.max_anticlimber_crush")):
            self.assertAlmostEqual(crush, crush_for(d_y), delta=1e-5 * crush)
            self.assertAlmostEqual(r1, crush_for(d_y) / 0.02, delta=1e-5 * r1)
        # The same runs in another order and with two jobs: bit for bit the same responses.
        self.assertEqual(list(column(explicit, "R1")), list(column(table, "R1"))[::-1])

    def test_without_pandas_a_dict_of_columns(self):
        with tempfile.TemporaryDirectory() as folder:
            model = pathlib.Path(folder) / "model.yaml"
            model.write_text(ANTICLIMBER)
            with mock.patch.dict(sys.modules, {"pandas": None}):  # import pandas raises ImportError
                table = railcrash.sweep(model, self.PLAN)
        self.assertIsInstance(table, dict)
        self.assertIsInstance(table["R1"], numpy.ndarray)
        self.assertEqual(table["status"], ["ok", "ok"])
        self.assertAlmostEqual(table["R1"][1], crush_for(0.012) / 0.02, delta=1e-5)

    def test_the_method_each_run_used(self):
        """integrator_used and euler_from_t: a ball bouncing on a floor (ten bounces in 2 s) run
        with ida, euler and auto, which hands it to Euler (Euler's step 1 ms) after five mode
        changes, at the time the same run made alone reports in summary.json, and takes it back
        when Euler's energy drift passes half the accuracy warnings' limit (euler_until_t)."""
        ball = ("railcrash: 1\nname: ball\nunits: SI\ngravity: [0, -9.81]\nbodies:\n"
                "  - {name: ball, mass: 1.0, inertia: 0.01, position: [0, 0.05]}\nelements:\n"
                "  - {name: floor, type: contact, stiffness: 1.0e5, damping: 20, friction: 0, line_point: [0, 0], "
                "line_normal: [0, 1], points: [{body: ball, at: [0, 0]}]}\n"
                "simulation: {t_end: 2.0, output_interval: 0.01, dt: 1.0e-3}\n")
        with tempfile.TemporaryDirectory() as folder:
            model = pathlib.Path(folder) / "ball.yaml"
            model.write_text(ball)
            plan = {"sweep": 1, "design": "full_factorial",
                    "factors": [{"key": "simulation.integrator", "levels": ["ida", "euler", "auto"]}],
                    "responses": ["t_reached"]}
            table = railcrash.sweep(model, plan, jobs=2)
            alone = railcrash.run(model)
        self.assertEqual(list(table["integrator_used"]), ["ida", "euler", "ida+euler+ida"])
        euler_from_t = numpy.asarray(table["euler_from_t"], dtype=float)
        self.assertTrue(numpy.isnan(euler_from_t[0]) and numpy.isnan(euler_from_t[1]))
        self.assertEqual(alone.summary["integrator_used"]["method"], "ida+euler+ida")
        self.assertGreater(alone.summary["integrator_used"]["euler_until_t"], alone.summary["integrator_used"]["euler_from_t"])
        # (summary.json writes 12 significant digits, runs.csv the exact double)
        self.assertAlmostEqual(euler_from_t[2], alone.summary["integrator_used"]["euler_from_t"], delta=1e-11)

    def test_a_plan_error_names_the_line(self):
        with tempfile.TemporaryDirectory() as folder:
            model = pathlib.Path(folder) / "model.yaml"
            model.write_text(ANTICLIMBER)
            plan = dict(self.PLAN, factors=[{"key": "elements.ac.no_such_key", "levels": [1.0]}])
            with self.assertRaisesRegex(railcrash.InputError, r"plan\.json:\d+: factor 'elements\.ac\.no_such_key'"):
                railcrash.sweep(model, plan)


class SensitivityTest(unittest.TestCase):
    def test_first_order_study_against_the_closed_form(self):
        with tempfile.TemporaryDirectory() as folder:
            model = pathlib.Path(folder) / "model.yaml"
            design = pathlib.Path(folder) / "design.yaml"
            model.write_text(ANTICLIMBER)
            design.write_text("sensitivity: 1\nfactor: 1.2\nparameters:\n"
                              "  - name: P7\n    description: horizontal yield force\n"
                              "    scale: [{key: elements.ac.horizontal_yield_deflection, power: 1}]\n")
            table = railcrash.sensitivity(model, design=design, jobs=2)
        runs = table["runs"]
        self.assertEqual([r["parameter"] for r in runs], ["base", "P7"])
        self.assertTrue(all(r["ok"] for r in runs))
        self.assertAlmostEqual(runs[0]["R1"], crush_for(0.01) / 0.02, delta=1e-5 * runs[0]["R1"])
        self.assertAlmostEqual(runs[1]["R1"], crush_for(0.012) / 0.02, delta=1e-5 * runs[1]["R1"])
        (p7,) = table["first_order"]
        expected = (crush_for(0.012) - crush_for(0.01)) / 0.02 / 0.2
        self.assertAlmostEqual(p7["A_R1"], expected, delta=1e-3 * abs(expected))
        self.assertLess(p7["A_R1"], 0.0)
        # The anticlimber only yields: no discrete outcome, one branch, nothing to bisect.
        self.assertEqual([r["branch"] for r in runs], ["none", "none"])
        self.assertEqual(table["branch_changes"], [])
        # The model names no integrator: auto, and IDA keeps these one-impact runs.
        self.assertEqual([r["integrator_used"] for r in runs], ["ida", "ida"])
        self.assertTrue(all(math.isnan(r["euler_from_t"]) for r in runs))

    def test_only_and_central(self):
        """--only and --central: the rows name the parameters that ran."""
        with tempfile.TemporaryDirectory() as folder:
            model = pathlib.Path(folder) / "model.yaml"
            design = pathlib.Path(folder) / "design.yaml"
            model.write_text(ANTICLIMBER)
            design.write_text("sensitivity: 1\nparameters:\n"
                              "  - name: P5\n    description: elastic slope\n"
                              "    scale: [{key: elements.ac.horizontal_elastic_stiffness, power: 1}]\n"
                              "  - name: P7\n    description: horizontal yield force\n"
                              "    scale: [{key: elements.ac.horizontal_yield_deflection, power: 1}]\n")
            table = railcrash.sensitivity(model, design=design, jobs=2, only=["P7"], central=0.05)
        self.assertTrue(table["central"])
        self.assertEqual([r["parameter"] for r in table["runs"]], ["base", "P7", "P7"])
        (p7,) = table["first_order"]
        self.assertEqual((p7["parameter"], p7["description"]), ("P7", "horizontal yield force"))
        expected = (crush_for(0.0105) - crush_for(0.0095)) / 0.02 / 0.1
        self.assertAlmostEqual(p7["A_R1"], expected, delta=1e-3 * abs(expected))

    def test_design_errors(self):
        with self.assertRaises(railcrash.InputError):
            railcrash.sensitivity("/no/such/model.yaml", design="/no/such/design.yaml")


class InterruptTest(unittest.TestCase):
    """Ctrl-C stops a sweep as it stops `railcrash sweep`: within a step of the run in progress,
    not after the last run (tests/robustness, README "Reliability")."""

    def test_ctrl_c_stops_a_sweep(self):
        import _thread
        # Ten explicit-Euler runs of five million steps each (about 1.5 s each on a 2-core VM): the
        # whole sweep takes some 15 s; the interruption comes 0.5 s after the start.
        slow = OSCILLATOR.replace("simulation: {t_end: 1.0, output_interval: 1.0e-4, rtol: 1.0e-9}",
                                  "simulation: {integrator: euler, dt: 2.0e-7, t_end: 1.0, output_interval: 0.01}")
        self.assertNotEqual(slow, OSCILLATOR)
        plan = ("sweep: 1\ndesign: full_factorial\nfactors:\n  - key: elements.spring.stiffness\n"
                "    levels: [700, 710, 720, 730, 740, 750, 760, 770, 780, 790]\nresponses: [cart.x@0.5]\n")
        with tempfile.TemporaryDirectory() as folder:
            model_path = pathlib.Path(folder) / "slow.yaml"
            plan_path = pathlib.Path(folder) / "plan.yaml"
            model_path.write_text(slow)
            plan_path.write_text(plan)
            timer = threading.Timer(0.5, _thread.interrupt_main)
            start = time.monotonic()
            timer.start()
            try:
                with self.assertRaises(KeyboardInterrupt):
                    railcrash.sweep(model_path, plan_path, jobs=1, out=pathlib.Path(folder) / "out")
            finally:
                timer.cancel()
            elapsed = time.monotonic() - start
        # Stopped at the next step of the first run and the 100 ms signal check: well under the
        # 1.5 s of one run, against some 15 s for the whole sweep.
        self.assertLess(elapsed, 3.0)


if __name__ == "__main__":
    unittest.main()
