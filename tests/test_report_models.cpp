// The report's transit-car models (models/report/): they load, pass the joint checks and run
// their first milliseconds under both integrators with a closed energy balance. (Their
// physics against the report is the subject of the verification side-by-side.)
#include <catch2/catch.hpp>

#include <cmath>

#include "railcrash/model_io.hpp"
#include "railcrash/run.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

RunOutcome run_report_model(const std::string& file, const std::vector<std::string>& settings) {
  const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/report/" + file, settings);
  return testing::simulate(model, 1e-3);
}

void check_energy(const RunOutcome& o, double tolerance) {
  const EnergyBalance e = EnergyBalance::between(o.initial_energy, o.final_energy);
  INFO("energy balance error " << e.error() << " of " << e.initial_total);
  CHECK(std::abs(e.error()) < tolerance * e.initial_total);
}

}  // namespace

TEST_CASE("final two-car model: the first 8 ms under both integrators", "[report_models]") {
  // 616 in/s closes the 3.75 in anticlimber gap at about 6.1 ms.
  const RunOutcome ida = run_report_model("final_two_car.yaml", {"simulation.t_end=0.008"});
  check_energy(ida, 1e-5);
  bool contact = false;
  for (const EventRecord& e : ida.events)
    if (e.element.find("anticlimber") != std::string::npos && e.what.find("contact") != std::string::npos) {
      contact = true;
      CHECK(e.t == Approx(3.75 / 616.0).epsilon(0.05));
    }
  CHECK(contact);
  const RunOutcome euler = run_report_model("final_two_car.yaml", {"simulation.t_end=0.0005", "simulation.integrator=euler"});
  check_energy(euler, 1e-3);
}

TEST_CASE("preliminary car: settles under gravity and meets the barrier", "[report_models]") {
  const RunOutcome ida = run_report_model("preliminary_car.yaml", {"simulation.t_end=0.008"});
  CHECK(ida.stats.settling_steps > 0);
  CHECK(ida.stats.settling_displacement > 0.5);  // the body sinks onto its springs (about 2.7 in)
  CHECK(ida.stats.settling_displacement < 5.0);
  check_energy(ida, 1e-5);
  const RunOutcome euler = run_report_model("preliminary_car.yaml", {"simulation.t_end=0.0005", "simulation.integrator=euler"});
  check_energy(euler, 1e-3);
}
