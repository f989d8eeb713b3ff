// Type 1 anticlimber: parameters, force laws against hand computations, energy consistency,
// Jacobians in every mode, and runs under both integrators against closed-form impacts
// (contact time, elastic-plastic crush and rebound, shear / bending / crushing failure,
// override).
#include <catch2/catch.hpp>

#include <cmath>
#include <iomanip>
#include <iterator>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "railcrash/elements/anticlimber.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/stability_limit.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

const double kPi = std::acos(-1.0);

// ---- model text ----------------------------------------------------------------------------

struct LawValues {
  double elastic, plastic, yield;
  std::optional<double> rupture;
  double yield_force() const { return elastic * yield; }
};

/// The test anticlimber (SI). Defaults: no ruptures, faces 0.2 m tall.
struct Parameters {
  LawValues horizontal{1e6, 1e4, 0.01, std::nullopt};
  LawValues vertical{2e5, 2e3, 0.02, std::nullopt};
  LawValues torsional{1e4, 1e2, 0.01, std::nullopt};
  double face_height = 0.2;
  double misalignment = 0.0;
  std::string misalignment_geometry;  // empty: not given (face)
  std::optional<double> facing;
  std::optional<double> length;
  std::string interlock;  // interlock_while_unloading; empty: not given (hold)
};

std::string number(double x) {
  std::ostringstream s;
  s << std::setprecision(17) << x;
  return s.str();
}

std::string law_yaml(const std::string& direction, const LawValues& law) {
  std::string s = "    " + direction + "_elastic_stiffness: " + number(law.elastic) + "\n" + "    " + direction +
                  "_plastic_stiffness: " + number(law.plastic) + "\n" + "    " + direction +
                  "_yield_deflection: " + number(law.yield) + "\n";
  if (law.rupture) s += "    " + direction + "_rupture_deflection: " + number(*law.rupture) + "\n";
  return s;
}

std::string parameters_yaml(const Parameters& p) {
  std::string s = law_yaml("horizontal", p.horizontal) + law_yaml("vertical", p.vertical) + law_yaml("torsional", p.torsional);
  s += "    face_height: " + number(p.face_height) + "\n";
  if (p.misalignment != 0.0) s += "    initial_misalignment: " + number(p.misalignment) + "\n";
  if (!p.misalignment_geometry.empty()) s += "    misalignment_geometry: " + p.misalignment_geometry + "\n";
  if (p.facing) s += "    facing: " + number(*p.facing) + "\n";
  if (p.length) s += "    length: " + number(*p.length) + "\n";
  if (!p.interlock.empty()) s += "    interlock_while_unloading: " + p.interlock + "\n";
  return s;
}

/// A body line for the bodies section.
struct BodySpec {
  std::string name;
  double mass, inertia, x, y, angle, vx, vy, omega;
};

std::string body_yaml(const BodySpec& b) {
  return "  - {name: " + b.name + ", mass: " + number(b.mass) + ", inertia: " + number(b.inertia) + ", position: [" +
         number(b.x) + ", " + number(b.y) + "], angle: " + number(b.angle) + ", velocity: [" + number(b.vx) + ", " +
         number(b.vy) + "], angular_velocity: " + number(b.omega) + "}\n";
}

struct Point {
  std::string body;
  double sx, sy;
};

/// A model with bodies, one anticlimber `ac` between points p1 and p2, extra element / load
/// YAML and simulation settings.
std::string model_yaml(const std::vector<BodySpec>& bodies, const Parameters& parameters, const Point& p1, const Point& p2,
                       const std::string& simulation, const std::string& extra_elements = "",
                       const std::string& loads = "") {
  std::string s = "railcrash: 1\nname: anticlimber test\nunits: SI\ngravity: [0, 0]\nbodies:\n";
  for (const BodySpec& b : bodies) s += body_yaml(b);
  s += "elements:\n  - name: ac\n    type: anticlimber\n" + parameters_yaml(parameters) + "    points: [{body: " + p1.body +
       ", at: [" + number(p1.sx) + ", " + number(p1.sy) + "]}, {body: " + p2.body + ", at: [" + number(p2.sx) + ", " +
       number(p2.sy) + "]}]\n" + extra_elements;
  if (!loads.empty()) s += "loads:\n" + loads;
  s += "simulation: {" + simulation + "}\n";
  return s;
}

Anticlimber& anticlimber_of(const Model& model) { return dynamic_cast<Anticlimber&>(*model.elements().front()); }

// ---- running -------------------------------------------------------------------------------

struct Samples : RunObserver {
  std::vector<double> t;
  std::vector<std::vector<double>> y;
  void sample(double time, const double* state, const double*, const double*, const double*) override {
    t.push_back(time);
    y.emplace_back(state, state + size);
  }
  int size = 0;
};

struct Run {
  RunOutcome outcome;
  Samples samples;
  Anticlimber::State final_mode;  // the anticlimber's (the model's first element) at the end
};

Run simulate(const LoadedModel& loaded) {
  DaeSystem system(loaded.model);
  Run run;
  run.samples.size = system.size();
  const SimulationSettings& simulation = loaded.run_spec.simulation;
  auto integrator = make_integrator(system, simulation);
  run.outcome = integrator->run(simulation.t_end, output_interval_of(simulation), run.samples);
  INFO(run.outcome.message);
  REQUIRE(run.outcome.ok);
  run.final_mode = system.modes().as<Anticlimber::State>(0);
  return run;
}

/// The n-th (1-based) event whose text is exactly `what`, or nullptr.
const EventRecord* find_event(const RunOutcome& outcome, const std::string& what, int occurrence = 1) {
  for (const EventRecord& e : outcome.events)
    if (e.what == what && --occurrence == 0) return &e;
  return nullptr;
}

std::string event_list(const RunOutcome& outcome) {
  std::ostringstream s;
  for (const EventRecord& e : outcome.events) s << std::setprecision(12) << e.t << " " << e.what << " " << e.value << "\n";
  return s.str();
}

/// Work done on the element `index` over the run.
double element_work(const RunOutcome& outcome, int index = 0) {
  return outcome.quadratures[static_cast<std::size_t>(DaeSystem::kFirstElementWork + index)];
}

/// Work to deform a bilinear law monotonically from 0 to d (d >= yield).
double bilinear_work(const LawValues& law, double d) {
  const double plastic = d - law.yield;
  return 0.5 * law.yield_force() * law.yield + law.yield_force() * plastic + 0.5 * law.plastic * plastic * plastic;
}

// ---- closed form: a mass m hits a rigid wall through the horizontal law -----------------------

struct Crush {
  double yield_time;    // after contact
  double peak_time;     // after contact: unloading
  double separation_time;
  double max_crush, peak_force, permanent_crush, rebound_speed, dissipated;
};

Crush crush_of(const LawValues& law, double mass, double speed) {
  Crush c;
  const double omega = std::sqrt(law.elastic / mass), omega_p = std::sqrt(law.plastic / mass);
  REQUIRE(speed / omega > law.yield);  // it does yield
  // Elastic: d = (u0/w) sin(w t).
  c.yield_time = std::asin(law.yield * omega / speed) / omega;
  const double speed_at_yield = std::sqrt(speed * speed - omega * omega * law.yield * law.yield);
  // Plastic: x = d - d_y, m x'' = -(F_y + k_p x): x = a (cos w_p t - 1) + (u_y / w_p) sin w_p t, a = F_y / k_p.
  const double a = law.yield_force() / law.plastic;
  c.peak_time = c.yield_time + std::atan2(speed_at_yield, omega_p * a) / omega_p;
  const double x_max = std::hypot(a, speed_at_yield / omega_p) - a;
  c.max_crush = law.yield + x_max;
  c.peak_force = law.yield_force() + law.plastic * x_max;
  c.permanent_crush = c.max_crush - c.peak_force / law.elastic;
  // Elastic rebound: a quarter period back to zero force.
  c.separation_time = c.peak_time + kPi / (2.0 * omega);
  c.rebound_speed = c.peak_force / std::sqrt(law.elastic * mass);
  c.dissipated = 0.5 * mass * (speed * speed - c.rebound_speed * c.rebound_speed);
  return c;
}

// ---- hand kinematics for the force checks ------------------------------------------------------

struct Vec {
  double x, y;
};
Vec rotated(double angle, double sx, double sy) {
  return {std::cos(angle) * sx - std::sin(angle) * sy, std::sin(angle) * sx + std::cos(angle) * sy};
}

/// Generalized forces of the element alone at body coordinates q (velocities zero).
std::vector<double> element_forces(const DaeSystem& system, const std::vector<double>& q) {
  const Element& e = *system.model().elements().front();
  const std::vector<double> v(q.size(), 0.0);
  const ElementState<double> s = gather_state(e, q.data(), v.data(), system.modes().of(0));
  std::array<Pose<double>, 2> f{};
  e.add_force(0.0, s, f);
  std::vector<double> out(q.size(), 0.0);
  for (int k = 0; k < 2; ++k) {
    const int body = e.slot_body(k);
    if (body == kGround) continue;
    out[static_cast<std::size_t>(3 * body)] += f[static_cast<std::size_t>(k)].x;
    out[static_cast<std::size_t>(3 * body + 1)] += f[static_cast<std::size_t>(k)].y;
    out[static_cast<std::size_t>(3 * body + 2)] += f[static_cast<std::size_t>(k)].theta;
  }
  return out;
}

