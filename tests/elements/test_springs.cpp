// Springs and dashpots: assembled Jacobians, force laws against hand computations, energy
// consistency, default free lengths / angles and element outputs.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "railcrash/elements/springs.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

// ---- test models --------------------------------------------------------------------

struct Attachment {
  int body;  // kGround or body index
  double sx, sy;
};

enum class Ends { GroundBody, BodyGround, BodyBody };

/// Where the element's two points sit in each configuration (the YAML is generated from this).
struct Layout {
  Attachment p1, p2;
};

Layout layout(Ends ends) {
  if (ends == Ends::GroundBody) return {{kGround, -0.5, 0.4}, {0, 0.35, -0.15}};
  if (ends == Ends::BodyGround) return {{0, 0.35, -0.15}, {kGround, -0.5, 0.4}};
  return {{0, 0.45, 0.2}, {1, -0.3, 0.25}};
}

std::string point_yaml(const Attachment& a) {
  std::ostringstream text;
  text << "{body: " << (a.body == kGround ? "ground" : (a.body == 0 ? "a" : "b")) << ", at: [" << a.sx << ", " << a.sy
       << "]}";
  return text.str();
}

/// A model with one element `e` of the given type; `parameters` are its YAML lines.
/// Body a: rotated and moving; body b (body-body only): rotated the other way.
/// Ground-body has the ground point first, body-ground the body point first.
std::string element_model(const std::string& type, const std::string& parameters, Ends ends) {
  const Layout points = layout(ends);
  std::ostringstream text;
  text << "railcrash: 1\nname: element test\nunits: SI\ngravity: [0, 0]\nbodies:\n"
       << "  - {name: a, mass: 2.0, inertia: 0.5, position: [0.3, -0.2], angle: 0.4, velocity: [0.5, -0.3], "
          "angular_velocity: 0.8}\n";
  if (ends == Ends::BodyBody)
    text << "  - {name: b, mass: 3.0, inertia: 0.7, position: [1.6, 0.5], angle: -0.6, velocity: [-0.4, 0.2], "
            "angular_velocity: -1.1}\n";
  text << "elements:\n  - name: e\n    type: " << type << "\n"
       << parameters << "    points: [" << point_yaml(points.p1) << ", " << point_yaml(points.p2) << "]\n"
       << "simulation: {t_end: 1.0}\n";
  return text.str();
}

const Ends kAllEnds[] = {Ends::GroundBody, Ends::BodyGround, Ends::BodyBody};
const char* ends_name(Ends ends) {
  return ends == Ends::GroundBody ? "ground-body" : (ends == Ends::BodyGround ? "body-ground" : "body-body");
}

constexpr double kStiffness = 40.0;
constexpr double kFreeLength = 0.9;
constexpr double kDamping = 7.0;
constexpr double kTorsionalStiffness = 25.0;
constexpr double kFreeAngle = 1.2;  // far from every relative angle the tests visit
constexpr double kTorsionalDamping = 3.0;

std::string linear_spring_parameters() {
  return "    stiffness: " + std::to_string(kStiffness) + "\n    free_length: " + std::to_string(kFreeLength) + "\n";
}
std::string linear_dashpot_parameters() { return "    damping: " + std::to_string(kDamping) + "\n"; }
std::string torsional_spring_parameters() {
  return "    stiffness: " + std::to_string(kTorsionalStiffness) + "\n    free_angle: " + std::to_string(kFreeAngle) + "\n";
}
std::string torsional_dashpot_parameters() { return "    damping: " + std::to_string(kTorsionalDamping) + "\n"; }

// ---- hand kinematics, written from the definitions in planar.hpp ---------------------

struct Vec {
  double x, y;
};

double theta_of(const std::vector<double>& q, const Attachment& a) { return a.body == kGround ? 0.0 : q[3 * a.body + 2]; }

/// R(theta) s for the attachment.
Vec arm(const std::vector<double>& q, const Attachment& a) {
  const double t = theta_of(q, a);
  return {std::cos(t) * a.sx - std::sin(t) * a.sy, std::sin(t) * a.sx + std::cos(t) * a.sy};
}

