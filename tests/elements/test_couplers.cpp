// Couplers and draft gears: closed-form runs under both integrators (event times and values,
// rebound speeds, loop areas, dissipated energy), forces against hand computations, the
// Jacobian in every mode, Euler converging to IDA, and input errors.
//
// The closed forms: in every mode the element's force is linear in its deflection, so a
// single mass tied to ground by the element moves harmonically (or uniformly) within each
// mode; the walkers below chain these motions from mode to mode, computing each switch
// time and position from the law stated in couplers.hpp.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "railcrash/elements/couplers.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kPi = std::acos(-1.0);

std::string num(double value) {
  std::ostringstream s;
  s.precision(17);
  s << value;
  return s.str();
}

// ---- closed-form motion of one mass --------------------------------------------------------

/// Motion of a mass m in a coordinate x under a force F = a + b x opposing x (m x'' = -F).
struct LinearPhase {
  double m, a, b;

  /// Time until x reaches `target` moving towards it; NaN target: until the velocity is zero.
  double time_to(double x, double v, double target) const {
    if (b == 0.0) {
      const double acc = -a / m;
      if (std::isnan(target)) return -v / acc;
      const double gap = target - x;
      // x + v t + acc t^2 / 2 = target, first crossing (stable form)
      return 2.0 * gap / (v + (v > 0.0 ? 1.0 : -1.0) * std::sqrt(v * v + 2.0 * acc * gap));
    }
    const double omega = std::sqrt(b / m), u0 = x + a / b, w = v / omega;
    const double radius = std::hypot(u0, w), alpha = std::atan2(w, u0);
    // u = x + a/b = R cos(omega t - alpha)
    if (std::isnan(target)) return (v > 0.0 ? alpha : alpha + kPi) / omega;
    const double angle = std::acos((target + a / b) / radius);
    return (v > 0.0 ? alpha - angle : alpha + angle) / omega;
  }
  void advance(double& x, double& v, double t) const {
    if (b == 0.0) {
      const double acc = -a / m;
      x += v * t + 0.5 * acc * t * t;
      v += acc * t;
      return;
    }
    const double omega = std::sqrt(b / m), u0 = x + a / b;
    const double c = std::cos(omega * t), s = std::sin(omega * t);
    x = u0 * c + v / omega * s - a / b;
    v = -u0 * omega * s + v * c;
  }
};

struct ExpectedEvent {
  std::string what;
  double t;
  double value;
};

/// Chains linear phases; records the events and the force-deflection path.
struct Walker {
  Walker(double mass, double speed) : m(mass), v(speed) {}
  double m;
  double t = 0.0, x = 0.0, v;
  std::vector<ExpectedEvent> events;
  std::vector<std::array<double, 2>> path{{0.0, 0.0}};  // (x, force) corners

  /// Moves under F = a + b x to `target` (NaN: to rest); logs `what` with `value_of(x)`.
  template <class Value>
  void go(double a, double b, double target, const std::string& what, Value value_of) {
    const LinearPhase phase{m, a, b};
    const double dt = phase.time_to(x, v, target);
    REQUIRE(dt >= 0.0);
    phase.advance(x, v, dt);
    t += dt;
    if (std::isnan(target)) v = 0.0;
    else x = target;
    events.push_back({what, t, value_of(x)});
    path.push_back({x, a + b * x});
  }
  /// Area enclosed by the path (closed back to the origin along zero force).
  double loop_area() const {
    double twice = 0.0;
    for (std::size_t k = 0; k < path.size(); ++k) {
      const auto& p = path[k];
      const auto& q = path[(k + 1) % path.size()];
      twice += p[0] * q[1] - q[0] * p[1];
    }
    return std::abs(0.5 * twice);
  }
};

// ---- runs ---------------------------------------------------------------------------------

struct Run {
  RunOutcome outcome;
  double x = 0.0, y = 0.0, vx = 0.0, vy = 0.0;  // the mass at t_end
};

Run run(DaeSystem& system, const SimulationSettings& simulation) {
  struct Null : RunObserver {
    void sample(double, const double*, const double*, const double*, const double*) override {}
  } observer;
  Run r;
  r.outcome = make_integrator(system, simulation)->run(simulation.t_end, simulation.t_end / 4.0, observer);
  INFO(r.outcome.message);
  REQUIRE(r.outcome.ok);
  r.x = r.outcome.y[0];
  r.y = r.outcome.y[1];
  r.vx = r.outcome.y[3];
  r.vy = r.outcome.y[4];
  return r;
}

Run run(const LoadedModel& loaded) {
  DaeSystem system(loaded.model);
  return run(system, loaded.run_spec.simulation);
}

/// A mass tied to ground by element `e`: the ground point at the origin, the mass's point at
/// its centre; `element` holds the element's type and parameter lines.
std::string one_mass(const std::string& element, double mass, double x, double y, double vx, double vy, double t_end,
                     const std::string& integrator, double dt = 1e-6, const std::string& units = "SI",
                     const std::string& loads = "") {
  std::ostringstream s;
  s << "railcrash: 1\nname: coupler test\nunits: " << units << "\ngravity: [0, 0]\nbodies:\n"
    << "  - {name: mass, mass: " << num(mass) << ", inertia: 1, position: [" << num(x) << ", " << num(y)
    << "], velocity: [" << num(vx) << ", " << num(vy) << "]}\n"
    << "elements:\n  - name: e\n" << element << "    points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]\n"
    << loads << "simulation: {t_end: " << num(t_end) << ", integrator: " << integrator
    << ", rtol: 1e-10, dt: " << num(dt) << "}\n";
  return s.str();
}

void check_events(const RunOutcome& outcome, const std::vector<ExpectedEvent>& expected, double t_margin,
                  double value_margin) {
  std::ostringstream seen;
  for (const EventRecord& e : outcome.events) seen << e.t << " " << e.what << " " << e.value << "\n";
  INFO("events seen:\n" << seen.str());
  REQUIRE(outcome.events.size() == expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    INFO("event " << k << ": " << expected[k].what);
    CHECK(outcome.events[k].what == expected[k].what);
    CHECK(outcome.events[k].t == Approx(expected[k].t).margin(t_margin).epsilon(0));
    CHECK(outcome.events[k].value ==
          Approx(expected[k].value).margin(value_margin * std::max(1.0, std::abs(expected[k].value))).epsilon(0));
  }
}

double element_work(const RunOutcome& o) { return o.quadratures[DaeSystem::kFirstElementWork]; }
double dissipated(const RunOutcome& o) { return EnergyBalance::between(o.initial_energy, o.final_energy).dissipated; }
double balance_error(const RunOutcome& o) { return EnergyBalance::between(o.initial_energy, o.final_energy).error(); }

// ---- draft gear ------------------------------------------------------------------------------

struct Gear {
  double k, s, K, H, Kt;  // initial_stiffness, travel, stiffness_after_bottoming, hysteresis_load, transition
  double U(double x) const { return x <= s ? k * x + H : k * s + H + K * (x - s); }
  double Lw(double x) const { return U(x) - 2.0 * H; }
};

std::string gear_yaml(const Gear& g, const std::string& extra = "") {
  return "    type: draft_gear\n    initial_stiffness: " + num(g.k) + "\n    travel: " + num(g.s) +
         "\n    stiffness_after_bottoming: " + num(g.K) + "\n    hysteresis_load: " + num(g.H) +
         "\n    transition_stiffness: " + num(g.Kt) + "\n" + extra;
}

const Gear kGear{1.0e6, 0.05, 2.0e7, 2.0e4, 2.0e7};
constexpr double kGearMass = 500.0;

/// A mass m hitting the gear at v0 on `side` (+1 buff, -1 draft), up to the release of the
/// mass; the side deflection x = side * compression.
Walker gear_bounce(const Gear& g, double m, double v0, int side) {
  const std::string label = side > 0 ? " (buff)" : " (draft)";
  const auto value = [side](double x) { return side * x; };  // events report the compression
  Walker w(m, v0);
  // stuck by friction: F = Kt x until it meets the loading line k x + H
  w.go(0.0, g.Kt, g.H / (g.Kt - g.k), "sliding" + label, value);
  // loading on k x + H; bottoming at travel if the energy left suffices
  if (0.5 * w.m * w.v * w.v > 0.5 * g.k * (g.s * g.s - w.x * w.x) + g.H * (g.s - w.x)) {
    w.go(g.H, g.k, g.s, "bottomed" + label, value);
    w.go(g.k * g.s + g.H - g.K * g.s, g.K, kNaN, "reversal" + label, value);
  } else {
    w.go(g.H, g.k, kNaN, "reversal" + label, value);
  }
  // back down the transition line F = U(xm) + Kt (x - xm) to the unloading line U - 2H
  const double xm = w.x, fm = g.U(xm);
  double meet = (fm - g.Kt * xm + g.H) / (g.k - g.Kt);  // on the initial part, k x - H
  if (g.Kt > g.K) {
    const double bottomed = (fm - g.Kt * xm - (g.k * g.s - g.H - g.K * g.s)) / (g.K - g.Kt);
    if (bottomed >= g.s) meet = bottomed;
  }
  if (g.Lw(meet) <= 0.0) {  // the transition line reaches zero force first
    w.go(fm - g.Kt * xm, g.Kt, xm - fm / g.Kt, "released" + label, value);
    return w;
  }
  w.go(fm - g.Kt * xm, g.Kt, meet, "unloading" + label, value);
  if (w.x > g.s) w.go(g.k * g.s - g.H - g.K * g.s, g.K, g.s, "off bottom" + label, value);
  w.go(-g.H, g.k, g.H / g.k, "released" + label, value);  // k x - H reaches zero
  return w;
}

DraftGear& gear_of(const Model& model) { return dynamic_cast<DraftGear&>(*model.elements()[0]); }

/// The gear of one mass tied to ground, set to a compression and a compression rate by hand
/// (its mode as the commits left it).
struct GearByHand {
  Model model = testing::model_from_text(one_mass(gear_yaml(kGear), kGearMass, 1.0, 0.0, 0.0, 0.0, 1.0, "ida"));
  DraftGear& gear = gear_of(model);
  DaeSystem system{model};
  std::vector<double> y = system.initial_state();
  ElementState<double> at(double d, double rate) {  // compression d, compression rate
    y[0] = 1.0 - d;
    y[3] = -rate;
    return gather_state(gear, y.data(), y.data() + 3, system.modes().of(0));
  }
};

// ---- couplings -----------------------------------------------------------------------------

/// Piecewise-linear curve through points, the last slope extended (test-side, by hand).
struct Curve {
  std::vector<double> x, y;
  int segment(double at) const {
    int j = 0;
    while (j + 2 < static_cast<int>(x.size()) && at >= x[static_cast<std::size_t>(j + 1)]) ++j;
    return j;
  }
  double slope(int j) const {
    const auto k = static_cast<std::size_t>(j);
    return (y[k + 1] - y[k]) / (x[k + 1] - x[k]);
  }
  double at(double v) const {
    const int j = segment(v);
    return y[static_cast<std::size_t>(j)] + slope(j) * (v - x[static_cast<std::size_t>(j)]);
  }
  /// F = a + b x on segment j
  double a(int j) const { return y[static_cast<std::size_t>(j)] - slope(j) * x[static_cast<std::size_t>(j)]; }
};

