// The run loop's chatter guard (chatter_guard.hpp) on event sequences written here: the storm
// emu3_unit_collision showed at --rtol 1e-3 before 83529b8 (one gear's changes 1.5e-11 s apart,
// the other gear's interleaved), against what real runs log.
#include <catch2/catch.hpp>

#include <memory>
#include <string>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/chatter_guard.hpp"

using railcrash::ChatterGuard;
using railcrash::EventRecord;

namespace {

EventRecord change(const char* element, double t) { return {t, element, "back on the loading curve (buff), reversal (buff)", 0.0, true}; }

}  // namespace

TEST_CASE("chatter guard: one element changing mode at one instant stops the run at the limit, interleaved or not",
          "[solver][events]") {
  const double t_end = 0.4;  // [s]
  ChatterGuard guard(t_end);
  const double t0 = 0.2098857, spacing = 1.5e-11;  // [s] (the storm's)
  for (long k = 1; k < ChatterGuard::kLimit; ++k) {
    REQUIRE_FALSE(guard.record(change("unitB.coupling1.draft_gear", t0 + spacing * static_cast<double>(k - 1))));
    REQUIRE_FALSE(guard.record(change("unitA.coupling1.draft_gear", 0.25 + spacing * static_cast<double>(k - 1))));
  }
  CHECK(guard.record(change("unitB.coupling1.draft_gear", t0 + spacing * static_cast<double>(ChatterGuard::kLimit - 1))));
  CHECK(guard.count() == ChatterGuard::kLimit);
  CHECK(guard.first_time() == t0);
}

TEST_CASE("chatter guard: changes apart in time, or one wide gap in a run of them, never stop a run", "[solver][events]") {
  const double t_end = 0.4;  // [s]
  ChatterGuard guard(t_end);
  // A 200-car train's many events: each element's changes at least 1e-6 s apart.
  for (long k = 0; k < 3 * ChatterGuard::kLimit; ++k)
    REQUIRE_FALSE(guard.record(change("car17.draft_gear", 1e-6 * static_cast<double>(k))));
  // Changes at one instant, but a gap wider than one instant (1e-9 t_end = 4e-10 s) every
  // kLimit - 1: the count starts again.
  double t = 0.3;
  for (int round = 0; round < 3; ++round) {
    for (long k = 0; k + 1 < ChatterGuard::kLimit; ++k, t += 1e-12) REQUIRE_FALSE(guard.record(change("zone", t)));
    t += 1e-9;
  }
  // Joined at one instant exactly (several changes with the same time) count like the others.
  ChatterGuard same_instant(t_end, 5);
  for (int k = 0; k < 4; ++k) REQUIRE_FALSE(same_instant.record(change("zone", 0.0843186049126)));
  CHECK(same_instant.record(change("zone", 0.0843186049126)));
}

TEST_CASE("chatter guard in a run: the run stops naming the element and its line, its results up to there kept",
          "[solver][events]") {
  // Under IDA scenario1_emu3's standing.car3.front_crush (an SI unit's crush zone) unloads
  // and separates at t = 0.00213 s: two mode changes at one instant, with a limit of 2 a
  // chatter, with the default nothing. (Until IDA kept its Jacobian between setups, IDA's path
  // had mu_3plus3_si's a1_end_front_crush change twice at t = 0.101 s instead; which element
  // does so moves with the path. Euler logs the changes of one step's end as one event: the
  // guard is the run loop's, the same for both.)
  const std::string path = std::string(RAILCRASH_SOURCE_DIR) + "/models/scenarios/scenario1_emu3.yaml";
  for (const char* integrator : {"ida"}) {
    CAPTURE(integrator);
    const railcrash::LoadedModel loaded = railcrash::load_model(path, {std::string("simulation.integrator=") + integrator});
    const railcrash::SimulationSettings& simulation = loaded.run_spec.simulation;
    struct Null : railcrash::RunObserver {
      void sample(double, const double*, const double*, const double*, const double*) override {}
    } observer;
    for (const long limit : {2L, ChatterGuard::kLimit}) {
      CAPTURE(limit);
      railcrash::DaeSystem system(loaded.model);
      const std::unique_ptr<railcrash::Integrator> run = railcrash::make_integrator(system, simulation);
      run->set_chatter_limit(limit);
      const railcrash::RunOutcome outcome = run->run(simulation.t_end, railcrash::output_interval_of(simulation), observer);
      if (limit == ChatterGuard::kLimit) {
        CHECK(outcome.ok);
        continue;
      }
      REQUIRE_FALSE(outcome.ok);
      CHECK_THAT(outcome.message, Catch::Contains("scenario1_emu3.yaml:"));
      CHECK_THAT(outcome.message,
                 Catch::Contains("element 'standing.car3.front_crush' (crush_spring) changed mode 2 times in a row at one instant"));
      CHECK_THAT(outcome.message, Catch::Contains("please report the model"));
      CHECK(outcome.t_reached > 0.001);  // the last output sample before t = 0.00213 s
      CHECK(outcome.t_reached < 0.00213);
      CHECK_FALSE(outcome.y.empty());
    }
  }
}