Vec position(const std::vector<double>& q, const Attachment& a) {
  const Vec r = arm(q, a);
  if (a.body == kGround) return r;
  return {q[3 * a.body] + r.x, q[3 * a.body + 1] + r.y};
}

double distance(const std::vector<double>& q, const Layout& l) {
  const Vec p1 = position(q, l.p1), p2 = position(q, l.p2);
  return std::hypot(p2.x - p1.x, p2.y - p1.y);
}

/// Unit vector from P1 to P2.
Vec direction(const std::vector<double>& q, const Layout& l) {
  const Vec p1 = position(q, l.p1), p2 = position(q, l.p2);
  const double length = distance(q, l);
  return {(p2.x - p1.x) / length, (p2.y - p1.y) / length};
}

/// dL/dt along the velocities v, by central differences of the hand-computed length.
double length_rate(const std::vector<double>& q, const std::vector<double>& v, const Layout& l) {
  const double h = 1e-6;
  std::vector<double> plus = q, minus = q;
  for (std::size_t k = 0; k < q.size(); ++k) {
    plus[k] += h * v[k];
    minus[k] -= h * v[k];
  }
  return (distance(plus, l) - distance(minus, l)) / (2.0 * h);
}

/// Generalized forces of a force F at P2 and -F at P1 (ground entries dropped).
std::vector<double> line_forces(const std::vector<double>& q, const Layout& l, const Vec& force_on_p2) {
  std::vector<double> f(q.size(), 0.0);
  const auto add = [&](const Attachment& a, const Vec& force) {
    if (a.body == kGround) return;
    const Vec r = arm(q, a);
    f[static_cast<std::size_t>(3 * a.body)] += force.x;
    f[static_cast<std::size_t>(3 * a.body + 1)] += force.y;
    f[static_cast<std::size_t>(3 * a.body + 2)] += r.x * force.y - r.y * force.x;
  };
  add(l.p2, force_on_p2);
  add(l.p1, {-force_on_p2.x, -force_on_p2.y});
  return f;
}

/// Generalized forces of a moment -M on body 2 and +M on body 1.
std::vector<double> torsion_forces(std::size_t size, const Layout& l, double moment) {
  std::vector<double> f(size, 0.0);
  if (l.p2.body != kGround) f[static_cast<std::size_t>(3 * l.p2.body + 2)] -= moment;
  if (l.p1.body != kGround) f[static_cast<std::size_t>(3 * l.p1.body + 2)] += moment;
  return f;
}

double relative_angle(const std::vector<double>& q, const Layout& l) { return theta_of(q, l.p2) - theta_of(q, l.p1); }
double relative_rate(const std::vector<double>& v, const Layout& l) { return theta_of(v, l.p2) - theta_of(v, l.p1); }

using testing::BodyState;
using testing::forces;
using testing::split;

void check_forces(const std::vector<double>& actual, const std::vector<double>& expected, double tolerance = 1e-10) {
  REQUIRE(actual.size() == expected.size());
  for (std::size_t k = 0; k < actual.size(); ++k) {
    INFO("generalized force " << k);
    CHECK(actual[k] == Approx(expected[k]).epsilon(tolerance).margin(tolerance));
  }
}

/// Largest absolute entry.
double largest(const std::vector<double>& values) {
  double worst = 0.0;
  for (double x : values) worst = std::max(worst, std::abs(x));
  return worst;
}

/// Runs `check(system, state)` at the initial state and at random states around it.
template <class Check>
void at_several_states(const DaeSystem& system, Check check) {
  std::mt19937 rng(11);
  check(split(system, system.initial_state()));
  for (int trial = 0; trial < 4; ++trial) {
    INFO("random state " << trial);
    check(split(system, testing::random_state(system, rng)));
  }
}

}  // namespace

// ---- (a) Jacobians ------------------------------------------------------------------

