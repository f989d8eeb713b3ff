#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

// The crush-impact case (a 100 kg mass crushing an elastic-perfectly-plastic structure:
// largest crush 0.055 m after a 0.5 m gap) with a crush gauge from the anchor to the mass.
LoadedModel crush_model(const std::string& responses) {
  std::ifstream in(std::string(RAILCRASH_SOURCE_DIR) + "/verification/cases/crush_impact.yaml");
  std::stringstream text;
  text << in.rdbuf() << responses;
  return testing::loaded_from_text(text.str());
}

}  // namespace

TEST_CASE("R1 is the largest shortening of the crush gauges over the reference crush", "[responses]") {
  const LoadedModel loaded = crush_model(
      "responses:\n  crush_gauges:\n    - {name: structure, points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n"
      "  reference_crush: 0.5\n");
  const RunReport report = run_model(loaded.model, loaded.run_spec, "");
  REQUIRE(report.outcome.ok);
  REQUIRE(report.has_responses);
  // Gauge from 1.5 m down to 1 - 0.055 m: shortening 0.555 m (the gap plus the crush),
  // sampled every millisecond: the peak lies within v dt^2-ish of a sample.
  CHECK(report.responses.max_crush.at(0) == Approx(0.555).margin(2e-4));
  CHECK(report.responses.r1 == Approx(0.555 / 0.5).margin(4e-4));
  CHECK(report.responses.r2 == 0.0);                      // no anticlimber
  CHECK(report.responses.r3 == Approx(report.responses.r1 + report.responses.r2));  // R1 >= 1: the sum
}

TEST_CASE("R3 is the larger of R1 and R2 while both are below one", "[responses]") {
  const LoadedModel loaded = crush_model(
      "responses:\n  crush_gauges:\n    - {name: structure, points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n"
      "  reference_crush: 2.0\n");
  const RunReport report = run_model(loaded.model, loaded.run_spec, "");
  CHECK(report.responses.r1 == Approx(0.555 / 2.0).margin(1e-4));
  CHECK(report.responses.r3 == Approx(report.responses.r1));
}

TEST_CASE("R2 from the anticlimber: vertical force over yield, or 1 + relative speed after override", "[responses]") {
  // A car end (1000 kg) driven into a fixed anticlimber face while sliding up at 3 m/s: the
  // faces meet 0.05 m apart vertically and interlock, the vertical law yields (its plastic
  // force, about 1e4 N, cannot stop 4500 J of vertical motion), and the ends override when
  // the offset passes the 0.1 m face height. Vertical yield force = 1e6 N/m x 0.01 m = 1e4 N.
  const std::string text =
      "railcrash: 1\nname: r2\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: car, mass: 1000, inertia: 100, position: [0.1, -0.1], velocity: [-2, 3]}\nelements:\n"
      "  - name: ac\n    type: anticlimber\n"
      "    horizontal_elastic_stiffness: 1.0e7\n    horizontal_plastic_stiffness: 1.0e5\n    horizontal_yield_deflection: 0.01\n"
      "    vertical_elastic_stiffness: 1.0e6\n    vertical_plastic_stiffness: 1.0e4\n    vertical_yield_deflection: 0.01\n"
      "    torsional_elastic_stiffness: 1.0e6\n    torsional_plastic_stiffness: 1.0e4\n    torsional_yield_deflection: 0.01\n"
      "    face_height: 0.1\n    points: [{body: ground, at: [0, 0]}, {body: car, at: [0, 0]}]\n"
      "responses:\n  anticlimber: ac\n  reference_velocity: 4.0\n  override_velocity_at: override\n"
      "simulation: {t_end: 0.5, rtol: 1e-8, output_interval: 0.0005}\n";
  const LoadedModel loaded = testing::loaded_from_text(text);
  const Model& model = loaded.model;
  const RunReport report = run_model(model, loaded.run_spec, "");
  REQUIRE(report.outcome.ok);
  const Responses& r = report.responses;
  CHECK(r.vertical_yield_force == Approx(1.0e4));
  INFO("max vertical force " << r.max_vertical_force << ", override " << r.overridden << " at " << r.override_time);
  REQUIRE(r.overridden);
  CHECK(r.max_vertical_force > r.vertical_yield_force);  // it yielded before overriding
  // After override (override_velocity_at: override, the variant from before issue 40):
  // R2 = 1 + |relative horizontal velocity at the override| / reference velocity.
  CHECK(r.override_relative_velocity == r.relative_velocity_at_override);
  CHECK(r.r2 == Approx(1.0 + r.override_relative_velocity / 4.0));
  CHECK(r.override_relative_velocity > 0.0);
  CHECK(r.override_relative_velocity < 2.0);  // the crush slowed it down
  CHECK(r.r3 == Approx(r.r1 + r.r2));
}