double energy_at(const DaeSystem& system, const std::vector<double>& q) {
  const Element& e = *system.model().elements().front();
  const std::vector<double> v(q.size(), 0.0);
  return e.potential_energy(gather_state(e, q.data(), v.data(), system.modes().of(0)));
}

std::vector<double> positions(const DaeSystem& system, const std::vector<double>& y) {
  return {y.begin(), y.begin() + system.body_unknowns()};
}

std::vector<double> element_outputs(const DaeSystem& system, const std::vector<double>& y) {
  std::vector<double> out(system.output_names().size(), 0.0);
  system.outputs(y.data(), y.data() + 2 * system.body_unknowns(), out.data());
  return out;
}

using Mode = ElasticPlasticLaw::Mode;

/// A law state in a given mode with a plastic offset (elastic range consistent with it).
ElasticPlasticLaw::State law_state(const ElasticPlasticLaw& law, Mode mode, double offset) {
  ElasticPlasticLaw::State st = law.fresh();
  st.mode = mode;
  st.offset = offset;
  const double shift = law.elastic_stiffness * offset / (law.elastic_stiffness - law.plastic_stiffness);
  st.upper = law.yield_deflection + shift;
  st.lower = law.one_sided ? offset : -law.yield_deflection + shift;
  return st;
}

/// Jacobian against finite differences at random states near the start, in the element's
/// current mode.
void check_jacobian_near_start(const DaeSystem& system, std::mt19937& rng) {
  for (int trial = 0; trial < 3; ++trial) {
    const std::vector<double> y = testing::random_state(system, rng, 0.05);
    const std::vector<double> yp = testing::random_state(system, rng, 0.05);
    double outside = -1.0;
    CHECK(testing::jacobian_error(system, 0.1, 30.0 * (trial + 1), y, yp, &outside) < 1e-6);
    CHECK(outside == 0.0);
  }
}

// Two cars: body 1 turned by 0.15 rad, body 2 by -0.1 rad; face points away from the centres.
const Point kCar1Face{"car1", 0.6, -0.1};
const Point kCar2Face{"car2", -0.7, 0.05};
std::vector<BodySpec> two_cars() {
  return {{"car1", 50.0, 4.0, 0.0, 0.0, 0.15, 0.3, -0.1, 0.05}, {"car2", 70.0, 6.0, 1.45, 0.3, -0.1, -0.2, 0.1, -0.04}};
}

}  // namespace

// ---- parameters ------------------------------------------------------------------------------

TEST_CASE("anticlimber reads the report's Table 5 values and gives their yield forces", "[elements][anticlimber]") {
  // Report Table 5 / 8 as read in anticlimber.hpp (in-lbf-s): vertical 175,000 lb/in, 1633 lb/in,
  // 0.20 in, 5 in; horizontal 4,450,000 lb/in, 20,620 lb/in, 0.053 in, 56 in; torsional
  // 110,800 in-lb/rad, 25,500 in-lb/rad, 0.001 rad, 1 rad; face height 6 in, length 58.125 in.
  const std::string text =
      "railcrash: 1\nname: table 5\nunits: in-lbf-s\ngravity: [0, 0]\nbodies:\n"
      "  - {name: a, weight: 6180, inertia: 4000, position: [0, 0]}\n"
      "  - {name: b, weight: 6180, inertia: 4000, position: [100, 0]}\n"
      "elements:\n  - name: ac\n    type: anticlimber\n"
      "    vertical_elastic_stiffness: 175000\n    vertical_plastic_stiffness: 1633\n"
      "    vertical_yield_deflection: 0.20\n    vertical_rupture_deflection: 5\n"
      "    horizontal_elastic_stiffness: 4450000\n    horizontal_plastic_stiffness: 20620\n"
      "    horizontal_yield_deflection: 0.053\n    horizontal_rupture_deflection: 56\n"
      "    torsional_elastic_stiffness: 110800\n    torsional_plastic_stiffness: 25500\n"
      "    torsional_yield_deflection: 0.001\n    torsional_rupture_deflection: 1\n"
      "    face_height: 6\n    length: 58.125\n"
      "    points: [{body: a, at: [17.5, -11.9]}, {body: b, at: [-17.5, -11.9]}]\n"
      "simulation: {t_end: 0.1}\n";
  const Model model = testing::model_from_text(text);
  const Anticlimber& ac = anticlimber_of(model);
  CHECK(ac.vertical_yield_force() == Approx(35000.0).epsilon(1e-12));  // 175,000 lb/in x 0.20 in
  CHECK(ac.horizontal.yield_force() == Approx(235850.0).epsilon(1e-12));  // 4,450,000 lb/in x 0.053 in
  CHECK(ac.torsional.yield_force() == Approx(110.8).epsilon(1e-12));  // 110,800 in-lb/rad x 0.001 rad
  CHECK(*ac.horizontal.rupture_deflection == 56.0);
  CHECK(*ac.vertical.rupture_deflection == 5.0);
  CHECK(*ac.torsional.rupture_deflection == 1.0);
  CHECK(ac.vertical.plastic_stiffness == 1633.0);
  CHECK(ac.face_height == 6.0);
  CHECK(*ac.length == 58.125);
  CHECK(*ac.facing == 1.0);  // b lies ahead of a along a's x axis
  CHECK(ac.horizontal.one_sided);
  CHECK_FALSE(ac.vertical.one_sided);
}

TEST_CASE("anticlimber rejects bad parameters and starting configurations", "[elements][anticlimber]") {
  const std::vector<BodySpec> bodies{{"b", 1.0, 1.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0}};
  const Point ground{"ground", 0.0, 0.0}, body{"b", 0.0, 0.0};
  const auto load = [&](const Parameters& p, const Point& p1 = Point{"ground", 0.0, 0.0}, const Point& p2 = Point{"b", 0.0, 0.0},
                        const std::vector<BodySpec>& b = {}) {
    return testing::model_from_text(model_yaml(b.empty() ? bodies : b, p, p1, p2, "t_end: 1"));
  };
  Parameters good;
  CHECK_NOTHROW(load(good));
  {
    Parameters p;
    p.horizontal.plastic = p.horizontal.elastic;
    CHECK_THROWS_WITH(load(p), Catch::Contains("horizontal_plastic_stiffness") && Catch::Contains("below"));
  }
  {
    Parameters p;
    p.vertical.rupture = p.vertical.yield;
    CHECK_THROWS_WITH(load(p), Catch::Contains("vertical_rupture_deflection") && Catch::Contains("exceed"));
  }
  {
    Parameters p;
    p.torsional.yield = 0.0;
    CHECK_THROWS_WITH(load(p), Catch::Contains("torsional_yield_deflection") && Catch::Contains("positive"));
  }
  {
    Parameters p;
    p.facing = 0.5;
    CHECK_THROWS_WITH(load(p), Catch::Contains("facing"));
  }
  {
    Parameters p;
    p.length = 0.3;
    p.horizontal.rupture = 0.5;
    CHECK_THROWS_WITH(load(p), Catch::Contains("horizontal_rupture_deflection") && Catch::Contains("length"));
  }
  {
    Parameters p;
    p.length = 0.3;  // without a horizontal rupture deflection: crushed through over the length
    const Model model = load(p);
    CHECK(*anticlimber_of(model).horizontal.rupture_deflection == 0.3);
  }
  {
    std::string text = model_yaml(bodies, good, ground, body, "t_end: 1");
    text.replace(text.find("    face_height"), text.find('\n', text.find("    face_height")) - text.find("    face_height") + 1, "");
    CHECK_THROWS_WITH(testing::model_from_text(text), Catch::Contains("face_height"));
  }
  CHECK_THROWS_WITH(load(good, Point{"b", 0.0, 0.0}, Point{"b", 0.2, 0.0}), Catch::Contains("same body"));
  // Faces overlapping at the start (facing given, body behind the face).
  {
    Parameters p;
    p.facing = -1.0;
    CHECK_THROWS_WITH(load(p), Catch::Contains("overlap"));
  }
  // Touching at the start: which way they face must be given.
  const std::vector<BodySpec> touching{{"b", 1.0, 1.0, 0.0, 0.05, 0.0, -1.0, 0.0, 0.0}};
  CHECK_THROWS_WITH(load(good, ground, body, touching), Catch::Contains("facing"));
  Parameters faced;
  faced.facing = 1.0;
  const Model engaged = load(faced, ground, body, touching);  // closing at 1 m/s: engaged from the start
  CHECK(DaeSystem(engaged).modes().as<Anticlimber::State>(0).contact == Anticlimber::Contact::Engaged);
  const std::vector<BodySpec> touching_still{{"b", 1.0, 1.0, 0.0, 0.05, 0.0, 0.0, 0.0, 0.0}};
  const Model open = load(faced, ground, body, touching_still);
  CHECK(DaeSystem(open).modes().as<Anticlimber::State>(0).contact == Anticlimber::Contact::Open);
}

