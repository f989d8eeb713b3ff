#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "railcrash/model/model_io.hpp"
#include "railcrash/solver/initial_conditions.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

std::string num(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

// A 1 m pendulum: pin at the origin, bob's point [-1, 0] on the pin.
std::string pendulum(double x, double y, double angle, double vx, double vy) {
  return "railcrash: 1\nname: p\nunits: SI\ngravity: [0, -9.81]\nbodies:\n"
         "  - {name: bob, mass: 2.0, inertia: 0.1, position: [" + num(x) + ", " + num(y) +
         "], angle: " + num(angle) + ", velocity: [" + num(vx) + ", " + num(vy) +
         "]}\nelements:\n  - {name: hinge, type: pin_joint, points: [{body: ground, at: [0, 0]}, {body: bob, at: [-1, 0]}]}\n"
         "simulation: {t_end: 1}\n";
}

}  // namespace

TEST_CASE("position assembly closes a joint that starts slightly open", "[initial]") {
  // The bob starts 2 cm too far out and 1 cm low: the pin is open by about 0.022 m.
  const Model model = testing::model_from_text(pendulum(1.02, -0.01, 0.0, 0.0, 0.0));
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  REQUIRE(system.constraint_residual(y.data()) > 0.01);
  const AssemblyReport report = assemble_initial_state(system, y);
  CHECK(system.constraint_residual(y.data()) < 1e-12);
  CHECK(report.largest_position_change > 0.005);
  CHECK(report.largest_position_change < 0.05);
  // The pin point of the bob is back on the origin.
  const double x = y[0], yy = y[1], theta = y[2];
  CHECK(std::abs(x - std::cos(theta)) < 1e-12);
  CHECK(std::abs(yy - std::sin(theta)) < 1e-12);
}

TEST_CASE("velocity projection removes the velocity that would open the joint", "[initial]") {
  // Horizontal pendulum: the pin allows only vertical motion of the bob (with rotation).
  const Model model = testing::model_from_text(pendulum(1.0, 0.0, 0.0, 0.5, -1.0));
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  const AssemblyReport report = assemble_initial_state(system, y);
  CHECK(std::abs(y[3]) < 1e-12);  // radial velocity removed
  CHECK(y[4] != 0.0);             // tangential velocity kept
  // Pin point velocity = (vx, vy) + omega perp(R s) with R s = (-1, 0): (vx, vy - omega) = 0.
  CHECK(std::abs(y[4] - y[5]) < 1e-12);
  CHECK(report.largest_velocity_change >= 0.5);
}

TEST_CASE("consistent rates give the joint force and acceleration of Newton's law", "[initial]") {
  SECTION("hanging at rest: the pin carries the weight") {
    const Model model = testing::model_from_text(pendulum(0.0, -1.0, -M_PI / 2, 0.0, 0.0));
    DaeSystem system(model);
    std::vector<double> y = system.initial_state(), yp;
    assemble_initial_state(system, y);
    consistent_rates(system, 0.0, y, yp);
    CHECK(std::abs(yp[3]) < 1e-12);
    CHECK(std::abs(yp[4]) < 1e-12);
    double out[2];
    system.outputs(y.data(), y.data() + 6, out);
    CHECK(out[0] == Approx(0.0).margin(1e-12));
    CHECK(out[1] == Approx(2.0 * 9.81));  // reaction on the bob: its weight, upward
  }
  SECTION("horizontal at rest: free fall of the centre, no pin force") {
    // J = 0.1, m = 2, arm 1: angular acceleration m g L / (J + m L^2), linear a = alpha L.
    const Model model = testing::model_from_text(pendulum(1.0, 0.0, 0.0, 0.0, 0.0));
    DaeSystem system(model);
    std::vector<double> y = system.initial_state(), yp;
    consistent_rates(system, 0.0, y, yp);
    const double alpha = -2.0 * 9.81 * 1.0 / (0.1 + 2.0);
    CHECK(yp[5] == Approx(alpha));
    CHECK(yp[4] == Approx(alpha));
    CHECK(std::abs(yp[3]) < 1e-12);
    // The residual of the DAE vanishes at the consistent (y, y').
    std::vector<double> r(static_cast<std::size_t>(system.size()));
    system.residual(0.0, y.data(), yp.data(), r.data());
    for (double value : r) CHECK(std::abs(value) < 1e-12);
  }
  SECTION("spinning at the bottom: the pin adds the centripetal force") {
    const double omega = 3.0;  // the bob moves right at omega * 1 m
    const Model model = testing::model_from_text(pendulum(0.0, -1.0, -M_PI / 2, omega, 0.0));
    DaeSystem system(model);
    std::vector<double> y = system.initial_state(), yp;
    y[5] = omega;
    assemble_initial_state(system, y);
    consistent_rates(system, 0.0, y, yp);
    double out[2];
    system.outputs(y.data(), y.data() + 6, out);
    CHECK(out[1] == Approx(2.0 * 9.81 + 2.0 * omega * omega * 1.0));
    CHECK(yp[4] == Approx(omega * omega * 1.0));  // centripetal acceleration, toward the pin
  }
}