TEST_CASE("responses input errors", "[responses]") {
  CHECK_THROWS_WITH(crush_model("responses:\n  crush_gauges:\n    - {name: s, points: [{body: ground}, {body: mass}]}\n"),
                    Catch::Contains("reference_crush"));
  CHECK_THROWS_WITH(crush_model("responses:\n  anticlimber: crush\n  reference_velocity: 1\n"),
                    Catch::Contains("must name an element of type anticlimber") || Catch::Contains("anticlimber"));
  CHECK_THROWS_WITH(crush_model("responses:\n  crush_gauges: []\n  crush: average\n"), Catch::Contains("total or largest"));
}

TEST_CASE("R1 from the anticlimber's crush: a car end into a fixed anticlimber, closed form", "[responses]") {
  // 1000 kg at 2 m/s: elastic to 0.01 m (500 J), then 1e5 N + 1e5 N/m beyond: the remaining
  // 1500 J give u^2 + 2u - 0.03 = 0, u = sqrt(1.03) - 1, largest crush 0.01 + u.
  const std::string text = testing::anticlimber_r1_model_text(0.2);
  const LoadedModel loaded = testing::loaded_from_text(text);
  const RunReport report = run_model(loaded.model, loaded.run_spec, "");
  REQUIRE(report.outcome.ok);
  const double crush = 0.01 + std::sqrt(1.03) - 1.0;
  CHECK(report.responses.max_anticlimber_crush == Approx(crush).epsilon(1e-5));
  CHECK(report.responses.r1 == Approx(crush / 0.02).epsilon(1e-5));
  CHECK_FALSE(report.responses.overridden);
  CHECK(report.responses.r2 == Approx(0.0).margin(1e-9));  // no vertical load
}

// ---- summary.json extras: peak accelerations and the crush of each car (results.hpp) ----

namespace {

std::string temporary_folder(const std::string& name) {
  const auto path = testing::temp_path("railcrash_test_" + name);
  std::filesystem::remove_all(path);
  return path.string();
}

}  // namespace

TEST_CASE("peak deceleration and crush of the crush-impact case match the closed form under both integrators", "[responses]") {
  // On the structure's plateau the force is F0 = 100 kN on 100 kg: 1000 m/s^2 (101.97 g);
  // largest crush 0.055 m (crush_impact.yaml). The mass is one car: its body declares `car: car`.
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    LoadedModel loaded = crush_model("");
    loaded.run_spec.simulation.integrator = std::string(integrator) == "ida" ? IntegratorKind::Ida : IntegratorKind::Euler;
    loaded.run_spec.simulation.dt = 2e-6;
    const RunReport report = run_model(loaded.model, loaded.run_spec, temporary_folder(std::string("peaks_") + integrator));
    REQUIRE(report.outcome.ok);
    REQUIRE(report.acceleration_peaks.size() == 1);
    const AccelerationPeaks& p = report.acceleration_peaks[0];
    CHECK(p.x == Approx(1000.0).epsilon(1e-6));
    CHECK(p.magnitude == Approx(1000.0).epsilon(1e-6));
    CHECK(p.y == Approx(0.0).margin(1e-9));
    CHECK(p.magnitude / standard_gravity(loaded.model) == Approx(1000.0 / 9.80665).epsilon(1e-6));
    REQUIRE(report.car_crush.size() == 1);
    CHECK(report.car_crush[0].car == "car");
    CHECK(report.car_crush[0].max_crush == Approx(0.055).epsilon(5e-3));
  }
}