TEST_CASE("spring and dashpot DAE Jacobians match central differences inside the pattern", "[elements]") {
  const std::pair<const char*, std::string> elements[] = {
      {"linear_spring", linear_spring_parameters()},
      {"linear_spring", "    stiffness: 40\n    free_length: 0\n"},  // the zero-free-length force law
      {"linear_dashpot", linear_dashpot_parameters()},
      {"torsional_spring", torsional_spring_parameters()},
      {"torsional_dashpot", torsional_dashpot_parameters()},
  };
  for (const auto& [type, parameters] : elements)
    for (const Ends ends : kAllEnds) {
      INFO(type << " " << ends_name(ends) << "\n" << parameters);
      const Model model = testing::model_from_text(element_model(type, parameters, ends));
      DaeSystem system(model);
      std::mt19937 rng(3);
      for (int trial = 0; trial < 4; ++trial) {
        INFO("trial " << trial);
        const std::vector<double> y = testing::random_state(system, rng);
        const std::vector<double> yp = testing::random_state(system, rng);
        double outside = -1.0;
        CHECK(testing::jacobian_error(system, 0.1, 20.0 * (trial + 1), y, yp, &outside) < 1e-6);
        CHECK(outside == 0.0);
      }
    }
}

// ---- (b) force laws -------------------------------------------------------------------

TEST_CASE("linear_spring pulls with stiffness times stretch along the line", "[elements]") {
  for (const Ends ends : kAllEnds) {
    INFO(ends_name(ends));
    const Model model = testing::model_from_text(element_model("linear_spring", linear_spring_parameters(), ends));
    DaeSystem system(model);
    const Layout l = layout(ends);
    at_several_states(system, [&](const BodyState& s) {
      const double tension = kStiffness * (distance(s.q, l) - kFreeLength);
      const Vec u = direction(s.q, l);
      check_forces(forces(system, s), line_forces(s.q, l, {-tension * u.x, -tension * u.y}));
    });
  }
}

TEST_CASE("linear_spring on a rotated body: force and moment at a known configuration", "[elements]") {
  // Ground point at (0, 0.5); body at (2, 0) turned by 90 degrees, point at [0.5, 0] -> (2, 0.5).
  // L = 2, L0 = 1.5, k = 100: tension 50, force on the body (-50, 0) at arm (0, 0.5): moment +25.
  const Model model = testing::model_from_text(
      "railcrash: 1\nname: known\nunits: SI\ngravity: [0, 0]\n"
      "bodies:\n  - {name: a, mass: 1.0, inertia: 1.0, position: [2.0, 0.0], angle: 1.5707963267948966}\n"
      "elements:\n  - name: e\n    type: linear_spring\n    stiffness: 100\n    free_length: 1.5\n"
      "    points: [{body: ground, at: [0, 0.5]}, {body: a, at: [0.5, 0]}]\n"
      "simulation: {t_end: 1.0}\n");
  DaeSystem system(model);
  check_forces(forces(system, split(system, system.initial_state())), {-50.0, 0.0, 25.0});
}

TEST_CASE("linear_spring with zero free length pulls with stiffness times separation", "[elements]") {
  const Model model =
      testing::model_from_text(element_model("linear_spring", "    stiffness: 40\n    free_length: 0\n", Ends::BodyBody));
  DaeSystem system(model);
  const Layout l = layout(Ends::BodyBody);
  at_several_states(system, [&](const BodyState& s) {
    const Vec p1 = position(s.q, l.p1), p2 = position(s.q, l.p2);
    check_forces(forces(system, s), line_forces(s.q, l, {-40.0 * (p2.x - p1.x), -40.0 * (p2.y - p1.y)}));
  });
}

TEST_CASE("linear_dashpot resists with damping times the rate of length", "[elements]") {
  for (const Ends ends : kAllEnds) {
    INFO(ends_name(ends));
    const Model model = testing::model_from_text(element_model("linear_dashpot", linear_dashpot_parameters(), ends));
    DaeSystem system(model);
    const Layout l = layout(ends);
    at_several_states(system, [&](const BodyState& s) {
      const double force = kDamping * length_rate(s.q, s.v, l);
      REQUIRE(std::abs(force) > 1e-3);  // the states do stretch or shorten the dashpot
      const Vec u = direction(s.q, l);
      // The rate comes from central differences: allow for their error.
      check_forces(forces(system, s), line_forces(s.q, l, {-force * u.x, -force * u.y}), 1e-7);
    });
  }
}