TEST_CASE("a free body with zero inertia makes the equations singular, with a clear message", "[initial]") {
  const LoadedModel loaded = testing::loaded_from_text(
      "railcrash: 1\nname: p\nunits: SI\nbodies:\n  - {name: dot, mass: 1, inertia: 0, position: [0, 0]}\n"
      "simulation: {t_end: 1}\n");
  const Model& model = loaded.model;
  DaeSystem system(model);
  std::vector<double> y = system.initial_state(), yp;
  CHECK_THROWS_WITH(consistent_rates(system, 0.0, y, yp), Catch::Contains("'dot'") && Catch::Contains("zero inertia"));
}

TEST_CASE("static equilibrium settles a body onto its wheels before the run", "[initial]") {
  // 1000 kg on two wheel-rail contacts 1.5 m ahead of and 1.0 m behind its centre of mass.
  // Vertical balance: N_f + N_r = W; moment balance: N_f 1.5 = N_r 1.0 (to the small pitch).
  const std::string text =
      "railcrash: 1\nname: s\nunits: SI\nbodies:\n"
      "  - {name: body, mass: 1000, inertia: 800, position: [0, 1.0], velocity: [5, 0]}\nelements:\n"
      "  - {name: front, type: wheel_rail, wheel_radius: 0.5, stiffness: 1.0e6, stiffness_above: 3.0e6, breakpoint: 0.003, "
      "damping: 1.0e4, points: [{body: body, at: [1.5, -0.5]}]}\n"
      "  - {name: rear, type: wheel_rail, wheel_radius: 0.5, stiffness: 1.0e6, stiffness_above: 3.0e6, breakpoint: 0.003, "
      "damping: 1.0e4, points: [{body: body, at: [-1.0, -0.5]}]}\n"
      "simulation: {t_end: 0.5, static_equilibrium: true, rtol: 1e-8}\n";
  const double weight = 1000.0 * 9.80665;
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    LoadedModel loaded = testing::loaded_from_text(text);
    Model& model = loaded.model;
    loaded.run_spec.simulation.integrator = std::string(integrator) == "ida" ? IntegratorKind::Ida : IntegratorKind::Euler;
    loaded.run_spec.simulation.dt = 2e-5;
    DaeSystem system(model);
    const RunOutcome o = testing::simulate(system, loaded.run_spec.simulation);
    // Both wheels close and pass their breakpoint while settling, at t = 0.
    REQUIRE(o.events.size() >= 4);
    for (const EventRecord& e : o.events) {
      CHECK(e.t == 0.0);
      CHECK_THAT(e.what, Catch::StartsWith("static equilibrium: "));
    }
    // It stays at rest vertically: no bounce at t = 0, and the forward speed is kept.
    CHECK(std::abs(o.y[4]) < 1e-6);
    CHECK(o.y[3] == Approx(5.0));
    double out[6];  // in the modes the run ended in
    system.outputs(o.y.data(), o.y.data() + 6, out);
    const double front = out[0], rear = out[3];
    CHECK(front + rear == Approx(weight).epsilon(1e-6));
    CHECK(front == Approx(weight * 1.0 / 2.5).epsilon(1e-3));
    // Above the breakpoint: N = k1 d_L + k2 (d - d_L).
    CHECK(out[2] == Approx(0.003 + (front - 3000.0) / 3.0e6).epsilon(1e-6));
    CHECK(out[5] == Approx(0.003 + (rear - 3000.0) / 3.0e6).epsilon(1e-6));
  }
}