TEST_CASE("peak acceleration of a pendulum released from the horizontal includes the joint reaction", "[responses]") {
  // Rigid pendulum (mass m, inertia I about its centre, centre at L from the pin) released at
  // rest with its arm horizontal: at the bottom no moment acts and the centre moves on its
  // circle with omega^2 = 2 m g L / (I + m L^2), so |a| = omega^2 L = 2 g m L^2 / (I + m L^2),
  // the largest acceleration of the swing (at angle phi below the horizontal
  // |a|^2 = (a_t cos phi)^2 + (omega^2 L)^2 grows to it). Without the reaction -G^T lambda
  // the acceleration would be gravity's alone.
  const double g = 9.81, m = 2.0, inertia = 0.1, length = 1.0;
  const std::string text =
      "railcrash: 1\nname: pendulum\nunits: SI\ngravity: [0, -9.81]\nbodies:\n"
      "  - {name: bob, mass: 2, inertia: 0.1, position: [1, 0]}\nelements:\n"
      "  - {name: hinge, type: pin_joint, points: [{body: ground, at: [0, 0]}, {body: bob, at: [-1, 0]}]}\n"
      "simulation: {t_end: 0.8, rtol: 1e-9, output_interval: 0.0005, dt: 1e-5}\n";
  const double expected = 2.0 * g * m * length * length / (inertia + m * length * length);
  for (const char* integrator : {"ida", "euler"}) {
    INFO(integrator);
    LoadedModel loaded = testing::loaded_from_text(text);
    Model& model = loaded.model;
    loaded.run_spec.simulation.integrator = std::string(integrator) == "ida" ? IntegratorKind::Ida : IntegratorKind::Euler;
    const RunReport report = run_model(model, loaded.run_spec, temporary_folder(std::string("pendulum_") + integrator));
    REQUIRE(report.outcome.ok);
    const AccelerationPeaks& p = report.acceleration_peaks.at(0);
    CHECK(p.magnitude == Approx(expected).epsilon(std::string(integrator) == "ida" ? 1e-4 : 1e-2));
    // At the bottom the acceleration points up at the pin: |y''| peaks there too.
    CHECK(p.y == Approx(expected).epsilon(std::string(integrator) == "ida" ? 1e-4 : 1e-2));
  }
}