// ---- the elastic-plastic law on its own -------------------------------------------------------

namespace {

/// Moves a law's deformation monotonically from d to `to`, leaving modes at their boundaries
/// (found exactly: the elastic range ends, the rupture deflection), and returns the work
/// done, the integral of F dd (exact: F is linear between boundaries). It stops early at a
/// release or a rupture. Reversing afterwards is the caller's leave() through the rate root.
double drive(const ElasticPlasticLaw& law, ElasticPlasticLaw::State& st, double& d, double to,
             std::vector<ElasticPlasticLaw::Outcome>& outcomes) {
  double work = 0.0;
  const double sign = to > d ? 1.0 : -1.0;
  while (sign * (to - d) > 0.0) {
    double next = to;
    int index = -1;
    if (st.mode == Mode::Elastic && sign > 0.0 && st.upper < next) next = st.upper, index = 0;
    if (st.mode == Mode::Elastic && sign < 0.0 && st.lower > next) next = st.lower, index = 1;
    if (law.rupture_deflection && st.mode != Mode::Failed && std::abs(next) > *law.rupture_deflection)
      next = sign * *law.rupture_deflection, index = 2;
    work += 0.5 * (law.force(st, d) + law.force(st, next)) * (next - d);
    d = next;
    if (index < 0) break;
    double g[3];
    law.roots(st, d, sign, g);
    CHECK(g[index] == Approx(0.0).margin(1e-15));  // the root marks this boundary
    REQUIRE(law.active(st, index));
    outcomes.push_back(law.leave(st, index, d));
    if (outcomes.back() == ElasticPlasticLaw::Outcome::Release || outcomes.back() == ElasticPlasticLaw::Outcome::Rupture)
      break;  // the faces let go: stop here
  }
  return work;
}

}  // namespace

TEST_CASE("anticlimber elastic-plastic law: bilinear loading, kinematic hardening loops, release and rupture",
          "[elements][anticlimber]") {
  using Outcome = ElasticPlasticLaw::Outcome;
  ElasticPlasticLaw law;
  law.elastic_stiffness = 2e5;
  law.plastic_stiffness = 2e3;
  law.yield_deflection = 0.02;
  const double ke = 2e5, kp = 2e3, dy = 0.02, fy = 4000.0, amplitude = 0.08;
  SECTION("two-sided cycles between +-D") {
    ElasticPlasticLaw::State st = law.fresh();
    double d = 0.0;
    std::vector<Outcome> outcomes;
    // 0 -> D: the bilinear curve.
    const double first = drive(law, st, d, amplitude, outcomes);
    CHECK(first == Approx(0.5 * fy * dy + fy * (amplitude - dy) + 0.5 * kp * std::pow(amplitude - dy, 2)).epsilon(1e-12));
    CHECK(law.force(st, d) == Approx(fy + kp * (amplitude - dy)).epsilon(1e-12));
    // Turn: unloading through the rate root, then D -> -D -> D.
    double g[3];
    law.roots(st, d, 0.0, g);
    CHECK(g[0] == 0.0);
    outcomes.push_back(law.leave(st, 0, d));
    const double peak = law.force(st, d);
    CHECK(peak == Approx(fy + kp * (amplitude - dy)).epsilon(1e-12));  // no jump at unloading
    CHECK(st.upper == amplitude);
    CHECK(st.lower == Approx(amplitude - 2 * dy).epsilon(1e-12));
    CHECK(st.offset == Approx(amplitude - peak / ke).epsilon(1e-12));
    // Down: elastic over 2 d_y (the force drops by 2 F_y: kinematic hardening), then plastic
    // flow down the lower line to -D, where the motion turns again.
    double loop = drive(law, st, d, -amplitude, outcomes);
    outcomes.push_back(law.leave(st, 1, d));
    CHECK(law.force(st, d) == Approx(-fy - kp * (amplitude - dy)).epsilon(1e-12));
    loop += drive(law, st, d, amplitude, outcomes);
    // Closed form: a parallelogram of area 4 (D - d_y) d_y (k_e - k_p).
    CHECK(loop == Approx(4.0 * (amplitude - dy) * dy * (ke - kp)).epsilon(1e-12));
    CHECK(law.force(st, d) == Approx(peak).epsilon(1e-12));  // back at the same point of the upper line
    const std::vector<Outcome> expected{Outcome::Yield,     Outcome::Unloading, Outcome::Reloading,
                                        Outcome::Unloading, Outcome::Reloading};
    CHECK(outcomes == expected);
  }
  SECTION("one-sided (horizontal): unloading ends in a release at the permanent deformation") {
    law.one_sided = true;
    ElasticPlasticLaw::State st = law.fresh();
    CHECK(st.lower == 0.0);
    double d = 0.0;
    std::vector<Outcome> outcomes;
    const double in = drive(law, st, d, amplitude, outcomes);
    outcomes.push_back(law.leave(st, 0, d));
    const double out = drive(law, st, d, -1.0, outcomes);
    REQUIRE(outcomes.back() == Outcome::Release);
    const double peak = fy + kp * (amplitude - dy);
    CHECK(d == Approx(amplitude - peak / ke).epsilon(1e-12));
    CHECK(in + out == Approx(in - peak * peak / (2.0 * ke)).epsilon(1e-12));  // the elastic energy comes back
    CHECK(law.force(st, d) == Approx(0.0).margin(1e-9));
  }
  SECTION("past an end of the elastic range but moving back is no crossing, at rest the position decides") {
    // The constraints' position correction moves a deflection without its rate (hybrid.hpp,
    // position_root_moving_on): yield, reloading and release are crossed only moving on.
    const ElasticPlasticLaw::State st = law.fresh();
    const double past = 1e-6 * dy;
    double g[3];
    law.roots(st, dy + past, -1e-9, g);  // past the upper yield point, moving down
    CHECK(g[0] > 0.0);
    law.roots(st, dy + past, 1e-3, g);   // moving up
    CHECK(g[0] == Approx(-past).margin(1e-15));
    law.roots(st, dy + past, 0.0, g);    // at rest
    CHECK(g[0] == Approx(-past).margin(1e-15));
    law.roots(st, -dy - past, 1e-9, g);  // past the lower yield point, moving up
    CHECK(g[1] > 0.0);
    law.roots(st, -dy - past, -1e-3, g);
    CHECK(g[1] == Approx(-past).margin(1e-15));
    // One-sided: the release at the permanent deformation, only while the faces open.
    law.one_sided = true;
    ElasticPlasticLaw::State one = law.fresh();
    one.offset = one.lower = 0.01;
    one.upper = 0.05;
    law.roots(one, 0.01 - past, 1e-9, g);
    CHECK(g[1] > 0.0);
    law.roots(one, 0.01 - past, -1e-3, g);
    CHECK(g[1] < 0.0);
    law.one_sided = false;
  }
  SECTION("rupture at the rupture deflection, in either direction") {
    for (const double sign : {1.0, -1.0}) {
      law.rupture_deflection = 0.05;
      ElasticPlasticLaw::State st = law.fresh();
      double d = 0.0;
      std::vector<Outcome> outcomes;
      drive(law, st, d, sign * amplitude, outcomes);
      CHECK(outcomes == std::vector<Outcome>{Outcome::Yield, Outcome::Rupture});
      CHECK(d == Approx(sign * 0.05).epsilon(1e-15));
      CHECK(st.mode == Mode::Failed);
      CHECK(law.force(st, 0.3) == 0.0);
      for (int i = 0; i < 3; ++i) CHECK_FALSE(law.active(st, i));
    }
  }
}

// ---- force laws ----------------------------------------------------------------------------

TEST_CASE("anticlimber applies no force while open, after override and once crushed", "[elements][anticlimber]") {
  const Model model =
      testing::model_from_text(model_yaml(two_cars(), Parameters{}, kCar1Face, kCar2Face, "t_end: 1"));
  DaeSystem system(model);
  Anticlimber& ac = anticlimber_of(model);
  REQUIRE(system.modes().as<Anticlimber::State>(0).contact == Anticlimber::Contact::Open);
  std::mt19937 rng(7);
  for (const Anticlimber::Contact contact :
       {Anticlimber::Contact::Open, Anticlimber::Contact::Overridden, Anticlimber::Contact::Crushed}) {
    Anticlimber::State st = system.modes().as<Anticlimber::State>(0);
    st.contact = contact;
    testing::set_mode<Anticlimber::State>(system, st);
    for (int trial = 0; trial < 5; ++trial) {
      // Random states, also ones where the faces are pressed together (gap < 0).
      const std::vector<double> y = testing::random_state(system, rng, 0.4);
      for (double f : element_forces(system, positions(system, y))) CHECK(f == 0.0);
      CHECK(ac.potential_energy(gather_state(ac, y.data(), y.data() + 6, system.modes().of(0))) == 0.0);
      const std::vector<double> out = element_outputs(system, y);
      CHECK(out[0] == 0.0);
      CHECK(out[1] == 0.0);
      CHECK(out[2] == 0.0);
      CHECK(out[7] == (contact == Anticlimber::Contact::Overridden ? 1.0 : 0.0));
    }
  }
}