TEST_CASE("static equilibrium reports a body that nothing holds", "[initial]") {
  const LoadedModel loaded = testing::loaded_from_text(
      "railcrash: 1\nname: s\nunits: SI\nbodies:\n  - {name: stone, mass: 1, inertia: 1, position: [0, 1]}\n"
      "simulation: {t_end: 1, static_equilibrium: true}\n");
  DaeSystem system(loaded.model);
  std::vector<double> y;
  std::vector<EventRecord> events;
  CHECK_THROWS_WITH(prepare_start(system, y, events, loaded.run_spec.simulation.static_equilibrium), Catch::Contains("no static equilibrium"));
}

TEST_CASE("a settle that fails names the body, the direction, the value and what pushes there, not gravity",
          "[initial]") {
  // A 100 kg block on a frictionless slider joint along x (the joint carries its weight, 981 N)
  // and a constant 50 N load along x that nothing resists: no equilibrium. The message must
  // name the x row of 'block' (line 5), its value, the load (line 9), and must not blame gravity
  // (it has no x component); the joint, which pushes 0 in x, is not listed among the pushes.
  const LoadedModel loaded = testing::loaded_from_text(
      "railcrash: 1\nname: s\nunits: SI\nbodies:\n"
      "  - {name: block, mass: 100, inertia: 1, position: [0, 1]}\n"
      "elements:\n"
      "  - {name: rail, type: slider_joint, axis: [1, 0], points: [{body: ground, at: [0, 1]}, {body: block, at: [0, 0]}]}\n"
      "loads:\n"
      "  - {type: force, body: block, at: [0, 0], value: [50, 0]}\n"
      "simulation: {t_end: 1, static_equilibrium: true}\n");
  DaeSystem system(loaded.model);
  std::vector<double> y;
  std::vector<EventRecord> events;
  std::string message = "no error";
  try {
    prepare_start(system, y, events, loaded.run_spec.simulation.static_equilibrium);
  } catch (const SolverError& e) {
    message = e.what();
  }
  INFO(message);
  CHECK_THAT(message, Catch::Contains("no static equilibrium found") &&
                          Catch::Contains("the largest unbalanced force is 50 in x on test.yaml:5: body 'block'") &&
                          Catch::Contains("On that body in x: load (line 9) 50.") &&
                          Catch::Contains("Nothing in the model balances these in x"));
  CHECK_THAT(message, !Catch::Contains("gravity"));
}

