// Nonlinear spring, nonlinear dashpot and special spring (report types 19, 20, 21): laws
// against hand values, Jacobians in every mode, event timing and closed-form runs under both
// integrators, energy bookkeeping, fracture, starting on a breakpoint, input checks.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "railcrash/elements/nonlinear.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/stability_limit.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

const double kPi = std::acos(-1.0);

// ---- models ------------------------------------------------------------------------------

/// One body on the x axis (or the y axis when vertical), tied to a ground point at the
/// origin by element `e` of the given type; parameters are YAML "key: value" pairs.
struct Axial {
  std::string type;
  std::string parameters;
  double mass = 1.0;
  double position = 1.0;   // [m] along the axis
  double velocity = 0.0;   // [m/s] along the axis
  bool vertical = false;   // along y, with gravity g in -y
  double gravity = 0.0;    // [m/s^2]
  double load = 0.0;       // [N] constant force on the body along the axis
  std::string simulation;  // the simulation map's contents
};

Axial axial(const std::string& type, const std::string& parameters, double mass = 1.0) {
  Axial a;
  a.type = type;
  a.parameters = parameters;
  a.mass = mass;
  return a;
}

std::string axial_yaml(const Axial& a) {
  std::ostringstream s;
  s.precision(17);
  const auto along = [&](double value) {
    std::ostringstream v;
    v.precision(17);
    v << "[" << (a.vertical ? 0.0 : value) << ", " << (a.vertical ? value : 0.0) << "]";
    return v.str();
  };
  s << "railcrash: 1\nname: axial\nunits: SI\ngravity: " << along(-a.gravity) << "\nbodies:\n"
    << "  - {name: m, mass: " << a.mass << ", inertia: 1.0, position: " << along(a.position)
    << ", velocity: " << along(a.velocity) << "}\n"
    << "elements:\n  - {name: e, type: " << a.type << ", " << a.parameters
    << ", points: [{body: ground, at: [0, 0]}, {body: m, at: [0, 0]}]}\n";
  if (a.load != 0.0) s << "loads:\n  - {type: force, body: m, at: [0, 0], value: " << along(a.load) << "}\n";
  s << "simulation: {" << a.simulation << "}\n";
  return s.str();
}

std::string ida(double t_end, double rtol = 1e-10) {
  std::ostringstream s;
  s.precision(17);
  s << "t_end: " << t_end << ", integrator: ida, rtol: " << rtol << ", output_interval: " << t_end;
  return s.str();
}

std::string euler(double t_end, double dt) {
  std::ostringstream s;
  s.precision(17);
  s << "t_end: " << t_end << ", integrator: euler, dt: " << dt << ", output_interval: " << t_end;
  return s.str();
}

struct Quiet : RunObserver {
  void sample(double, const double*, const double*, const double*, const double*) override {}
};

RunOutcome run(const std::string& yaml) {
  const LoadedModel loaded = testing::loaded_from_text(yaml);
  const Model& model = loaded.model;
  DaeSystem system(model);
  auto integrator = make_integrator(system, loaded.run_spec.simulation);
  Quiet quiet;
  RunOutcome outcome = integrator->run(loaded.run_spec.simulation.t_end, output_interval_of(loaded.run_spec.simulation), quiet);
  INFO(outcome.message);
  REQUIRE(outcome.ok);
  return outcome;
}

/// The single element of the axial model `a` at its initial state: its outputs (law value, x),
/// the generalized forces on the body and its stored energy.
struct AtStart {
  std::vector<double> out = std::vector<double>(2, 0.0);
  std::vector<double> f = std::vector<double>(3, 0.0);
  double energy = 0.0;
};
AtStart at_start(const Axial& a) {
  const Model model = testing::model_from_text(axial_yaml(a));
  DaeSystem system(model);
  const std::vector<double> y = system.initial_state();
  AtStart r;
  system.generalized_forces(0.0, y.data(), y.data() + 3, r.f.data());
  system.outputs(y.data(), nullptr, r.out.data());
  const Element& e = *model.elements().front();
  r.energy = e.potential_energy(gather_state(e, y.data(), y.data() + 3, system.modes().of(0)));
  return r;
}

/// Position and velocity of the single body along its axis at the end of a run.
double final_position(const RunOutcome& o, bool vertical = false) { return o.y[vertical ? 1 : 0]; }
double final_velocity(const RunOutcome& o, bool vertical = false) { return o.y[vertical ? 4 : 3]; }

std::vector<EventRecord> events_named(const RunOutcome& o, const std::string& what) {
  std::vector<EventRecord> found;
  for (const EventRecord& e : o.events)
    if (e.what == what) found.push_back(e);
  return found;
}

std::string event_list(const RunOutcome& o) {
  std::ostringstream s;
  for (const EventRecord& e : o.events) s << e.t << " " << e.what << " (" << e.value << ")\n";
  return s.str();
}

/// Work done on element 0 over the run (its quadrature).
double element_work(const RunOutcome& o) { return o.quadratures[DaeSystem::kFirstElementWork]; }

// ---- closed forms, written from Newton's law (not from the program) -----------------------

/// A mass m enters a one-sided region at d = 0 with speed v_in > 0 (d increasing). The
/// force against d is c + k1 d up to d = b, then c + k1 b + k2 (d - b) (k1, k2 > 0; b < 0:
/// no second segment). Harmonic arcs: times to reach b and to come back to d = 0.
struct Excursion {
  bool passes_breakpoint = false;
  double to_breakpoint = 0.0;       // [s] from entry to d = b
  double in_second_segment = 0.0;   // [s] spent beyond b
  double total = 0.0;               // [s] from entry back to d = 0
  double peak = 0.0;                // [m] largest d
};

Excursion excursion(double m, double v_in, double c, double k1, double b, double k2) {
  Excursion e;
  const double w1 = std::sqrt(k1 / m);
  const double y0 = c / k1;  // d measured from the first segment's equilibrium -c/k1
  const double amplitude = std::hypot(y0, v_in / w1);
  const double phase = std::atan2(y0, v_in / w1);  // y = A sin(w1 t + phase)
  const double yb = b + c / k1;
  if (b < 0.0 || yb >= amplitude) {
    e.total = (kPi - 2.0 * phase) / w1;
    e.peak = amplitude - y0;
    return e;
  }
  e.passes_breakpoint = true;
  e.to_breakpoint = (std::asin(yb / amplitude) - phase) / w1;
  const double vb = std::sqrt(v_in * v_in - w1 * w1 * (yb * yb - y0 * y0));
  const double w2 = std::sqrt(k2 / m);
  const double z0 = (c + k1 * b) / k2;  // beyond b, d - b measured from that segment's equilibrium
  const double amplitude2 = std::hypot(z0, vb / w2);
  const double phase2 = std::atan2(z0, vb / w2);
  e.in_second_segment = (kPi - 2.0 * phase2) / w2;
  e.total = 2.0 * e.to_breakpoint + e.in_second_segment;
  e.peak = b - z0 + amplitude2;
  return e;
}

