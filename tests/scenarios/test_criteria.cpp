// Scenario criteria against hand-computed histories, and the `scenario:` section's checks.
#include <catch2/catch.hpp>

#include <cmath>

#include "railcrash/core/error.hpp"
#include "railcrash/elements/anticlimber.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/scenario_criteria.hpp"

using namespace railcrash;

namespace {

/// vx(t): v0 until t0, then falling at `deceleration` until t1, then constant; sampled every dt.
void ramp(double v0, double deceleration, double t0, double t1, double t_end, double dt, std::vector<double>& t, std::vector<double>& v) {
  for (int k = 0; k * dt <= t_end + 1e-12; ++k) {
    const double time = k * dt;
    t.push_back(time);
    v.push_back(v0 - deceleration * std::clamp(time - t0, 0.0, t1 - t0));
  }
}

const char* kTwoCarts = R"(railcrash: 1
name: two carts
units: SI
gravity: [0, 0]
bodies:
  - {name: a, mass: 1000, inertia: 100, position: [0, 1]}
  - {name: b, mass: 1000, inertia: 100, position: [3, 1]}
elements:
  - name: faces
    type: anticlimber
    horizontal_elastic_stiffness: 1.0e7
    horizontal_plastic_stiffness: 1.0e5
    horizontal_yield_deflection: 0.01
    horizontal_rupture_deflection: 1
    vertical_elastic_stiffness: 1.0e6
    vertical_plastic_stiffness: 1.0e4
    vertical_yield_deflection: 0.01
    vertical_rupture_deflection: 1
    torsional_elastic_stiffness: 1.0e6
    torsional_plastic_stiffness: 1.0e4
    torsional_yield_deflection: 0.01
    torsional_rupture_deflection: 1
    face_height: 0.2
    length: 2
    points:
      - {body: a, at: [1.5, 0]}
      - {body: b, at: [-1.5, 0]}
simulation: {t_end: 0.1}
scenario:
  standard: EN 15227
  number: 1
  category: C-I
  closing_speed: 10
  mean_deceleration: {limit: 49.0, source: test, bodies: [a, b]}
  survival_space: {limit: 0.05, source: test, gauges: [{name: ab, front: a, rear: b}]}
  override: {limit: 0.1, source: test, interface: faces, wheel_lift_limit: 0.02, wheel_lift_source: test, wheels: [WHEELS]}
)";

std::string with(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

}  // namespace

TEST_CASE("scenario criteria: mean deceleration of a constant-deceleration pulse", "[scenario]") {
  std::vector<double> t, v;
  // 10 m/s falling at 50 m/s^2 from 0.1 s to 0.3 s: mean deceleration 50 m/s^2 (hand: 10 / 0.2).
  ramp(10.0, 50.0, 0.1, 0.3, 0.5, 0.005, t, v);  // 5 ms samples: too coarse for CFC 60, unfiltered
  bool complete = false;
  CHECK(filtered_mean_deceleration(t, v, 60.0, &complete) == Approx(50.0).epsilon(1e-12));
  CHECK(complete);
  t.clear();
  v.clear();
  // Filtered at CFC 60 (1e-4 s samples): the filter rounds each corner over about one period of
  // its design frequency fd = 2.0775 x 60 Hz, so the collision found starts and ends at most
  // 1 / fd = 8.0 ms beyond the ramp's corners: 50 x 0.2 / (0.2 + 2 / fd) < mean < 50.
  ramp(10.0, 50.0, 0.1, 0.3, 0.5, 1e-4, t, v);
  const double filtered = filtered_mean_deceleration(t, v, 60.0, &complete);
  const double design_frequency = 2.0775 * 60.0;  // [Hz]
  CHECK(filtered < 50.0);
  CHECK(filtered > 50.0 * 0.2 / (0.2 + 2.0 / design_frequency));
  // A pulse still going at the end of the record is flagged.
  t.clear();
  v.clear();
  ramp(10.0, 50.0, 0.1, 0.3, 0.2, 0.005, t, v);
  filtered_mean_deceleration(t, v, 60.0, &complete);
  CHECK_FALSE(complete);
}

TEST_CASE("scenario criteria: shortening, vertical change and wheel lift of hand histories", "[scenario]") {
  CHECK(largest_shortening({10.0, 9.9, 9.5, 9.7, 10.2}) == Approx(0.5));
  CHECK(largest_shortening({10.0, 10.1, 10.3}) == 0.0);
  CHECK(largest_change({0.04, 0.05, -0.02, 0.01}) == Approx(0.06));
  CHECK(largest_lift({0.001, 0.0, -0.004, -0.002}) == Approx(0.004));
  CHECK(largest_lift({0.001, 0.002}) == 0.0);
  // A car's crush at one time: only the positive parts count, an element between two cars by half.
  const double outputs[] = {9.0, 0.6, 0.2, -0.1};  // the car's columns are 2, 3 and 1
  CHECK(shared_crush(outputs, {2, 3, 1}, {1.0, 1.0, 0.5}) == Approx(0.2 + 0.0 + 0.3));
  CHECK(shared_crush(outputs, {}, {}) == 0.0);
}