TEST_CASE("a settle ends at the round-off of the forces that meet at a body, not of its weight", "[initial]") {
  // A 1 kg bob (weight 9.8 N) between two springs in tension, 1e12 N/m stretched 0.5 m from the
  // left and 2e12 N/m stretched 0.25 m from the right (5e11 N each way in x), and a weak spring
  // pulling 1.3e-5 N to the right. Lengths near 1 m move in steps of 2.2e-16 m, so the two
  // strong forces change in steps of about 2e-4 N: the x row cannot come closer to zero than
  // some 1e-5 N, far above 1e-10 of the weight (1e-9 N). The settle used to fail there ("no
  // static equilibrium"); within 1e-10 of the forces that meet at that row it is balanced.
  // Equilibrium: x moves by 1.3e-5 / 3e12 m (nothing), y sags by W / (T1 / L1 + T2 / L2) =
  // 9.80665 / 1e12 m.
  const LoadedModel loaded = testing::loaded_from_text(
      "railcrash: 1\nname: s\nunits: SI\nbodies:\n  - {name: bob, mass: 1, inertia: 1, position: [0, 0]}\n"
      "elements:\n"
      "  - {name: left, type: linear_spring, stiffness: 1.0e12, free_length: 0.5, points: [{body: ground, at: [-1, 0]}, {body: bob, at: [0, 0]}]}\n"
      "  - {name: right, type: linear_spring, stiffness: 2.0e12, free_length: 0.75, points: [{body: ground, at: [1, 0]}, {body: bob, at: [0, 0]}]}\n"
      "  - {name: weak, type: linear_spring, stiffness: 1.0e-5, free_length: 3.7, points: [{body: ground, at: [5, 0]}, {body: bob, at: [0, 0]}]}\n"
      "simulation: {t_end: 1, static_equilibrium: true}\n");
  DaeSystem system(loaded.model);
  std::vector<double> y;
  std::vector<EventRecord> events;
  REQUIRE_NOTHROW(prepare_start(system, y, events, loaded.run_spec.simulation.static_equilibrium));
  CHECK(std::abs(y[0]) < 1e-15);
  CHECK(y[1] == Approx(-9.80665 / 1.0e12).epsilon(1e-6));
}

TEST_CASE("a settle that fails in y lists gravity among what pushes there", "[initial]") {
  // A free 2 kg stone: gravity (-19.6133 N in y) is the one push, and the message says so.
  const LoadedModel loaded = testing::loaded_from_text(
      "railcrash: 1\nname: s\nunits: SI\nbodies:\n  - {name: stone, mass: 2, inertia: 1, position: [0, 1]}\n"
      "simulation: {t_end: 1, static_equilibrium: true}\n");
  DaeSystem system(loaded.model);
  std::vector<double> y;
  std::vector<EventRecord> events;
  CHECK_THROWS_WITH(prepare_start(system, y, events, loaded.run_spec.simulation.static_equilibrium),
                    Catch::Contains("the largest unbalanced force is -19.6133 in y on test.yaml:5: body 'stone'") &&
                        Catch::Contains("On that body in y: gravity -19.6133."));
}