// ---- parameters used throughout --------------------------------------------------------------

// nonlinear_spring: kc1 100, kc2 1000 beyond 0.2 compression; ke1 50, ke2 400 beyond 0.3
// extension; preload 5 (compressive); free length 1.
const char* kSpringParameters =
    "compression_stiffness_1: 100, compression_stiffness_2: 1000, compression_breakpoint: 0.2, "
    "extension_stiffness_1: 50, extension_stiffness_2: 400, extension_breakpoint: 0.3, preload: 5, free_length: 1.0";

// nonlinear_dashpot: compression 100 up to 0.5, then 20; extension 40 up to 0.25, then 10.
const char* kDashpotParameters =
    "damping_compression_1: 100, damping_compression_2: 20, compression_switch_velocity: 0.5, "
    "damping_extension_1: 40, damping_extension_2: 10, extension_switch_velocity: 0.25";

// special_spring: 2000 up to 0.02 deflection, then 20000; preload 5; free length 1.
std::string special_parameters(int kind) {
  return "kind: " + std::to_string(kind) +
         ", stiffness_1: 2000, stiffness_2: 20000, breakpoint: 0.02, preload: 5, free_length: 1.0";
}

// ---- geometry for the Jacobian checks (same layouts as the spring tests) ------------------------

enum class Ends { GroundBody, BodyBody };

std::string general_yaml(const std::string& type, const std::string& parameters, Ends ends) {
  std::ostringstream s;
  s << "railcrash: 1\nname: general\nunits: SI\ngravity: [0, 0]\nbodies:\n"
    << "  - {name: a, mass: 2.0, inertia: 0.5, position: [0.3, -0.2], angle: 0.4, velocity: [0.5, -0.3], "
       "angular_velocity: 0.8}\n";
  if (ends == Ends::BodyBody)
    s << "  - {name: b, mass: 3.0, inertia: 0.7, position: [1.6, 0.5], angle: -0.6, velocity: [-0.4, 0.2], "
         "angular_velocity: -1.1}\n";
  s << "elements:\n  - {name: e, type: " << type << ", " << parameters << ", points: ["
    << (ends == Ends::GroundBody ? "{body: ground, at: [-0.5, 0.4]}, {body: a, at: [0.35, -0.15]}"
                                 : "{body: a, at: [0.45, 0.2]}, {body: b, at: [-0.3, 0.25]}")
    << "]}\nsimulation: {t_end: 1.0}\n";
  return s.str();
}

/// A value of x inside segment k of the law (away from its breakpoints).
double inside(const PiecewiseLinearLaw& law, int k) {
  if (law.has_lower(k) && law.has_upper(k)) return 0.5 * (law.lower(k) + law.upper(k));
  if (law.has_upper(k)) return law.upper(k) - 0.1;
  if (law.has_lower(k)) return law.lower(k) + 0.1;
  return 0.0;
}

/// Assembled Jacobian against central differences at states scattered (1e-3) around y.
void check_jacobian_near(const DaeSystem& system, const std::vector<double>& y, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> near(-1e-3, 1e-3), any(-1.0, 1.0);
  for (int trial = 0; trial < 3; ++trial) {
    INFO("trial " << trial);
    std::vector<double> state = y, rate(y.size());
    for (double& v : state) v += near(rng);
    for (double& v : rate) v = any(rng);
    double outside = -1.0;
    CHECK(testing::jacobian_error(system, 0.1, 20.0 * (trial + 1), state, rate, &outside) < 1e-6);
    CHECK(outside == 0.0);
  }
}

/// Runs check(system, element, y) in every mode of the element (each segment, and broken
/// when it can break), at a state y whose x lies inside that segment. place(element, y, x)
/// moves the element's reference (free length) or the velocities so that x(y) = x.
template <class Element, class Place, class Check>
void for_every_mode(const std::string& type, const std::string& parameters, Place place, Check check) {
  for (const Ends ends : {Ends::GroundBody, Ends::BodyBody}) {
    INFO(type << (ends == Ends::GroundBody ? " ground-body" : " body-body"));
    const Model model = testing::model_from_text(general_yaml(type, parameters, ends));
    DaeSystem system(model);
    auto& element = dynamic_cast<Element&>(*model.elements().front());
    const int segments = element.law().segment_count();
    for (int k = 0; k <= segments; ++k) {
      const bool broken = k == segments;
      if (broken && !element.fracture_load) continue;
      INFO("mode: " << (broken ? std::string("broken") : element.law().segment(k).name));
      std::vector<double> y = system.initial_state();
      const double x = inside(element.law(), broken ? 0 : k);
      place(element, y, x);
      const int nq = system.body_unknowns();
      REQUIRE(element.measure_of(gather_state(element, y.data(), y.data() + nq, nullptr)) == Approx(x).margin(1e-12));
      testing::modes_to_write(system).as<SegmentMode>(0) = SegmentMode{broken ? 0 : k, broken};
      check(system, element, y, k);
    }
  }
}

template <class Element, class Place>
void check_every_mode(const std::string& type, const std::string& parameters, Place place) {
  for_every_mode<Element>(type, parameters, place, [](const DaeSystem& system, const Element&, const std::vector<double>& y, int k) {
    check_jacobian_near(system, y, 7u + static_cast<unsigned>(k));
  });
}

/// Generalized forces of the model's only element equal minus the gradient of its energy
/// (central differences), at y.
void check_force_is_energy_gradient(const DaeSystem& system, const Element& element, const std::vector<double>& y) {
  const int nq = system.body_unknowns();
  const std::vector<double> q(y.begin(), y.begin() + nq), v(y.begin() + nq, y.begin() + 2 * nq);
  std::vector<double> f(static_cast<std::size_t>(nq), 0.0);
  system.generalized_forces(0.0, q.data(), v.data(), f.data());
  const auto energy = [&](const std::vector<double>& at) { return element.potential_energy(gather_state(element, at.data(), v.data(), system.modes().of(0))); };
  double largest = 0.0;
  for (std::size_t k = 0; k < q.size(); ++k) {
    const double h = 1e-6;
    std::vector<double> plus = q, minus = q;
    plus[k] += h;
    minus[k] -= h;
    INFO("component " << k);
    CHECK(f[k] == Approx(-(energy(plus) - energy(minus)) / (2.0 * h)).epsilon(1e-6).margin(1e-5));
    largest = std::max(largest, std::abs(f[k]));
  }
  // Loaded (a force of at least 1) exactly when it stores energy: open and broken modes neither.
  CHECK((largest > 1.0) == (energy(q) != 0.0));
}

