// Helpers shared by the unit tests.
#pragma once

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "railcrash/model/model.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "railcrash/solver/events.hpp"
#include "railcrash/solver/integrator.hpp"

namespace railcrash::testing {

/// A path in the system's temporary folder for a test's scratch file or folder, its name
/// prefixed with this process's id: two test processes (ctest -j, or two checkouts tested on
/// one machine) never share one.
std::filesystem::path temp_path(const std::string& name);

/// Loads a model from YAML text (file name "test.yaml" in messages): the physical model alone.
Model model_from_text(const std::string& yaml);
/// The same with the run's settings beside it.
LoadedModel loaded_from_text(const std::string& yaml);

/// Largest relative difference between the assembled Jacobian dF/dy + cj dF/dy' and a
/// central finite difference of the residual, at the given y, yp, beyond the difference
/// quotient's round-off floor (100 eps |r| / h for residual entries of size |r|). Also checks that every
/// nonzero of the finite-difference Jacobian lies inside the sparsity pattern
/// (outside_pattern receives the largest |entry| found outside it).
double jacobian_error(const DaeSystem& system, double t, double cj, const std::vector<double>& y,
                      const std::vector<double>& yp, double* outside_pattern = nullptr);

/// Runs the model with the integrator its run settings ask for (no files, output every
/// output_interval) and requires success.
RunOutcome simulate(const LoadedModel& loaded, double output_interval = 0.01);
/// The same on a given system (with the run's simulation settings), whose element modes then
/// hold the run's final ones.
RunOutcome simulate(DaeSystem& system, const SimulationSettings& simulation, double output_interval = 0.01);
/// The same for a run that may stop early (a test of a stop's message): the outcome, ok or not.
RunOutcome simulate_to_stop(const LoadedModel& loaded, double output_interval = 0.001);
/// The time a stop's message names ("... at t = T s ..."); NaN without one.
double message_time(const std::string& message);

/// The system's element modes to write by hand (an element test commits an element directly or
/// sets its mode), through a ModeTracker of the system: their one writer. The reference is the
/// system's (it outlives the tracker).
inline ElementStates& modes_to_write(DaeSystem& system) { return ModeTracker(system).modes(); }

/// Puts element e of the system in mode st (State: the element's declared slot type), through
/// a ModeTracker (the one writer of a system's modes).
template <class State>
void set_mode(DaeSystem& system, const State& st, std::size_t e = 0) {
  modes_to_write(system).as<State>(e) = st;
}

/// Element `index` of a system's model driven by hand (element tests): reads and writes its
/// slot in the system's ElementStates (through a ModeTracker of the system, their one writer).
template <class E>
class DrivenElement {
 public:
  using State = typename E::State;
  DrivenElement(DaeSystem& system, std::size_t index)
      : modes_(system), index_(index), element_(dynamic_cast<const E&>(*system.model().elements()[index])) {}

  const E& element() const { return element_; }
  const E* operator->() const { return &element_; }
  State& state() const { return modes_.modes().template as<State>(index_); }
  void set_state(const State& st) const { state() = st; }
  /// Back to the mode the element starts a run in.
  void reset_modes() const { element_.write_start_mode(modes_.modes().of(index_)); }
  /// The element's local state at (q, v) with its mode.
  ElementState<double> at(const double* q, const double* v) const {
    return gather_state(element_, q, v, modes_.modes().of(index_));
  }
  bool commit(int root, int direction, double t, ElementState<double> s, const double* lambda,
              Element::Event& event) const {
    s.mode = modes_.modes().of(index_);
    return element_.commit(root, direction, t, s, lambda, modes_.modes().of(index_), event);
  }

 private:
  mutable ModeTracker modes_;  // the writer of the system's modes
  std::size_t index_;
  const E& element_;
};

/// The R1 test model (SI): a 1000 kg car end at 2 m/s into an anticlimber fixed to ground
/// (elastic to 0.01 m at 1e7 N/m, then 1e5 N/m), with a responses section (reference crush
/// 0.02 m), simulated to t_end: tests/models/anticlimber_r1.yaml (which the Python and shell
/// tests read too) with its end time replaced.
std::string anticlimber_r1_model_text(double t_end);

/// Positions and velocities of a DAE state.
struct BodyState {
  std::vector<double> q, v;
};
BodyState split(const DaeSystem& system, const std::vector<double>& y);
/// Generalized forces (gravity, loads, force elements) at that state, t = 0.
std::vector<double> forces(const DaeSystem& system, const BodyState& s);

/// A random state near the model's initial one (positions, velocities, multipliers).
std::vector<double> random_state(const DaeSystem& system, std::mt19937& rng, double spread = 0.3);

}  // namespace railcrash::testing
