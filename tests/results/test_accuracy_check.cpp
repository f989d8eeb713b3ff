// Accuracy warnings (results/accuracy_check.hpp): the limits on their own, then on a model of
// one's own in SI (models/examples/emu3_unit_collision.yaml) against the report's car.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/accuracy_check.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/dae_system.hpp"

using namespace railcrash;

namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("relative balance error is the energy gained over the energy turned over", "[unit][accuracy]") {
  EnergyBalance e;
  e.initial_total = 1000.0;
  e.kinetic = 300.0;
  e.elastic = 100.0;
  e.gravity = -50.0;
  e.dissipated = 700.0;  // 1050 at the end against 1000 at the start: 50 gained
  e.external_work = 0.0;
  // turned over: max(1000, 300 + 100 + 50 + 700 + 0) = 1150
  CHECK(relative_balance_error(e, 0.0) == Approx(50.0 / 1150.0).epsilon(1e-14));
  // More turned over at some output sample than at the end: that is the scale.
  CHECK(relative_balance_error(e, 2000.0) == Approx(50.0 / 2000.0).epsilon(1e-14));
  CHECK(relative_balance_error(e, 500.0) == Approx(50.0 / 1150.0).epsilon(1e-14));
  EnergyBalance nothing;
  CHECK(relative_balance_error(nothing, 0.0) == 0.0);
}

TEST_CASE("a pendulum from rest that ends at its turning point is not warned about", "[unit][accuracy]") {
  // The pendulum of verification/cases/pendulum.yaml (1 kg on 1 m, released from rest 120
  // degrees from the downward vertical, period 2.754 s) stopped at half its period, at rest at
  // its starting height on the other side: kinetic energy and the change of gravity's
  // potential are both near zero there, so the energy turned over at the end is round-off, and
  // the run's drift of 7e-7 J read "created 100 %". At the bottom it had turned over
  // K + |change of potential| = 2 m g L (1 - cos 120 deg) = 29.4 J.
  const LoadedModel loaded = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/verification/cases/pendulum.yaml",
                                        {"simulation.t_end=1.377"});
  const RunReport report = run_model(loaded.model, loaded.run_spec, "", nullptr, false, /*keep_in_memory=*/true);
  REQUIRE(report.outcome.ok);
  const EnergyBalance end = EnergyBalance::between(report.outcome.initial_energy, report.outcome.final_energy);
  REQUIRE(end.turned_over() < 1e-5);  // [J] the end alone: round-off
  CHECK(report.outcome.most_energy_turned_over == Approx(2.0 * 9.81 * 1.5).epsilon(0.01));  // [J] at the output sample nearest the bottom
  const nlohmann::json summary = nlohmann::json::parse(report.summary_json);
  CHECK(std::abs(summary["energy"]["relative_balance_error"].get<double>()) < 1e-6);
  CHECK(summary["accuracy_warnings"].empty());
}