TEST_CASE("torsional_spring applies opposite moments proportional to the relative rotation", "[elements]") {
  for (const Ends ends : kAllEnds) {
    INFO(ends_name(ends));
    const Model model = testing::model_from_text(element_model("torsional_spring", torsional_spring_parameters(), ends));
    DaeSystem system(model);
    const Layout l = layout(ends);
    at_several_states(system, [&](const BodyState& s) {
      const double moment = kTorsionalStiffness * (relative_angle(s.q, l) - kFreeAngle);
      check_forces(forces(system, s), torsion_forces(s.q.size(), l, moment));
    });
  }
}

TEST_CASE("torsional_dashpot applies opposite moments proportional to the relative angular velocity", "[elements]") {
  for (const Ends ends : kAllEnds) {
    INFO(ends_name(ends));
    const Model model =
        testing::model_from_text(element_model("torsional_dashpot", torsional_dashpot_parameters(), ends));
    DaeSystem system(model);
    const Layout l = layout(ends);
    at_several_states(system, [&](const BodyState& s) {
      const double moment = kTorsionalDamping * relative_rate(s.v, l);
      REQUIRE(std::abs(moment) > 1e-3);
      check_forces(forces(system, s), torsion_forces(s.q.size(), l, moment));
    });
  }
}

// ---- (c) energy -----------------------------------------------------------------------

TEST_CASE("spring forces are minus the gradient of their potential energy", "[elements]") {
  const std::pair<const char*, std::string> springs[] = {
      {"linear_spring", linear_spring_parameters()},
      {"linear_spring", "    stiffness: 40\n    free_length: 0\n"},
      {"torsional_spring", torsional_spring_parameters()},
  };
  for (const auto& [type, parameters] : springs)
    for (const Ends ends : kAllEnds) {
      INFO(type << " " << ends_name(ends) << "\n" << parameters);
      const Model model = testing::model_from_text(element_model(type, parameters, ends));
      DaeSystem system(model);
      const Element& element = *model.elements().front();
      const auto energy = [&](const std::vector<double>& q, const std::vector<double>& v) {
        return element.potential_energy(gather_state(element, q.data(), v.data()));
      };
      at_several_states(system, [&](const BodyState& s) {
        REQUIRE(energy(s.q, s.v) > 1e-3);  // stretched or twisted: the check is not vacuous
        std::vector<double> gradient(s.q.size());
        for (std::size_t k = 0; k < s.q.size(); ++k) {
          const double h = 1e-6;
          std::vector<double> plus = s.q, minus = s.q;
          plus[k] += h;
          minus[k] -= h;
          gradient[k] = -(energy(plus, s.v) - energy(minus, s.v)) / (2.0 * h);
        }
        const std::vector<double> f = forces(system, s);
        for (std::size_t k = 0; k < f.size(); ++k) {
          INFO("component " << k);
          CHECK(f[k] == Approx(gradient[k]).epsilon(1e-6).margin(1e-6));
        }
      });
    }
}

TEST_CASE("spring potential energy is half stiffness times deformation squared", "[elements]") {
  for (const Ends ends : kAllEnds) {
    INFO(ends_name(ends));
    const Layout l = layout(ends);
    const Model linear = testing::model_from_text(element_model("linear_spring", linear_spring_parameters(), ends));
    const Model torsional =
        testing::model_from_text(element_model("torsional_spring", torsional_spring_parameters(), ends));
    DaeSystem system(linear);  // both models have the same bodies: the states fit either
    at_several_states(system, [&](const BodyState& s) {
      const Element& spring = *linear.elements().front();
      const double stretch = distance(s.q, l) - kFreeLength;
      CHECK(spring.potential_energy(gather_state(spring, s.q.data(), s.v.data())) ==
            Approx(0.5 * kStiffness * stretch * stretch).epsilon(1e-12));
      const Element& torsion = *torsional.elements().front();
      const double twist = relative_angle(s.q, l) - kFreeAngle;
      CHECK(torsion.potential_energy(gather_state(torsion, s.q.data(), s.v.data())) ==
            Approx(0.5 * kTorsionalStiffness * twist * twist).epsilon(1e-12));
    });
  }
}