TEST_CASE("anticlimber forces follow the three laws at a known configuration", "[elements][anticlimber]") {
  // Ground face at (0, 0) looking along +x; the car's point 0.5 m behind its centre (and 0.02 m
  // above), its face 0.01 m above that (initial_misalignment, misalignment_geometry: face): the
  // face centre is (-0.5, 0.03) in the car's frame, where the forces act. The car is then put at
  // (0.47, 0.13), turned by 0.02 rad, pressed into the face.
  const std::vector<BodySpec> bodies{{"b", 10.0, 1.0, 0.6, 0.0, 0.0, 0.0, 0.0, 0.0}};
  Parameters p;
  p.misalignment = 0.01;
  const Model model =
      testing::model_from_text(model_yaml(bodies, p, Point{"ground", 0.0, 0.0}, Point{"b", -0.5, 0.02}, "t_end: 1"));
  DaeSystem system(model);
  Anticlimber& ac = anticlimber_of(model);
  // Engaged at v_e = 0.03, phi_e = 0.005; horizontal plastic, vertical elastic with offset
  // 0.004, torsional plastic downwards.
  Anticlimber::State st = system.modes().as<Anticlimber::State>(0);
  st.contact = Anticlimber::Contact::Engaged;
  st.vertical_reference = 0.03;
  st.torsional_reference = 0.005;
  st.horizontal = law_state(ac.horizontal, Mode::PlasticUp, 0.0);
  st.vertical = law_state(ac.vertical, Mode::Elastic, 0.004);
  st.torsional = law_state(ac.torsional, Mode::PlasticDown, 0.0);
  testing::set_mode<Anticlimber::State>(system, st);

  const double x = 0.47, y = 0.13, theta = 0.02;
  const Vec arm = rotated(theta, -0.5, 0.02 + 0.01);  // to the face centre (point + misalignment)
  const Vec r2{x + arm.x, y + arm.y};
  const double d_h = -r2.x;               // gap = r2 . (1, 0)
  const double v = r2.y;                  // the face centre's height
  REQUIRE(d_h > 0.01);                    // beyond the horizontal yield deflection
  const double h = 1e4 + 1e4 * (d_h - 0.01);                      // F_y + k_p (d - d_y)
  const double vf = 2e5 * ((v - 0.03) - 0.004);                    // k_e (d_v - p)
  const double m = -100.0 + 1e2 * ((theta - 0.005) + 0.01);       // -F_y + k_p (d + d_y)
  // Force on the car at its face: (H, -V); moment arm x F, minus the torsional moment.
  const double fx = h, fy = -vf;
  const std::vector<double> expected{fx, fy, arm.x * fy - arm.y * fx - m};
  const std::vector<double> actual = element_forces(system, {x, y, theta});
  for (std::size_t k = 0; k < 3; ++k) {
    INFO("component " << k);
    CHECK(actual[k] == Approx(expected[k]).epsilon(1e-12).margin(1e-9));
  }
  // Outputs at the same state.
  std::vector<double> state = system.initial_state();
  state[0] = x;
  state[1] = y;
  state[2] = theta;
  CHECK(system.output_names() ==
        std::vector<std::string>{"ac.horizontal_force", "ac.vertical_force", "ac.moment", "ac.horizontal_deformation",
                                 "ac.vertical_deformation", "ac.torsional_deformation", "ac.vertical_offset",
                                 "ac.override"});
  const std::vector<double> out = element_outputs(system, state);
  CHECK(out[0] == Approx(h).epsilon(1e-12));
  CHECK(out[1] == Approx(vf).epsilon(1e-12));
  CHECK(out[2] == Approx(m).epsilon(1e-12));
  CHECK(out[3] == Approx(d_h).epsilon(1e-12));
  CHECK(out[4] == Approx(v - 0.03).epsilon(1e-12));
  CHECK(out[5] == Approx(theta - 0.005).epsilon(1e-12));
  CHECK(out[6] == Approx(v).epsilon(1e-12));
  CHECK(out[7] == 0.0);
  // Elastic energy: each law's F^2 / (2 k_e).
  CHECK(ac.potential_energy(gather_state(ac, state.data(), state.data() + 3, system.modes().of(0))) ==
        Approx(h * h / 2e6 + vf * vf / 4e5 + m * m / 2e4).epsilon(1e-12));
}

TEST_CASE("anticlimber forces are minus the gradient of the elastic energy and conserve momentum",
          "[elements][anticlimber]") {
  for (const double facing : {1.0, -1.0}) {
    INFO("facing " << facing);
    // facing -1: car 2 behind car 1's face point along car 1's axis.
    std::vector<BodySpec> bodies = two_cars();
    if (facing < 0.0) bodies[1].x = -1.45;
    const Point p2{"car2", facing > 0.0 ? -0.7 : 0.7, 0.05};
    const Point p1{"car1", facing > 0.0 ? 0.6 : -0.6, -0.1};
    const Model model = testing::model_from_text(model_yaml(bodies, Parameters{}, p1, p2, "t_end: 1"));
    DaeSystem system(model);
    Anticlimber& ac = anticlimber_of(model);
    REQUIRE(*ac.facing == facing);
    // Engaged, all three laws elastic with plastic offsets: there U is the potential of the forces.
    Anticlimber::State st = system.modes().as<Anticlimber::State>(0);
    st.contact = Anticlimber::Contact::Engaged;
    st.vertical_reference = 0.25;
    st.torsional_reference = -0.2;
    st.horizontal = law_state(ac.horizontal, Mode::Elastic, -0.08);
    st.vertical = law_state(ac.vertical, Mode::Elastic, 0.01);
    st.torsional = law_state(ac.torsional, Mode::Elastic, -0.02);
    testing::set_mode<Anticlimber::State>(system, st);
    std::mt19937 rng(11);
    for (int trial = 0; trial < 4; ++trial) {
      const std::vector<double> q = positions(system, testing::random_state(system, rng, 0.1));
      REQUIRE(energy_at(system, q) > 1.0);  // deformed: the check is not vacuous
      const std::vector<double> f = element_forces(system, q);
      for (std::size_t k = 0; k < q.size(); ++k) {
        const double step = 1e-6;
        std::vector<double> plus = q, minus = q;
        plus[k] += step;
        minus[k] -= step;
        const double gradient = (energy_at(system, plus) - energy_at(system, minus)) / (2.0 * step);
        INFO("trial " << trial << " component " << k);
        CHECK(f[k] == Approx(-gradient).epsilon(1e-6).margin(1e-4));
      }
      // Momentum: forces sum to zero; angular momentum: moments about the origin sum to zero.
      CHECK(f[0] + f[3] == Approx(0.0).margin(1e-8));
      CHECK(f[1] + f[4] == Approx(0.0).margin(1e-8));
      const double moment = (q[0] * f[1] - q[1] * f[0] + f[2]) + (q[3] * f[4] - q[4] * f[3] + f[5]);
      CHECK(moment == Approx(0.0).margin(1e-7));
    }
  }
}

TEST_CASE("anticlimber Jacobian matches finite differences in every mode", "[elements][anticlimber]") {
  const Mode law_modes[] = {Mode::Elastic, Mode::PlasticUp, Mode::PlasticDown, Mode::Failed};
  struct Layout {
    const char* name;
    std::vector<BodySpec> bodies;
    Point p1, p2;
  };
  const Layout layouts[] = {
      {"two cars", two_cars(), kCar1Face, kCar2Face},
      {"ground and car", {{"car2", 70.0, 6.0, 1.45, 0.3, -0.1, -0.2, 0.1, -0.04}}, Point{"ground", 0.6, -0.1}, kCar2Face},
      {"car and ground", {{"car1", 50.0, 4.0, 0.0, 0.0, 0.15, 0.3, -0.1, 0.05}}, kCar1Face, Point{"ground", 1.45, 0.3}},
  };
  for (const Layout& layout : layouts) {
    INFO(layout.name);
    const Model model = testing::model_from_text(model_yaml(layout.bodies, Parameters{}, layout.p1, layout.p2, "t_end: 1"));
    DaeSystem system(model);
    Anticlimber& ac = anticlimber_of(model);
    std::mt19937 rng(3);
    int checked = 0;
    const auto check_here = [&]() {
      check_jacobian_near_start(system, rng);
      ++checked;
    };
    for (const Mode h : {Mode::Elastic, Mode::PlasticUp})
      for (const Mode v : law_modes)
        for (const Mode m : law_modes) {
          INFO("modes " << static_cast<int>(h) << static_cast<int>(v) << static_cast<int>(m));
          Anticlimber::State st = system.modes().as<Anticlimber::State>(0);
          st.contact = Anticlimber::Contact::Engaged;
          st.vertical_reference = 0.2;
          st.torsional_reference = -0.1;
          st.horizontal = law_state(ac.horizontal, h, 0.003);
          st.vertical = law_state(ac.vertical, v, -0.005);
          st.torsional = law_state(ac.torsional, m, 0.002);
          testing::set_mode<Anticlimber::State>(system, st);
          // Not vacuous: engaged with all laws elastic, the forces are large.
          if (h == Mode::Elastic && v == Mode::Elastic && m == Mode::Elastic) {
            const std::vector<double> y = system.initial_state();
            double norm = 0.0;
            for (double f : element_forces(system, positions(system, y))) norm += std::abs(f);
            REQUIRE(norm > 1.0);
          }
          check_here();
        }
    for (const Anticlimber::Contact contact :
         {Anticlimber::Contact::Open, Anticlimber::Contact::Overridden, Anticlimber::Contact::Crushed}) {
      Anticlimber::State st = system.modes().as<Anticlimber::State>(0);
      st.contact = contact;
      testing::set_mode<Anticlimber::State>(system, st);
      check_here();
    }
    CHECK(checked == 2 * 4 * 4 + 3);
  }
}