TEST_CASE("R2's window: the whole run, until the largest crush or until separation, closed form", "[responses]") {
  // A 1000 kg point mass at (0.002, 0) moving at (-2, 0.2) m/s into an anticlimber face on
  // ground (no gravity). The faces meet at t_c = 1 ms. Horizontally (closed form, see the R1
  // case): elastic at 1e7 N/m to 0.01 m (Omega = 100 rad/s, sin(Omega t1) = 0.5: t1 = 5.236 ms,
  // speed 2 cos 30 deg = 1.732 m/s), then 1e5 N + 1e5 N/m (u'' + 100 u = -100, u = -1 + cos 10t
  // + 0.1732 sin 10t, largest crush at tan 10t = 0.1732: 17.151 ms later), then elastic
  // unloading to zero force in a quarter period pi / (2 Omega) = 15.708 ms. Vertically the
  // interlock is elastic (1e6 N/m, omega = 31.623 rad/s, amplitude 0.2 / omega = 6.32 mm, below
  // the 0.01 m yield) and independent of the horizontal motion (the mass has no arm):
  // V(t) = 1e6 (0.2 / omega) sin(omega (t - t_c)) while the faces are engaged.
  const auto run = [](const std::string& window) {
    const std::string text = "railcrash: 1\nname: window\nunits: SI\ngravity: [0, 0]\nbodies:\n"
                                  "  - {name: car, mass: 1000, inertia: 100, position: [0.002, 0], velocity: [-2, 0.2]}\nelements:\n"
                                  "  - name: ac\n    type: anticlimber\n"
                                  "    horizontal_elastic_stiffness: 1.0e7\n    horizontal_plastic_stiffness: 1.0e5\n"
                                  "    horizontal_yield_deflection: 0.01\n"
                                  "    vertical_elastic_stiffness: 1.0e6\n    vertical_plastic_stiffness: 1.0e4\n"
                                  "    vertical_yield_deflection: 0.01\n"
                                  "    torsional_elastic_stiffness: 1.0e6\n    torsional_plastic_stiffness: 1.0e4\n"
                                  "    torsional_yield_deflection: 0.01\n"
                                  "    face_height: 0.1\n    points: [{body: ground, at: [0, 0]}, {body: car, at: [0, 0]}]\n"
                                  "responses:\n  anticlimber: ac\n  reference_velocity: 4.0\n  collision_post_distance: 1.0\n" +
                                  (window.empty() ? std::string() : "  vertical_force_window: " + window + "\n") +
                                  "simulation: {t_end: 0.08, rtol: 1e-9, output_interval: 1.0e-5}\n";
    const LoadedModel loaded = testing::loaded_from_text(text);
    const RunReport report = run_model(loaded.model, loaded.run_spec, "");
    REQUIRE(report.outcome.ok);
    REQUIRE_FALSE(report.responses.overridden);
    return report.responses.max_vertical_force;
  };
  const double omega = std::sqrt(1.0e3), amplitude = 1.0e6 * 0.2 / omega;
  const double t1 = (M_PI / 6.0) / 100.0, t_plastic = std::atan(std::sqrt(3.0) / 10.0) / 10.0, t_unload = M_PI / 200.0;
  const double at_largest_crush = amplitude * std::sin(omega * (t1 + t_plastic));
  const double at_separation = amplitude * std::sin(omega * (t1 + t_plastic + t_unload));
  CHECK(at_largest_crush == Approx(4113).epsilon(1e-3));  // the numbers in the comment
  CHECK(at_separation == Approx(5905).epsilon(1e-3));
  // The peaks are taken at every step's end and on both sides of every event (the window
  // closes after the side before its event): each is the force at its event, to the
  // integrator's tolerance, whatever the output rows (it was up to one row, 1e-5 s, early).
  const auto at_the_event = [&](double peak, double exact) {
    INFO("peak " << peak << ", closed form " << exact);
    CHECK(peak == Approx(exact).epsilon(1e-6));
  };
  at_the_event(run("until_largest_crush"), at_largest_crush);
  at_the_event(run("until_separation"), at_separation);
  // After the separation the faces carry nothing: the whole run's peak is the separation's.
  at_the_event(run(""), at_separation);
  at_the_event(run("whole_run"), at_separation);
  CHECK_THROWS_WITH(load_model_text(testing::anticlimber_r1_model_text(0.1), "r1.yaml", {"responses.vertical_force_window=later"}),
                    Catch::Contains("vertical_force_window must be whole_run, until_largest_crush or until_separation"));
}