// ---- (d) defaults from the initial configuration ----------------------------------------

TEST_CASE("linear_spring without free_length is unstressed in the initial configuration", "[elements]") {
  for (const Ends ends : kAllEnds) {
    INFO(ends_name(ends));
    const Model model = testing::model_from_text(element_model("linear_spring", "    stiffness: 40\n", ends));
    DaeSystem system(model);
    const Layout l = layout(ends);
    const BodyState start = split(system, system.initial_state());
    const auto& spring = dynamic_cast<const LinearSpring&>(*model.elements().front());
    REQUIRE(spring.free_length.has_value());
    CHECK(*spring.free_length == Approx(distance(start.q, l)).epsilon(1e-12));
    CHECK(largest(forces(system, start)) < 1e-12);

    // Away from the start it pulls back towards the initial length.
    BodyState moved = start;
    moved.q[0] += 0.2;
    const double tension = 40.0 * (distance(moved.q, l) - distance(start.q, l));
    REQUIRE(std::abs(tension) > 1.0);
    const Vec u = direction(moved.q, l);
    check_forces(forces(system, moved), line_forces(moved.q, l, {-tension * u.x, -tension * u.y}));
  }
}

TEST_CASE("torsional_spring without free_angle is unstressed in the initial configuration", "[elements]") {
  for (const Ends ends : kAllEnds) {
    INFO(ends_name(ends));
    const Model model = testing::model_from_text(element_model("torsional_spring", "    stiffness: 25\n", ends));
    DaeSystem system(model);
    const Layout l = layout(ends);
    const BodyState start = split(system, system.initial_state());
    const auto& spring = dynamic_cast<const TorsionalSpring&>(*model.elements().front());
    REQUIRE(spring.free_angle.has_value());
    // Initial angles: a 0.4, b -0.6 (ground 0); free_angle is theta2 - theta1.
    const double expected = ends == Ends::GroundBody ? 0.4 : (ends == Ends::BodyGround ? -0.4 : -1.0);
    CHECK(*spring.free_angle == Approx(expected).epsilon(1e-12));
    CHECK(largest(forces(system, start)) < 1e-12);

    BodyState turned = start;
    turned.q[2] += 0.1;  // body a turns: the relative angle changes by -/+ 0.1
    const double moment = 25.0 * (relative_angle(turned.q, l) - relative_angle(start.q, l));
    CHECK(std::abs(moment) == Approx(2.5).epsilon(1e-12));
    check_forces(forces(system, turned), torsion_forces(turned.q.size(), l, moment));
  }
}

// ---- (e) outputs ------------------------------------------------------------------------

namespace {

/// Output names and values of the single element of a model at a state.
std::vector<double> element_outputs(const DaeSystem& system, const std::vector<double>& y) {
  std::vector<double> out(system.output_names().size(), 0.0);
  system.outputs(y.data(), y.data() + 2 * system.body_unknowns(), out.data());
  return out;
}

/// A state with the given positions and velocities and no multipliers.
std::vector<double> join(const BodyState& s) {
  std::vector<double> y = s.q;
  y.insert(y.end(), s.v.begin(), s.v.end());
  return y;
}

}  // namespace