// ---- runs -----------------------------------------------------------------------------------

TEST_CASE("anticlimber contact fires at gap / closing speed", "[elements][anticlimber]") {
  // Car 1 turned by 0.3 rad, at rest; car 2 approaches along car 1's axis from ahead (facing
  // +1) or from behind (facing -1), both inferred from the start. Nothing acts before contact.
  for (const double facing : {1.0, -1.0}) {
    for (const char* integrator : {"ida", "euler"}) {
      INFO("facing " << facing << ", " << integrator);
      const double angle = 0.3, gap = 0.12, speed = 1.7;
      // Body 1: a massive car turned by `angle`, at rest; body 2 approaches along body 1's axis.
      const Vec axis{std::cos(angle), std::sin(angle)};
      const double start = facing * (0.5 + gap);  // distance of car 2's face from car 1's centre along the axis
      const std::vector<BodySpec> bodies{
          {"car1", 1e3, 1e3, 0.0, 0.0, angle, 0.0, 0.0, 0.0},
          {"car2", 2.0, 0.5, axis.x * start, axis.y * start, angle, -facing * speed * axis.x, -facing * speed * axis.y, 0.0}};
      const std::string sim = std::string("t_end: 0.1, integrator: ") + integrator + ", rtol: 1e-10, dt: 1e-6";
      const LoadedModel loaded = testing::loaded_from_text(
          model_yaml(bodies, Parameters{}, Point{"car1", facing * 0.5, 0.0}, Point{"car2", 0.0, 0.0}, sim));
      const Model& model = loaded.model;
      REQUIRE(*anticlimber_of(model).facing == facing);
      const Run run = simulate(loaded);
      const EventRecord* contact = find_event(run.outcome, "contact");
      INFO(event_list(run.outcome));
      REQUIRE(contact != nullptr);
      CHECK(run.outcome.events.front().what == "contact");
      if (std::string(integrator) == "ida") {
        CHECK(contact->t == Approx(gap / speed).epsilon(0).margin(1e-8));
        CHECK(contact->value == Approx(0.0).margin(1e-8));
      } else {
        // Euler sees the contact at the end of the step that closes the gap.
        CHECK(contact->t >= gap / speed);
        CHECK(contact->t <= gap / speed + 1.0001e-6);
      }
    }
  }
}

TEST_CASE("anticlimber crush of a mass: yield, plastic flow, unloading and rebound match the closed form",
          "[elements][anticlimber]") {
  const double mass = 100.0, speed = 2.0, gap = 0.1;
  const Parameters p;
  const Crush c = crush_of(p.horizontal, mass, speed);
  const double contact_time = gap / speed;
  for (const char* integrator : {"ida", "euler"}) {
    const bool ida = std::string(integrator) == "ida";
    INFO(integrator);
    const std::vector<BodySpec> bodies{{"b", mass, 1.0, gap, 0.0, 0.0, -speed, 0.0, 0.0}};
    const std::string sim = std::string("t_end: 0.15, integrator: ") + integrator + ", rtol: 1e-10, dt: 1e-6";
    const LoadedModel loaded = testing::loaded_from_text(model_yaml(bodies, p, Point{"ground", 0.0, 0.0}, Point{"b", 0.0, 0.0}, sim));
    const Run run = simulate(loaded);
    const RunOutcome& o = run.outcome;
    INFO(event_list(o));
    REQUIRE(o.events.size() == 4);
    CHECK(o.events[0].what == "contact");
    CHECK(o.events[1].what == "horizontal yield");
    CHECK(o.events[2].what == "horizontal unloading");
    CHECK(o.events[3].what == "separation");
    const double time_tol = ida ? 1e-8 : 3e-6, crush_tol = ida ? 1e-8 : 4e-6;
    CHECK(o.events[0].t == Approx(contact_time).epsilon(0).margin(time_tol));
    CHECK(o.events[1].t == Approx(contact_time + c.yield_time).epsilon(0).margin(time_tol));
    CHECK(o.events[1].value == Approx(p.horizontal.yield).epsilon(0).margin(crush_tol));
    CHECK(o.events[2].t == Approx(contact_time + c.peak_time).epsilon(0).margin(ida ? 1e-7 : 3e-5));
    CHECK(o.events[2].value == Approx(c.max_crush).epsilon(0).margin(crush_tol));
    CHECK(o.events[3].t == Approx(contact_time + c.separation_time).epsilon(0).margin(ida ? 1e-7 : 3e-5));
    CHECK(o.events[3].value == Approx(c.permanent_crush).epsilon(0).margin(crush_tol));
    // Rebound speed (momentum after the elastic return of the peak force) and the energy: all
    // but the rebound's kinetic energy is dissipated by plastic flow in the element.
    const double rel = ida ? 1e-7 : 2e-4;
    CHECK(o.y[3] == Approx(c.rebound_speed).epsilon(rel));
    CHECK(element_work(o) == Approx(c.dissipated).epsilon(rel));
    const EnergyBalance balance = EnergyBalance::between(o.initial_energy, o.final_energy);
    CHECK(balance.dissipated == Approx(c.dissipated).epsilon(rel));
    CHECK(balance.elastic == Approx(0.0).margin(1e-9));
    // Euler-Cromer's energy error is O(omega dt) of the energy exchanged: 1e-4 of it.
    CHECK(std::abs(balance.error()) < (ida ? 1e-8 : 1e-4) * balance.initial_total);
    // The permanent crush is remembered while the faces are apart.
    CHECK(run.final_mode.contact == Anticlimber::Contact::Open);
    CHECK(run.final_mode.horizontal.offset == Approx(c.permanent_crush).epsilon(0).margin(crush_tol));
  }
}

TEST_CASE("two cars crush through the anticlimber with the reduced mass and conserve momentum", "[elements][anticlimber]") {
  const double m1 = 100.0, m2 = 300.0, speed = 2.0, gap = 0.1;
  const double reduced = m1 * m2 / (m1 + m2);
  const Parameters p;
  const Crush c = crush_of(p.horizontal, reduced, speed);
  for (const char* integrator : {"ida", "euler"}) {
    const bool ida = std::string(integrator) == "ida";
    INFO(integrator);
    // Faces at the centres' height: the impact is central, nothing turns.
    const std::vector<BodySpec> bodies{{"car1", m1, 5.0, 0.0, 0.0, 0.0, speed, 0.0, 0.0},
                                       {"car2", m2, 9.0, 0.9 + gap, 0.0, 0.0, 0.0, 0.0, 0.0}};
    const std::string sim = std::string("t_end: 0.15, integrator: ") + integrator + ", rtol: 1e-10, dt: 1e-6";
    const LoadedModel loaded = testing::loaded_from_text(model_yaml(bodies, p, Point{"car1", 0.4, 0.0}, Point{"car2", -0.5, 0.0}, sim));
    const Run run = simulate(loaded);
    const RunOutcome& o = run.outcome;
    INFO(event_list(o));
    REQUIRE(find_event(o, "separation") != nullptr);
    CHECK(find_event(o, "separation")->t == Approx(gap / speed + c.separation_time).epsilon(0).margin(ida ? 1e-7 : 3e-5));
    // Centre-of-mass velocity unchanged; relative velocity reversed to the rebound speed.
    const double vcm = m1 * speed / (m1 + m2);
    const double rel = ida ? 1e-7 : 2e-4;
    CHECK(o.y[6] == Approx(vcm - m2 / (m1 + m2) * c.rebound_speed).epsilon(rel));
    CHECK(o.y[9] == Approx(vcm + m1 / (m1 + m2) * c.rebound_speed).epsilon(rel));
    CHECK(m1 * o.y[6] + m2 * o.y[9] == Approx(m1 * speed).epsilon(1e-12));
    CHECK(o.y[7] == Approx(0.0).margin(1e-12));
    CHECK(o.y[8] == Approx(0.0).margin(1e-12));
    CHECK(element_work(o) == Approx(c.dissipated).epsilon(rel));
  }
}