namespace {

// A 1000 kg car end at x = 0.1 m moving at -2 m/s towards an anticlimber face on ground at
// x = 0, braked by a constant 1000 N (deceleration 1 m/s^2), no gravity. Its face is 0.2 m
// above the ground face, more than the 0.1 m face height: the faces miss each other at contact
// (x = 0) and override. From there the faces' approach is d_h = -x.
RunReport override_run(const std::string& responses_extra) {
  const std::string text =
      "railcrash: 1\nname: post\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: car, mass: 1000, inertia: 100, position: [0.1, 0], velocity: [-2, 0]}\nelements:\n"
      "  - name: ac\n    type: anticlimber\n"
      "    horizontal_elastic_stiffness: 1.0e7\n    horizontal_plastic_stiffness: 1.0e5\n    horizontal_yield_deflection: 0.01\n"
      "    vertical_elastic_stiffness: 1.0e6\n    vertical_plastic_stiffness: 1.0e4\n    vertical_yield_deflection: 0.01\n"
      "    torsional_elastic_stiffness: 1.0e6\n    torsional_plastic_stiffness: 1.0e4\n    torsional_yield_deflection: 0.01\n"
      "    face_height: 0.1\n    initial_misalignment: 0.2\n"
      "    points: [{body: ground, at: [0, 0]}, {body: car, at: [0, 0]}]\n"
      "loads:\n  - {type: force, body: car, at: [0, 0], value: [1000, 0]}\n"
      "responses:\n  anticlimber: ac\n  reference_velocity: 4.0\n" + responses_extra +
      "simulation: {t_end: 2.5, rtol: 1e-9, output_interval: 0.001}\n";
  const LoadedModel loaded = testing::loaded_from_text(text);
  const RunReport report = run_model(loaded.model, loaded.run_spec, "");
  REQUIRE(report.outcome.ok);
  REQUIRE(report.responses.overridden);
  return report;
}

}  // namespace

TEST_CASE("R2 after override takes the relative velocity when the end sill reaches the collision post, closed form",
          "[responses]") {
  // Uniform deceleration a = 1 m/s^2 from 2 m/s at x = 0.1: v^2 = 4 - 2 a (0.1 - x).
  // Override at x = 0: v = sqrt(3.8) = 1.94936 m/s, t = 2 - sqrt(3.8) = 0.050641 s.
  // The collision post 0.5 m behind the face (approach d_h = 0.5, x = -0.5):
  // v = sqrt(2.8) = 1.67332 m/s, t = 2 - sqrt(2.8) = 0.326680 s; R2 = 1 + 1.67332 / 4.
  const RunReport at_post = override_run("  collision_post_distance: 0.5\n");
  const Responses& r = at_post.responses;
  CHECK(r.override_time == Approx(2.0 - std::sqrt(3.8)).epsilon(1e-6));
  CHECK(r.relative_velocity_at_override == Approx(std::sqrt(3.8)).epsilon(1e-6));
  REQUIRE(r.collision_post_reached);
  CHECK(r.collision_post_time == Approx(2.0 - std::sqrt(2.8)).epsilon(1e-5));
  CHECK(r.override_relative_velocity == Approx(std::sqrt(2.8)).epsilon(1e-6));
  CHECK(r.r2 == Approx(1.0 + std::sqrt(2.8) / 4.0).epsilon(1e-6));
  // The default distance is reference_crush (the report's "distance from the anticlimber to
  // the collision post" defines both).
  const RunReport by_default = override_run("  crush: anticlimber\n  reference_crush: 0.5\n");
  CHECK(by_default.responses.override_relative_velocity == Approx(std::sqrt(2.8)).epsilon(1e-6));
  // The variant from before issue 40: the velocity at the override.
  const RunReport at_override = override_run("  collision_post_distance: 0.5\n  override_velocity_at: override\n");
  CHECK(at_override.responses.r2 == Approx(1.0 + std::sqrt(3.8) / 4.0).epsilon(1e-6));
  // A post farther than the car ever gets (it stops at x = -1.9, d_h = 1.9): never hit, R2 = 1.
  const RunReport never = override_run("  collision_post_distance: 3.0\n");
  CHECK_FALSE(never.responses.collision_post_reached);
  CHECK(never.responses.r2 == 1.0);
  // Without a distance (no reference_crush either) the report's R2 cannot be taken.
  CHECK_THROWS_WITH(testing::model_from_text(
                        "railcrash: 1\nname: x\nunits: SI\nbodies:\n  - {name: car, mass: 1, inertia: 1, position: [0.1, 0]}\n"
                        "elements:\n  - name: ac\n    type: anticlimber\n"
                        "    horizontal_elastic_stiffness: 1.0e7\n    horizontal_plastic_stiffness: 1.0e5\n"
                        "    horizontal_yield_deflection: 0.01\n    vertical_elastic_stiffness: 1.0e6\n"
                        "    vertical_plastic_stiffness: 1.0e4\n    vertical_yield_deflection: 0.01\n"
                        "    torsional_elastic_stiffness: 1.0e6\n    torsional_plastic_stiffness: 1.0e4\n"
                        "    torsional_yield_deflection: 0.01\n    face_height: 0.1\n"
                        "    points: [{body: ground, at: [0, 0]}, {body: car, at: [0, 0]}]\n"
                        "responses:\n  anticlimber: ac\n  reference_velocity: 4.0\n"
                        "simulation: {t_end: 0.1}\n"),
                    Catch::Contains("collision_post_distance"));
}

