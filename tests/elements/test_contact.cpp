#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>

#include "railcrash/elements/contact.hpp"
#include "railcrash/results/run.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

const double kG = 9.81;

std::string body_on(const std::string& element, double x, double y, double vx, double vy, const std::string& simulation,
                    const std::string& loads = "") {
  std::ostringstream s;
  s.precision(17);
  s << "railcrash: 1\nname: contact\nunits: SI\ngravity: [0, " << -kG << "]\nbodies:\n"
    << "  - {name: ball, mass: 2.0, inertia: 0.01, position: [" << x << ", " << y << "], velocity: [" << vx << ", " << vy
    << "]}\nelements:\n" << element << loads << "simulation: {" << simulation << "}\n";
  return s.str();
}

const std::string kFloor =
    "  - {name: floor, type: contact, line_point: [0, 0], line_normal: [0, 1], stiffness: 1.0e6, points: [{body: ball, at: [0, 0]}]}\n";

RunOutcome run(const LoadedModel& loaded) { return testing::simulate(loaded); }

}  // namespace

TEST_CASE("contact: a dropped ball touches the floor at sqrt(2h/g) and bounces back elastically", "[elements][contact]") {
  const double h = 1.0, t_contact = std::sqrt(2.0 * h / kG), v_impact = kG * t_contact;
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    const bool ida = std::string(integrator) == "ida";
    const LoadedModel loaded = testing::loaded_from_text(
        body_on(kFloor, 0.0, h, 0.0, 0.0, std::string("t_end: 0.6, rtol: 1e-10, dt: 1e-6, integrator: ") + integrator));
    const RunOutcome o = run(loaded);
    REQUIRE(o.events.size() == 2);
    CHECK(o.events[0].what == "contact");
    CHECK(o.events[0].t == Approx(t_contact).margin(ida ? 1e-9 : 2e-6));
    CHECK(o.events[0].value == Approx(v_impact).epsilon(ida ? 1e-8 : 1e-5));  // closing speed
    CHECK(o.events[1].what == "separation");
    // Undamped: the ball leaves with its impact speed (energy conserved through the contact).
    CHECK(-o.events[1].value == Approx(v_impact).epsilon(ida ? 1e-6 : 1e-3));
    // In contact the ball oscillates about the static deflection d_s = m g / k with amplitude
    // A = sqrt(d_s^2 + (v / w)^2), w = sqrt(k / m): it stays for (pi + 2 asin(d_s / A)) / w.
    const double w = std::sqrt(1.0e6 / 2.0), d_s = 2.0 * kG / 1.0e6;
    const double amplitude = std::hypot(d_s, v_impact / w);
    CHECK(o.events[1].t - o.events[0].t == Approx((M_PI + 2.0 * std::asin(d_s / amplitude)) / w).epsilon(ida ? 1e-6 : 2e-3));
  }
}

TEST_CASE("contact: a damped contact dissipates what the damper's work says", "[elements][contact]") {
  const std::string floor =
      "  - {name: floor, type: contact, line_point: [0, 0], line_normal: [0, 1], stiffness: 1.0e6, damping: 300, "
      "points: [{body: ball, at: [0, 0]}]}\n";
  const LoadedModel loaded = testing::loaded_from_text(body_on(floor, 0.0, 1.0, 0.0, 0.0, "t_end: 0.6, rtol: 1e-10"));
  const RunOutcome o = run(loaded);
  const EnergyBalance e = EnergyBalance::between(o.initial_energy, o.final_energy);
  CHECK(std::abs(e.error()) < 1e-6 * 2.0 * kG);
  CHECK(e.dissipated > 0.1 * 2.0 * kG * 1.0);  // zeta = 300 / (2 sqrt(2e6)) = 0.106: a real loss
  CHECK(o.quadratures[DaeSystem::kFirstElementWork] == Approx(e.dissipated).epsilon(1e-6));
  // The ball rebounds slower than it hit, and the release (damper would pull) comes before lift-off.
  REQUIRE(o.events.size() >= 3);
  CHECK(o.events[1].what == "released (damper would pull)");
  CHECK(o.events[2].what == "separation");
  CHECK(-o.events[2].value < 0.9 * o.events[0].value);
}

TEST_CASE("contact: Coulomb friction stops a sliding block at v^2 / (2 mu g)", "[elements][contact]") {
  const double mu = 0.5, v0 = 2.0, k = 1.0e6;
  const std::string floor =
      "  - {name: floor, type: contact, line_point: [0, 0], line_normal: [0, 1], stiffness: 1.0e6, friction: 0.5, "
      "friction_velocity: 1.0e-4, points: [{body: ball, at: [0, 0]}]}\n";
  // Starts resting on the floor at its static penetration m g / k.
  const LoadedModel loaded = testing::loaded_from_text(body_on(floor, 0.0, -2.0 * kG / k, v0, 0.0, "t_end: 0.6, rtol: 1e-9"));
  const RunOutcome o = run(loaded);
  CHECK(o.events.empty());  // stays in contact all along
  CHECK(o.y[0] == Approx(v0 * v0 / (2.0 * mu * kG)).epsilon(1e-3));
  CHECK(std::abs(o.y[3]) < 1e-3);  // stopped
}

