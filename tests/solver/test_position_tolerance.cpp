// IDA's two forms of the positions' tolerance (simulation: position_tolerance; README "Position
// tolerances"): relative, SUNDIALS' rtol |q| + atol, and absolute, atol alone (by default rtol
// times the speed scale over the model's highest frequency).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/accuracy_check.hpp"
#include "railcrash/results/run.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

/// A 1 kg mass on a 1e4 N/m spring to a ground point, both `offset` m along x from the origin,
/// let go 10 mm stretched: x(t) = offset + 1 + 0.01 cos(100 t).
std::string oscillator(double offset, const char* position_tolerance) {
  std::ostringstream s;
  s.precision(17);
  s << "railcrash: 1\nname: oscillator\nunits: SI\ngravity: [0, 0]\nbodies:\n"
    << "  - {name: m, mass: 1, inertia: 1, position: [" << offset + 1.01 << ", 0]}\n"
    << "elements:\n  - {name: k, type: linear_spring, stiffness: 1.0e4, free_length: 1, points: [{body: ground, at: ["
    << offset << ", 0]}, {body: m, at: [0, 0]}]}\n"
    << "simulation: {t_end: 0.5, integrator: ida, rtol: 1.0e-6, output_interval: 0.5, position_tolerance: "
    << position_tolerance << "}\n";
  return s.str();
}

struct Oscillation {
  long steps = 0;
  double error = 0.0;  // [m] |x(t_end) - exact|
  double origin_distance_in_sizes = 0.0;  // RunStatistics'
  std::vector<std::string> warnings;      // the run's accuracy warnings
};

Oscillation oscillate(double offset, const char* position_tolerance) {
  const LoadedModel loaded = testing::loaded_from_text(oscillator(offset, position_tolerance));
  const RunOutcome outcome = testing::simulate(loaded, 0.5);
  return {outcome.stats.steps, std::abs(outcome.y[0] - (offset + 1.0 + 0.01 * std::cos(100.0 * 0.5))),
          outcome.stats.origin_distance_in_sizes, accuracy_warnings(accuracy_facts(outcome, "ida", UnitSystem::SI))};
}

double largest_crush(const LoadedModel& loaded) {
  const RunReport report = run_model(loaded.model, loaded.run_spec, "", nullptr, false, /*keep_in_memory=*/true);
  INFO(report.outcome.message);
  REQUIRE(report.outcome.ok);
  double largest = 0.0;  // [m]
  for (const CarCrush& car : report.car_crush) largest = std::max(largest, car.max_crush);
  return largest;
}

}  // namespace

TEST_CASE("position_tolerance: absolute holds positions alike wherever the model lies, relative loosens with the distance",
          "[solver][ida]") {
  // 10 km along the track, rtol |q| is 1e-2 m in the relative form: the 10 mm swing is hardly
  // held at all. The absolute form's tolerance does not depend on where the spring is.
  const Oscillation near_absolute = oscillate(0.0, "absolute"), far_absolute = oscillate(1.0e4, "absolute");
  const Oscillation near_relative = oscillate(0.0, "relative"), far_relative = oscillate(1.0e4, "relative");
  INFO("steps: absolute " << near_absolute.steps << " / " << far_absolute.steps << ", relative " << near_relative.steps
                          << " / " << far_relative.steps);
  INFO("errors [m]: absolute " << near_absolute.error << " / " << far_absolute.error << ", relative " << near_relative.error
                               << " / " << far_relative.error);
  CHECK(std::abs(far_absolute.steps - near_absolute.steps) <= near_absolute.steps / 50);
  CHECK(far_absolute.error < 1e-6);
  CHECK(near_absolute.error < 1e-6);
  CHECK(far_relative.steps < near_relative.steps / 2);
  CHECK(far_relative.error > 10.0 * far_absolute.error);
  // The relative run 10 km out says so (the spring and its mass span 1.01 m: 9,900 sizes from
  // the origin); the runs at the origin and the absolute one say nothing.
  CHECK(near_relative.origin_distance_in_sizes == Approx(1.0));
  CHECK(far_relative.origin_distance_in_sizes == Approx((1.0e4 + 1.01) / 1.01).epsilon(1e-9));
  CHECK(far_absolute.origin_distance_in_sizes == 0.0);
  CHECK(near_relative.warnings.empty());
  CHECK(near_absolute.warnings.empty());
  CHECK(far_absolute.warnings.empty());
  // (It also lost 2.5 % of its energy: that warning comes first.)
  REQUIRE(!far_relative.warnings.empty());
  CHECK_THAT(far_relative.warnings.back(), Catch::Contains("sits 9.9e+03 times its own size from its origin") &&
                                               Catch::Contains("position_tolerance: absolute"));
}

TEST_CASE("position_tolerance: absolute gets a 3+3-car unit's largest crush to 0.5 % at rtol 1e-3", "[solver][ida]") {
  // mu_3plus3_si (bench/mu_model.py): crush zones of 1.5-1.7 MN behind 1e9 N/m anticlimbers on
  // 800 kg end structures. In the relative form IDA at rtol 1e-3 allows 12-60 mm per step in the
  // positions, and its order-1 steps lose the work of the crush forces on the ends' extra
  // motion: 2.4 % of the largest crush. The reference: the same model at rtol 1e-8.
  const std::string path = std::string(RAILCRASH_SOURCE_DIR) + "/models/examples/mu_3plus3_si.yaml";
  const double reference = largest_crush(load_model(path, {"simulation.integrator=ida", "simulation.rtol=1e-8"}));
  const double absolute = largest_crush(
      load_model(path, {"simulation.integrator=ida", "simulation.rtol=1e-3", "simulation.position_tolerance=absolute"}));
  const double relative = largest_crush(load_model(path, {"simulation.integrator=ida", "simulation.rtol=1e-3"}));
  INFO("largest crush [m]: reference " << reference << ", absolute " << absolute << ", relative " << relative);
  CHECK(reference == Approx(0.7848).epsilon(1e-3));
  CHECK(absolute == Approx(reference).epsilon(5e-3));
  CHECK(std::abs(relative / reference - 1.0) > 1e-2);
}

TEST_CASE("position_tolerance: the model file's key takes relative or absolute, and names the line of anything else",
          "[solver][ida][model]") {
  CHECK(testing::loaded_from_text(oscillator(0.0, "absolute")).run_spec.simulation.position_tolerance ==
        PositionTolerance::Absolute);
  CHECK(testing::loaded_from_text(oscillator(0.0, "relative")).run_spec.simulation.position_tolerance ==
        PositionTolerance::Relative);
  try {
    testing::loaded_from_text(oscillator(0.0, "tight"));
    FAIL("a position_tolerance of 'tight' was taken");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::Contains("test.yaml:9"));
    CHECK_THAT(e.what(), Catch::Contains("position_tolerance must be relative"));
    CHECK_THAT(e.what(), Catch::Contains("not 'tight'"));
  }
}