/// Moves the free length of a spring so that x(y) = x (x = direction (free_length - s)).
template <class Spring>
void place_spring(Spring& e, std::vector<double>& y, double x, double direction) {
  const int nq = static_cast<int>(y.size()) / 2;
  const double now = e.measure_of(gather_state(e, y.data(), y.data() + nq, nullptr));  // x needs no mode
  e.free_length = *e.free_length + direction * (x - now);
}

}  // namespace

// ---- Jacobians ----------------------------------------------------------------------------------

TEST_CASE("nonlinear element Jacobians match central differences in every mode", "[elements][nonlinear]") {
  SECTION("nonlinear_spring") {
    check_every_mode<NonlinearSpring>("nonlinear_spring", std::string(kSpringParameters) + ", fracture_load: 1e6",
                                      [](NonlinearSpring& e, std::vector<double>& y, double x) { place_spring(e, y, x, -1.0); });
  }
  for (int kind : {1, 2}) {
    for (const std::string axis : {"", ", axis: [0.6, -0.8]"}) {
      SECTION("special_spring kind " + std::to_string(kind) + axis) {
        check_every_mode<SpecialSpring>("special_spring", special_parameters(kind) + ", fracture_load: 1e6" + axis,
                                        [](SpecialSpring& e, std::vector<double>& y, double x) {
                                          place_spring(e, y, x, e.direction());
                                        });
      }
    }
  }
  SECTION("nonlinear_dashpot") {
    check_every_mode<NonlinearDashpot>(
        "nonlinear_dashpot", kDashpotParameters, [](NonlinearDashpot& e, std::vector<double>& y, double x) {
          // All velocities zero but body a's translation, set along the line to give rate x.
          const int nq = static_cast<int>(y.size()) / 2;
          std::fill(y.begin() + nq, y.end(), 0.0);
          const LineGeometry<double> g = line_geometry(e, gather_state(e, y.data(), y.data() + nq, nullptr));
          const double ux = g.d.x / g.length, uy = g.d.y / g.length;
          const double sign = e.point(1).body == 0 ? 1.0 : -1.0;  // body a holds P2 (+) or P1 (-)
          y[static_cast<std::size_t>(nq)] = sign * x * ux;
          y[static_cast<std::size_t>(nq + 1)] = sign * x * uy;
        });
  }
}

TEST_CASE("nonlinear spring forces are minus the gradient of their energy in every mode", "[elements][nonlinear]") {
  // On a body-body pair with offsets and rotations: also checks that the special spring
  // along an axis (which turns with body 1) is conservative.
  const auto gradient = [](const DaeSystem& system, const auto& element, const std::vector<double>& y, int) {
    check_force_is_energy_gradient(system, element, y);
  };
  for_every_mode<NonlinearSpring>("nonlinear_spring", std::string(kSpringParameters) + ", fracture_load: 1e6",
                                  [](NonlinearSpring& e, std::vector<double>& y, double x) { place_spring(e, y, x, -1.0); },
                                  gradient);
  for (int kind : {1, 2})
    for (const std::string axis : {"", ", axis: [0.6, -0.8]"}) {
      INFO("kind " << kind << axis);
      for_every_mode<SpecialSpring>("special_spring", special_parameters(kind) + ", fracture_load: 1e6" + axis,
                                    [](SpecialSpring& e, std::vector<double>& y, double x) { place_spring(e, y, x, e.direction()); },
                                    gradient);
    }
}

// ---- laws against hand values ---------------------------------------------------------------------

TEST_CASE("nonlinear_spring force and energy follow both branches past both breakpoints", "[elements][nonlinear]") {
  // T = -5 + 100 e (-0.2 <= e <= 0), beyond: T(-0.2) = -25, slope 1000;
  // T = -5 + 50 e (0 <= e <= 0.3), beyond: T(0.3) = 10, slope 400.
  struct Point {
    double deformation, tension, energy;
  };
  const Point points[] = {
      {-0.35, -5.0 - 20.0 - 150.0, 18.0},   // energy: 3 (to -0.2) + 3.75 + 11.25
      {-0.1, -5.0 - 10.0, 0.5 + 0.5},       // 5 * 0.1 + 100 * 0.01 / 2
      {0.15, -5.0 + 7.5, -0.75 + 0.5625},   // -5 * 0.15 + 50 * 0.0225 / 2
      {0.5, -5.0 + 15.0 + 80.0, 0.75 + 10.0},  // 0.75 to 0.3, then 10 * 0.2 + 400 * 0.2^2 / 2
  };
  for (const Point& p : points) {
    for (bool flip : {false, true}) {  // body on +x or on -x of the ground point
      INFO("deformation " << p.deformation << (flip ? " (body on -x)" : ""));
      Axial a = axial("nonlinear_spring", kSpringParameters);
      a.position = (flip ? -1.0 : 1.0) * (1.0 + p.deformation);
      a.simulation = ida(1.0);
      const auto [out, f, energy_at_start] = at_start(a);
      CHECK(out[0] == Approx(p.tension).epsilon(1e-12));
      CHECK(out[1] == Approx(p.deformation).epsilon(1e-12));
      // Tension pulls the body towards the ground point.
      CHECK(f[0] == Approx((flip ? 1.0 : -1.0) * -(-p.tension)).epsilon(1e-12));
      CHECK(f[1] == Approx(0.0).margin(1e-12));
      CHECK(energy_at_start == Approx(p.energy).epsilon(1e-12));
    }
  }
}

TEST_CASE("nonlinear_dashpot force follows both branches past both switch velocities", "[elements][nonlinear]") {
  // T = 100 v (-0.5 <= v <= 0), beyond: -50 + 20 (v + 0.5); T = 40 v (0 <= v <= 0.25), beyond: 10 + 10 (v - 0.25).
  const std::pair<double, double> points[] = {{-0.8, -50.0 - 6.0}, {-0.2, -20.0}, {0.1, 4.0}, {0.65, 10.0 + 4.0}};
  for (const auto& [rate, tension] : points) {
    INFO("rate " << rate);
    Axial a = axial("nonlinear_dashpot", kDashpotParameters);
    a.velocity = rate;  // body at +1 on x: its velocity is the rate of length
    a.simulation = ida(1.0);
    const auto [out, f, energy_at_start] = at_start(a);
    CHECK(out[0] == Approx(tension).epsilon(1e-12));
    CHECK(out[1] == Approx(rate).epsilon(1e-12));
    CHECK(f[0] == Approx(-tension).epsilon(1e-12));
    CHECK(energy_at_start == 0.0);
  }
}