namespace {

// A 1000 kg car end (pitch inertia 100 kg m^2) whose anticlimber face is 0.5 m ahead of its
// centre of mass, driven at 2 m/s into a face on ground, no gravity. With the face centre at
// the height of the centre of mass the horizontal force has no arm and nothing loads the
// interlock vertically.
double largest_vertical_force(const std::string& car_point_y, const std::string& misalignment) {
  const std::string text =
      "railcrash: 1\nname: p9\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: car, mass: 1000, inertia: 100, position: [0.51, 0], velocity: [-2, 0]}\nelements:\n"
      "  - name: ac\n    type: anticlimber\n"
      "    horizontal_elastic_stiffness: 1.0e7\n    horizontal_plastic_stiffness: 1.0e5\n    horizontal_yield_deflection: 0.01\n"
      "    vertical_elastic_stiffness: 1.0e6\n    vertical_plastic_stiffness: 1.0e4\n    vertical_yield_deflection: 0.01\n"
      "    torsional_elastic_stiffness: 1.0e6\n    torsional_plastic_stiffness: 1.0e4\n    torsional_yield_deflection: 0.01\n"
      "    face_height: 0.1\n" + misalignment +
      "    points: [{body: ground, at: [0, 0]}, {body: car, at: [-0.5, " + car_point_y + "]}]\n"
      "responses:\n  anticlimber: ac\n  reference_velocity: 4.0\n  collision_post_distance: 1.0\n"
      "simulation: {t_end: 0.06, rtol: 1e-9, output_interval: 0.0005}\n";
  const LoadedModel loaded = testing::loaded_from_text(text);
  const RunReport report = run_model(loaded.model, loaded.run_spec, "");
  REQUIRE(report.outcome.ok);
  REQUIRE_FALSE(report.responses.overridden);
  return report.responses.max_vertical_force;
}

}  // namespace

TEST_CASE("P9: the initial misalignment is where face 2 is, so the horizontal force pitches the car ends", "[responses]") {
  const double aligned = largest_vertical_force("0", "");
  CHECK(aligned == Approx(0.0).margin(1e-6));
  // Face 2 0.03 m above point 2: the same model as point 2 at the face centre.
  const double misaligned = largest_vertical_force("0", "    initial_misalignment: 0.03\n");
  const double at_face_centre = largest_vertical_force("0.03", "");
  CHECK(misaligned == Approx(at_face_centre).epsilon(1e-9));
  // The horizontal force (about 1.1e5 N) acts 0.03 m above the car's centre of mass: the car
  // pitches and its face, 0.5 m ahead, moves down on the interlock.
  CHECK(misaligned > 1000.0);
  // The variant from before issue 40 (misalignment_geometry: offset): the interlock takes the
  // offset at contact as its reference, so a constant misalignment changes nothing.
  const double offset_only =
      largest_vertical_force("0", "    initial_misalignment: 0.03\n    misalignment_geometry: offset\n");
  CHECK(offset_only == Approx(aligned).margin(1e-6));
}