TEST_CASE("scenario criteria: survival-space cars, excluded elements and the interface are checked", "[scenario]") {
  std::string text = with(kTwoCarts, "wheels: [WHEELS]", "wheels: [faces]");
  text = with(text, "{name: a, mass: 1000,", "{name: a, car: car_a, mass: 1000,");
  const auto error = [](const std::string& model) {
    try {
      load_model_text(model, "cases.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string gauges = "gauges: [{name: ab, front: a, rear: b}]";
  CHECK_THAT(error(with(text, gauges, "cars: [car_b]")), Catch::Contains("cases.yaml:35") && Catch::Contains("no body declares 'car: car_b'"));
  CHECK_THAT(error(with(text, gauges, "cars: [car_a], excluded: [face]")), Catch::Contains("excluded: no element named 'face'"));
  CHECK_THAT(error(with(text, ", " + gauges, "")), Catch::Contains("give 'cars: [..]'"));
  // Only scenario 3 (an obstacle) goes without an interface, and then has no override limit.
  const std::string no_interface = with(text, "limit: 0.1, source: test, interface: faces, ", "");
  CHECK_THAT(error(no_interface), Catch::Contains("only scenario 3 (an obstacle) has no interface"));
  CHECK_THAT(error(with(with(text, "number: 1", "number: 3"), "interface: faces, ", "")), Catch::Contains("'limit' and 'source' belong to an interface"));
  CHECK_THAT(error(with(no_interface, "number: 1", "number: 3")), Catch::Contains("faces' is of type anticlimber"));  // the rest still checked
}

TEST_CASE("scenario criteria: the section is checked with file:line messages", "[scenario]") {
  const std::string no_wheels = with(kTwoCarts, "wheels: [WHEELS]", "wheels: [faces]");
  try {
    load_model_text(no_wheels, "cases.yaml");
    FAIL("a wheel list naming an anticlimber was accepted");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::Contains("cases.yaml:36") && Catch::Contains("'faces' is of type anticlimber; it must be of type wheel_rail"));
  }
  try {
    load_model_text(with(no_wheels, "category: C-I", "category: C-V"), "cases.yaml");
    FAIL("category C-V was accepted");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::Contains("cases.yaml:32") && Catch::Contains("C-I, C-II, C-III or C-IV"));
  }
  try {
    load_model_text(with(no_wheels, "rear: b", "rear: c"), "cases.yaml");
    FAIL("an unknown gauge body was accepted");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::Contains("cases.yaml:35") && Catch::Contains("no body named 'c'"));
  }
}

TEST_CASE("scenario criteria: a misspelt or repeated key is named with the closest key and the allowed ones", "[scenario]") {
  // The section's keys go through the model file's one key check (before: no suggestion, a repeated key taken).
  const std::string text = with(kTwoCarts, "wheels: [WHEELS]", "wheels: [faces]");
  try {
    load_model_text(with(text, "{limit: 49.0, source: test,", "{limit: 49.0, sorce: test,"), "cases.yaml");
    FAIL("a misspelt key was accepted");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::StartsWith("cases.yaml:34: scenario: mean_deceleration: unknown key 'sorce' (did you mean 'source'?); "
                                           "allowed keys: limit, cfc, source, bodies"));
  }
  try {
    load_model_text(with(text, "{limit: 49.0, source: test,", "{limit: 49.0, limit: 50.0, source: test,"), "cases.yaml");
    FAIL("a repeated key was accepted");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::StartsWith("cases.yaml:34: scenario: mean_deceleration: key 'limit' is given twice; keep only one"));
  }
}

TEST_CASE("scenario criteria: an anticlimber is known by one check, of its type name or of the element", "[scenario]") {
  std::string flat = kTwoCarts;
  flat = flat.substr(0, flat.find("scenario:"));
  flat = with(flat, "    face_height: 0.2\n", "    face_height: 0.2\n    facing: 1\n");  // the faces touch at the start
  flat = with(flat, "simulation:", "  - {name: s, type: linear_spring, stiffness: 1.0, free_length: 3.0, points: [{body: a}, {body: b}]}\nsimulation:");
  const Model model = load_model_text(flat, "cases.yaml").model;
  REQUIRE(model.elements().size() == 2);
  const Anticlimber* faces = as_anticlimber(*model.elements()[0]);
  REQUIRE(faces != nullptr);
  CHECK(faces->name() == "faces");
  CHECK(faces->horizontal.elastic_stiffness == 1.0e7);
  CHECK(as_anticlimber(*model.elements()[1]) == nullptr);
  CHECK(is_anticlimber_type(model.elements()[0]->type()));
  CHECK_FALSE(is_anticlimber_type(model.elements()[1]->type()));
  CHECK_FALSE(is_anticlimber_type("Anticlimber"));
}