TEST_CASE("special_spring acts one way only: compression (kind 1) or tension (kind 2)", "[elements][nonlinear]") {
  // P = 5 + 2000 d (0 <= d <= 0.02), then 45 + 20000 (d - 0.02); open: 0.
  const std::pair<double, double> points[] = {{-0.01, 0.0}, {0.01, 25.0}, {0.03, 245.0}};
  for (int kind : {1, 2}) {
    for (const auto& [deflection, force] : points) {
      INFO("kind " << kind << " deflection " << deflection);
      Axial a = axial("special_spring", special_parameters(kind));
      a.position = kind == 1 ? 1.0 - deflection : 1.0 + deflection;
      a.simulation = ida(1.0);
      const auto [out, f, energy_at_start] = at_start(a);
      CHECK(out[0] == Approx(force).margin(1e-12));
      CHECK(out[1] == Approx(deflection).epsilon(1e-12));
      // kind 1 pushes the body away from the ground point (+x), kind 2 pulls it back (-x).
      CHECK(f[0] == Approx(kind == 1 ? force : -force).margin(1e-12));
      // energy: 5 d + 1000 d^2, beyond 0.02: 0.5 + 45 (d - 0.02) + 10000 (d - 0.02)^2
      const double energy = deflection <= 0.0 ? 0.0
                            : deflection <= 0.02
                                ? 5.0 * deflection + 1000.0 * deflection * deflection
                                : 0.5 + 45.0 * (deflection - 0.02) + 10000.0 * std::pow(deflection - 0.02, 2);
      CHECK(energy_at_start == Approx(energy).margin(1e-12));
    }
  }
}

TEST_CASE("special_spring along an axis: force along the turned axis, lever arm on the stop's body",
          "[elements][nonlinear]") {
  // Body a at the origin turned by 90 degrees: its axis [1, 0] points along global +y.
  // P2 on body b at (0.5, 0.8): s = 0.8, d = 1 - 0.8 = 0.2, P = 100 * 0.2 = 20.
  // On b: (0, +20) at its centre. On a: (0, -20) at r2, arm (0.5, 0.8): moment 0.5 * -20 = -10.
  const Model model = testing::model_from_text(
      "railcrash: 1\nname: axis\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: a, mass: 1, inertia: 1, position: [0, 0], angle: 1.5707963267948966}\n"
      "  - {name: b, mass: 1, inertia: 1, position: [0.5, 0.8]}\n"
      "elements:\n  - {name: e, type: special_spring, stiffness_1: 100, free_length: 1.0, axis: [1, 0], "
      "points: [{body: a, at: [0, 0]}, {body: b, at: [0, 0]}]}\n"
      "simulation: {t_end: 1}\n");
  DaeSystem system(model);
  const std::vector<double> y = system.initial_state();
  std::vector<double> f(6, 0.0), out(2, 0.0);
  system.generalized_forces(0.0, y.data(), y.data() + 6, f.data());
  system.outputs(y.data(), nullptr, out.data());
  const double expected[] = {0.0, -20.0, -10.0, 0.0, 20.0, 0.0};
  for (std::size_t k = 0; k < 6; ++k) {
    INFO("component " << k);
    CHECK(f[k] == Approx(expected[k]).margin(1e-12));
  }
  CHECK(out[0] == Approx(20.0));
  CHECK(out[1] == Approx(0.2));
  const Element& e = *model.elements().front();
  CHECK(e.potential_energy(gather_state(e, y.data(), y.data() + 6, system.modes().of(0))) == Approx(2.0));
}

TEST_CASE("a breakpoint that is no kink is merged: the report's symmetric dashpot and gap spring",
          "[elements][nonlinear]") {
  // Report Table 5 nonlinear dashpot: 1180 lb-s/in below 4.5 in/s, 173 above, both ways.
  Axial dashpot = axial("nonlinear_dashpot",
                "damping_compression_1: 1180, damping_compression_2: 173, compression_switch_velocity: 4.5, "
                "damping_extension_1: 1180, damping_extension_2: 173, extension_switch_velocity: 4.5");
  dashpot.velocity = 10.0;
  dashpot.simulation = ida(1.0);
  const Model model = testing::model_from_text(axial_yaml(dashpot));
  const auto& law = dynamic_cast<const NonlinearDashpot&>(*model.elements().front()).law();
  REQUIRE(law.segment_count() == 3);
  CHECK(law.breakpoints() == std::vector<double>{-4.5, 4.5});
  CHECK(law.value(10.0, 2) == Approx(1180.0 * 4.5 + 173.0 * 5.5));
  CHECK(law.value(-10.0, 0) == Approx(-(1180.0 * 4.5 + 173.0 * 5.5)));
  CHECK(law.value(2.0, 1) == Approx(2360.0));

  // Report Table 5 special spring (Type 2): 0 below 4 in of deflection, 175,000 above, no
  // preload, free length 4: force-free until the point has crossed the stop plane (deflection
  // 4, along the axis), then stiff. Mass 10 from s = 4 at 2 towards the plane: closes at
  // t = 2, comes back after half a period pi / sqrt(175000 / 10) with the same speed.
  Axial gap = axial("special_spring",
            "stiffness_1: 0, stiffness_2: 175000, breakpoint: 4.0, fracture_load: 700000, free_length: 4.0, axis: [1, 0]");
  gap.position = 4.0;
  gap.velocity = -2.0;
  gap.mass = 10.0;
  const double half_period = kPi / std::sqrt(17500.0), t_end = 2.1;
  gap.simulation = ida(t_end);
  const Model gap_model = testing::model_from_text(axial_yaml(gap));
  const auto& gap_law = dynamic_cast<const SpecialSpring&>(*gap_model.elements().front()).law();
  REQUIRE(gap_law.segment_count() == 2);
  CHECK(gap_law.breakpoints() == std::vector<double>{4.0});
  const RunOutcome o = run(axial_yaml(gap));
  INFO(event_list(o));
  REQUIRE(o.events.size() == 2);
  CHECK(o.events[0].what == "closing (segment 2)");
  CHECK(o.events[0].t == Approx(2.0).margin(1e-9));
  CHECK(o.events[1].what == "opening");
  CHECK(o.events[1].t == Approx(2.0 + half_period).margin(1e-8));
  CHECK(final_velocity(o) == Approx(2.0).epsilon(1e-8));
  CHECK(final_position(o) == Approx(2.0 * (t_end - 2.0 - half_period)).margin(1e-8));
}