namespace {

// A massive car 2 driven at constant velocity (u toward the face, w up, omega) into a
// ground-fixed anticlimber: its motion is prescribed to within F t / M ~ 1e-6 m.
struct Drive {
  double u, w, omega;
};
constexpr double kHeavy = 1e9;  // [kg] and [kg m^2]

LoadedModel driven_model(const Parameters& p, const Drive& drive, const std::string& integrator, double t_end) {
  const std::vector<BodySpec> bodies{{"car2", kHeavy, kHeavy, 0.1, 0.0, 0.0, -drive.u, drive.w, drive.omega}};
  const std::string sim = "t_end: " + number(t_end) + ", integrator: " + integrator + ", rtol: 1e-10, dt: 1e-5";
  return testing::loaded_from_text(model_yaml(bodies, p, Point{"ground", 0.0, 0.0}, Point{"car2", 0.0, 0.0}, sim));
}

}  // namespace

TEST_CASE("anticlimber shear failure, bending failure then override under prescribed motion",
          "[elements][anticlimber]") {
  Parameters p;
  p.horizontal.rupture = 0.5;
  p.vertical.rupture = 0.1;
  p.torsional.rupture = 0.05;
  p.misalignment = 0.02;
  p.misalignment_geometry = "offset";  // the closed form below adds the misalignment to v only
  p.face_height = 0.2;
  const Drive drive{1.0, 0.5, 0.2};
  // Contact at t = 0.1 (gap 0.1 at 1 m/s) with v = 0.02 + 0.5 * 0.1 = 0.07 < 0.2: engaged.
  // Then d_h = t - 0.1, d_v = 0.5 (t - 0.1), d_t = 0.2 (t - 0.1):
  struct Expected {
    const char* what;
    double t, value;
  };
  const Expected expected[] = {
      {"contact", 0.1, 0.0},
      {"horizontal yield", 0.11, 0.01},   // d_h = 0.01
      {"vertical yield", 0.14, 0.02},     // d_v = 0.02
      {"torsional yield", 0.15, 0.01},    // d_t = 0.01
      {"shear failure", 0.30, 0.1},       // d_v = vertical rupture
      {"bending failure", 0.35, 0.05},    // d_t = torsional rupture
      {"override", 0.36, 0.2},            // v = 0.07 + 0.5 (t - 0.1) reaches the face height
  };
  for (const char* integrator : {"ida", "euler"}) {
    const bool ida = std::string(integrator) == "ida";
    INFO(integrator);
    const LoadedModel loaded = driven_model(p, drive, integrator, 0.4);
    const Run run = simulate(loaded);
    const RunOutcome& o = run.outcome;
    INFO(event_list(o));
    REQUIRE(o.events.size() == std::size(expected));
    // Prescribed to ~1e-6 m by the heavy car (Euler: also within one step of 1e-5 s).
    const double time_tol = ida ? 5e-6 : 3e-5, value_tol = ida ? 1e-8 : 2e-5;
    for (std::size_t k = 0; k < std::size(expected); ++k) {
      INFO("event " << k);
      CHECK(o.events[k].what == expected[k].what);
      CHECK(o.events[k].t == Approx(expected[k].t).epsilon(0).margin(time_tol));
      CHECK(o.events[k].value == Approx(expected[k].value).epsilon(0).margin(value_tol));
    }
    CHECK(Anticlimber::overridden(run.final_mode));
    CHECK(run.final_mode.override_time == Approx(0.36).epsilon(0).margin(time_tol));
    CHECK(run.final_mode.vertical.mode == Mode::Failed);
    CHECK(run.final_mode.torsional.mode == Mode::Failed);
    DaeSystem system(loaded.model);
    testing::set_mode(system, run.final_mode);
    const std::vector<double> out = element_outputs(system, o.y);
    CHECK(out[7] == 1.0);
    CHECK(out[0] == 0.0);
    // All the work done is dissipated: the three areas under the bilinear curves up to the
    // crush at override (0.26), the vertical and the torsional rupture.
    const double work = bilinear_work(p.horizontal, 0.26) + bilinear_work(p.vertical, 0.1) + bilinear_work(p.torsional, 0.05);
    CHECK(work == Approx(2862.5 + 366.4 + 4.58).epsilon(1e-12));  // by hand: the test's own arithmetic
    CHECK(element_work(o) == Approx(work).epsilon(ida ? 2e-5 : 1e-3));
    const EnergyBalance balance = EnergyBalance::between(o.initial_energy, o.final_energy);
    CHECK(balance.elastic == 0.0);
  }
}

TEST_CASE("anticlimber crushing failure at the horizontal rupture deflection ends all forces", "[elements][anticlimber]") {
  for (const bool from_length : {false, true}) {
    INFO((from_length ? "rupture from length" : "rupture given"));
    Parameters p;
    if (from_length)
      p.length = 0.5;
    else
      p.horizontal.rupture = 0.5;
    const LoadedModel loaded = driven_model(p, Drive{1.0, 0.0, 0.0}, "ida", 0.7);
    const Run run = simulate(loaded);
    const RunOutcome& o = run.outcome;
    INFO(event_list(o));
    REQUIRE(o.events.size() == 3);
    CHECK(o.events[0].what == "contact");
    CHECK(o.events[1].what == "horizontal yield");
    CHECK(o.events[2].what == "crushing failure");
    CHECK(o.events[2].t == Approx(0.6).epsilon(0).margin(5e-6));
    CHECK(o.events[2].value == Approx(0.5).epsilon(0).margin(1e-8));
    CHECK(run.final_mode.contact == Anticlimber::Contact::Crushed);
    CHECK_FALSE(Anticlimber::overridden(run.final_mode));
    CHECK(element_work(o) == Approx(6150.5).epsilon(2e-5));  // 50 + 1e4 * 0.49 + 1e4 * 0.49^2 / 2
    CHECK(bilinear_work(p.horizontal, 0.5) == Approx(6150.5).epsilon(1e-12));
    DaeSystem system(loaded.model);
    testing::set_mode(system, run.final_mode);
    const std::vector<double> out = element_outputs(system, o.y);
    CHECK(out[0] == 0.0);
    CHECK(out[3] > 0.55);  // the car kept going through the crushed structure
  }
}

TEST_CASE("anticlimber faces that miss each other override at contact", "[elements][anticlimber]") {
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    Parameters p;
    p.misalignment = 0.25;  // above the face height 0.2
    const std::vector<BodySpec> bodies{{"b", 10.0, 1.0, 0.1, 0.0, 0.0, -1.0, 0.0, 0.0}};
    const LoadedModel loaded = testing::loaded_from_text(model_yaml(bodies, p, Point{"ground", 0.0, 0.0}, Point{"b", 0.0, 0.0},
                                                            std::string("t_end: 0.3, integrator: ") + integrator + ", dt: 1e-5"));
    const Run run = simulate(loaded);
    INFO(event_list(run.outcome));
    REQUIRE(run.outcome.events.size() == 1);
    CHECK(run.outcome.events[0].what == "override");
    CHECK(run.outcome.events[0].t == Approx(0.1).epsilon(0).margin(2e-5));
    CHECK(run.outcome.events[0].value == Approx(0.25).epsilon(1e-12));
    CHECK(run.outcome.y[3] == Approx(-1.0).epsilon(1e-14));  // never touched
    CHECK(Anticlimber::overridden(run.final_mode));
  }
}

TEST_CASE("anticlimber re-contact starts at the permanent crush and reloading at the largest crush",
          "[elements][anticlimber]") {
  // A mass hits the anticlimber, rebounds and is pushed back by a growing load: the second
  // contact is at the permanent crush p = d_u - F_u(d_u) / k_e of the first unloading at d_u,
  // and plastic flow resumes exactly at d_u.
  const Parameters p;
  const std::vector<BodySpec> bodies{{"b", 100.0, 1.0, 0.1, 0.0, 0.0, -2.0, 0.0, 0.0}};
  const std::string load = "  - {type: force, body: b, value: [[0, 0, 0], [1, -20000, 0]]}\n";
  const LoadedModel loaded = testing::loaded_from_text(model_yaml(bodies, p, Point{"ground", 0.0, 0.0}, Point{"b", 0.0, 0.0},
                                                          "t_end: 0.6, rtol: 1e-10", "", load));
  const Run run = simulate(loaded);
  const RunOutcome& o = run.outcome;
  INFO(event_list(o));
  const EventRecord* unloading = find_event(o, "horizontal unloading");
  const EventRecord* separation = find_event(o, "separation");
  const EventRecord* second = find_event(o, "contact", 2);
  const EventRecord* reloading = find_event(o, "horizontal reloading");
  REQUIRE(unloading != nullptr);
  REQUIRE(separation != nullptr);
  REQUIRE(second != nullptr);
  REQUIRE(reloading != nullptr);
  CHECK(unloading->t < separation->t);
  CHECK(separation->t < second->t);
  CHECK(second->t < reloading->t);
  const double d_u = unloading->value;
  const LawValues& h = p.horizontal;
  const double permanent = d_u - (h.yield_force() + h.plastic * (d_u - h.yield)) / h.elastic;
  REQUIRE(permanent > 1e-3);  // a real offset, not zero
  CHECK(separation->value == Approx(permanent).epsilon(0).margin(1e-9));
  CHECK(second->value == Approx(permanent).epsilon(0).margin(1e-9));
  CHECK(reloading->value == Approx(d_u).epsilon(0).margin(1e-9));
}