TEST_CASE("static equilibrium settles onto the kink of a stop spring", "[initial]") {
  // A 100 kg block on a linear spring "adjusted for load": free length 1 + W / k, so the
  // spring alone carries the weight W = 981 N at length 1.0, exactly where a stop spring
  // (0 N/m, then 1e7 N/m in compression from length 1.0) begins. The equilibrium is the kink
  // itself: y = 1.0 with no force in the stop. A horizontal guide spring at its free length
  // there holds x. Started 0.2 m high, the settle must land on the kink and the run must
  // then not move.
  const std::string text =
      "railcrash: 1\nname: kink\nunits: SI\ngravity: [0, -9.81]\nbodies:\n"
      "  - {name: block, mass: 100, inertia: 1, position: [0, 1.2]}\nelements:\n"
      "  - {name: main, type: linear_spring, stiffness: 1.0e4, free_length: 1.0981, "
      "points: [{body: ground, at: [0, 0]}, {body: block, at: [0, 0]}]}\n"
      "  - {name: stop, type: nonlinear_spring, free_length: 1.0, compression_stiffness_1: 0, "
      "compression_stiffness_2: 1.0e7, compression_breakpoint: 0, extension_stiffness_1: 0, "
      "points: [{body: ground, at: [0, 0]}, {body: block, at: [0, 0]}]}\n"
      "  - {name: guide, type: linear_spring, stiffness: 1.0e5, free_length: 1.0, "
      "points: [{body: ground, at: [-1, 1.0]}, {body: block, at: [0, 0]}]}\n"
      "simulation: {t_end: 0.1, static_equilibrium: true, rtol: 1e-8}\n";
  const LoadedModel loaded = testing::loaded_from_text(text);
  const Model& model = loaded.model;
  DaeSystem system(model);
  std::vector<double> y;
  std::vector<EventRecord> events;
  const StartReport start = prepare_start(system, y, events, loaded.run_spec.simulation.static_equilibrium);
  CHECK(start.equilibrium.steps > 0);
  CHECK(start.equilibrium.residual_force < 1e-6);
  CHECK(y[1] == Approx(1.0).margin(1e-9));
  CHECK(y[0] == Approx(0.0).margin(1e-9));
  std::vector<double> out(system.output_names().size());
  system.outputs(y.data(), y.data() + 2 * system.body_unknowns(), out.data());
  const auto& names = system.output_names();
  const auto stop_force = std::find(names.begin(), names.end(), "stop.force");
  REQUIRE(stop_force != names.end());
  CHECK(std::abs(out[static_cast<std::size_t>(stop_force - names.begin())]) < 1e-2);  // [N]
  const RunOutcome o = testing::simulate(loaded);
  CHECK(o.y[1] == Approx(1.0).margin(1e-8));
  CHECK(std::abs(o.y[4]) < 1e-6);
}

TEST_CASE("a parallelogram four-bar lying flat is a singular configuration that names its joints", "[initial][faults]") {
  // Ground pins A (0, 0) and D (2, 0), crank and rocker 1 m, coupler 2 m. Upright (crank at
  // 90 degrees) the joints' gradient has full rank; flat (crank at 0) every link lies on the x
  // axis and the four pins' eight equations have rank 7 (the y rows of the chain repeat).
  std::string text =
      "railcrash: 1\nname: four-bar\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: crank, mass: 1, inertia: 0.08, position: [0, 0.5], angle: 1.5707963267949}\n"
      "  - {name: coupler, mass: 2, inertia: 0.67, position: [1, 1]}\n"
      "  - {name: rocker, mass: 1, inertia: 0.08, position: [2, 0.5], angle: 1.5707963267949}\nelements:\n"
      "  - {name: pin_a, type: pin_joint, points: [{body: ground, at: [0, 0]}, {body: crank, at: [-0.5, 0]}]}\n"
      "  - {name: pin_b, type: pin_joint, points: [{body: crank, at: [0.5, 0]}, {body: coupler, at: [-1, 0]}]}\n"
      "  - {name: pin_c, type: pin_joint, points: [{body: coupler, at: [1, 0]}, {body: rocker, at: [0.5, 0]}]}\n"
      "  - {name: pin_d, type: pin_joint, points: [{body: ground, at: [2, 0]}, {body: rocker, at: [-0.5, 0]}]}\n"
      "simulation: {t_end: 1}\n";
  const Model model = testing::model_from_text(text);
  DaeSystem system(model);
  std::vector<double> q = system.initial_state();
  CHECK(singular_configuration(system, q.data(), 0.0).empty());
  // Flat: crank centre (0.5, 0), coupler (2, 0), rocker (2.5, 0), all at angle 0.
  const double flat[9] = {0.5, 0.0, 0.0, 2.0, 0.0, 0.0, 2.5, 0.0, 0.0};
  std::copy(flat, flat + 9, q.begin());
  int rank = 0;
  CHECK_FALSE(dependent_constraint_rows(system, q.data(), 1e-10, rank).empty());
  CHECK(rank == 7);
  CHECK_THAT(singular_configuration(system, q.data(), 1.5),
             Catch::Contains("singular configuration: joints 'pin_a' (pin_joint, line 10), 'pin_b' (pin_joint, line 11), "
                             "'pin_c' (pin_joint, line 12), 'pin_d' (pin_joint, line 13) lose rank at t = 1.5 "
                             "(1 of the 8 constraint equations depend on the others there)"));
}