TEST_CASE("a zero breakpoint leaves no empty segment: the report's nonlinear spring type 5", "[elements][nonlinear]") {
  // Table 5, type 5: compression 0 lb/in up to 1.25 in, then 3e6; extension 0 up to 0 in, then 3e6.
  PiecewiseLinearLaw::Branch compression{0.0, 3e6, 1.25}, extension{0.0, 3e6, 0.0};
  const PiecewiseLinearLaw law = PiecewiseLinearLaw::two_branch(0.0, compression, "compression", extension, "extension");
  REQUIRE(law.segment_count() == 3);
  CHECK(law.breakpoints() == std::vector<double>{-1.25, 0.0});
  CHECK(law.segment(2).name == "extension segment 2");
  CHECK(law.segment_at(0.0, 1) == 2);
  CHECK(law.segment_at(0.0, -1) == 1);
  CHECK(law.value(0.1, 2) == Approx(3e5));
  CHECK(law.value(-1.0, 1) == 0.0);
  CHECK(law.value(-1.5, 0) == Approx(-7.5e5));
  CHECK(law.integral(0.1, 2) == Approx(15000.0));
  CHECK(law.integral(-1.0, 1) == 0.0);
  CHECK(law.integral(-1.5, 0) == Approx(3e6 * 0.25 * 0.25 / 2.0));
}

// ---- events and closed forms ---------------------------------------------------------------------

TEST_CASE("special_spring contact at constant speed: closing at gap / speed, breakpoint and rebound",
          "[elements][nonlinear]") {
  // Mass 2 at speed 1.2 towards the spring, 0.03 before contact; no gravity.
  const double m = 2.0, v = 1.2, gap = 0.03;
  const Excursion contact = excursion(m, v, 5.0, 2000.0, 0.02, 20000.0);
  REQUIRE(contact.passes_breakpoint);
  const double t_close = gap / v, t_open = t_close + contact.total;
  const double t_end = t_open + 0.02;
  for (int kind : {1, 2}) {
    for (const bool use_euler : {false, true}) {
      INFO("kind " << kind << (use_euler ? " euler" : " ida"));
      Axial a = axial("special_spring", special_parameters(kind), m);
      // kind 1: body beyond the free length, moving in; kind 2: inside it, moving out.
      const double s = kind == 1 ? 1.0 : -1.0;
      a.position = 1.0 + s * gap;
      a.velocity = -s * v;
      a.simulation = use_euler ? euler(t_end, 1e-6) : ida(t_end);
      const RunOutcome o = run(axial_yaml(a));
      INFO(event_list(o));
      REQUIRE(o.events.size() == 4);
      const double tolerance = use_euler ? 2e-6 : 1e-9;
      CHECK(o.events[0].what == "closing (segment 1)");
      CHECK(o.events[0].t == Approx(t_close).margin(use_euler ? 2e-6 : 1e-12));
      CHECK(o.events[1].what == "segment 2");
      CHECK(o.events[1].t == Approx(t_close + contact.to_breakpoint).margin(tolerance));
      CHECK(o.events[1].value == Approx(0.02).margin(use_euler ? 1e-5 : 1e-12));
      CHECK(o.events[2].what == "segment 1");
      CHECK(o.events[2].t == Approx(t_close + contact.to_breakpoint + contact.in_second_segment).margin(tolerance));
      CHECK(o.events[3].what == "opening");
      CHECK(o.events[3].t == Approx(t_open).margin(tolerance * 2));
      // Elastic rebound: the same speed back, then free flight.
      CHECK(final_velocity(o) == Approx(s * v).epsilon(use_euler ? 1e-4 : 1e-9));
      CHECK(final_position(o) == Approx(1.0 + s * v * (t_end - t_open)).margin(use_euler ? 1e-5 : 1e-9));
    }
  }
}

TEST_CASE("a mass bouncing on a special_spring under gravity: contact time and rebound", "[elements][nonlinear]") {
  // Mass 2 dropped from 0.05 above the free length 1 (vertical, g = 9.81). In contact the
  // force against compression is (5 - m g) + 2000 d, then beyond 0.02: + 20000 (d - 0.02).
  const double m = 2.0, g = 9.81, h = 0.05;
  const double v_in = std::sqrt(2.0 * g * h), t_close = std::sqrt(2.0 * h / g);
  const Excursion contact = excursion(m, v_in, 5.0 - m * g, 2000.0, 0.02, 20000.0);
  REQUIRE(contact.passes_breakpoint);
  const double t_open = t_close + contact.total;
  const double t_end = t_open + 0.06;  // rising, before the apex (v_in / g = 0.1 s later)
  const double tau = t_end - t_open;
  for (const bool use_euler : {false, true}) {
    INFO((use_euler ? "euler" : "ida"));
    Axial a = axial("special_spring", special_parameters(1), m);
    a.vertical = true;
    a.gravity = g;
    a.position = 1.0 + h;
    a.simulation = use_euler ? euler(t_end, 1e-6) : ida(t_end);
    const RunOutcome o = run(axial_yaml(a));
    INFO(event_list(o));
    REQUIRE(o.events.size() == 4);
    const double tolerance = use_euler ? 3e-6 : 1e-9;
    CHECK(o.events[0].what == "closing (segment 1)");
    CHECK(o.events[0].t == Approx(t_close).margin(tolerance));
    CHECK(o.events[1].t == Approx(t_close + contact.to_breakpoint).margin(tolerance));
    CHECK(o.events[3].what == "opening");
    CHECK(o.events[3].t == Approx(t_open).margin(2.0 * tolerance));
    // Rebound with the impact speed (no dissipation): free flight from the free length.
    CHECK(final_velocity(o, true) == Approx(v_in - g * tau).epsilon(use_euler ? 1e-4 : 1e-7));
    CHECK(final_position(o, true) == Approx(1.0 + v_in * tau - 0.5 * g * tau * tau).margin(use_euler ? 1e-5 : 1e-9));
    const EnergyBalance energy = EnergyBalance::between(o.initial_energy, o.final_energy);
    // Euler's rectangle-rule work quadrature errs by about omega dt = 1e-4 of the energy.
    CHECK(std::abs(energy.dissipated) < (use_euler ? 5e-4 : 1e-7) * m * g * h);
  }
}