/// A mass at v0 through the horizontal slack into a coupling (U loading, Lw unloading, both
/// on the breakpoints of U, transition stiffness Kt), back out into the slack (or, without
/// slack, straight into draft). Events report the deflection u = x + slack / 2.
Walker coupling_bounce(const Curve& U, const Curve& Lw, double Kt, double slack, double m, double v0) {
  const auto value = [slack](double x) { return x + 0.5 * slack; };
  Walker w(m, v0);
  if (slack > 0.0) {
    w.x = -0.5 * slack;
    w.go(0.0, 0.0, 0.0, "slack taken up (buff)", value);
    w.path = {{0.0, 0.0}};
  }
  int j = 0;
  for (;; ++j) {  // loading, segment by segment
    const bool last = j + 2 >= static_cast<int>(U.x.size());
    const double end = U.x[static_cast<std::size_t>(j + 1)];
    const double work_to_end = 0.5 * (U.at(w.x) + U.at(end)) * (end - w.x);
    if (last || 0.5 * m * w.v * w.v <= work_to_end) break;
    w.go(U.a(j), U.slope(j), end, "curve segment " + std::to_string(j + 2) + " (buff)", value);
  }
  w.go(U.a(j), U.slope(j), kNaN, "reversal (buff)", value);
  const double xm = w.x, fm = U.at(xm);
  // transition down to Lw: search the segments from xm's downward
  double meet = 0.0;
  for (int i = Lw.segment(xm); i >= 0; --i) {
    const double xi = (Lw.a(i) - fm + Kt * xm) / (Kt - Lw.slope(i));
    if (xi >= Lw.x[static_cast<std::size_t>(i)] && xi <= xm) {
      meet = xi;
      break;
    }
  }
  w.go(fm - Kt * xm, Kt, meet, "unloading (buff)", value);
  for (int i = Lw.segment(meet); i > 0; --i)
    w.go(Lw.a(i), Lw.slope(i), Lw.x[static_cast<std::size_t>(i)], "curve segment " + std::to_string(i) + " (buff)", value);
  w.go(Lw.a(0), Lw.slope(0), 0.0, slack > 0.0 ? "in the slack" : "through zero force to draft", value);
  return w;
}

std::string table(const Curve& c) {
  std::string s = "[";
  for (std::size_t k = 0; k < c.x.size(); ++k) s += (k ? ", [" : "[") + num(c.x[k]) + ", " + num(c.y[k]) + "]";
  return s + "]";
}

// ---- Jacobian checks ---------------------------------------------------------------------------

/// Two rotated, moving bodies (or ground and one body) joined by element `e`.
std::string two_bodies(const std::string& element, bool ground_first) {
  std::ostringstream s;
  s << "railcrash: 1\nname: jacobian\nunits: SI\ngravity: [0, 0]\nbodies:\n"
    << "  - {name: a, mass: 2.0, inertia: 0.5, position: [0.3, -0.2], angle: 0.3, velocity: [0.5, -0.3], "
       "angular_velocity: 0.8}\n"
    << "  - {name: b, mass: 3.0, inertia: 0.7, position: [1.5, 0.1], angle: -0.2, velocity: [-0.4, 0.2], "
       "angular_velocity: -1.1}\n"
    << "elements:\n  - name: e\n" << element << "    points: ["
    << (ground_first ? "{body: ground, at: [0.1, -0.15]}" : "{body: a, at: [0.25, 0.1]}")
    << ", {body: b, at: [-0.3, 0.05]}]\nsimulation: {t_end: 1.0}\n";
  return s.str();
}

/// Jacobian against central differences at random states near the start, in the mode the
/// element is in now.
void check_jacobian_here(const DaeSystem& system, std::mt19937& rng) {
  for (int trial = 0; trial < 3; ++trial) {
    INFO("trial " << trial);
    const std::vector<double> y = testing::random_state(system, rng, 1e-3);
    const std::vector<double> yp = testing::random_state(system, rng, 0.3);
    double outside = -1.0;
    CHECK(testing::jacobian_error(system, 0.0, 40.0 * (trial + 1), y, yp, &outside) < 1e-6);
    CHECK(outside == 0.0);
  }
}