TEST_CASE("accuracy warnings fire past the stated limits and name what to change", "[unit][accuracy]") {
  AccuracyFacts facts;
  facts.units = UnitSystem::SI;
  facts.euler_ran = true;
  facts.euler_step = 4.0e-4;  // [s]
  facts.relative_balance_error = 0.0099;
  facts.max_constraint_residual = 0.00099;  // [m]
  CHECK(accuracy_warnings(facts).empty());

  facts.relative_balance_error = -0.0101;  // lost
  std::vector<std::string> w = accuracy_warnings(facts);
  REQUIRE(w.size() == 1);
  CHECK(contains(w[0], "lost 1.01 %"));
  CHECK(contains(w[0], "--dt 0.0002"));
  CHECK(contains(w[0], "--integrator ida"));

  facts.relative_balance_error = 0.05;  // created
  facts.max_constraint_residual = 0.0011;
  w = accuracy_warnings(facts);
  REQUIRE(w.size() == 2);
  CHECK(contains(w[0], "created 5 %"));
  CHECK(contains(w[1], "0.0011 m"));

  // in-lbf-s: the limit is 1 mm = 0.03937 in
  facts.units = UnitSystem::InLbfS;
  facts.relative_balance_error = 0.0;
  facts.max_constraint_residual = 0.039;
  CHECK(accuracy_warnings(facts).empty());
  facts.max_constraint_residual = 0.040;
  w = accuracy_warnings(facts);
  REQUIRE(w.size() == 1);
  CHECK(contains(w[0], "0.04 in"));

  // auto that ran Euler for a while and took the run back: the remedy names that part and leaves Euler out
  facts.euler_from = 0.0147;
  facts.ida_took_back_at = 0.0261;
  w = accuracy_warnings(facts);
  REQUIRE(w.size() == 1);
  CHECK(contains(w[0], "integrator auto ran Euler (steps of 0.0004 s) from t = 0.0147 to 0.0261, where IDA took the run back"));
  CHECK(contains(w[0], "--integrator ida"));
  CHECK(contains(w[0], "--rtol"));  // IDA ran most of such a run: its own tolerance may be the cause
  CHECK_FALSE(contains(w[0], "--dt"));
  facts.ida_took_back_at = -1.0;

  // IDA: the remedy is its tolerance, not a step
  facts.euler_ran = false;
  w = accuracy_warnings(facts);
  REQUIRE(w.size() == 1);
  CHECK(contains(w[0], "--rtol"));
  CHECK_FALSE(contains(w[0], "--dt"));

  // IDA's relative position tolerance on a model far from its origin: at 10 of its sizes not yet
  facts.max_constraint_residual = 0.0;
  facts.origin_distance_in_sizes = 10.0;
  CHECK(accuracy_warnings(facts).empty());
  facts.origin_distance_in_sizes = 84.2;
  w = accuracy_warnings(facts);
  REQUIRE(w.size() == 1);
  CHECK(contains(w[0], "sits 84.2 times its own size from its origin (more than 10)"));
  CHECK(contains(w[0], "--set simulation.position_tolerance=absolute"));
}

TEST_CASE("a user's SI unit run by Euler's default step is warned about and the same run by IDA is not",
          "[unit][accuracy]") {
  const std::string path = std::string(RAILCRASH_SOURCE_DIR) + "/models/examples/emu3_unit_collision.yaml";
  for (const std::string integrator : {"euler", "ida"}) {
    CAPTURE(integrator);
    const LoadedModel loaded = load_model(path, {"simulation.integrator=" + integrator});
    const Model& model = loaded.model;
    const RunReport report = run_model(model, loaded.run_spec, "", nullptr, false, /*keep_in_memory=*/true);
    REQUIRE(report.outcome.ok);
    const nlohmann::json summary = nlohmann::json::parse(report.summary_json);
    // The share from summary.json's own energy figures, computed here.
    const nlohmann::json& e = summary["energy"];
    const double parts = std::abs(e["kinetic"].get<double>()) + std::abs(e["elastic"].get<double>()) +
                         std::abs(e["gravity"].get<double>()) + std::abs(e["dissipated"].get<double>()) +
                         std::abs(e["external_work"].get<double>());
    const double share = std::abs(e["integration_drift"].get<double>()) / std::max(std::abs(e["initial_total"].get<double>()), parts);
    const double residual = summary["constraint_residual_max"].get<double>();  // [m]
    const std::vector<std::string> warnings = summary["accuracy_warnings"].get<std::vector<std::string>>();
    if (integrator == "euler") {
      CHECK(share > 0.02);       // measured 3.9 % at Euler's default step
      CHECK(residual > 0.01);    // measured 0.036 m (angle rows at their bodies' size; 0.44 m at the model's length)
      REQUIRE(warnings.size() == 2);
      CHECK(contains(warnings[0], "created"));
      CHECK(contains(warnings[1], "joints open"));
    } else {
      CHECK(share < 1e-4);
      CHECK(residual < 1e-6);
      CHECK(warnings.empty());
    }
  }
}

TEST_CASE("the report's car run by Euler at its printed step is within the limits", "[unit][accuracy]") {
  const LoadedModel loaded = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/report/preliminary_car.yaml",
                                 {"simulation.integrator=euler"});
  const Model& model = loaded.model;
  const RunReport report = run_model(model, loaded.run_spec, "", nullptr, false, true);
  REQUIRE(report.outcome.ok);
  const nlohmann::json summary = nlohmann::json::parse(report.summary_json);
  CHECK(std::abs(summary["energy"]["relative_balance_error"].get<double>()) < 0.001);  // measured 0.025 %
  CHECK(summary["constraint_residual_max"].get<double>() < 0.03937);                    // measured 0.00041 in
  CHECK(summary["accuracy_warnings"].empty());
}