TEST_CASE("nonlinear_spring undamped oscillation across all breakpoints: period, events, energy",
          "[elements][nonlinear]") {
  // Mass 1 leaves the free length at 1.5 in extension. No preload: the half cycles are
  // harmonic arcs with ke 100 / 900 beyond 0.05 and kc 400 / 2500 beyond 0.04.
  const double m = 1.0, v0 = 1.5;
  const std::string parameters =
      "compression_stiffness_1: 400, compression_stiffness_2: 2500, compression_breakpoint: 0.04, "
      "extension_stiffness_1: 100, extension_stiffness_2: 900, extension_breakpoint: 0.05";
  const Excursion out = excursion(m, v0, 0.0, 100.0, 0.05, 900.0);
  const Excursion in = excursion(m, v0, 0.0, 400.0, 0.04, 2500.0);
  REQUIRE(out.passes_breakpoint);
  REQUIRE(in.passes_breakpoint);
  const double period = out.total + in.total;
  const double t_end = period + 0.5 * out.to_breakpoint;
  const struct {
    const char* what;
    double t, value;
  } expected[] = {
      {"extension segment 2", out.to_breakpoint, 0.05},
      {"extension segment 1", out.to_breakpoint + out.in_second_segment, 0.05},
      {"compression segment 1", out.total, 0.0},
      {"compression segment 2", out.total + in.to_breakpoint, -0.04},
      {"compression segment 1", out.total + in.to_breakpoint + in.in_second_segment, -0.04},
      {"extension segment 1", period, 0.0},
  };
  for (const bool use_euler : {false, true}) {
    INFO((use_euler ? "euler" : "ida"));
    Axial a = axial("nonlinear_spring", parameters, m);
    a.velocity = v0;
    a.simulation = use_euler ? euler(t_end, 1e-6) : ida(t_end);
    const RunOutcome o = run(axial_yaml(a));
    INFO(event_list(o));
    REQUIRE(o.events.size() == 6);
    for (std::size_t k = 0; k < 6; ++k) {
      INFO("event " << k);
      CHECK(o.events[k].what == expected[k].what);
      CHECK(o.events[k].t == Approx(expected[k].t).margin(use_euler ? 2e-5 : 1e-8));
      CHECK(o.events[k].value == Approx(expected[k].value).margin(use_euler ? 2e-5 : 1e-9));
    }
    // One period later the motion repeats: e = (v0 / 10) sin(10 tau).
    const double tau = t_end - period;
    CHECK(final_position(o) - 1.0 == Approx(v0 / 10.0 * std::sin(10.0 * tau)).margin(use_euler ? 5e-5 : 1e-8));
    const EnergyBalance energy = EnergyBalance::between(o.initial_energy, o.final_energy);
    const double e0 = 0.5 * m * v0 * v0;
    CHECK(energy.initial_total == Approx(e0));
    CHECK(std::abs(energy.dissipated) < (use_euler ? 5e-4 : 1e-7) * e0);
    CHECK(std::abs(energy.error()) < (use_euler ? 5e-4 : 1e-7) * e0);
  }
}

TEST_CASE("nonlinear_spring with preload conserves energy across its breakpoints (IDA, tight)", "[elements][nonlinear]") {
  // Preload 5 and the laws of kSpringParameters; started at the free length at 3 (inwards):
  // the motion crosses both breakpoints (checked through the events).
  Axial a = axial("nonlinear_spring", kSpringParameters, 1.0);
  a.velocity = -3.0;
  a.simulation = ida(1.5);
  const RunOutcome o = run(axial_yaml(a));
  INFO(event_list(o));
  CHECK(events_named(o, "compression segment 2").size() >= 2);
  CHECK(events_named(o, "extension segment 2").size() >= 2);
  const EnergyBalance energy = EnergyBalance::between(o.initial_energy, o.final_energy);
  const double e0 = 0.5 * 1.0 * 9.0;
  CHECK(energy.initial_total == Approx(e0));
  CHECK(std::abs(energy.dissipated) < 1e-7 * e0);
  CHECK(std::abs(energy.error()) < 1e-7 * e0);
  // Work done on the spring equals its stored energy (both zero at the free length).
  CHECK(element_work(o) == Approx(energy.elastic).margin(1e-7 * e0));
  CHECK(energy.elastic > 0.01 * e0);  // the end is not at a trivial state
}

TEST_CASE("nonlinear_dashpot decelerating a mass: switch time, final state, dissipated energy",
          "[elements][nonlinear]") {
  // Mass 2 leaves at 1 in extension. Above 0.25: T = 10 + 10 (v - 0.25), so
  // v = -0.75 + 1.75 exp(-5 t) until v = 0.25 at t_s = ln(1.75) / 5; then v = 0.25 exp(-20 (t - t_s)).
  const double m = 2.0, v0 = 1.0, t_end = 0.3;
  const double t_switch = std::log(1.75) / 5.0;
  const double v_end = 0.25 * std::exp(-20.0 * (t_end - t_switch));
  const double travel = -0.75 * t_switch + 1.75 * (1.0 - std::exp(-5.0 * t_switch)) / 5.0 +
                        0.25 * (1.0 - std::exp(-20.0 * (t_end - t_switch))) / 20.0;
  const double dissipated = 0.5 * m * (v0 * v0 - v_end * v_end);
  for (const bool use_euler : {false, true}) {
    INFO((use_euler ? "euler" : "ida"));
    Axial a = axial("nonlinear_dashpot", kDashpotParameters, m);
    a.velocity = v0;
    a.simulation = use_euler ? euler(t_end, 1e-6) : ida(t_end);
    const RunOutcome o = run(axial_yaml(a));
    INFO(event_list(o));
    REQUIRE(o.events.size() == 1);
    CHECK(o.events[0].what == "extension segment 1");
    CHECK(o.events[0].t == Approx(t_switch).margin(use_euler ? 2e-6 : 1e-9));
    CHECK(o.events[0].value == Approx(0.25).margin(use_euler ? 1e-5 : 1e-10));
    CHECK(final_velocity(o) == Approx(v_end).epsilon(use_euler ? 1e-4 : 1e-7));
    CHECK(final_position(o) == Approx(1.0 + travel).epsilon(use_euler ? 1e-6 : 1e-10));
    // Everything the mass lost went into the dashpot, and it stores nothing.
    const EnergyBalance energy = EnergyBalance::between(o.initial_energy, o.final_energy);
    CHECK(element_work(o) == Approx(dissipated).epsilon(use_euler ? 1e-4 : 1e-8));
    CHECK(energy.dissipated == Approx(dissipated).epsilon(use_euler ? 1e-4 : 1e-8));
    CHECK(energy.elastic == 0.0);
  }
}

TEST_CASE("Euler converges to the IDA solution of the nonlinear dashpot as the step shrinks", "[elements][nonlinear]") {
  Axial a = axial("nonlinear_dashpot", kDashpotParameters, 2.0);
  a.velocity = -1.2;  // compression: through the 0.5 switch velocity
  a.simulation = ida(0.2);
  const RunOutcome reference = run(axial_yaml(a));
  REQUIRE(events_named(reference, "compression segment 1").size() == 1);
  double previous = 0.0;
  for (const double dt : {1e-4, 2.5e-5, 6.25e-6}) {
    INFO("dt " << dt);
    a.simulation = euler(0.2, dt);
    const RunOutcome o = run(axial_yaml(a));
    const double error = std::abs(final_position(o) - final_position(reference)) +
                         std::abs(final_velocity(o) - final_velocity(reference)) * 0.2;
    CHECK(error < 2.0 * dt);  // first order: about 1 x dt here
    if (previous > 0.0) CHECK(error < 0.35 * previous);
    previous = error;
  }
  CHECK(previous < 1e-5);
}

// ---- fracture -----------------------------------------------------------------------------------