TEST_CASE("contact with a circle: outside and inside surfaces", "[elements][contact]") {
  SECTION("a point moving at 1 m/s reaches a circle of radius 1 centred 2 m away after 1 s") {
    const std::string wall =
        "  - {name: wall, type: contact, circle_center: [2, 0], circle_radius: 1, stiffness: 1.0e5, "
        "points: [{body: ball, at: [0, 0]}]}\n";
    const LoadedModel loaded = testing::loaded_from_text(
        "railcrash: 1\nname: c\nunits: SI\ngravity: [0, 0]\nbodies:\n"
        "  - {name: ball, mass: 2.0, inertia: 0.01, position: [0, 0], velocity: [1, 0]}\nelements:\n" + wall +
        "simulation: {t_end: 1.2, rtol: 1e-10}\n");
    const RunOutcome o = run(loaded);
    REQUIRE(!o.events.empty());
    CHECK(o.events[0].t == Approx(1.0).margin(1e-9));
  }
  SECTION("inside a circle the point is pushed back toward the centre") {
    const std::string bowl =
        "  - {name: bowl, type: contact, circle_center: [0, 0], circle_radius: 1, inside: true, stiffness: 1.0e5, "
        "points: [{body: ball, at: [0, 0]}]}\n";
    const LoadedModel loaded = testing::loaded_from_text(
        "railcrash: 1\nname: c\nunits: SI\ngravity: [0, 0]\nbodies:\n"
        "  - {name: ball, mass: 2.0, inertia: 0.01, position: [0.5, 0], velocity: [1, 0]}\nelements:\n" + bowl +
        "simulation: {t_end: 0.6, rtol: 1e-10}\n");
    const RunOutcome o = run(loaded);
    REQUIRE(o.events.size() >= 2);
    CHECK(o.events[0].t == Approx(0.5).margin(1e-9));
    CHECK(o.y[3] == Approx(-1.0).epsilon(1e-6));  // elastic bounce back
  }
}

TEST_CASE("wheel_rail: two slopes, static deflection, and lift-off under a rising pull", "[elements][contact]") {
  // Wheel of radius 0.4 m on a rail at height 0: stiffness 1e6 N/m up to 1 mm, 4e6 N/m above.
  const std::string wheel =
      "  - {name: wheel, type: wheel_rail, wheel_radius: 0.4, stiffness: 1.0e6, stiffness_above: 4.0e6, breakpoint: 0.001, "
      "damping: 2000, points: [{body: ball, at: [0, 0]}]}\n";
  SECTION("resting under gravity it settles at the deflection where the force carries the weight") {
    // W = 2 g = 19.62 N: below the breakpoint force of 1000 N, so d = W / k1; with a 20 kN
    // extra load d = d_L + (W + 20000 - k1 d_L) / k2.
    const LoadedModel light_loaded = testing::loaded_from_text(body_on(wheel, 0.0, 0.4, 0.0, 0.0, "t_end: 1.0, rtol: 1e-9"));
    const RunOutcome a = run(light_loaded);
    CHECK(0.4 - a.y[1] == Approx(2.0 * kG / 1.0e6).epsilon(1e-4));
    const LoadedModel heavy_loaded = testing::loaded_from_text(
        body_on(wheel, 0.0, 0.4, 0.0, 0.0, "t_end: 1.0, rtol: 1e-9", "loads:\n  - {type: force, body: ball, value: [0, -20000]}\n"));
    const RunOutcome b = run(heavy_loaded);
    const double expected = 0.001 + (2.0 * kG + 20000.0 - 1000.0) / 4.0e6;
    CHECK(0.4 - b.y[1] == Approx(expected).epsilon(1e-4));
    // It starts exactly touching the rail at rest: contact is committed at t = 0 (the state
    // sits on the mode boundary and its acceleration takes it in), then it passes d_L.
    REQUIRE(b.events.size() >= 2);
    CHECK(b.events[0].what == "wheel contact");
    CHECK(b.events[0].t == 0.0);
    CHECK(b.events[1].what == "above breakpoint");
  }
  SECTION("an upward pull rising at 100 N/s lifts the wheel off when it exceeds the weight") {
    // Static start at d = W / k1; lift-off when the pull reaches W (quasi-static: the
    // contact's own dynamics shift it by far less than the tolerance).
    const LoadedModel loaded = testing::loaded_from_text(body_on(
        wheel, 0.0, 0.4 - 2.0 * kG / 1.0e6, 0.0, 0.0, "t_end: 0.3, rtol: 1e-9",
        "loads:\n  - {type: force, body: ball, value: [[0, [0, 0]], [1, [0, 100]]]}\n"));
    const RunOutcome o = run(loaded);
    REQUIRE(o.events.size() >= 2);
    // The contact force reaches zero first (the damper cannot pull), then the wheel leaves.
    CHECK(o.events[0].what == "wheel unloaded (damper would pull)");
    CHECK(o.events[0].t == Approx(2.0 * kG / 100.0).epsilon(1e-3));
    CHECK(o.events[1].what == "wheel lift-off");
    CHECK(o.events[1].t > o.events[0].t);
  }
}