TEST_CASE("the singular-configuration check finds no joint losing rank in the shipped models as they start", "[initial][faults]") {
  // Its threshold applied to G W^1/2 times the model's length (784 in on the preliminary car)
  // flagged every row between two bodies' origins (norm sqrt 2) as dependent, and an IDA
  // failure on any model with such joints blamed them: "joints 'coupler_pin', 'front_axle_1_slider'
  // ... lose rank". With the rows of unit length and the angles as arcs at each body's size
  // none of these is near-singular, and the flat four-bar above still is.
  for (const char* file : {"models/report/preliminary_car.yaml", "models/report/final_two_car.yaml",
                           "models/barrier/two_car_barrier.yaml", "models/examples/mu_3plus3_si.yaml",
                           "models/examples/emu3_unit_collision.yaml", "models/scenarios/scenario2_report_car.yaml"}) {
    INFO(file);
    const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/" + file).model;
    DaeSystem system(model);
    REQUIRE(system.constraint_rows() > 0);
    std::vector<double> y = system.initial_state();
    assemble_initial_state(system, y);
    CHECK(singular_configuration(system, y.data(), 0.0).empty());
    int rank = 0;
    CHECK(dependent_constraint_rows(system, y.data(), 0.1, rank, RowScaling::UnitRows).empty());
    CHECK(rank == system.constraint_rows());
  }
}

TEST_CASE("consistent rates with a kept ordering equal those without one, bit for bit", "[initial]") {
  // The IDA integrator keeps the LU ordering between restarts (ConsistentRatesCache): reused
  // while the matrix pattern is the same, made again when it is not.
  const Model two_car = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml").model;
  const Model slider_crank = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/verification/cases/slider_crank.yaml").model;
  DaeSystem two_car_system(two_car), slider_crank_system(slider_crank);
  REQUIRE(two_car_system.constraint_rows() > 0);
  REQUIRE(slider_crank_system.constraint_rows() > 0);
  auto rates = [](const DaeSystem& system, std::vector<double> y, ConsistentRatesCache* cache) {
    std::vector<double> yp;
    consistent_rates(system, 0.0, y, yp, cache);
    yp.insert(yp.end(), y.begin(), y.end());  // the multipliers are written into y
    return yp;
  };
  std::vector<double> start = two_car_system.initial_state();
  assemble_initial_state(two_car_system, start);
  // A second state of the same pattern with other values: every body's velocities changed
  // (the multipliers depend on them through the constraints' acceleration bias).
  std::vector<double> moved = start;
  const int nq = two_car_system.body_unknowns();
  for (int k = 0; k < nq; ++k) moved[static_cast<std::size_t>(nq + k)] *= 0.5 + 0.01 * (k % 7);
  assemble_initial_state(two_car_system, moved);
  std::vector<double> crank_start = slider_crank_system.initial_state();
  assemble_initial_state(slider_crank_system, crank_start);

  ConsistentRatesCache cache;
  CHECK(rates(two_car_system, start, &cache) == rates(two_car_system, start, nullptr));
  CHECK(cache.analysed() == 1);
  CHECK(cache.reused() == 0);
  const std::vector<double> moved_rates = rates(two_car_system, moved, &cache);
  CHECK(cache.analysed() == 1);
  CHECK(cache.reused() == 1);
  CHECK(moved_rates == rates(two_car_system, moved, nullptr));
  CHECK(moved_rates != rates(two_car_system, start, nullptr));
  // Another pattern: a new ordering, and the same rates as without the cache.
  CHECK(rates(slider_crank_system, crank_start, &cache) == rates(slider_crank_system, crank_start, nullptr));
  CHECK(cache.analysed() == 2);
  CHECK(cache.reused() == 1);
}