TEST_CASE("nonlinear_spring fractures when its force reaches the fracture load", "[elements][nonlinear]") {
  // Mass 1 at 1 from the free length, k = 100 (w = 10): T = 10 sin(10 t) reaches 3 at
  // t = asin(0.3) / 10; the mass then flies on with sqrt(1 - 9 / 100), and the 9 / 200
  // the spring held is dissipated.
  const double t_fracture = std::asin(0.3) / 10.0, t_end = 0.1;
  const double v_after = std::sqrt(1.0 - 9.0 / 100.0);
  for (const double sign : {1.0, -1.0}) {  // extension, compression
    for (const bool use_euler : {false, true}) {
      INFO((sign > 0 ? "tension" : "compression") << (use_euler ? " euler" : " ida"));
      Axial a = axial("nonlinear_spring", "compression_stiffness_1: 100, extension_stiffness_1: 100, fracture_load: 3");
      a.velocity = sign;
      a.simulation = use_euler ? euler(t_end, 1e-6) : ida(t_end);
      const RunOutcome o = run(axial_yaml(a));
      INFO(event_list(o));
      const auto fractures = events_named(o, "fracture");
      REQUIRE(fractures.size() == 1);
      CHECK(o.events.size() == 1);
      CHECK(fractures[0].t == Approx(t_fracture).margin(use_euler ? 2e-6 : 1e-9));
      CHECK(fractures[0].value == Approx(3.0 * sign).epsilon(use_euler ? 1e-3 : 1e-8));
      CHECK(final_velocity(o) == Approx(sign * v_after).epsilon(use_euler ? 1e-4 : 1e-8));
      const EnergyBalance energy = EnergyBalance::between(o.initial_energy, o.final_energy);
      CHECK(energy.elastic == 0.0);
      CHECK(energy.dissipated == Approx(9.0 / 200.0).epsilon(use_euler ? 1e-3 : 1e-7));
    }
  }
}

TEST_CASE("special_spring fractures at its fracture load", "[elements][nonlinear]") {
  // Mass 1 meets it at 2 (no preload, k = 1000, w = sqrt(1000)): P = 2 sqrt(1000) sin(w t)
  // reaches 50 at t = asin(50 / (2 sqrt(1000))) / w after contact.
  const double w = std::sqrt(1000.0);
  const double t_close = 0.01 / 2.0;
  const double t_fracture = t_close + std::asin(50.0 / (2.0 * w)) / w;
  Axial a = axial("special_spring", "stiffness_1: 1000, fracture_load: 50, free_length: 1.0");
  a.position = 1.01;
  a.velocity = -2.0;
  a.simulation = ida(0.1);
  const RunOutcome o = run(axial_yaml(a));
  INFO(event_list(o));
  REQUIRE(o.events.size() == 2);
  CHECK(o.events[0].what == "closing (segment 1)");
  CHECK(o.events[1].what == "fracture");
  CHECK(o.events[1].t == Approx(t_fracture).margin(1e-9));
  CHECK(o.events[1].value == Approx(50.0).epsilon(1e-8));
  CHECK(final_velocity(o) == Approx(-std::sqrt(4.0 - 2500.0 / 1000.0)).epsilon(1e-8));
}

// ---- starting on a breakpoint -------------------------------------------------------------------

TEST_CASE("starting at rest on a kink, the element follows the branch the motion takes", "[elements][nonlinear]") {
  // Mass 1 at rest, pulled (+2) or pushed (-2) by a constant load.
  const double t_end = 0.2;
  for (const double load : {2.0, -2.0}) {
    for (const bool use_euler : {false, true}) {
      INFO("load " << load << (use_euler ? " euler" : " ida"));
      {
        INFO("nonlinear_dashpot: extension 10, compression 100");
        Axial a = axial("nonlinear_dashpot", "damping_compression_1: 100, damping_extension_1: 10");
        a.load = load;
        a.simulation = use_euler ? euler(t_end, 1e-5) : ida(t_end);
        const RunOutcome o = run(axial_yaml(a));
        INFO(event_list(o));
        const double c = load > 0.0 ? 10.0 : 100.0;  // v = (F / c)(1 - exp(-c t / m))
        CHECK(final_velocity(o) == Approx(load / c * (1.0 - std::exp(-c * t_end))).epsilon(use_euler ? 1e-3 : 1e-7));
        // It starts in compression (the lower segment) and leaves it at once when pulled.
        CHECK(o.events.size() == (load > 0.0 ? 1u : 0u));
        if (load > 0.0 && !o.events.empty()) CHECK(o.events.front().t == 0.0);
      }
      {
        INFO("nonlinear_spring at its free length: extension 100, compression 400");
        Axial a = axial("nonlinear_spring", "compression_stiffness_1: 400, extension_stiffness_1: 100");
        a.load = load;
        a.simulation = use_euler ? euler(t_end, 1e-5) : ida(t_end);
        const RunOutcome o = run(axial_yaml(a));
        INFO(event_list(o));
        const double k = load > 0.0 ? 100.0 : 400.0;  // x = (F / k)(1 - cos(w t)), w = sqrt(k / m)
        const double expected = load / k * (1.0 - std::cos(std::sqrt(k) * t_end));
        CHECK(final_position(o) - 1.0 == Approx(expected).epsilon(use_euler ? 1e-3 : 1e-7));
        if (load > 0.0) {
          REQUIRE(!o.events.empty());
          CHECK(o.events.front().what == "extension segment 1");
          CHECK(o.events.front().t == 0.0);  // committed by the start check, not found later
        } else {
          CHECK(o.events.empty());  // 0.2 s is less than a period: it never comes back to the kink
        }
      }
    }
  }
}

// ---- input checks -------------------------------------------------------------------------------

TEST_CASE("nonlinear elements reject incomplete or inconsistent parameters", "[elements][nonlinear]") {
  const auto load = [](const std::string& type, const std::string& parameters) {
    Axial a = axial(type, parameters);
    a.simulation = "t_end: 1";
    return testing::model_from_text(axial_yaml(a));
  };
  CHECK_THROWS_WITH(load("nonlinear_spring", "compression_stiffness_1: 1, compression_stiffness_2: 2, extension_stiffness_1: 1"),
                    Catch::Contains("compression_breakpoint"));
  CHECK_THROWS_WITH(load("nonlinear_spring", "compression_stiffness_1: 1, extension_stiffness_1: 1, extension_breakpoint: 1"),
                    Catch::Contains("extension_stiffness_2"));
  CHECK_THROWS_WITH(load("nonlinear_spring", "compression_stiffness_1: 1"), Catch::Contains("extension_stiffness_1"));
  CHECK_THROWS_WITH(load("nonlinear_spring", "compression_stiffness_1: -1, extension_stiffness_1: 1"),
                    Catch::Contains("must not be negative"));
  CHECK_THROWS_WITH(load("nonlinear_spring", "compression_stiffness_1: 1, extension_stiffness_1: 1, preload: -8, fracture_load: 5"),
                    Catch::Contains("preload"));
  CHECK_THROWS_WITH(load("special_spring", "kind: 3, stiffness_1: 1"), Catch::Contains("'kind' must be 1"));
  CHECK_THROWS_WITH(load("special_spring", "stiffness_1: 1, preload: -1"), Catch::Contains("must not be negative"));
  CHECK_THROWS_WITH(load("nonlinear_dashpot", "damping_compression_1: 1, damping_extension_1: 1, extension_switch_velocity: 2"),
                    Catch::Contains("damping_extension_2"));
  // Starting beyond the fracture load: 100 * 0.5 = 50 > 10.
  CHECK_THROWS_WITH(load("nonlinear_spring", "compression_stiffness_1: 100, extension_stiffness_1: 100, free_length: 0.5, fracture_load: 10"),
                    Catch::Contains("fracture_load"));
}