TEST_CASE("spring and dashpot outputs are the force or moment and the quantity it is proportional to", "[elements]") {
  // Each type's outputs: (coefficient x quantity, quantity), the quantity from the hand
  // kinematics above, at several states of every arrangement of ends.
  struct OutputCase {
    const char* type;
    std::string parameters;
    std::vector<std::string> names;
    double coefficient;                                    // stiffness or damping of the type
    double (*quantity)(const BodyState& s, const Layout& l);  // what the second output is
    double tolerance;                                      // relative and absolute
  };
  const OutputCase cases[] = {
      {"linear_spring", linear_spring_parameters(), {"e.force", "e.deformation"}, kStiffness,
       [](const BodyState& s, const Layout& l) { return distance(s.q, l) - kFreeLength; }, 1e-12},
      // The rate of length comes from central differences of the hand-computed length.
      {"linear_dashpot", linear_dashpot_parameters(), {"e.force", "e.rate"}, kDamping,
       [](const BodyState& s, const Layout& l) { return length_rate(s.q, s.v, l); }, 1e-8},
      {"torsional_spring", torsional_spring_parameters(), {"e.moment", "e.rotation"}, kTorsionalStiffness,
       [](const BodyState& s, const Layout& l) { return relative_angle(s.q, l) - kFreeAngle; }, 1e-12},
      {"torsional_dashpot", torsional_dashpot_parameters(), {"e.moment", "e.rate"}, kTorsionalDamping,
       [](const BodyState& s, const Layout& l) { return relative_rate(s.v, l); }, 1e-12},
  };
  for (const OutputCase& c : cases)
    for (const Ends ends : kAllEnds) {
      INFO(c.type << " " << ends_name(ends));
      const Model model = testing::model_from_text(element_model(c.type, c.parameters, ends));
      DaeSystem system(model);
      const Layout l = layout(ends);
      CHECK(system.output_names() == c.names);
      at_several_states(system, [&](const BodyState& s) {
        const double quantity = c.quantity(s, l);
        const std::vector<double> out = element_outputs(system, join(s));
        CHECK(out[0] == Approx(c.coefficient * quantity).epsilon(c.tolerance).margin(c.tolerance));
        CHECK(out[1] == Approx(quantity).epsilon(c.tolerance).margin(c.tolerance));
      });
    }
}

TEST_CASE("linear_spring output force is positive when stretched and negative when compressed", "[elements]") {
  // Body at (2, 0), ground point at the origin: L = 2.
  const auto spring_at = [](double free_length) {
    return testing::model_from_text(
        "railcrash: 1\nname: sign\nunits: SI\ngravity: [0, 0]\n"
        "bodies:\n  - {name: a, mass: 1.0, inertia: 1.0, position: [2.0, 0.0]}\n"
        "elements:\n  - name: e\n    type: linear_spring\n    stiffness: 10\n    free_length: " +
        std::to_string(free_length) + "\n    points: [{body: ground}, {body: a}]\nsimulation: {t_end: 1.0}\n");
  };
  const Model stretched = spring_at(1.5), compressed = spring_at(2.5);
  DaeSystem stretched_system(stretched), compressed_system(compressed);
  const std::vector<double> out_stretched = element_outputs(stretched_system, stretched_system.initial_state());
  const std::vector<double> out_compressed = element_outputs(compressed_system, compressed_system.initial_state());
  CHECK(out_stretched[0] == Approx(5.0));
  CHECK(out_stretched[1] == Approx(0.5));
  CHECK(out_compressed[0] == Approx(-5.0));
  CHECK(out_compressed[1] == Approx(-0.5));
  // A stretched spring pulls the body back towards the ground point.
  CHECK(forces(stretched_system, split(stretched_system, stretched_system.initial_state()))[0] == Approx(-5.0));
}

namespace {
/// A 1 kg mass 1 m along +x from a ground point, moving towards it at `speed`, tied to it by a
/// linear_spring of 10 N/m with free length `free_length`.
std::string spring_impact(double speed, double free_length, const std::string& integrator, double dt = 1e-5) {
  std::ostringstream s;
  s.precision(17);
  s << "railcrash: 1\nname: spring impact\nunits: SI\ngravity: [0, 0]\nbodies:\n"
    << "  - {name: mass, mass: 1, inertia: 1, position: [1, 0], velocity: [" << -speed << ", 0]}\n"
    << "elements:\n  - {name: k, type: linear_spring, stiffness: 10, free_length: " << free_length
    << ", points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n"
    << "simulation: {t_end: 1, integrator: " << integrator << ", rtol: 1e-10, dt: " << dt << ", output_interval: 0.01}\n";
  return s.str();
}
}  // namespace

