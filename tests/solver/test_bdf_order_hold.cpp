// IDA's BDF order held to 2 where the integration creates energy (IdaIntegrator::
// hold_order_if_energy_created; bench/HISTORY.md, "BDF order held where the integration
// creates energy").
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/ida_integrator.hpp"

using namespace railcrash;

namespace {

struct BarrierCarsRun {
  bool ok = false;
  std::string message;
  double lead_crush = 0.0;     // [in] the striking lead car's largest crush
  double held_at = -1.0;       // [s] stats.bdf_order_held_at
  double created_share = 0.0;  // [-] energy the integration created, of the energy turned over
};

/// EN 15227 scenario 1 of the barrier test's cars (models/scenarios/scenario1_barrier_cars.yaml)
/// under IDA, its whole 0.8 s.
BarrierCarsRun barrier_cars(const std::string& rtol, const std::string& positions) {
  const std::string path = std::string(RAILCRASH_SOURCE_DIR) + "/models/scenarios/scenario1_barrier_cars.yaml";
  const LoadedModel loaded = load_model(path, {"simulation.integrator=ida", "simulation.rtol=" + rtol,
                                               "simulation.position_tolerance=" + positions,
                                               "simulation.linear_ordering=amd"});
  const RunReport report = run_model(loaded.model, loaded.run_spec, "", nullptr, false, /*keep_in_memory=*/true);
  BarrierCarsRun run;
  run.ok = report.outcome.ok;
  run.message = report.outcome.message;
  for (const CarCrush& car : report.car_crush)
    if (car.car == "s_lead") run.lead_crush = car.max_crush;
  run.held_at = report.outcome.stats.bdf_order_held_at;
  const EnergyBalance balance = EnergyBalance::between(report.outcome.initial_energy, report.outcome.final_energy);
  run.created_share = -balance.integration_drift() / balance.turned_over();
  return run;
}

/// The run at (rtol, positions), which must finish with IDA's order held from a time in
/// (after, before) [s].
BarrierCarsRun held_run(const std::string& rtol, const std::string& positions, double after, double before) {
  const BarrierCarsRun run = barrier_cars(rtol, positions);
  INFO("rtol " << rtol << ", " << positions << " positions: " << run.message);
  REQUIRE(run.ok);
  CHECK(run.held_at > after);
  CHECK(run.held_at < before);
  return run;
}

}  // namespace

TEST_CASE("ida: an oscillation growing under BDF orders 3 to 5 is stopped by holding the order to 2",
          "[solver][ida][energy]") {
  // With positions held to an absolute tolerance at rtol 3e-3, the striking lead car body's
  // bounce off its crush zone (t = 0.037 s) grew under IDA's higher orders: its vertical
  // velocity went from 0.3 to 1,600 in/s within 6 ms, the kinetic energy from 1.5e7 to 1.3e9
  // in-lbf, and the run stopped at 0.045 s with a truck spring crushed through. Without the
  // hold held_run's REQUIRE fails so.
  const BarrierCarsRun loose = held_run("3e-3", "absolute", 0.035, 0.045);
  // The growth is stopped at the first check past the threshold, not undone; a burst between
  // two checks overshoots it: measured 3.85 % against the 2 % threshold. With the threshold at
  // 5 %, as first set, the run created 11.0 %, in one burst between t = 0.040 and 0.044 s.
  // Without the hold it created 98.8 %.
  CHECK(loose.created_share > IdaIntegrator::kCreatedEnergyShare);
  CHECK(loose.created_share < 2.5 * IdaIntegrator::kCreatedEnergyShare);
  // The crush is the tight run's: an independent run at rtol 1e-6, which never holds.
  const BarrierCarsRun tight = barrier_cars("1e-6", "absolute");
  INFO(tight.message);
  REQUIRE(tight.ok);
  CHECK(tight.held_at == -1.0);
  CHECK(std::abs(tight.created_share) < 1e-3);
  CHECK(loose.lead_crush == Approx(tight.lead_crush).epsilon(0.01));  // measured 4.465 against 4.480 in
}

TEST_CASE("ida: a check that finds energy created since the previous one holds the order before a burst",
          "[solver][ida][energy]") {
  // The same model in the default position form at rtol 2e-3: one BDF5 step (h = 1.8e-4 s,
  // from 0.10665 to 0.10684 s, just before the front faces separate) turned both lead car
  // bodies' vertical velocities round (18.7 -> -55.7 and -8.3 -> 66.2 in/s) and created 9 % of
  // the energy at once; the step before it had created 2.7 %. On the 2 % threshold alone
  // the hold came after that step and the run ended 8.56 % created; on the energy created
  // since the previous check (kCreatedInOneCheckShare, 1 %) it comes one step earlier.
  const BarrierCarsRun loose = held_run("2e-3", "relative", 0.1060, 0.10668);  // the burst's step starts at 0.106654 s
  CHECK(loose.created_share < IdaIntegrator::kCreatedEnergyShare);  // measured 0.46 %
}