TEST_CASE("Euler's stability limit sees a piecewise law's steepest segment before the spring reaches it",
          "[elements][nonlinear][integrators]") {
  // A 1 kg mass on a special spring at its free length: 100 N/m up to 0.05 m of compression,
  // 40000 N/m beyond. Starting on the soft segment (limit 2 / 10 = 0.2 s), the estimate must
  // be the steep segment's 2 / sqrt(40000) = 0.01 s: an Euler step sized at the start would
  // otherwise run unstable once the spring closes to its second segment.
  const Model model = testing::model_from_text(
      "railcrash: 1\nname: stiffening\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: m, mass: 1, inertia: 1, position: [1, 0], velocity: [-1, 0]}\n"
      "elements:\n  - {name: e, type: special_spring, stiffness_1: 100, stiffness_2: 40000, breakpoint: 0.05, "
      "free_length: 1.0, points: [{body: ground, at: [0, 0]}, {body: m, at: [0, 0]}]}\n"
      "simulation: {t_end: 1}\n");
  DaeSystem system(model);
  CHECK(explicit_stability_limit(system, system.initial_state(), nullptr) == Approx(0.01).epsilon(1e-9));
}

TEST_CASE("nonlinear_spring and special_spring compressed through their points stop the run naming them",
          "[elements][faults]") {
  // As the linear spring's test (test_springs.cpp): a 1 kg mass 1 m from a ground point at
  // 10 m/s into 10 N/m over a free length of 1 m reaches the point; the stop is at x = 1e-3 m,
  // t = asin(0.999 w / v0) / w, w = sqrt(10). Along an axis a special spring's separation has a
  // sign and its force a direction, so it has no such stop: the mass goes through.
  const double v0 = 10.0, w = std::sqrt(10.0);
  const double t_meet = std::asin((1.0 - PointsMeet::kFraction) * w / v0) / w;  // [s] 0.1016
  const auto model = [](const std::string& element, const std::string& integrator) {
    return "railcrash: 1\nname: spring impact\nunits: SI\ngravity: [0, 0]\nbodies:\n"
           "  - {name: mass, mass: 1, inertia: 1, position: [1, 0], velocity: [-10, 0]}\n"
           "elements:\n  - {name: s, " + element + ", points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n"
           "simulation: {t_end: 1, integrator: " + integrator + ", rtol: 1e-10, dt: 1e-5, output_interval: 0.01}\n";
  };
  const std::string nonlinear = "type: nonlinear_spring, compression_stiffness_1: 10, extension_stiffness_1: 10, free_length: 1";
  const std::string special = "type: special_spring, kind: 1, stiffness_1: 10, free_length: 1";
  for (const auto& [element, type] : {std::pair{nonlinear, std::string("nonlinear_spring")}, std::pair{special, std::string("special_spring")}}) {
    for (const char* integrator : {"ida", "euler"}) {
      INFO(type << ", " << integrator);
      const RunOutcome outcome = testing::simulate_to_stop(testing::loaded_from_text(model(element, integrator)));
      INFO(outcome.message);
      CHECK_FALSE(outcome.ok);
      CHECK_THAT(outcome.message, Catch::StartsWith("test.yaml:8: " + type + " 's' is compressed through the whole distance") &&
                                      Catch::Contains("of a free_length of 1,"));
      CHECK(testing::message_time(outcome.message) == Approx(t_meet).epsilon(std::string(integrator) == "euler" ? 1e-3 : 1e-6));
    }
  }
  // Along the axis the mass goes 2.16 m past the point and back: a half period pi / w in
  // contact, then it leaves at 10 m/s, at x = 1 + v0 (1 - pi / w) at t = 1.
  const RunOutcome along_axis = testing::simulate(testing::loaded_from_text(model(special + ", axis: [1, 0]", "ida")));
  CHECK(along_axis.y[0] == Approx(1.0 + v0 * (1.0 - std::acos(-1.0) / w)).epsilon(1e-6));
}

TEST_CASE("A tension-only nonlinear_spring lets its points pass each other: it is slack there", "[elements][faults]") {
  // The mass of the test above through a nonlinear_spring with no compression stiffness and no
  // preload: slack from the start, the force is zero whichever way the points lie, so the mass
  // coasts through the ground point at 10 m/s. At t = 0.15 s it is 0.5 m past it; the tie then
  // stretches (extension 10 N/m once L > 1 m: at x = -1 m, t = 0.2 s) and pulls it back.
  const std::string text =
      "railcrash: 1\nname: slack tie\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: mass, mass: 1, inertia: 1, position: [1, 0], velocity: [-10, 0]}\n"
      "elements:\n  - {name: s, type: nonlinear_spring, compression_stiffness_1: 0, extension_stiffness_1: 10, "
      "free_length: 1, points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n";
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const RunOutcome outcome = testing::simulate(
        testing::loaded_from_text(text + "simulation: {t_end: 0.15, integrator: " + integrator +
                                  ", rtol: 1e-10, dt: 1e-5, output_interval: 0.01}\n"));
    INFO(outcome.message);
    REQUIRE(outcome.ok);
    CHECK(outcome.y[0] == Approx(1.0 - 10.0 * 0.15).epsilon(1e-6));
  }
  // With a preload it pushes at the point (a direction it does not have there): the stop.
  const RunOutcome preloaded = testing::simulate_to_stop(testing::loaded_from_text(
      "railcrash: 1\nname: preloaded tie\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: mass, mass: 1, inertia: 1, position: [1, 0], velocity: [-10, 0]}\n"
      "elements:\n  - {name: s, type: nonlinear_spring, compression_stiffness_1: 0, extension_stiffness_1: 10, "
      "preload: 1, free_length: 1, points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n"
      "simulation: {t_end: 0.15, integrator: ida, rtol: 1e-10, output_interval: 0.01}\n"));
  CHECK_FALSE(preloaded.ok);
  CHECK_THAT(preloaded.message, Catch::Contains("nonlinear_spring 's' is compressed through the whole distance"));
}
