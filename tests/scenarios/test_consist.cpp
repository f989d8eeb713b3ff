// Consists built from the report's two-car model: structure, geometry and a quiet start of
// the couplings (faces touching, no force) checked against the template's own numbers.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "railcrash/core/error.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/scenarios/consist.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

const std::string kTemplate = std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml";

const Body& body_named(const Model& model, const std::string& name) {
  for (const Body& b : model.bodies())
    if (b.name == name) return b;
  FAIL("no body " << name);
  throw std::logic_error("unreachable");
}

double output_of(const DaeSystem& system, const std::vector<double>& y, const std::string& name) {
  std::vector<double> out(system.output_names().size());
  system.outputs(y.data(), y.data() + 2 * system.body_unknowns(), out.data());
  for (std::size_t k = 0; k < out.size(); ++k)
    if (system.output_names()[k] == name) return out[k];
  FAIL("no output " << name);
  return 0.0;
}

}  // namespace

TEST_CASE("consist: three cars per side keep the template's cars, shifted by the car length", "[consist]") {
  const Model pair = load_model(kTemplate).model;
  const Model train = testing::model_from_text(make_consist_model(kTemplate, 3));
  REQUIRE(train.body_count() == 3 * pair.body_count());
  // Every template element per car, the two interface elements once, two couplings per extra car.
  REQUIRE(train.elements().size() == 3 * (pair.elements().size() - 2) + 2 + 2 * 2);
  double pair_mass = 0.0, train_mass = 0.0;
  for (const Body& b : pair.bodies()) pair_mass += b.mass;
  for (const Body& b : train.bodies()) train_mass += b.mass;
  CHECK(train_mass == Approx(3.0 * pair_mass).epsilon(1e-12));

  // Length over the coupler faces: twice the centre body's distance from the faces at x = 0.
  const double length_s = 2.0 * std::abs(body_named(pair, "car1_center_body").x);
  const double length_t = 2.0 * std::abs(body_named(pair, "car2_center_body").x);
  CHECK(body_named(train, "s3_rear_body").x == Approx(body_named(pair, "car1_rear_body").x - 2.0 * length_s));
  CHECK(body_named(train, "t2_coupler").x == Approx(body_named(pair, "car2_coupler").x + length_t));
  CHECK(body_named(train, "s2_center_body").vx == body_named(pair, "car1_center_body").vx);
  CHECK(body_named(train, "t3_front_truck").vx == 0.0);
  CHECK(body_named(train, "s1_coupler").x == body_named(pair, "car1_coupler").x);
  // Each generated car declares itself: the bodies renamed s<k>_ / t<k>_ form car s<k> / t<k>,
  // so the summary has six cars, each with the template car's bodies.
  for (const Body& b : train.bodies()) {
    INFO(b.name);
    CHECK(b.car == b.name.substr(0, b.name.find('_')));
  }
  const std::vector<CarCrush> cars = cars_of(DaeSystem(train));
  REQUIRE(cars.size() == 6);
  for (const CarCrush& car : cars) CHECK(car.bodies.size() * 2 == static_cast<std::size_t>(pair.body_count()));
}

TEST_CASE("consist: couplings start with the faces touching and carry no force", "[consist]") {
  const Model train = testing::model_from_text(make_consist_model(kTemplate, 2));
  DaeSystem system(train);
  const std::vector<double> y = system.initial_state();
  for (const char* coupling : {"s2_coupling", "t2_coupling"}) {
    INFO(coupling);
    CHECK(std::abs(output_of(system, y, std::string(coupling) + ".gap")) < 1e-9);
    CHECK(output_of(system, y, std::string(coupling) + ".normal_force") == Approx(0.0).margin(1e-6));
  }
}

TEST_CASE("consist: a template without the car1_/car2_ naming is refused with the reason", "[consist]") {
  const auto path = testing::temp_path("railcrash_consist_bad.yaml");
  {
    std::ofstream file(path);
    file << "railcrash: 1\nname: x\nunits: SI\nbodies:\n  - {name: a, mass: 1, inertia: 1, position: [0, 0]}\n"
            "elements:\n  - {name: s, type: linear_spring, stiffness: 1, points: [{body: a, at: [0, 0]}, {body: ground, at: [1, 0]}]}\n";
  }
  CHECK_THROWS_WITH(make_consist_model(path.string(), 2), Catch::Contains("coupler_faces"));
  CHECK_THROWS_AS(make_consist_model(path.string(), 0), InputError);
  std::filesystem::remove(path);
}

TEST_CASE("consist: a size that would not fit in memory is refused with the memory it needs", "[consist]") {
  // 2 x 1000 cars at 0.8 MB: 1.6 GB; with 1 GB available at most 1e9 / 1.6e6 = 625 cars per side.
  try {
    check_consist_memory("t.yaml", 1000, 1e9);
    FAIL("accepted");
  } catch (const InputError& e) {
    CHECK_THAT(std::string(e.what()), Catch::Matchers::StartsWith("t.yaml: consist: 1000 + 1000 cars would need about 1.6 GB"));
    CHECK_THAT(std::string(e.what()), Catch::Matchers::Contains("use --cars 625 or fewer"));
  }
  CHECK_NOTHROW(check_consist_memory("t.yaml", 625, 1e9));
  CHECK(available_memory_bytes() > 0.0);
}