TEST_CASE("contact Jacobian matches central differences in every mode", "[elements][contact]") {
  const std::string element =
      "  - {name: w, type: wheel_rail, wheel_radius: 0.4, stiffness: 1.0e6, stiffness_above: 4.0e6, breakpoint: 0.001, "
      "damping: 2000, friction: 0.3, friction_velocity: 0.05, points: [{body: ball, at: [0.1, -0.05]}]}\n";
  const Model model = testing::model_from_text(body_on(element, 0.0, 0.5, 0.3, 0.0, "t_end: 1"));
  DaeSystem system(model);
  const testing::DrivenElement<SurfaceContact> contact(system, 0);
  std::mt19937 rng(11);
  const auto check_mode = [&](double penetration) {
    for (int trial = 0; trial < 3; ++trial) {
      std::vector<double> y = testing::random_state(system, rng, 0.02);
      y[2] = 0.0;  // the point's height is then y - 0.05
      y[1] = 0.45 - penetration;
      const std::vector<double> yp = testing::random_state(system, rng, 0.3);
      double outside = 0.0;
      CHECK(testing::jacobian_error(system, 0.0, 30.0, y, yp, &outside) < 1e-6);
      CHECK(outside == 0.0);
    }
  };
  REQUIRE(contact.state().mode == SurfaceContact::Mode::Open);
  check_mode(-0.01);
  std::vector<double> y = system.initial_state();
  y[1] = 0.45;
  y[4] = -1.0;
  Element::Event event;
  REQUIRE(contact.commit(0, -1, 0.0, contact.at(y.data(), y.data() + 3), nullptr, event));
  REQUIRE(contact.state().mode == SurfaceContact::Mode::Contact);
  check_mode(0.0005);
  REQUIRE(contact.commit(2, -1, 0.0, contact.at(y.data(), y.data() + 3), nullptr, event));
  REQUIRE(contact.state().segment == 1);
  check_mode(0.002);
  REQUIRE(contact.commit(1, -1, 0.0, contact.at(y.data(), y.data() + 3), nullptr, event));
  REQUIRE(contact.state().mode == SurfaceContact::Mode::Released);
  check_mode(0.002);
}

TEST_CASE("contact: its wall or barrier surface is given for drawing the scene, a wheel's rail is not", "[elements][contact]") {
  // A line given with a normal of length 2 is normalised; a circle keeps centre, radius and side.
  const Model model = testing::model_from_text(body_on(
      "  - {name: wall, type: contact, line_point: [0.05, 0.2], line_normal: [-2, 0], stiffness: 1.0e6, points: [{body: ball, at: [0, 0]}]}\n"
      "  - {name: drum, type: contact, circle_center: [0, 1.5], circle_radius: 1.5, inside: true, stiffness: 1.0e6, points: [{body: ball, at: [0, 0]}]}\n"
      "  - {name: wheel, type: wheel_rail, wheel_radius: 0.4, stiffness: 1.0e6, points: [{body: ball, at: [0, 0]}]}\n",
      0.0, 1.0, 0.0, 0.0, "t_end: 0.1"));
  const auto wall = model.elements()[0]->ground_surface();
  REQUIRE(wall);
  CHECK(wall->kind == Element::GroundSurface::Kind::Line);
  CHECK(wall->x == 0.05);
  CHECK(wall->y == 0.2);
  CHECK(wall->nx == -1.0);
  CHECK(wall->ny == 0.0);
  const auto drum = model.elements()[1]->ground_surface();
  REQUIRE(drum);
  CHECK(drum->kind == Element::GroundSurface::Kind::Circle);
  CHECK(drum->x == 0.0);
  CHECK(drum->y == 1.5);
  CHECK(drum->radius == 1.5);
  CHECK(drum->inside);
  CHECK_FALSE(model.elements()[2]->ground_surface());
}