TEST_CASE("anticlimber commit engages a fresh interlock after a separation and ignores stale crossings",
          "[elements][anticlimber]") {
  Parameters p;
  p.misalignment = 0.01;
  const std::vector<BodySpec> bodies{{"b", 10.0, 1.0, 0.1, 0.03, 0.0, 0.0, 0.0, 0.0}};
  const Model model = testing::model_from_text(model_yaml(bodies, p, Point{"ground", 0.0, 0.0}, Point{"b", 0.0, 0.0}, "t_end: 1"));
  const Anticlimber& ac = anticlimber_of(model);
  DaeSystem system(model);
  const auto state_at = [](double x, double y, double vx) {
    ElementState<double> s;
    s.q[1] = {x, y, 0.0};  // slot 0 is the ground (point 1), slot 1 the body
    s.v[1] = {vx, 0.0, 0.0};
    return s;
  };
  Element::Event event;
  // Still apart: the contact root is positive, nothing to commit.
  CHECK_FALSE(ac.commit(Anticlimber::kContactRoot, -1, 0.0, state_at(0.01, 0.03, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  // A rising crossing never leaves a mode.
  CHECK_FALSE(ac.commit(Anticlimber::kContactRoot, 1, 0.0, state_at(0.0, 0.03, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  REQUIRE(ac.commit(Anticlimber::kContactRoot, -1, 0.1, state_at(0.0, 0.03, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "contact");
  CHECK(system.modes().as<Anticlimber::State>(0).contact == Anticlimber::Contact::Engaged);
  CHECK(system.modes().as<Anticlimber::State>(0).vertical_reference == Approx(0.04).epsilon(1e-15));  // y + misalignment
  // A root of the open mode is no longer active.
  CHECK_FALSE(ac.commit(Anticlimber::kContactRoot, -1, 0.1, state_at(0.0, 0.03, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  // Faces open again (d_h < 0): separation through the horizontal law's lower bound.
  REQUIRE(ac.commit(Anticlimber::kHorizontalRoots + 1, -1, 0.2, state_at(0.001, 0.05, 1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "separation");
  CHECK(system.modes().as<Anticlimber::State>(0).contact == Anticlimber::Contact::Open);
  // Re-contact higher up: the interlock takes the new offset as its reference.
  REQUIRE(ac.commit(Anticlimber::kContactRoot, -1, 0.3, state_at(0.0, 0.08, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(system.modes().as<Anticlimber::State>(0).vertical_reference == Approx(0.09).epsilon(1e-15));
  // An Euler step that lands beyond yield in one go: contact and yield in one commit.
  ModeTracker(system).reset_modes();
  REQUIRE(system.modes().as<Anticlimber::State>(0).contact == Anticlimber::Contact::Open);
  REQUIRE(ac.commit(Anticlimber::kContactRoot, -1, 0.1, state_at(-0.02, 0.03, -1.0), nullptr, testing::modes_to_write(system).of(0), event));
  CHECK(event.what == "contact, horizontal yield");
  CHECK(event.value == Approx(0.02).epsilon(1e-12));
  CHECK(system.modes().as<Anticlimber::State>(0).horizontal.mode == Mode::PlasticUp);
}

TEST_CASE("anticlimber crush under Euler converges to the closed form as the step shrinks", "[elements][anticlimber]") {
  const double mass = 100.0, speed = 2.0, gap = 0.1;
  const Parameters p;
  const Crush c = crush_of(p.horizontal, mass, speed);
  const auto rebound_error = [&](const std::string& integrator, double dt) {
    const std::vector<BodySpec> bodies{{"b", mass, 1.0, gap, 0.0, 0.0, -speed, 0.0, 0.0}};
    const std::string sim = "t_end: 0.15, integrator: " + integrator + ", rtol: 1e-10, dt: " + number(dt);
    const LoadedModel loaded = testing::loaded_from_text(model_yaml(bodies, p, Point{"ground", 0.0, 0.0}, Point{"b", 0.0, 0.0}, sim));
    const Run run = simulate(loaded);
    return std::abs(run.outcome.y[3] - c.rebound_speed);
  };
  const double e1 = rebound_error("euler", 4e-5), e2 = rebound_error("euler", 1e-5), e3 = rebound_error("euler", 2.5e-6);
  const double ida = rebound_error("ida", 0.0 + 1e-6);
  INFO("errors " << e1 << " " << e2 << " " << e3 << " ida " << ida);
  CHECK(e2 < 0.5 * e1);
  CHECK(e3 < 0.5 * e2);
  CHECK(e3 < 1e-3 * c.rebound_speed);
  CHECK(ida < 1e-7 * c.rebound_speed);
}

// ---- interlock while unloading: hold | release ------------------------------------------------

namespace {

/// A mass sliding up at 0.1 m/s hits the anticlimber at 2 m/s while a load (8 kN growing by
/// 20 kN/s) presses it on: the faces crush, unload elastically from the largest crush and,
/// pressed on by the growing load, reload onto the yield line without separating.
LoadedModel pressed_sliding_mass(const std::string& interlock, const std::string& integrator, double t_end) {
  Parameters p;
  p.interlock = interlock;
  const std::vector<BodySpec> bodies{{"b", 100.0, 1.0, 0.001, 0.0, 0.0, -1.5, 0.1, 0.0}};
  const std::string load = "  - {type: force, body: b, value: [[0, -6000, 0], [1, -26000, 0]]}\n";
  const std::string sim = "t_end: " + number(t_end) + ", integrator: " + integrator + ", rtol: 1e-10, dt: 1e-6, output_interval: 1e-4";
  return testing::loaded_from_text(model_yaml(bodies, p, Point{"ground", 0.0, 0.0}, Point{"b", 0.0, 0.0}, sim, "", load));
}

}  // namespace

TEST_CASE("anticlimber interlock_while_unloading: hold keeps the vertical force while the faces unload, release lets go "
          "until reloading",
          "[elements][anticlimber]") {
  // Horizontal and vertical motion are independent here (the point is the mass's centre, the
  // faces stay square), so both readings have the same horizontal events. Vertically the
  // interlock is elastic (|V| stays below the 4 kN yield): V = k_v (y - v_e).
  const Parameters p;
  const double kv = p.vertical.elastic, omega_v = std::sqrt(kv / 100.0), t_end = 0.114;
  for (const char* integrator : {"ida", "euler"}) {
    const bool ida = std::string(integrator) == "ida";
    const LoadedModel hold_model = pressed_sliding_mass("hold", integrator, t_end);
    const LoadedModel release_model = pressed_sliding_mass("release", integrator, t_end);
    const Run hold = simulate(hold_model), release = simulate(release_model);
    INFO(integrator << "\nhold:\n" << event_list(hold.outcome) << "release:\n" << event_list(release.outcome));
    const char* const hold_events[] = {"contact", "horizontal yield", "horizontal unloading", "horizontal reloading"};
    const char* const release_events[] = {"contact", "horizontal yield", "horizontal unloading, interlock released",
                                          "horizontal reloading, interlock re-seated"};
    REQUIRE(hold.outcome.events.size() == 4);
    REQUIRE(release.outcome.events.size() == 4);
    for (std::size_t k = 0; k < 4; ++k) {
      CHECK(hold.outcome.events[k].what == hold_events[k]);
      CHECK(release.outcome.events[k].what == release_events[k]);
      CHECK(release.outcome.events[k].t == Approx(hold.outcome.events[k].t).epsilon(0).margin(ida ? 1e-9 : 1e-6));
      CHECK(release.outcome.events[k].value == Approx(hold.outcome.events[k].value).epsilon(0).margin(1e-9));
    }
    const double t_unloading = hold.outcome.events[2].t, t_reloading = hold.outcome.events[3].t;
    REQUIRE(t_reloading - t_unloading > 0.05);
    // hold: the vertical force of the interlock (reference: the offset at contact) builds up
    // while the faces unload: it reaches a good part of the amplitude m w_v 0.1 = 447 N.
    const double reference = hold.final_mode.vertical_reference;
    double hold_peak = 0.0;
    int inside = 0;
    for (std::size_t k = 0; k < hold.samples.t.size(); ++k) {
      const double t = hold.samples.t[k];
      if (t <= t_unloading + 1e-5 || t >= t_reloading - 1e-5) continue;
      hold_peak = std::max(hold_peak, std::abs(kv * (hold.samples.y[k][1] - reference)));
      ++inside;
    }
    CHECK(inside > 100);
    CHECK(hold_peak > 200.0);
    // release: no vertical force from the unloading event to the reloading event: the mass
    // slides up at the vertical speed it had at the unloading event.
    std::optional<std::size_t> first;
    double release_drift = 0.0;
    for (std::size_t k = 0; k < release.samples.t.size(); ++k) {
      const double t = release.samples.t[k];
      if (t <= t_unloading + 1e-5 || t >= t_reloading - 1e-5) continue;
      if (!first) first = k;
      release_drift = std::max(release_drift, std::abs(release.samples.y[k][4] - release.samples.y[*first][4]));
      const double expected_y = release.samples.y[*first][1] + release.samples.y[*first][4] * (t - release.samples.t[*first]);
      CHECK(release.samples.y[k][1] == Approx(expected_y).epsilon(0).margin(ida ? 1e-10 : 1e-9));
    }
    REQUIRE(first);
    CHECK(release_drift < (ida ? 1e-10 : 1e-12));
    // ... and the force comes back at reloading: the interlock re-seats at the offset of that
    // moment, y_r = y_u + w_u (t_r - t_u), and the mass oscillates about it from there:
    // y = y_r + (w_u / w_v) sin(w_v (t - t_r)).
    const double y_u = release.samples.y[*first][1] - release.samples.y[*first][4] * (release.samples.t[*first] - t_unloading);
    const double w_u = release.samples.y[*first][4];
    const double y_r = y_u + w_u * (t_reloading - t_unloading);
    CHECK(Anticlimber::interlocked(release.final_mode));
    CHECK(release.final_mode.vertical_reference == Approx(y_r).epsilon(0).margin(ida ? 1e-9 : 1e-7));
    CHECK(std::abs(w_u) > 0.02);  // a real slide, so the re-seated interlock is loaded again
    const double y_end = y_r + w_u / omega_v * std::sin(omega_v * (t_end - t_reloading));
    CHECK(release.outcome.y[1] == Approx(y_end).epsilon(0).margin(ida ? 1e-8 : 1e-6));
    DaeSystem system(release_model.model);
    testing::set_mode(system, release.final_mode);
    const std::vector<double> out = element_outputs(system, release.outcome.y);
    CHECK(out[1] == Approx(kv * (release.outcome.y[1] - release.final_mode.vertical_reference)).epsilon(1e-12));
    CHECK(std::abs(out[1]) > 50.0);
    // Energy: the release dissipates the vertical elastic energy of that moment; the balance
    // closes for both readings (Euler-Cromer: O(omega dt) of the energy exchanged).
    for (const Run* r : {&hold, &release}) {
      const EnergyBalance balance = EnergyBalance::between(r->outcome.initial_energy, r->outcome.final_energy);
      CHECK(std::abs(balance.error()) < (ida ? 1e-7 : 1e-4) * (balance.initial_total + balance.external_work));
    }
    const EnergyBalance held = EnergyBalance::between(hold.outcome.initial_energy, hold.outcome.final_energy);
    const EnergyBalance released = EnergyBalance::between(release.outcome.initial_energy, release.outcome.final_energy);
    // Same horizontal history, same external work; the vertical energy at the release went.
    CHECK(released.external_work == Approx(held.external_work).epsilon(ida ? 1e-9 : 1e-5));
    // The vertical law stays elastic in both, so the difference is the energy released:
    // V_u^2 / 2 k_v with V_u = k_v (y_u - v_e), about 0.31 J here.
    const double released_energy = 0.5 * kv * (y_u - reference) * (y_u - reference);
    CHECK(released_energy > 0.1);
    CHECK(released.dissipated - held.dissipated == Approx(released_energy).epsilon(ida ? 1e-5 : 2e-2));
  }
}

TEST_CASE("anticlimber Jacobian matches finite differences with the interlock released", "[elements][anticlimber]") {
  Parameters p;
  p.interlock = "release";
  const Model model = testing::model_from_text(model_yaml(two_cars(), p, kCar1Face, kCar2Face, "t_end: 1"));
  DaeSystem system(model);
  Anticlimber& ac = anticlimber_of(model);
  CHECK(ac.release_while_unloading);
  std::mt19937 rng(5);
  for (const Mode v : {Mode::Elastic, Mode::PlasticUp, Mode::Failed}) {
    INFO("vertical mode " << static_cast<int>(v));
    Anticlimber::State st = system.modes().as<Anticlimber::State>(0);
    st.contact = Anticlimber::Contact::Engaged;
    st.interlock_released = true;
    st.vertical_reference = 0.2;
    st.torsional_reference = -0.1;
    st.horizontal = law_state(ac.horizontal, Mode::Elastic, 0.003);
    st.vertical = law_state(ac.vertical, v, -0.005);
    st.torsional = law_state(ac.torsional, Mode::Elastic, 0.002);
    testing::set_mode<Anticlimber::State>(system, st);
    check_jacobian_near_start(system, rng);
    // Released: only the horizontal law acts, along body 1's axis at face 2 (no moment M).
    const std::vector<double> y = system.initial_state();
    const std::vector<double> q = positions(system, y);
    const std::vector<double> f = element_forces(system, q);
    const double e1x = std::cos(0.15), e1y = std::sin(0.15);
    CHECK(std::abs(f[3] * e1y - f[4] * e1x) < 1e-9 * (std::abs(f[3]) + std::abs(f[4]) + 1.0));  // along e1
    const std::vector<double> out = element_outputs(system, y);
    CHECK(out[1] == 0.0);
    CHECK(out[2] == 0.0);
    CHECK(out[4] == 0.0);
    CHECK(out[5] == 0.0);
    CHECK(energy_at(system, q) == Approx(ac.horizontal.elastic_energy(st.horizontal, out[3])).epsilon(1e-12));
    double g[Anticlimber::kRootCount];
    ac.roots(0.0, gather_state(ac, y.data(), y.data() + system.body_unknowns(), system.modes().of(0)), nullptr, g);
    for (int i = Anticlimber::kVerticalRoots; i < Anticlimber::kContactRoot; ++i) CHECK(g[i] == 1.0);
  }
}

TEST_CASE("anticlimber interlock_while_unloading must be hold or release", "[elements][anticlimber]") {
  const auto load = [](const std::string& interlock) {
    Parameters p;
    p.interlock = interlock;
    return testing::model_from_text(model_yaml(two_cars(), p, kCar1Face, kCar2Face, "t_end: 1"));
  };
  for (const char* bad : {"keep", "1"})
    CHECK_THROWS_WITH(load(bad), Catch::Contains("test.yaml:") && Catch::Contains("'interlock_while_unloading' must be hold") &&
                                     Catch::Contains(std::string("not '") + bad + "'"));
  CHECK_THROWS_WITH(load("[hold]"), Catch::Contains("'interlock_while_unloading' must be a word"));
  CHECK_FALSE(anticlimber_of(load("hold")).release_while_unloading);
  CHECK(anticlimber_of(load("release")).release_while_unloading);
  Parameters p;  // not given: hold
  CHECK_FALSE(anticlimber_of(testing::model_from_text(model_yaml(two_cars(), p, kCar1Face, kCar2Face, "t_end: 1")))
                  .release_while_unloading);
}

TEST_CASE("Euler's stability limit sees the stiffness of anticlimber faces that start apart", "[elements][anticlimber][integrators]") {
  // Two 1000 kg car ends 0.05 m apart; the faces' horizontal elastic stiffness 1e9 N/m acts
  // once they meet: omega^2 = k (1/m1 + 1/m2) = 2e6 s^-2, limit 2 / omega. The vertical and
  // torsional laws are soft enough not to matter (1e3 N/m, 1e2 N m/rad on 100 kg m^2).
  const Model model = testing::model_from_text(R"(railcrash: 1
name: open anticlimber
units: SI
gravity: [0, 0]
bodies:
  - {name: a, mass: 1000, inertia: 100, position: [0, 0], velocity: [1, 0]}
  - {name: b, mass: 1000, inertia: 100, position: [0.05, 0]}
elements:
  - {name: faces, type: anticlimber, points: [{body: a, at: [0, 0]}, {body: b, at: [0, 0]}],
     horizontal_elastic_stiffness: 1.0e9, horizontal_plastic_stiffness: 1.0e6, horizontal_yield_deflection: 0.0025,
     vertical_elastic_stiffness: 1.0e3, vertical_plastic_stiffness: 1.0e2, vertical_yield_deflection: 0.005,
     torsional_elastic_stiffness: 1.0e2, torsional_plastic_stiffness: 1.0e1, torsional_yield_deflection: 0.01,
     face_height: 0.3}
simulation: {t_end: 0.1}
)");
  DaeSystem system(model);
  const double limit = explicit_stability_limit(system, system.initial_state(), nullptr);
  CHECK(limit == Approx(2.0 / std::sqrt(2e6)).epsilon(1e-4));
}