std::string error_of(const std::string& text) {
  try {
    testing::model_from_text(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

// =================================================================================================
// draft_gear
// =================================================================================================

TEST_CASE("draft_gear: a mass bounces off it in buff and in draft, closed form under both integrators",
          "[elements][couplers]") {
  const double v0 = 2.0;
  for (const int side : {1, -1}) {
    const Walker expected = gear_bounce(kGear, kGearMass, v0, side);
    const double speed = -expected.v;  // rebound speed when the gear lets go
    // Stop while the mass coasts away, before the gear comes back through zero compression.
    const double t_end = expected.t + 0.5 * (kGear.H / kGear.k) / speed;
    // The loop: 2 H x_max less the corners cut by the stick and transition lines and by the
    // release at x = H / k (H^2 / 2k): between these bounds.
    const double area = expected.loop_area(), xm = expected.events[1].value * side;
    REQUIRE(area < 2.0 * kGear.H * xm);
    REQUIRE(area > 2.0 * kGear.H * xm - kGear.H * kGear.H / (2.0 * kGear.k) - 3.0 * kGear.H * kGear.H / (kGear.Kt - kGear.k));
    // Energy: what the mass lost is the loop area.
    REQUIRE(0.5 * kGearMass * (v0 * v0 - speed * speed) == Approx(area).epsilon(1e-12));
    for (const char* integrator : {"ida", "euler"}) {
      INFO((side > 0 ? "buff " : "draft ") << integrator);
      const bool ida = std::string(integrator) == "ida";
      const LoadedModel loaded = testing::loaded_from_text(one_mass(gear_yaml(kGear), kGearMass, 1.0, 0.0, -side * v0, 0.0, t_end, integrator));
      const Model& model = loaded.model;
      DaeSystem system(model);
      const Run r = run(system, loaded.run_spec.simulation);
      check_events(r.outcome, expected.events, ida ? 1e-8 : 3e-6, ida ? 1e-9 : 1e-5);
      CHECK(r.vx == Approx(side * speed).epsilon(ida ? 1e-8 : 1e-3));
      CHECK(element_work(r.outcome) == Approx(area).epsilon(ida ? 1e-7 : 2e-3));
      CHECK(dissipated(r.outcome) == Approx(area).epsilon(ida ? 1e-7 : 2e-3));
      CHECK(std::abs(balance_error(r.outcome)) < (ida ? 1e-7 : 1e-4) * area);
      CHECK(system.modes().as<DraftGear::State>(0).law.mode == AxialHysteresis::Mode::Released);
    }
  }
}

TEST_CASE("draft_gear: released gear returns to neutral at zero compression and sticks in draft",
          "[elements][couplers]") {
  // After the buff bounce the mass coasts away; at zero compression the gear is neutral again
  // (event at t_release + (H / k) / v) and then stuck in draft: F = Kt d (harmonic).
  const Walker bounce = gear_bounce(kGear, kGearMass, 2.0, 1);
  const double speed = -bounce.v, t_neutral = bounce.t + (kGear.H / kGear.k) / speed, extra = 2e-4;
  std::vector<ExpectedEvent> expected = bounce.events;
  expected.push_back({"neutral", t_neutral, 0.0});
  double d = 0.0, v = -speed;
  LinearPhase{kGearMass, 0.0, kGear.Kt}.advance(d, v, extra);
  REQUIRE(-kGear.Kt * d < kGear.H * (1.0 + kGear.k / (kGear.Kt - kGear.k)));  // still stuck
  const LoadedModel loaded = testing::loaded_from_text(one_mass(gear_yaml(kGear), kGearMass, 1.0, 0.0, -2.0, 0.0, t_neutral + extra, "ida"));
  const Run r = run(loaded);
  check_events(r.outcome, expected, 1e-8, 1e-9);
  CHECK(r.x == Approx(1.0 - d).epsilon(1e-10));
  CHECK(r.vx == Approx(-v).epsilon(1e-7));
  // The cycle is closed: the work done on the gear is still its loop area, plus the stick
  // spring's (stored) energy.
  CHECK(element_work(r.outcome) == Approx(bounce.loop_area() + 0.5 * kGear.Kt * d * d).epsilon(1e-7));
  CHECK(dissipated(r.outcome) == Approx(bounce.loop_area()).epsilon(1e-7));
}

TEST_CASE("draft_gear: bottoms at exactly its travel", "[elements][couplers]") {
  // With the default transition stiffness (= K) the gear unloads from the bottom along its
  // loading line; with a stiffer transition it meets the unloading line while still
  // bottomed and comes "off bottom" at exactly its travel too.
  for (const double kt : {kGear.K, 2.0 * kGear.K}) {
    Gear g = kGear;
    g.Kt = kt;
    const Walker expected = gear_bounce(g, kGearMass, 5.0, 1);
    REQUIRE(expected.events[1].what == "bottomed (buff)");
    REQUIRE(expected.events.size() == (kt > g.K ? 6u : 5u));
    const double t_end = expected.t + 0.5 * (g.H / g.k) / -expected.v;
    for (const char* integrator : {"ida", "euler"}) {
      INFO(integrator << ", transition stiffness " << kt);
      const bool ida = std::string(integrator) == "ida";
      const LoadedModel loaded = testing::loaded_from_text(one_mass(gear_yaml(g), kGearMass, 1.0, 0.0, -5.0, 0.0, t_end, integrator));
      const Run r = run(loaded);
      check_events(r.outcome, expected.events, ida ? 1e-8 : 3e-6, ida ? 1e-9 : 2e-5);
      REQUIRE(r.outcome.events.size() > 1);
      CHECK(r.outcome.events[1].value == Approx(g.s).margin(ida ? 1e-9 : 1e-5));
      if (kt > g.K) CHECK(r.outcome.events[4].value == Approx(g.s).margin(ida ? 1e-9 : 1e-5));
      CHECK(r.vx == Approx(-expected.v).epsilon(ida ? 1e-8 : 1e-3));
      CHECK(dissipated(r.outcome) == Approx(expected.loop_area()).epsilon(ida ? 1e-7 : 2e-3));
    }
  }
}

TEST_CASE("draft_gear: the pin shears at the pin shear load, travels, goes solid and fractures at the fracture load",
          "[elements][couplers]") {
  const double pin = 1.2e5, post = 0.02, fracture = 2.0e5, v0 = 10.0;
  const std::string extra = "    pin_shear_load: " + num(pin) + "\n    post_shear_travel: " + num(post) +
                            "\n    fracture_load: " + num(fracture) + "\n";
  const Gear& g = kGear;
  const auto compression = [](double x) { return x; };
  Walker w(kGearMass, v0);
  w.go(0.0, g.Kt, g.H / (g.Kt - g.k), "sliding (buff)", compression);
  w.go(g.H, g.k, g.s, "bottomed (buff)", compression);
  const double x_pin = g.s + (pin - g.U(g.s)) / g.K;
  w.go(g.k * g.s + g.H - g.K * g.s, g.K, x_pin, "pin shear", [&](double) { return pin; });
  w.go(0.0, 0.0, x_pin + post, "solid", compression);  // free sliding: uniform motion
  const double x_solid = x_pin + post;
  w.go(-g.K * x_solid, g.K, x_solid + fracture / g.K, "fracture", [&](double) { return fracture; });
  // Dissipated: the work on the gear up to the pin shear (its stored energy is lost there)
  // and the solid spring's energy lost at fracture.
  const double x1 = g.H / (g.Kt - g.k);
  const double to_pin = 0.5 * g.Kt * x1 * x1 + 0.5 * (g.U(x1) + g.U(g.s)) * (g.s - x1) + 0.5 * (g.U(g.s) + pin) * (x_pin - g.s);
  const double lost = to_pin + 0.5 * fracture * fracture / g.K;
  const double speed = std::sqrt(v0 * v0 - 2.0 * lost / kGearMass);
  REQUIRE(w.v == Approx(speed).epsilon(1e-12));
  const double t_end = w.t + 0.01;
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const bool ida = std::string(integrator) == "ida";
    const LoadedModel loaded = testing::loaded_from_text(one_mass(gear_yaml(g, extra), kGearMass, 1.0, 0.0, -v0, 0.0, t_end, integrator));
    const Model& model = loaded.model;
    DaeSystem system(model);
    const Run r = run(system, loaded.run_spec.simulation);
    check_events(r.outcome, w.events, ida ? 1e-8 : 3e-6, ida ? 1e-9 : 2e-3);
    // The pin lets go at the pin shear load, the gear breaks at the fracture load.
    REQUIRE(r.outcome.events.size() == 5);
    // Euler sees a crossing at the end of its step: the force overshoots by up to K v dt.
    CHECK(r.outcome.events[2].value == Approx(pin).epsilon(ida ? 1e-9 : 3e-3));
    CHECK(r.outcome.events[4].value == Approx(fracture).epsilon(ida ? 1e-9 : 3e-3));
    CHECK(r.vx == Approx(-speed).epsilon(ida ? 1e-8 : 1e-4));  // coasting on after fracture
    CHECK(dissipated(r.outcome) == Approx(lost).epsilon(ida ? 1e-7 : 2e-3));
    CHECK(system.modes().as<DraftGear::State>(0).stage == DraftGear::Stage::Fractured);
  }
}

TEST_CASE("draft_gear: its points meeting while it carries force stops the run naming it under every integrator",
          "[elements][couplers][faults]") {
  // 500 kg at 30 m/s into a gear 1 m long that is soft after bottoming (1e5 N/m): 225 kJ against
  // about 60 kJ over the whole metre, so the mass reaches the gear's ground point. Closed form
  // (Walker): stuck to H / (Kt - k), loading on k x + H to the travel, bottomed on K up to the
  // points-meet margin, compression 0.999 m. Before this check Euler carried the mass past the
  // ground point with the force turned around (the gear's line of action reverses with r2 - r1).
  const Gear g{1.0e5, 0.05, 1.0e5, 1.0e4, 1.0e6};
  const double v0 = 30.0, meet = 1.0 - PointsMeet::kFraction;
  const auto compression = [](double x) { return x; };
  Walker w(kGearMass, v0);
  w.go(0.0, g.Kt, g.H / (g.Kt - g.k), "sliding (buff)", compression);
  w.go(g.H, g.k, g.s, "bottomed (buff)", compression);
  w.go(g.k * g.s + g.H - g.K * g.s, g.K, meet, "points meet", compression);
  REQUIRE(w.v > 20.0);  // still fast: the gear is driven through, not stopped short
  for (const char* integrator : {"ida", "euler", "auto"}) {
    INFO(integrator);
    const bool euler = std::string(integrator) == "euler";
    const RunOutcome outcome = testing::simulate_to_stop(
        testing::loaded_from_text(one_mass(gear_yaml(g), kGearMass, 1.0, 0.0, -v0, 0.0, 0.2, integrator)));
    INFO(outcome.message);
    CHECK_FALSE(outcome.ok);
    CHECK_THAT(outcome.message, Catch::StartsWith("test.yaml:8: draft_gear 'e' is compressed through the whole distance "
                                                  "between its points at t = ") &&
                                    Catch::Contains("(intact): its points are ") && Catch::Contains("of a free_length of 1,"));
    const double t_message = testing::message_time(outcome.message);
    CHECK(t_message == Approx(w.t).epsilon(euler ? 1e-4 : 1e-6));
    CHECK(outcome.t_reached <= t_message);  // the run keeps its samples up to there
    CHECK(outcome.stats.handed_over_at < 0.0);  // auto: not an IDA failure, no hand-over to Euler
  }
  // A step that carries the mass past the ground point (Euler at 1 ms moves it 26 mm) is caught
  // as well, and the message says so.
  const RunOutcome outcome = testing::simulate_to_stop(
      testing::loaded_from_text(one_mass(gear_yaml(g), kGearMass, 1.0, 0.0, -v0, 0.0, 0.2, "euler", 1e-3)));
  INFO(outcome.message);
  CHECK_FALSE(outcome.ok);
  CHECK_THAT(outcome.message, Catch::Contains("draft_gear 'e' is compressed through") &&
                                  Catch::Contains("its points have passed each other (by "));
}

TEST_CASE("draft_gear: the points-meet root measures along the turned initial direction, near the points alone",
          "[elements][couplers][faults]") {
  // The gear from ground (body 1, axis +x) to a mass 1 m along +x: free length 1 m, margin 1 mm.
  GearByHand h;
  const double margin = PointsMeet::kFraction * 1.0;
  const auto at = [&](double x, double y) {
    h.y[0] = x;
    h.y[1] = y;
    return gather_state(h.gear, h.y.data(), h.y.data() + 3, h.system.modes().of(0));
  };
  CHECK(h.gear.points_meet_gap(at(1.0, 0.0)) == Approx(1.0 - margin));
  CHECK(h.gear.points_meet_gap(at(0.002, 0.0)) == Approx(0.002 - margin));  // about to meet
  CHECK(h.gear.points_meet_gap(at(0.0005, 0.0)) < 0.0);                      // within the margin
  CHECK(h.gear.points_meet_gap(at(-0.03, 0.0)) == Approx(-0.03 - margin));   // passed
  CHECK(h.gear.points_meet_gap(at(-0.3, 0.0)) == Approx(-0.3 - margin));     // passed (an explicit step's jump)
  // Abeam of body 1, or behind it farther than half the free length: swung round, not passed.
  CHECK(h.gear.points_meet_gap(at(0.0, 1.0)) == Approx(1.0 - margin));
  CHECK(h.gear.points_meet_gap(at(-0.8, 0.0)) == Approx(0.8 - margin));
  // Behind P1 along body 1's turned axis but not along body 2's: the mass has turned round with
  // the gear (a half turn, as a crank would carry it): swung, not passed.
  h.y[2] = kPi;
  CHECK(h.gear.points_meet_gap(at(-0.3, 0.0)) == Approx(0.3 - margin));
  h.y[2] = 0.0;
}

TEST_CASE("draft_gear: a fractured gear's points may pass each other, the run goes on (the report's final_two_car)",
          "[elements][couplers][faults]") {
  // Fracture at 5e4 N during the bottomed phase; after it no force acts and the mass coasts past
  // the gear's ground point (its line of action has no direction there, and no force to direct).
  const Gear g{1.0e5, 0.05, 1.0e5, 1.0e4, 1.0e6};
  const double v0 = 30.0;
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const LoadedModel loaded = testing::loaded_from_text(
        one_mass(gear_yaml(g, "    fracture_load: 5.0e4\n"), kGearMass, 1.0, 0.0, -v0, 0.0, 0.1, integrator));
    DaeSystem system(loaded.model);
    const Run r = run(system, loaded.run_spec.simulation);
    CHECK(r.x < -1.0);  // well past the ground point
    CHECK(system.modes().as<DraftGear::State>(0).stage == DraftGear::Stage::Fractured);
    CHECK(r.outcome.events.back().what == "fracture");
  }
}

TEST_CASE("draft_gear: in draft the pin does not shear, the gear fractures at the fracture load",
          "[elements][couplers]") {
  const double fracture = 1.0e5, v0 = 10.0;
  const std::string extra = "    pin_shear_load: 8.0e4\n    fracture_load: " + num(fracture) + "\n";
  const Gear& g = kGear;
  const auto extension = [](double x) { return -x; };
  Walker w(kGearMass, v0);
  w.go(0.0, g.Kt, g.H / (g.Kt - g.k), "sliding (draft)", extension);
  w.go(g.H, g.k, g.s, "bottomed (draft)", extension);
  w.go(g.k * g.s + g.H - g.K * g.s, g.K, g.s + (fracture - g.U(g.s)) / g.K, "fracture", [&](double) { return fracture; });
  const LoadedModel loaded = testing::loaded_from_text(one_mass(gear_yaml(g, extra), kGearMass, 1.0, 0.0, v0, 0.0, w.t + 0.01, "ida"));
  const Run r = run(loaded);
  check_events(r.outcome, w.events, 1e-8, 1e-9);
  CHECK(r.vx == Approx(w.v).epsilon(1e-8));
}

TEST_CASE("draft_gear with the report's Table 5 values (in-lbf-s): rebound closed form", "[elements][couplers]") {
  // Report Table 5 / 8: initial stiffness 24,000 lb/in, travel 1.25 in, stiffness after
  // bottoming 320,000 lb/in, hysteresis load 10,000 lb, pin shear load 150,000 lb,
  // post-shear travel 1.375 in, fracture load 250,000 lb.
  const Gear report{24000.0, 1.25, 320000.0, 10000.0, 320000.0};
  const std::string element = "    type: draft_gear\n    initial_stiffness: 24000\n    travel: 1.25\n"
                              "    stiffness_after_bottoming: 320000\n    hysteresis_load: 10000\n"
                              "    pin_shear_load: 150000\n    post_shear_travel: 1.375\n    fracture_load: 250000\n";
  // A 10 lbf s^2/in mass (3861 lbf) at 50 in/s: stays below travel and the pin shear load.
  const double mass = 10.0, v0 = 50.0;
  const Walker w = gear_bounce(report, mass, v0, 1);
  REQUIRE(w.events[1].value < report.s);
  REQUIRE(w.events.size() == 4);
  const LoadedModel loaded = testing::loaded_from_text(
      one_mass(element, mass, 1.0, 0.0, -v0, 0.0, w.t + 0.001, "ida", 1e-6, "in-lbf-s"));
  const Model& model = loaded.model;
  const DraftGear& gear = gear_of(model);
  CHECK(gear.transition_stiffness == 320000.0);  // default: the stiffness after bottoming
  const Run r = run(loaded);
  check_events(r.outcome, w.events, 1e-8, 1e-9);
  CHECK(r.vx == Approx(-w.v).epsilon(1e-8));
  CHECK(dissipated(r.outcome) == Approx(w.loop_area()).epsilon(1e-7));
}

TEST_CASE("draft_gear: explicit Euler converges to IDA as the step shrinks", "[elements][couplers]") {
  const Walker expected = gear_bounce(kGear, kGearMass, 5.0, 1);
  const double t_end = expected.t + 0.5 * (kGear.H / kGear.k) / -expected.v;
  const auto final_vx = [&](const std::string& integrator, double dt) {
    return run(testing::loaded_from_text(one_mass(gear_yaml(kGear), kGearMass, 1.0, 0.0, -5.0, 0.0, t_end, integrator, dt))).vx;
  };
  const double ida = final_vx("ida", 1e-6);
  CHECK(ida == Approx(-expected.v).epsilon(1e-8));
  double previous = std::numeric_limits<double>::infinity();
  for (const double dt : {1.6e-5, 4e-6, 1e-6}) {
    INFO("dt " << dt);
    const double error = std::abs(final_vx("euler", dt) - ida);
    CHECK(error < previous);
    CHECK(error < 2000.0 * dt);  // first order: about 2e-3 per microsecond of step or less
    previous = error;
  }
  CHECK(previous < 2e-3);
}

TEST_CASE("draft_gear: stored energy is what unloading gives back, and forces follow the stated law",
          "[elements][couplers]") {
  const Model model = testing::model_from_text(one_mass(gear_yaml(kGear), kGearMass, 1.0, 0.0, 0.0, 0.0, 1.0, "ida"));
  DraftGear& gear = gear_of(model);
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  const auto at = [&](double d) {
    y[0] = 1.0 - d;
    return gather_state(gear, y.data(), y.data() + 3, system.modes().of(0));
  };
  const auto force_on_mass = [&](double d) {
    std::array<Pose<double>, 2> f{};
    gear.add_force(0.0, at(d), f);
    return f[static_cast<std::size_t>(gear.point_slot(1))].x;
  };
  using M = AxialHysteresis::Mode;
  const Gear& g = kGear;
  DraftGear::State st;
  // Loading, bottomed (draft): F = -(k s + H + K (x - s)) at compression -x.
  st.law = {M::Loading, -1, 1, 0.0, 0.0};
  testing::set_mode<DraftGear::State>(system, st);
  CHECK(force_on_mass(-0.06) == Approx(-g.U(0.06)));
  CHECK(gear.potential_energy(at(-0.06)) > 0.0);
  // Unloading (buff) at x: energy = integral of k x - H down to H / k.
  st.law = {M::Unloading, 1, 0, 0.0, 0.0};
  testing::set_mode<DraftGear::State>(system, st);
  const double x = 0.03;
  CHECK(force_on_mass(x) == Approx(g.k * x - g.H));
  CHECK(gear.potential_energy(at(x)) == Approx(0.5 * (g.k * x - g.H) * (x - g.H / g.k)));
  // Transition from (0.04, U(0.04)) at 0.0395: energy = trapezoid down to the unloading line + tail.
  st.law = {M::Transition, 1, 0, 0.04, g.U(0.04)};
  testing::set_mode<DraftGear::State>(system, st);
  const double f = g.U(0.04) + g.Kt * (0.0395 - 0.04);
  const double meet = (g.U(0.04) - g.Kt * 0.04 + g.H) / (g.k - g.Kt);
  const double f_meet = g.k * meet - g.H;
  CHECK(force_on_mass(0.0395) == Approx(f));
  CHECK(gear.potential_energy(at(0.0395)) ==
        Approx(0.5 * (f + f_meet) * (0.0395 - meet) + 0.5 * f_meet * (meet - g.H / g.k)).epsilon(1e-12));
  // Neutral: Kt d^2 / 2; released, sheared, fractured: nothing.
  st.law = {M::Neutral, 1, 0, 0.0, 0.0};
  testing::set_mode<DraftGear::State>(system, st);
  CHECK(force_on_mass(-1e-4) == Approx(-g.Kt * 1e-4));
  CHECK(gear.potential_energy(at(-1e-4)) == Approx(0.5 * g.Kt * 1e-8));
  st.law = {M::Released, 1, 0, 0.0, 0.0};
  testing::set_mode<DraftGear::State>(system, st);
  CHECK(force_on_mass(0.01) == 0.0);
  CHECK(gear.potential_energy(at(0.01)) == 0.0);
  st.stage = DraftGear::Stage::Solid;
  st.solid_compression = 0.07;
  testing::set_mode<DraftGear::State>(system, st);
  CHECK(force_on_mass(0.075) == Approx(g.K * 0.005));
  CHECK(gear.potential_energy(at(0.075)) == Approx(0.5 * g.K * 0.005 * 0.005));
  st.stage = DraftGear::Stage::Fractured;
  testing::set_mode<DraftGear::State>(system, st);
  CHECK(force_on_mass(0.075) == 0.0);
}

TEST_CASE("draft_gear: reloading, rejoining the loading curve, and crossings committed together", "[elements][couplers]") {
  GearByHand by_hand;
  DraftGear& gear = by_hand.gear;
  DaeSystem& system = by_hand.system;
  const auto at = [&](double d, double rate) { return by_hand.at(d, rate); };
  const auto force = [&](double d) {
    std::array<Pose<double>, 2> f{};
    gear.add_force(0.0, at(d, 0.0), f);
    return f[1].x;
  };
  const Gear& g = kGear;
  using M = AxialHysteresis::Mode;
  REQUIRE(system.modes().as<DraftGear::State>(0).law.mode == M::Neutral);
  Element::Event event;
  const double x1 = g.H / (g.Kt - g.k);
  CHECK_FALSE(gear.commit(0, -1, 0.0, at(0.5 * x1, 1.0), nullptr, testing::modes_to_write(system).of(0), event));  // not crossed: stale
  CHECK_FALSE(gear.commit(0, 1, 0.0, at(2.0 * x1, 1.0), nullptr, testing::modes_to_write(system).of(0), event));   // upward crossings never leave a mode
  CHECK(gear.commit(0, -1, 0.0, at(x1, 1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "sliding (buff)");
  // Reversal at 0.03, partial unloading to the lower line, reloading at 0.025.
  CHECK(gear.commit(0, -1, 0.0, at(0.03, 0.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "reversal (buff)");
  CHECK(force(0.0295) == Approx(g.U(0.03) - g.Kt * 0.0005));
  const double meet = 0.03 - 2.0 * g.H / (g.Kt - g.k);
  // (Position roots switch a band of 1e-12 x travel past their boundary: step just past it.)
  const double past = 1e-12;
  CHECK(gear.commit(1, -1, 0.0, at(meet - past, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "unloading (buff)");
  CHECK(force(0.026) == Approx(g.Lw(0.026)));
  CHECK(gear.commit(0, -1, 0.0, at(0.025, 1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "reloading (buff)");
  CHECK(force(0.026) == Approx(g.Lw(0.025) + g.Kt * 0.001));
  // Elastic back up until the line meets k x + H again, 2 H / (Kt - k) further on.
  const double rejoin = 0.025 + 2.0 * g.H / (g.Kt - g.k);
  CHECK_FALSE(gear.commit(0, -1, 0.0, at(rejoin - 1e-6, 1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(gear.commit(0, -1, 0.0, at(rejoin + past, 1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "back on the loading curve (buff)");
  CHECK(force(0.04) == Approx(g.U(0.04)));
  // An Euler step that goes past several boundaries (breakaway, then the reversal): each
  // change is applied in one commit.
  ModeTracker(system).reset_modes();
  CHECK(gear.commit(0, -1, 0.0, at(0.03, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "sliding (buff), reversal (buff)");
  CHECK(system.modes().as<DraftGear::State>(0).law.mode == M::Transition);
  CHECK(force(0.03) == Approx(g.U(0.03)));
  ModeTracker(system).reset_modes();
  CHECK(gear.commit(0, -1, 0.0, at(0.06, 1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "sliding (buff)");
  CHECK(system.modes().as<DraftGear::State>(0).law.segment == 1);  // on the bottomed part
  CHECK(force(0.06) == Approx(g.U(0.06)));
  // Bottomed, the transition stiffness equals K: the gear unloads along its loading line
  // (solid, the friction does not slip) until it is back off the bottom.
  CHECK(gear.commit(0, -1, 0.0, at(0.06, 0.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(force(0.055) == Approx(g.U(0.055)));
  double g_roots[DraftGear::kRoots];
  gear.roots(0.0, at(0.055, -1.0), nullptr, g_roots);
  for (const double value : g_roots) CHECK(value > 0.0);
  // Outputs: force and compression.
  double out[2];
  gear.outputs(at(0.055, 0.0), nullptr, out);
  CHECK(out[0] == Approx(g.U(0.055)));
  CHECK(out[1] == Approx(0.055));
}

TEST_CASE("draft_gear: past a boundary but moving back is no crossing (a gear resting on its reversal point)",
          "[elements][couplers]") {
  GearByHand by_hand;
  DraftGear& gear = by_hand.gear;
  DaeSystem& system = by_hand.system;
  const auto at = [&](double d, double rate) { return by_hand.at(d, rate); };
  using M = AxialHysteresis::Mode;
  const Gear& g = kGear;
  Element::Event event;
  // Loaded to 0.03 and reversed there: the transition line starts on the loading curve.
  REQUIRE(gear.commit(0, -1, 0.0, at(0.03, 1.0), nullptr, testing::modes_to_write(system).of(0), event));
  REQUIRE(gear.commit(0, -1, 0.0, at(0.03, 0.0), nullptr, testing::modes_to_write(system).of(0), event));
  REQUIRE(event.what == "reversal (buff)");
  REQUIRE(system.modes().as<DraftGear::State>(0).law.mode == M::Transition);
  // 1e-10 m past the reversal point (10^4 times the roots' band) while unloading at 1 nm/s: the
  // position correction of the constraints moves x without x' (emu3_unit_collision at rtol
  // 1e-3 chattered there, "back on the loading curve, reversal", 1.15 million times).
  const double creep = 0.03 + 1e-10;
  double roots[DraftGear::kRoots];
  gear.roots(0.0, at(creep, -1e-9), nullptr, roots);
  CHECK(roots[0] > 0.0);
  CHECK_FALSE(gear.commit(0, -1, 0.0, at(creep, -1e-9), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(system.modes().as<DraftGear::State>(0).law.mode == M::Transition);
  // Moving up, or at rest (a static settle: the position alone decides), the same point is
  // back on the loading curve, and the force is U's.
  gear.roots(0.0, at(creep, 0.0), nullptr, roots);
  CHECK(roots[0] < 0.0);
  CHECK(gear.commit(0, -1, 0.0, at(creep, 1e-3), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "back on the loading curve (buff)");
  CHECK(system.modes().as<DraftGear::State>(0).law.mode == M::Loading);
  // The mirror: reloaded from the lower curve at 0.025, the line meets it again going down
  // only while moving down.
  REQUIRE(gear.commit(0, -1, 0.0, at(0.04, 0.0), nullptr, testing::modes_to_write(system).of(0), event));  // reversal at 0.04
  const double meet = 0.04 - 2.0 * g.H / (g.Kt - g.k);
  REQUIRE(gear.commit(1, -1, 0.0, at(meet - 1e-12, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  REQUIRE(event.what == "unloading (buff)");
  REQUIRE(gear.commit(0, -1, 0.0, at(0.025, 0.0), nullptr, testing::modes_to_write(system).of(0), event));
  REQUIRE(event.what == "reloading (buff)");
  const double below = 0.025 - 1e-10;
  gear.roots(0.0, at(below, 1e-9), nullptr, roots);
  CHECK(roots[1] > 0.0);
  CHECK_FALSE(gear.commit(1, -1, 0.0, at(below, 1e-9), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(gear.commit(1, -1, 0.0, at(below, -1e-3), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "unloading (buff)");
}

TEST_CASE("draft_gear: a 3-car unit's gears at rtol 1e-3 do not chatter on their reversal points", "[elements][couplers]") {
  // Before the rate condition on the transition line's exits: 1,153,628 events and 30 s of
  // wall time here (IDA restarted at each), against 301 events and 709 steps now.
  const std::string path = std::string(RAILCRASH_SOURCE_DIR) + "/models/examples/emu3_unit_collision.yaml";
  const LoadedModel loaded = load_model(path, {"simulation.integrator=ida", "simulation.rtol=1e-3"});
  const RunReport report = run_model(loaded.model, loaded.run_spec, "", nullptr, false, /*keep_in_memory=*/true);
  REQUIRE(report.outcome.ok);
  const nlohmann::json summary = nlohmann::json::parse(report.summary_json);
  CHECK(summary["stats"]["events"].get<int>() < 1000);
  CHECK(summary["stats"]["steps"].get<int>() < 2000);
  // The same crush as the model's own rtol 1e-6 to 1 % (the leading cars' 0.905 m).
  for (const char* car : {"unitA.car1", "unitB.car1"}) CHECK(summary["car_crush"][car]["max_crush"].get<double>() == Approx(0.905).epsilon(0.01));
}

TEST_CASE("draft_gear Jacobian matches central differences in every mode", "[elements][couplers]") {
  using M = AxialHysteresis::Mode;
  using S = DraftGear::Stage;
  const std::vector<DraftGear::State> modes = {
      {S::Intact, {M::Neutral, 1, 0, 0.0, 0.0}, 0.0},       {S::Intact, {M::Loading, 1, 0, 0.0, 0.0}, 0.0},
      {S::Intact, {M::Loading, -1, 1, 0.0, 0.0}, 0.0},      {S::Intact, {M::Transition, 1, 0, 0.01, 3e4}, 0.0},
      {S::Intact, {M::Transition, -1, 0, 0.06, 2e5}, 0.0},  {S::Intact, {M::Unloading, 1, 0, 0.0, 0.0}, 0.0},
      {S::Intact, {M::Unloading, -1, 1, 0.0, 0.0}, 0.0},    {S::Intact, {M::Released, 1, 0, 0.0, 0.0}, 0.0},
      {S::Sheared, {}, 0.1},                                {S::Solid, {}, -0.2},
      {S::Fractured, {}, 0.0}};
  for (const bool ground_first : {true, false}) {
    Model model = testing::model_from_text(two_bodies(gear_yaml(kGear, "    free_length: 1.0\n"), ground_first));
    DaeSystem system(model);
    std::mt19937 rng(5);
    for (std::size_t k = 0; k < modes.size(); ++k) {
      INFO((ground_first ? "ground-body" : "body-body") << ", mode " << k);
      testing::set_mode<DraftGear::State>(system, modes[k]);
      check_jacobian_here(system, rng);
    }
  }
}

// =================================================================================================
// coupler_end
// =================================================================================================

namespace {
// Faces: 360,000 and 360,000 (series 180,000), 0.05 behind each face (contact spacing 0.1).
std::string coupler_end_yaml(const std::string& extra = "") {
  return "    type: coupler_end\n    horizontal_stiffness: [3.6e5, 3.6e5]\n    free_length: [0.05, 0.05]\n"
         "    coupler_height: [0.3, 0.3]\n" + extra;
}
constexpr double kFaceStiffness = 1.8e5, kContact = 0.1;
}  // namespace

TEST_CASE("coupler_end: the gap closes at gap / speed, uncoupled faces never pull, coupled ones do after the slack",
          "[elements][couplers]") {
  const double m = 100.0, v = 2.0, gap = 0.03, slack = 0.05;
  const double half_period = kPi * std::sqrt(m / kFaceStiffness);
  const double t_contact = gap / v, t_separation = t_contact + half_period;
  const double t_draft = t_separation + slack / v;  // from the contact spacing to c + s
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const bool ida = std::string(integrator) == "ida";
    const double t_margin = ida ? 1e-8 : 3e-6;
    const double t_end = t_draft + half_period + 0.01;
    // Uncoupled: an elastic bounce, then the mass goes away for good at +v.
    {
      const Run r = run(testing::loaded_from_text(
          one_mass(coupler_end_yaml("    friction: 0.3\n"), m, kContact + gap, 0.0, -v, 0.0, t_end, integrator)));
      check_events(r.outcome, {{"contact", t_contact, 0.0}, {"separation", t_separation, 0.0}}, t_margin, ida ? 1e-9 : 1e-5);
      CHECK(r.vx == Approx(v).epsilon(ida ? 1e-8 : 1e-4));
      CHECK(r.x == Approx(kContact + v * (t_end - t_separation)).epsilon(ida ? 1e-8 : 1e-4));
    }
    // Coupled with slack: caught in draft after the slack, pulled back at -v.
    {
      const Run r = run(testing::loaded_from_text(one_mass(
          coupler_end_yaml("    coupled: true\n    total_horizontal_slack: " + num(slack) + "\n"), m, kContact + gap, 0.0, -v,
          0.0, t_end, integrator)));
      check_events(r.outcome,
                   {{"contact", t_contact, 0.0},
                    {"separation", t_separation, 0.0},
                    {"slack taken up (draft)", t_separation + slack / v, slack},
                    {"draft released", t_separation + slack / v + half_period, slack}},
                   t_margin, ida ? 1e-9 : 1e-5);
      CHECK(r.vx == Approx(-v).epsilon(ida ? 1e-8 : 1e-4));
      // Elastic both ways: nothing dissipated.
      CHECK(std::abs(dissipated(r.outcome)) < (ida ? 1e-7 : 1e-2) * 0.5 * m * v * v);
    }
  }
}

TEST_CASE("coupler_end friction: regularized Coulomb, bounded by mu times the normal force", "[elements][couplers]") {
  const double mu = 0.3, vf = 0.01;
  const Model model = testing::model_from_text(
      one_mass(coupler_end_yaml("    friction: 0.3\n    friction_velocity: 0.01\n"), 10.0, 0.09, 0.02, 0.0, 0.0, 1.0, "ida"));
  const Element& e = *model.elements()[0];
  DaeSystem system(model);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> gap(-0.02, -1e-4), slip(-0.05, 0.05), lateral(-0.1, 0.1);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> y = system.initial_state();
    y[0] = kContact + gap(rng);  // in contact (the initial mode is contact: the mass starts at 0.09)
    y[1] = lateral(rng);
    y[3] = slip(rng);
    y[4] = slip(rng);
    std::array<Pose<double>, 2> f{};
    e.add_force(0.0, gather_state(e, y.data(), y.data() + 3, system.modes().of(0)), f);
    const Pose<double>& on_mass = f[static_cast<std::size_t>(e.point_slot(1))];
    const double normal = kFaceStiffness * (kContact - y[0]);
    INFO("trial " << trial);
    CHECK(on_mass.x == Approx(normal).epsilon(1e-12));
    CHECK(on_mass.y == Approx(-mu * normal * std::tanh(y[4] / vf)).epsilon(1e-12));
    CHECK(std::abs(on_mass.y) <= mu * normal);
  }
}

TEST_CASE("coupler_end: a face pressed and sliding decelerates by the regularized friction law, closed form",
          "[elements][couplers]") {
  // Load P presses the mass onto the face at equilibrium (compression P / k); it slides
  // vertically at v0: m v' = -mu P tanh(v / vf)  ->  sinh(v / vf) = sinh(v0 / vf) exp(-mu P t / (m vf)).
  const double m = 10.0, P = 1000.0, mu = 0.3, vf = 0.01, v0 = 1.0, T = 0.02;
  const double vT = vf * std::asinh(std::sinh(v0 / vf) * std::exp(-mu * P * T / (m * vf)));
  REQUIRE(vT > 0.2);
  const std::string load = "loads:\n  - {type: force, body: mass, at: [0, 0], value: [" + num(-P) + ", 0]}\n";
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const bool ida = std::string(integrator) == "ida";
    const Run r = run(testing::loaded_from_text(one_mass(coupler_end_yaml("    friction: 0.3\n    friction_velocity: 0.01\n"),
                                                          m, kContact - P / kFaceStiffness, 0.0, 0.0, v0, T, integrator, 1e-6,
                                                          "SI", load)));
    CHECK(r.outcome.events.empty());
    CHECK(r.vy == Approx(vT).epsilon(ida ? 1e-7 : 1e-3));
    CHECK(r.x == Approx(kContact - P / kFaceStiffness).epsilon(1e-9));  // stays pressed, at rest in x
    // Friction dissipates the kinetic energy lost.
    CHECK(dissipated(r.outcome) == Approx(0.5 * m * (v0 * v0 - vT * vT)).epsilon(ida ? 1e-7 : 2e-3));
  }
}

TEST_CASE("coupler_end: contact ends when the faces lose vertical overlap", "[elements][couplers]") {
  // Frictionless, pressed at equilibrium, sliding up at 1: the faces (0.3 high each) part at
  // Dy = 0.3; from then on the load pushes the mass freely: x = x0 - P/(2m) (t - t_lost)^2.
  const double m = 10.0, P = 1000.0, vy = 1.0, y0 = 0.1, T = 0.25;
  const double t_lost = (0.3 - y0) / vy, x0 = kContact - P / kFaceStiffness;
  const std::string load = "loads:\n  - {type: force, body: mass, at: [0, 0], value: [" + num(-P) + ", 0]}\n";
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const bool ida = std::string(integrator) == "ida";
    const Run r = run(testing::loaded_from_text(
        one_mass(coupler_end_yaml(), m, x0, y0, 0.0, vy, T, integrator, 1e-6, "SI", load)));
    check_events(r.outcome, {{"vertical overlap lost", t_lost, 0.3}}, ida ? 1e-8 : 2e-6, ida ? 1e-9 : 2e-6);
    CHECK(r.x == Approx(x0 - 0.5 * P / m * (T - t_lost) * (T - t_lost)).epsilon(ida ? 1e-8 : 1e-4));
  }
}

TEST_CASE("coupler_end: overlap regained with the faces past each other gives no force until they clear",
          "[elements][couplers]") {
  const Model model = testing::model_from_text(one_mass(coupler_end_yaml(), 10.0, 0.09, 0.5, 0.0, 0.0, 1.0, "ida"));
  CouplerEnd& e = dynamic_cast<CouplerEnd&>(*model.elements()[0]);
  DaeSystem system(model);
  REQUIRE_FALSE(system.modes().as<CouplerEnd::State>(0).overlapping);  // starts 0.5 above: no overlap
  std::vector<double> y = system.initial_state();
  const auto state_at = [&](double x, double dy, double vx) {
    y[0] = x;
    y[1] = dy;
    y[3] = vx;
    return gather_state(e, y.data(), y.data() + 3, system.modes().of(0));
  };
  const auto force_x = [&](double x, double dy) {
    std::array<Pose<double>, 2> f{};
    e.add_force(0.0, state_at(x, dy, 0.0), f);
    return f[1].x;
  };
  CHECK(force_x(0.08, 0.5) == 0.0);
  Element::Event event;
  // Coming down into overlap while horizontally 0.02 past contact: blocked.
  CHECK(e.commit(2, -1, 0.0, state_at(0.08, 0.29, 0.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "vertical overlap regained, faces past each other");
  CHECK(system.modes().as<CouplerEnd::State>(0).blocked);
  CHECK(force_x(0.08, 0.2) == 0.0);
  // A stale crossing (a root that is positive in the current mode) changes nothing.
  CHECK_FALSE(e.commit(2, -1, 0.0, state_at(0.08, 0.1, 0.0), nullptr, testing::modes_to_write(system).of(0), event));
  // Moving apart past the contact spacing: clear, then a new approach makes contact.
  CHECK(e.commit(0, -1, 0.0, state_at(0.1 + 1e-9, 0.1, 1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "faces clear");
  CHECK_FALSE(system.modes().as<CouplerEnd::State>(0).blocked);
  CHECK(e.commit(0, -1, 0.0, state_at(0.1 - 1e-9, 0.1, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "contact");
  CHECK(force_x(0.09, 0.1) == Approx(kFaceStiffness * 0.01));
  ModeTracker(system).reset_modes();
  CHECK_FALSE(system.modes().as<CouplerEnd::State>(0).overlapping);
}

TEST_CASE("coupler_end: faces touching at rest at the start: a load closes them, a pull does not", "[elements][couplers]") {
  // Exactly at the contact spacing, at rest. Pushed by P: h = c - (P / k)(1 - cos w t).
  // Pulled by P: no force from the faces, x = c + P t^2 / (2 m).
  const double m = 10.0, P = 1000.0, omega = std::sqrt(kFaceStiffness / m), T = 0.6 * kPi / omega;
  for (const double sign : {-1.0, 1.0}) {
    INFO((sign < 0 ? "pushed" : "pulled"));
    const std::string load = "loads:\n  - {type: force, body: mass, at: [0, 0], value: [" + num(sign * P) + ", 0]}\n";
    const Run r = run(testing::loaded_from_text(one_mass(coupler_end_yaml(), m, kContact, 0.0, 0.0, 0.0, T, "ida", 1e-6, "SI", load)));
    if (sign < 0) {
      REQUIRE(r.outcome.events.size() == 1);
      CHECK(r.outcome.events[0].what == "contact");
      CHECK(r.outcome.events[0].t < 1e-4);
      CHECK(r.x == Approx(kContact - P / kFaceStiffness * (1.0 - std::cos(omega * T))).epsilon(1e-9));
    } else {
      CHECK(r.outcome.events.empty());
      CHECK(r.x == Approx(kContact + 0.5 * P / m * T * T).epsilon(1e-9));
    }
  }
}

TEST_CASE("coupler_end: Euler's stability estimate sees the face stiffness while the faces are apart",
          "[elements][couplers]") {
  const Model model = testing::model_from_text(one_mass(coupler_end_yaml(), 10.0, 0.5, 0.0, 0.0, 0.0, 1.0, "ida"));
  Element& e = *model.elements()[0];
  DaeSystem system(model);
  const std::vector<double> y = system.initial_state();
  const ElementState<double> s = gather_state(e, y.data(), y.data() + 3, system.modes().of(0));
  ForceBlock now{}, now_v{}, stiffest{}, stiffest_v{};
  std::array<Pose<double>, 2> f{};
  e.add_force_jacobian(0.0, s, f, now, now_v);
  e.stiffest_force_jacobian(0.0, s, stiffest, stiffest_v);
  const auto x = static_cast<std::size_t>(3 * e.point_slot(1));
  CHECK(now[x][x] == 0.0);  // open
  CHECK(stiffest[x][x] == Approx(-kFaceStiffness));
}

TEST_CASE("coupler_end Jacobian matches central differences in every mode", "[elements][couplers]") {
  using B = DeadBand::Mode;
  const std::vector<CouplerEnd::State> modes = {{B::Below, true, false}, {B::Inside, true, false}, {B::Above, true, false},
                                                {B::Below, false, false}, {B::Below, true, true}};
  for (const bool ground_first : {true, false}) {
    Model model = testing::model_from_text(two_bodies(
        coupler_end_yaml("    friction: 0.3\n    coupled: true\n    total_horizontal_slack: 0.02\n"), ground_first));
    DaeSystem system(model);
    std::mt19937 rng(7);
    for (std::size_t k = 0; k < modes.size(); ++k) {
      INFO((ground_first ? "ground-body" : "body-body") << ", mode " << k);
      testing::set_mode<CouplerEnd::State>(system, modes[k]);
      check_jacobian_here(system, rng);
    }
  }
}

// ---- coupler_end: restitution (permanent set) and face shear ------------------------------------

TEST_CASE("coupler_end restitution: a mass hitting the faces rebounds at e times its speed, closed form under both integrators",
          "[elements][couplers]") {
  // Loading P = k delta: a quarter period of omega = sqrt(k / m) to delta_max = v / omega;
  // unloading P = k_u (delta - p), k_u = k / e^2, p = delta_max (1 - e^2): a quarter period of
  // omega / e back to the set, leaving at omega_u (delta_max - p) = (omega / e) e^2 v / omega = e v.
  const double m = 100.0, v = 2.0, gap = 0.03, omega = std::sqrt(kFaceStiffness / m);
  for (const double e : {0.3, 0.8}) {
    const double peak = v / omega, set = peak * (1.0 - e * e);
    const double t_contact = gap / v, t_unloading = t_contact + 0.5 * kPi / omega;
    const double t_separation = t_unloading + 0.5 * kPi * e / omega, t_end = t_separation + 0.02;
    const double lost = 0.5 * m * v * v * (1.0 - e * e);
    for (const char* integrator : {"ida", "euler"}) {
      INFO("e = " << e << ", " << integrator);
      const bool ida = std::string(integrator) == "ida";
      const LoadedModel loaded = testing::loaded_from_text(one_mass(coupler_end_yaml("    restitution: " + num(e) + "\n"), m,
                                                            kContact + gap, 0.0, -v, 0.0, t_end, integrator));
      const Model& model = loaded.model;
      DaeSystem system(model);
      const Run r = run(system, loaded.run_spec.simulation);
      check_events(r.outcome, {{"contact", t_contact, 0.0}, {"unloading", t_unloading, -peak}, {"separation", t_separation, -set}},
                   ida ? 1e-8 : 3e-6, ida ? 1e-9 : 1e-5);
      // Euler (dt 1e-6) sees each switch up to one step late, but the force is continuous at
      // both (the lines meet at delta_max; both are zero at the set) and the reversal comes at
      // near-zero speed, so the rebound speed keeps second-order accuracy: measured 1e-8
      // relative; asserted to 1e-6.
      CHECK(r.vx == Approx(e * v).epsilon(ida ? 1e-8 : 1e-6));
      CHECK(r.x == Approx(kContact - set + e * v * (t_end - t_separation)).epsilon(ida ? 1e-8 : 1e-4));
      // Euler's work quadrature is first order: measured 5e-5 (e = 0.3) and 1.7e-4 (e = 0.8).
      CHECK(element_work(r.outcome) == Approx(lost).epsilon(ida ? 1e-7 : 5e-4));
      CHECK(dissipated(r.outcome) == Approx(lost).epsilon(ida ? 1e-7 : 5e-4));
      // Euler's energy error oscillates with relative amplitude of order omega dt, largest
      // on the stiffer unloading line (omega / e).
      CHECK(std::abs(balance_error(r.outcome)) < (ida ? 1e-7 : 3.0 * omega / e * 1e-6) * 0.5 * m * v * v);
      const CouplerEnd& end = dynamic_cast<const CouplerEnd&>(*model.elements()[0]);
      CHECK(system.modes().as<CouplerEnd::State>(0).peak == Approx(peak).epsilon(ida ? 1e-8 : 1e-4));
      CHECK(end.permanent_set(system.modes().as<CouplerEnd::State>(0)) == Approx(set).epsilon(ida ? 1e-8 : 1e-4));
    }
  }
}

TEST_CASE("coupler_end restitution: faces touching at rest, pushed by a load: reversal at 2 P / k, then the unloading line",
          "[elements][couplers]") {
  // Loading: delta = (P / k)(1 - cos w t), at rest again at t = pi / w, delta_max = 2 P / k.
  // Unloading line P_f = k_u (delta - p): harmonic at w / e about delta_eq = p + P / k_u; a
  // quarter of its period later the mass passes delta_eq at speed (delta_max - delta_eq) w / e.
  const double m = 10.0, P = 1000.0, e = 0.5, k = kFaceStiffness, ku = k / (e * e), omega = std::sqrt(k / m);
  const double peak = 2.0 * P / k, set = peak * (1.0 - e * e), equilibrium = set + P / ku;
  const double t_unloading = kPi / omega, t_end = t_unloading + 0.5 * kPi * e / omega;
  const std::string load = "loads:\n  - {type: force, body: mass, at: [0, 0], value: [" + num(-P) + ", 0]}\n";
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const bool ida = std::string(integrator) == "ida";
    const Run r = run(testing::loaded_from_text(one_mass(coupler_end_yaml("    restitution: 0.5\n"), m, kContact, 0.0, 0.0, 0.0,
                                                          t_end, integrator, 1e-6, "SI", load)));
    std::ostringstream seen;
    for (const EventRecord& ev : r.outcome.events) seen << ev.t << " " << ev.what << " " << ev.value << "\n";
    INFO(seen.str());
    REQUIRE(r.outcome.events.size() == 2);
    CHECK(r.outcome.events[0].what == "contact");
    CHECK(r.outcome.events[0].t < 1e-4);
    CHECK(r.outcome.events[1].what == "unloading");
    CHECK(r.outcome.events[1].t == Approx(t_unloading).epsilon(0).margin(ida ? 1e-7 : 3e-6));
    CHECK(r.outcome.events[1].value == Approx(-peak).epsilon(ida ? 1e-8 : 1e-4));
    CHECK(r.x == Approx(kContact - equilibrium).epsilon(ida ? 1e-7 : 1e-4));
    CHECK(r.vx == Approx((peak - equilibrium) * omega / e).epsilon(ida ? 1e-6 : 1e-3));
  }
}

TEST_CASE("coupler_end restitution: a set face reloads along its unloading line up to delta_max, then on the loading line",
          "[elements][couplers]") {
  const double e = 0.5, k = kFaceStiffness, ku = k / (e * e), peak = 0.02, set = peak * (1.0 - e * e);
  const Model model =
      testing::model_from_text(one_mass(coupler_end_yaml("    restitution: 0.5\n"), 10.0, 0.5, 0.0, 0.0, 0.0, 1.0, "ida"));
  CouplerEnd& end = dynamic_cast<CouplerEnd&>(*model.elements()[0]);
  CHECK(end.unloading_stiffness() == Approx(ku));
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  const auto state_at = [&](double delta, double delta_rate) {
    y[0] = kContact - delta;
    y[3] = -delta_rate;
    return gather_state(end, y.data(), y.data() + 3, system.modes().of(0));
  };
  const auto push = [&](double delta) {  // force on the mass along +x, the faces' push
    std::array<Pose<double>, 2> f{};
    end.add_force(0.0, state_at(delta, 0.0), f);
    return f[1].x;
  };
  Element::Event event;
  const auto crossing = [&](int index, double delta, double delta_rate) {
    return end.commit(index, -1, 0.0, state_at(delta, delta_rate), nullptr, testing::modes_to_write(system).of(0), event);
  };
  CHECK(push(0.01) == 0.0);
  REQUIRE(crossing(0, 1e-9, 1.0));
  CHECK(event.what == "contact");
  CHECK(push(0.01) == Approx(k * 0.01));
  CHECK_FALSE(crossing(0, 0.015, 0.5));  // still closing: no reversal
  REQUIRE(crossing(0, peak, -0.5));
  CHECK(event.what == "unloading");
  CHECK(event.value == Approx(-peak));
  CHECK(system.modes().as<CouplerEnd::State>(0).peak == Approx(peak));
  CHECK(push(peak) == Approx(k * peak));  // the lines meet at delta_max
  CHECK(push(0.018) == Approx(ku * (0.018 - set)));
  CHECK(end.potential_energy(state_at(0.018, 0.0)) == Approx(0.5 * std::pow(ku * (0.018 - set), 2) / ku));
  CHECK_FALSE(crossing(0, set + 1e-6, -0.5));  // not yet at the set
  // Past a point but moving back is no crossing (the constraints' position correction moves a
  // deflection without its rate: hybrid.hpp, position_root_moving_on), here and below.
  CHECK_FALSE(crossing(0, set - 1e-9, 1e-9));
  REQUIRE(crossing(0, set - 1e-9, -0.5));
  CHECK(event.what == "separation");
  CHECK(event.value == Approx(-set));
  CHECK(push(0.01) == 0.0);  // below the set: open
  // A new contact starts at the set, on the unloading line.
  CHECK_FALSE(crossing(0, set - 1e-6, 0.5));
  CHECK_FALSE(crossing(0, set + 1e-9, -1e-9));
  REQUIRE(crossing(0, set + 1e-9, 0.5));
  CHECK(event.what == "contact");
  CHECK(system.modes().as<CouplerEnd::State>(0).unloading);
  CHECK(push(0.018) == Approx(ku * (0.018 - set)));
  CHECK_FALSE(crossing(1, peak - 1e-6, 0.5));
  CHECK_FALSE(crossing(1, peak + 1e-9, -1e-9));
  REQUIRE(crossing(1, peak + 1e-9, 0.5));
  CHECK(event.what == "reloading");
  CHECK(push(0.025) == Approx(k * 0.025));
  CHECK(end.potential_energy(state_at(0.025, 0.0)) == Approx(0.5 * std::pow(k * 0.025, 2) / ku));
  // A reversal further in moves the set: delta_max 0.03, p = 0.0225.
  REQUIRE(crossing(0, 0.03, -0.1));
  CHECK(end.permanent_set(system.modes().as<CouplerEnd::State>(0)) == Approx(0.03 * (1.0 - e * e)));
  CHECK(push(0.025) == Approx(ku * (0.025 - 0.0225)));
  ModeTracker(system).reset_modes();
  CHECK(system.modes().as<CouplerEnd::State>(0).peak == 0.0);
  CHECK(push(0.01) == 0.0);
}

TEST_CASE("coupler_end restitution: loss of overlap while loading keeps the set, overlap regained past the set is blocked",
          "[elements][couplers]") {
  const double e = 0.5, peak = 0.02, set = peak * (1.0 - e * e);
  const Model model =
      testing::model_from_text(one_mass(coupler_end_yaml("    restitution: 0.5\n"), 10.0, 0.5, 0.0, 0.0, 0.0, 1.0, "ida"));
  CouplerEnd& end = dynamic_cast<CouplerEnd&>(*model.elements()[0]);
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  const auto state_at = [&](double delta, double dy, double delta_rate) {
    y[0] = kContact - delta;
    y[1] = dy;
    y[3] = -delta_rate;
    return gather_state(end, y.data(), y.data() + 3, system.modes().of(0));
  };
  Element::Event event;
  REQUIRE(end.commit(0, -1, 0.0, state_at(1e-9, 0.0, 1.0), nullptr, testing::modes_to_write(system).of(0), event));
  REQUIRE(end.commit(CouplerEnd::kOverlapRoot, -1, 0.0, state_at(peak, 0.3 + 1e-9, 1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "vertical overlap lost");
  CHECK(end.permanent_set(system.modes().as<CouplerEnd::State>(0)) == Approx(set));
  // Back into overlap with the faces deeper than the set: blocked, no force, clear at the set.
  REQUIRE(end.commit(CouplerEnd::kOverlapRoot, -1, 0.0, state_at(0.018, 0.1, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "vertical overlap regained, faces past each other");
  std::array<Pose<double>, 2> f{};
  end.add_force(0.0, state_at(0.018, 0.1, 0.0), f);
  CHECK(f[1].x == 0.0);
  CHECK_FALSE(end.commit(0, -1, 0.0, state_at(set + 1e-6, 0.1, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  REQUIRE(end.commit(0, -1, 0.0, state_at(set - 1e-9, 0.1, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "faces clear");
  REQUIRE(end.commit(0, -1, 0.0, state_at(set + 1e-9, 0.1, 1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "contact");
  CHECK(system.modes().as<CouplerEnd::State>(0).unloading);
}

TEST_CASE("coupler_end shear_load: the faces shear off at the stated force and carry nothing afterwards",
          "[elements][couplers]") {
  // Loading P = k delta reaches S at delta_s = S / k, at omega t = asin(omega delta_s / v)
  // after contact; then the mass flies on at sqrt(v^2 - (omega delta_s)^2). Lost: S^2 / 2k,
  // with either restitution (the energy the faces held is dissipated by the failure).
  const double m = 100.0, v = 2.0, gap = 0.03, omega = std::sqrt(kFaceStiffness / m);
  const double S = 0.6 * kFaceStiffness * v / omega, delta_s = S / kFaceStiffness;
  const double t_contact = gap / v, t_shear = t_contact + std::asin(omega * delta_s / v) / omega;
  const double v_after = std::sqrt(v * v - omega * omega * delta_s * delta_s), t_end = t_shear + 0.05;
  for (const char* e : {"1", "0.5"}) {
    for (const char* integrator : {"ida", "euler"}) {
      INFO("restitution " << e << ", " << integrator);
      const bool ida = std::string(integrator) == "ida";
      const LoadedModel loaded = testing::loaded_from_text(
          one_mass(coupler_end_yaml("    friction: 0.3\n    restitution: " + std::string(e) + "\n    shear_load: " + num(S) + "\n"),
                   m, kContact + gap, 0.0, -v, 0.0, t_end, integrator));
      const Model& model = loaded.model;
      DaeSystem system(model);
      const Run r = run(system, loaded.run_spec.simulation);
      // Euler sees the shear one step late: the force overshoots S by at most k v dt (0.36 here).
      check_events(r.outcome, {{"contact", t_contact, 0.0}, {"face shear failure", t_shear, S}}, ida ? 1e-8 : 3e-6,
                   ida ? 1e-9 : 1e-4);
      CHECK(r.vx == Approx(-v_after).epsilon(ida ? 1e-8 : 1e-4));
      CHECK(r.x == Approx(kContact - delta_s - v_after * (t_end - t_shear)).margin(ida ? 1e-9 : 1e-5));
      const double lost = 0.5 * S * S / kFaceStiffness;
      CHECK(dissipated(r.outcome) == Approx(lost).epsilon(ida ? 1e-7 : 2e-3));
      CHECK(element_work(r.outcome) == Approx(lost).epsilon(ida ? 1e-7 : 2e-3));
      // Sheared: no force in any direction, whatever the faces do.
      CouplerEnd& end = dynamic_cast<CouplerEnd&>(*model.elements()[0]);
      CHECK(system.modes().as<CouplerEnd::State>(0).sheared);
      std::vector<double> y = system.initial_state();
      y[0] = kContact - 0.05;
      y[4] = 0.5;
      std::array<Pose<double>, 2> f{};
      end.add_force(0.0, gather_state(end, y.data(), y.data() + 3, system.modes().of(0)), f);
      CHECK(f[1].x == 0.0);
      CHECK(f[1].y == 0.0);
      double g[CouplerEnd::kRoots];
      end.roots(0.0, gather_state(end, y.data(), y.data() + 3, system.modes().of(0)), nullptr, g);
      for (double value : g) CHECK(value > 0.0);
    }
  }
}

TEST_CASE("coupler_end restitution: Euler's stability estimate sees the unloading slope k / e^2", "[elements][couplers]") {
  const Model model =
      testing::model_from_text(one_mass(coupler_end_yaml("    restitution: 0.5\n"), 10.0, 0.5, 0.0, 0.0, 0.0, 1.0, "ida"));
  Element& e = *model.elements()[0];
  DaeSystem system(model);
  const std::vector<double> y = system.initial_state();
  ForceBlock stiffest{}, stiffest_v{};
  e.stiffest_force_jacobian(0.0, gather_state(e, y.data(), y.data() + 3, system.modes().of(0)), stiffest, stiffest_v);
  const auto x = static_cast<std::size_t>(3 * e.point_slot(1));
  CHECK(stiffest[x][x] == Approx(-4.0 * kFaceStiffness));
}

TEST_CASE("coupler_end with restitution and shear_load: Jacobian matches central differences in every mode",
          "[elements][couplers]") {
  using B = DeadBand::Mode;
  const std::vector<CouplerEnd::State> modes = {
      {B::Inside, true, false, false, 0.02, false},  // open, with a set
      {B::Below, true, false, false, 0.0, false},    // loading
      {B::Below, true, false, true, 0.02, false},    // unloading / reloading along k / e^2
      {B::Below, true, true, false, 0.02, false},    // blocked
      {B::Below, false, false, true, 0.02, false},   // overlap lost
      {B::Below, true, false, true, 0.02, true}};    // sheared
  for (const bool ground_first : {true, false}) {
    Model model = testing::model_from_text(
        two_bodies(coupler_end_yaml("    friction: 0.3\n    restitution: 0.6\n    shear_load: 1e9\n"), ground_first));
    DaeSystem system(model);
    std::mt19937 rng(11);
    for (std::size_t k = 0; k < modes.size(); ++k) {
      INFO((ground_first ? "ground-body" : "body-body") << ", mode " << k);
      testing::set_mode<CouplerEnd::State>(system, modes[k]);
      check_jacobian_here(system, rng);
    }
  }
}

// =================================================================================================
// coupling
// =================================================================================================

namespace {
const Curve kCouplingCurve{{0.0, 0.01, 0.05}, {0.0, 1.0e5, 3.0e5}};  // slopes 1e7, 5e6
std::string coupling_kind1(double factor, double slack, const std::string& extra = "") {
  return "    type: coupling\n    kind: 1\n    curve: " + table(kCouplingCurve) + "\n    unloading_factor: " + num(factor) +
         "\n    horizontal_slack: " + num(slack) + "\n" + extra;
}
Curve scaled(const Curve& c, double factor) {
  Curve out = c;
  for (double& y : out.y) y *= factor;
  return out;
}
}  // namespace

TEST_CASE("coupling kind 1: slack, loading curve, unloading at a fraction of it, closed form under both integrators",
          "[elements][couplers]") {
  const double m = 1000.0, v0 = 3.0, slack = 0.04, factor = 0.5;
  const Walker expected = coupling_bounce(kCouplingCurve, scaled(kCouplingCurve, factor), 1.0e7, slack, m, v0);
  const double speed = -expected.v;
  REQUIRE(0.5 * m * (v0 * v0 - speed * speed) == Approx(expected.loop_area()).epsilon(1e-12));
  const double t_end = expected.t + 0.5 * slack / speed;  // coasting back across the slack
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const bool ida = std::string(integrator) == "ida";
    const LoadedModel loaded = testing::loaded_from_text(one_mass(coupling_kind1(factor, slack), m, 1.0, 0.0, -v0, 0.0, t_end, integrator));
    const Run r = run(loaded);
    check_events(r.outcome, expected.events, ida ? 1e-8 : 3e-6, ida ? 1e-9 : 1e-5);
    CHECK(r.vx == Approx(speed).epsilon(ida ? 1e-8 : 1e-3));
    CHECK(element_work(r.outcome) == Approx(expected.loop_area()).epsilon(ida ? 1e-7 : 2e-3));
    CHECK(dissipated(r.outcome) == Approx(expected.loop_area()).epsilon(ida ? 1e-7 : 2e-3));
  }
}

TEST_CASE("coupling kind 2: separate loading and unloading curves, closed form", "[elements][couplers]") {
  const Curve loading{{0.0, 0.02}, {0.0, 2.0e5}};
  const Curve unloading{{0.0, 0.01, 0.02}, {0.0, 0.0, 1.0e5}};
  const Curve loading_on_union{{0.0, 0.01, 0.02}, {0.0, 1.0e5, 2.0e5}};
  const double m = 1000.0, v0 = 1.5, kt = 4.0e7, slack = 0.02;
  const Walker expected = coupling_bounce(loading_on_union, unloading, kt, slack, m, v0);
  const std::string element = "    type: coupling\n    kind: 2\n    loading_curve: " + table(loading) +
                              "\n    unloading_curve: " + table(unloading) + "\n    transition_stiffness: " + num(kt) +
                              "\n    horizontal_slack: " + num(slack) + "\n";
  const double t_end = expected.t + 0.5 * slack / -expected.v;
  const Run r = run(testing::loaded_from_text(one_mass(element, m, 1.0, 0.0, -v0, 0.0, t_end, "ida")));
  check_events(r.outcome, expected.events, 1e-8, 1e-9);
  CHECK(r.vx == Approx(-expected.v).epsilon(1e-8));
  CHECK(dissipated(r.outcome) == Approx(expected.loop_area()).epsilon(1e-7));
}

TEST_CASE("coupling without slack passes through zero force into draft", "[elements][couplers]") {
  // No slack: after the bounce in buff the force passes through zero at zero deflection and
  // the mass goes on into draft, where the mirror-image curve takes it: F = -1e7 u.
  const double m = 1000.0, v0 = 0.5, kt = 3.0e7, omega = std::sqrt(1.0e7 / m);
  const Walker expected = coupling_bounce(kCouplingCurve, scaled(kCouplingCurve, 0.5), kt, 0.0, m, v0);
  const double extra = 0.25 * (0.5 * kPi / omega);  // a quarter of the way to the draft extreme
  double x = 0.0, v = -expected.v;
  LinearPhase{m, 0.0, 1.0e7}.advance(x, v, extra);
  const std::string element = coupling_kind1(0.5, 0.0, "    transition_stiffness: " + num(kt) + "\n");
  const Run r = run(testing::loaded_from_text(one_mass(element, m, 1.0, 0.0, -v0, 0.0, expected.t + extra, "ida")));
  check_events(r.outcome, expected.events, 1e-8, 1e-9);
  CHECK(r.x == Approx(1.0 + x).epsilon(1e-9));
  CHECK(r.vx == Approx(v).epsilon(1e-7));
  // Work done: the loop area plus the draft loading so far. Stored: only what unloading from
  // here would give back (down the transition line to Lw = 0.5 U at xi, then along Lw).
  const double xi = (kt - 1.0e7) * x / (kt - 0.5e7);
  const double recoverable = 0.5 * (1.0e7 * x + 0.5e7 * xi) * (x - xi) + 0.5 * 0.5e7 * xi * xi;
  CHECK(element_work(r.outcome) == Approx(expected.loop_area() + 0.5 * 1.0e7 * x * x).epsilon(1e-7));
  CHECK(dissipated(r.outcome) == Approx(expected.loop_area() + 0.5 * 1.0e7 * x * x - recoverable).epsilon(1e-7));
}

TEST_CASE("coupling without slack, at rest at zero deflection: either direction engages its side", "[elements][couplers]") {
  // A constant load P from rest: x = (P / k1)(1 - cos w t) on the first segment (k1 = 1e7),
  // pulled into draft or pushed into buff; at a quarter period x = P / k1.
  const double m = 1000.0, P = 2.0e4, k1 = 1.0e7, omega = std::sqrt(k1 / m), T = 0.5 * kPi / omega;
  for (const double sign : {-1.0, 1.0}) {
    INFO((sign < 0 ? "pushed into buff" : "pulled into draft"));
    const std::string load = "loads:\n  - {type: force, body: mass, at: [0, 0], value: [" + num(sign * P) + ", 0]}\n";
    const Run r = run(testing::loaded_from_text(one_mass(coupling_kind1(0.5, 0.0), m, 1.0, 0.0, 0.0, 0.0, T, "ida", 1e-6, "SI", load)));
    REQUIRE(r.outcome.events.size() == 1);
    CHECK(r.outcome.events[0].what == (sign < 0 ? "back on the loading curve (buff)" : "through zero force to draft"));
    CHECK(r.outcome.events[0].t < 1e-4);
    CHECK(r.x == Approx(1.0 + sign * P / k1).epsilon(1e-9));
  }
}

TEST_CASE("coupling vertical: slack, flexibility and misalignment, with friction proportional to the horizontal force",
          "[elements][couplers]") {
  const double kv = 2.0e6, sv = 0.02, e = 0.004, mu = 0.25, vf = 0.01;
  const auto element = [&](double slack) {
    return coupling_kind1(0.5, slack,
                          "    vertical_slack: " + num(sv) + "\n    vertical_stiffness: " + num(kv) + "\n    misalignment: " +
                              num(e) + "\n    friction: " + num(mu) + "\n    friction_velocity: " + num(vf) + "\n");
  };
  SECTION("forces at given states") {
    // The mass at 1.0 - 0.004 (buff deflection 0.004 on the first segment), head L at Dy + e.
    const Model model = testing::model_from_text(one_mass(element(0.0), 1000.0, 1.0, 0.0, -0.1, 0.0, 1.0, "ida"));
    Coupling& c = dynamic_cast<Coupling&>(*model.elements()[0]);
    DaeSystem system(model);
    std::vector<double> y = system.initial_state();
    for (const double dy : {0.03, -0.03, 0.001}) {
      for (const double vy : {0.05, -0.004}) {
        y[0] = 1.0 - 0.004;
        y[1] = dy;
        y[4] = vy;
        const ElementState<double> s = gather_state(c, y.data(), y.data() + 3, system.modes().of(0));
        Coupling::State st = system.modes().as<Coupling::State>(0);
        st.horizontal = {AxialHysteresis::Mode::Loading, 1, 0, 0.0, 0.0};
        const double w = dy + e;
        st.vertical = w > 0.5 * sv ? DeadBand::Mode::Above : (w < -0.5 * sv ? DeadBand::Mode::Below : DeadBand::Mode::Inside);
        testing::set_mode<Coupling::State>(system, st);
        std::array<Pose<double>, 2> f{};
        c.add_force(0.0, s, f);
        const double horizontal = 1.0e7 * 0.004;
        const double vertical = w > 0.5 * sv ? kv * (w - 0.5 * sv) : (w < -0.5 * sv ? kv * (w + 0.5 * sv) : 0.0);
        const double friction = -mu * horizontal * std::tanh(vy / vf);
        INFO("dy " << dy << " vy " << vy);
        CHECK(f[1].x == Approx(horizontal));
        CHECK(f[1].y == Approx(-vertical + friction));
        CHECK(std::abs(friction) <= mu * horizontal);
        CHECK(c.potential_energy(s) == Approx(0.5 * 1.0e7 * 0.004 * 0.004 + 0.5 * vertical * vertical / kv));
      }
    }
  }
  SECTION("vertical slack taken up at the closed-form time, elastic vertical bounce") {
    // Horizontally in the slack (no horizontal force, so no friction); vertical speed 0.5 up.
    const double m = 100.0, vy = 0.5, y0 = 0.0;
    const double t_up = (0.5 * sv - (y0 + e)) / vy, half_period = kPi * std::sqrt(m / kv);
    const Run r = run(testing::loaded_from_text(one_mass(element(0.02), m, 1.0, y0, 0.0, vy, t_up + half_period + 0.01, "ida")));
    check_events(r.outcome,
                 {{"vertical slack taken up (head L above)", t_up, 0.5 * sv},
                  {"vertical slack", t_up + half_period, 0.5 * sv}},
                 1e-8, 1e-9);
    CHECK(r.vy == Approx(-vy).epsilon(1e-8));
  }
}

TEST_CASE("coupling Jacobian matches central differences in every mode", "[elements][couplers]") {
  using M = AxialHysteresis::Mode;
  using B = DeadBand::Mode;
  const std::vector<AxialHysteresis::State> horizontal = {
      {M::Open, 1, 0, 0.0, 0.0},         {M::Loading, 1, 0, 0.0, 0.0},     {M::Loading, -1, 1, 0.0, 0.0},
      {M::Transition, 1, 0, 0.03, 2e5},  {M::Unloading, -1, 1, 0.0, 0.0}, {M::Unloading, 1, 0, 0.0, 0.0}};
  for (const bool ground_first : {true, false}) {
    Model model = testing::model_from_text(two_bodies(
        coupling_kind1(0.5, 0.02,
                       "    vertical_slack: 0.01\n    vertical_stiffness: 2e6\n    misalignment: 0.003\n    friction: 0.3\n"
                       "    free_length: 1.0\n"),
        ground_first));
    DaeSystem system(model);
    std::mt19937 rng(13);
    for (const auto& h : horizontal)
      for (const B v : {B::Below, B::Inside, B::Above}) {
        INFO((ground_first ? "ground-body" : "body-body") << ", horizontal mode " << static_cast<int>(h.mode) << " side "
                                                          << h.side << ", vertical " << static_cast<int>(v));
        testing::set_mode<Coupling::State>(system, {h, v});
        check_jacobian_here(system, rng);
      }
  }
}

// =================================================================================================
// input errors
// =================================================================================================

TEST_CASE("coupler elements: input errors name the parameter and what to change", "[elements][couplers]") {
  const auto with = [](const std::string& element) { return one_mass(element, 10.0, 1.0, 0.0, 0.0, 0.0, 1.0, "ida"); };
  CHECK_THAT(error_of(with(gear_yaml({1e6, 0.05, 2e7, 2e4, 5e5}))), Catch::Contains("transition_stiffness"));
  CHECK_THAT(error_of(with(gear_yaml(kGear, "    post_shear_travel: 0.1\n"))), Catch::Contains("pin_shear_load"));
  CHECK_THAT(error_of(with("    type: draft_gear\n    initial_stiffness: 1e6\n    travel: 0\n"
                           "    stiffness_after_bottoming: 2e7\n    hysteresis_load: 2e4\n")),
             Catch::Contains("'travel' must be positive") && Catch::Contains("test.yaml:"));
  CHECK_THAT(error_of(with(gear_yaml(kGear, "    fracture_load: 1e4\n    free_length: 1.01\n"))),
             Catch::Contains("fracture_load"));  // starts compressed beyond it
  CHECK_THAT(error_of(with(coupler_end_yaml("    total_horizontal_slack: 0.1\n"))), Catch::Contains("coupled: true"));
  for (const char* e : {"0", "-0.2", "1.5"})
    CHECK_THAT(error_of(with(coupler_end_yaml("    restitution: " + std::string(e) + "\n"))),
               Catch::Contains("'restitution'") && Catch::Contains("at most 1") && Catch::Contains("test.yaml:"));
  CHECK_THAT(error_of(with(coupler_end_yaml("    restitution: 0.5\n    coupled: true\n"))),
             Catch::Contains("'restitution'") && Catch::Contains("coupled: false"));
  for (const char* load : {"0", "-5"})
    CHECK_THAT(error_of(with(coupler_end_yaml("    shear_load: " + std::string(load) + "\n"))), Catch::Contains("shear_load"));
  // Starts pressed 0.01 into the faces: 1800 > 1000.
  CHECK_THAT(error_of(one_mass(coupler_end_yaml("    shear_load: 1000\n"), 10.0, 0.09, 0.0, 0.0, 0.0, 1.0, "ida")),
             Catch::Contains("shear_load 1000") && Catch::Contains("coupler_end 'e'"));
  CHECK_THAT(error_of(with("    type: coupler_end\n    horizontal_stiffness: 3e5\n    free_length: [1, 1]\n"
                           "    coupler_height: [1, 1]\n")),
             Catch::Contains("horizontal_stiffness"));
  CHECK_THAT(error_of(with("    type: coupling\n    kind: 3\n")), Catch::Contains("'kind' must be 1"));
  CHECK_THAT(error_of(with("    type: coupling\n    curve: [[0, 0], [1, 5]]\n")), Catch::Contains("unloading_factor"));
  CHECK_THAT(error_of(with("    type: coupling\n    curve: [[0.1, 0], [1, 5]]\n    unloading_factor: 0.5\n")),
             Catch::Contains("must start at [0, 0]"));
  CHECK_THAT(error_of(with("    type: coupling\n    kind: 2\n    loading_curve: [[0, 0], [1, 5]]\n"
                           "    unloading_curve: [[0, 0], [1, 6]]\n")),
             Catch::Contains("must not lie above the loading curve"));
  CHECK_THAT(error_of(with("    type: coupling\n    kind: 2\n    curve: [[0, 0], [1, 5]]\n")), Catch::Contains("kind 2 takes"));
  CHECK_THAT(error_of(with(coupling_kind1(0.5, 0.0, "    transition_stiffness: 1e3\n"))),
             Catch::Contains("steepest slope"));
}