TEST_CASE("linear_spring compressed through its points stops the run naming it under every integrator",
          "[elements][faults]") {
  // 10 m/s against 10 N/m over 1 m: x = L0 - (v0 / w) sin(w t), w = sqrt(10), an amplitude of
  // 3.16 m, so the mass reaches the ground point; the stop is at x = 1e-3 L0. Before it Euler
  // carried the mass past the point with the spring's push k L0 turned around.
  const double v0 = 10.0, w = std::sqrt(10.0);
  const double t_meet = std::asin((1.0 - PointsMeet::kFraction) * w / v0) / w;  // [s] 0.1016
  for (const char* integrator : {"ida", "euler", "auto"}) {
    INFO(integrator);
    const RunOutcome outcome = testing::simulate_to_stop(testing::loaded_from_text(spring_impact(v0, 1.0, integrator)));
    INFO(outcome.message);
    CHECK_FALSE(outcome.ok);
    CHECK_THAT(outcome.message, Catch::StartsWith("test.yaml:8: linear_spring 'k' is compressed through the whole distance "
                                                  "between its points at t = ") &&
                                    Catch::Contains("s: its points are ") && Catch::Contains("of a free_length of 1,"));
    const double t_message = testing::message_time(outcome.message);
    CHECK(t_message == Approx(t_meet).epsilon(std::string(integrator) == "euler" ? 1e-3 : 1e-6));
  }
  // A step that carries the mass past the point (Euler at 5 ms moves it about 47 mm) says so.
  const RunOutcome coarse = testing::simulate_to_stop(testing::loaded_from_text(spring_impact(v0, 1.0, "euler", 5e-3)));
  CHECK_THAT(coarse.message, Catch::Contains("linear_spring 'k' is compressed through") &&
                                 Catch::Contains("its points have passed each other (by "));
  // A spring of zero free length pulls with k (r2 - r1), defined at every separation: the mass
  // swings through the point and the run goes on (x = -(v0 / w) sin(w t) ... from x = 1).
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const RunOutcome through = testing::simulate(testing::loaded_from_text(spring_impact(v0, 0.0, integrator)));
    const double x_end = std::cos(w) - v0 / w * std::sin(w);  // [m] at t = 1
    CHECK(through.y[0] == Approx(x_end).epsilon(std::string(integrator) == "euler" ? 1e-3 : 1e-7));
  }
}

namespace {
/// spring_impact's mass and spring (10 N/m, free length 1 m), the mass starting 0.5 mm from the
/// ground point, within the points-meet margin of 1e-3 L0, at `speed` along +x (away).
std::string spring_start_near(double speed, const std::string& integrator) {
  std::ostringstream s;
  s.precision(17);
  s << "railcrash: 1\nname: spring near\nunits: SI\ngravity: [0, 0]\nbodies:\n"
    << "  - {name: mass, mass: 1, inertia: 1, position: [0.0005, 0], velocity: [" << speed << ", 0]}\n"
    << "elements:\n  - {name: k, type: linear_spring, stiffness: 10, free_length: 1, "
    << "points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n"
    << "simulation: {t_end: 0.2, integrator: " << integrator << ", rtol: 1e-10, dt: 1e-5, output_interval: 0.01}\n";
  return s.str();
}
}  // namespace

TEST_CASE("linear_spring starting within the points-meet margin runs on while its points move apart", "[elements][faults]") {
  // x = 1 - (1 - x0) cos(w t) + (v0 / w) sin(w t), w = sqrt(10): moving away at 1 m/s the mass
  // leaves the margin at once; the start's commit of the negative root stopped the run at t = 0
  // before. Moving towards the point it stops there, at t = 0.
  const double w = std::sqrt(10.0), x0 = 0.0005, v0 = 1.0, t_end = 0.2;
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const RunOutcome away = testing::simulate(testing::loaded_from_text(spring_start_near(v0, integrator)));
    INFO(away.message);
    REQUIRE(away.ok);
    const double x_end = 1.0 - (1.0 - x0) * std::cos(w * t_end) + v0 / w * std::sin(w * t_end);  // [m]
    CHECK(away.y[0] == Approx(x_end).epsilon(std::string(integrator) == "euler" ? 1e-4 : 1e-7));
    const RunOutcome towards = testing::simulate_to_stop(testing::loaded_from_text(spring_start_near(-v0, integrator)));
    CHECK_FALSE(towards.ok);
    CHECK_THAT(towards.message, Catch::Contains("linear_spring 'k' is compressed through the whole distance between its "
                                                "points at t = 0 s: its points are 0.0005 apart"));
  }
}
