// One run of a model: the command line's `run`, also used by the tests and verification.
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/integrator.hpp"
#include "railcrash/model.hpp"
#include "railcrash/model_io.hpp"
#include "railcrash/outcomes.hpp"
#include "railcrash/responses.hpp"
#include "railcrash/results.hpp"

namespace railcrash {

/// Command-line settings that override the model's simulation section.
struct RunOverrides {
  std::optional<IntegratorKind> integrator;
  std::optional<double> t_end, rtol, atol, dt, output_interval;
  std::optional<long> max_steps;
  bool force_dt = false;
};

/// The overrides as simulation.KEY=VALUE settings named by their options ("--t-end 2"): the
/// command line's run options go through the loader's override path, as --set does
/// (load_model(path, settings, options)), so they are checked, and their mistakes reported, alike.
std::vector<OptionSetting> option_settings(const RunOverrides& overrides);

/// Applies overrides (checked) to an already loaded model's simulation settings: for the
/// library's and the studies' programmatic settings; the command line uses option_settings.
void apply_overrides(Model& model, const RunOverrides& overrides);

/// The integrator the model's settings ask for.
std::unique_ptr<Integrator> make_integrator(DaeSystem& system, const SimulationSettings& settings);

/// Output interval actually used (the setting, or t_end / 500).
double output_interval_of(const SimulationSettings& settings);

struct RunReport {
  RunOutcome outcome;
  std::string integrator;
  bool has_responses = false;  // the model has a responses section
  Responses responses;         // R1-R3 and what they are made of
  OutcomeSignature outcomes;   // the run's discrete outcome (outcomes.hpp; summary.json's "outcomes")
  // From the result writer (empty when no output folder): per body, per car (results.hpp).
  std::vector<AccelerationPeaks> acceleration_peaks;
  std::vector<CarCrush> car_crush;
  std::string summary_json;  // the text of summary.json (empty when neither a folder nor memory)
  std::string run_id;        // the run's id in its files (results/provenance.hpp; empty when neither a folder nor memory)
  // keep_in_memory: timeseries.csv in memory, column by column (events: outcome.events).
  std::vector<std::string> columns;
  std::vector<std::vector<double>> series;
  std::vector<FilteredAccelerations> filtered_accelerations;  // CFC 60 peaks, collision pulses
};

/// Runs the model and writes DIR/timeseries.csv, events.csv, summary.json (DIR empty: no files;
/// OutputFormat::Hdf5: timeseries.h5 in place of the per-row CSV files, results/hdf5_file.hpp);
/// with keep_in_memory the same results also come back in the report.
/// Input errors throw InputError before anything runs; solver failures come back with ok = false.
/// time_phases: the run's wall time split by phase (RunStatistics::phase_seconds; summary.json's
/// stats.seconds; `railcrash run --timings`).
RunReport run_model(const Model& model, const std::string& out_dir, const std::atomic<bool>* stop = nullptr,
                    bool show_progress = false, bool keep_in_memory = false, OutputFormat format = OutputFormat::Csv,
                    bool time_phases = false);

}  // namespace railcrash
