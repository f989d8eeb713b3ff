// One run of a model: the command line's `run`, also used by the tests and verification.
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/model/model.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/outcomes.hpp"
#include "railcrash/results/responses.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/solver/integrator.hpp"

namespace railcrash {

/// Settings that override the model's simulation section (the command line's run options, the
/// library's RunSettings, converge's runs), applied through option_settings.
struct RunOverrides {
  std::optional<IntegratorKind> integrator;
  std::optional<double> t_end, rtol, dt, output_interval;  // [s], -, [s], [s]
  std::optional<double> atol;                               // [the model file's length unit], as simulation.atol
  std::optional<long> max_steps;
  bool force_dt = false;
};

/// Who gave the overrides: messages name each setting by it.
enum class OverrideSource {
  CommandLine,  // "--t-end 2", "--force-dt"
  RunSettings,  // the library's api::RunSettings (and Python's run()): "RunSettings.t_end = 2"
  ConvergeRun,  // a run of railcrash converge: "converge run's rtol 1e-05"
};

/// The overrides as simulation.KEY=VALUE settings named by where they came from: every override
/// goes through the loader's path, as --set does (load_model(path, settings, options),
/// load_model_text(text, path, settings, options)), so they are checked, reported and listed in
/// the run's provenance alike. Lengths (atol) are in the model file's length unit, as the file's
/// own simulation.atol.
std::vector<OptionSetting> option_settings(const RunOverrides& overrides, OverrideSource source = OverrideSource::CommandLine);

/// The integrator the run's simulation settings ask for.
std::unique_ptr<Integrator> make_integrator(DaeSystem& system, const SimulationSettings& settings);

/// Output interval actually used (the setting, or t_end / 500). (Inline: the loader's
/// provenance uses it, and the fuzz target links the loader without the run's sources.)
inline double output_interval_of(const SimulationSettings& settings) {
  return settings.output_interval > 0.0 ? settings.output_interval : settings.t_end / 500.0;
}

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

/// The memory a run's output keeps until its end [bytes]: per row, 20 B per body (single-precision
/// velocities and accelerations for the CFC filter and the collision pulses, results.hpp) and
/// 16 B of times, and with keep_in_memory 8 B per timeseries column; rows = t_end /
/// output_interval + 2. A vector that grows may briefly need half as much again.
double output_memory_estimate(const DaeSystem& system, const RunSpec& run_spec, bool keep_in_memory);
/// The limit run_model holds output_memory_estimate to [bytes] (default 4 GiB; 0: no limit).
/// `railcrash run --max-output-memory GB` sets it for the process.
void set_output_memory_limit(double bytes);
double output_memory_limit();

/// Runs the model with the run's settings (run_spec) and writes DIR/timeseries.csv, events.csv, summary.json (DIR empty: no files;
/// format: a registered output format that writes files, results/output_sink.hpp: "hdf5" writes
/// timeseries.h5 in place of the per-row CSV files);
/// with keep_in_memory the same results also come back in the report.
/// Input errors throw InputError before anything runs (also an output whose memory estimate is
/// above output_memory_limit(), with the figures and what lowers it); solver failures come back
/// with ok = false, and so does running out of memory (std::bad_alloc: summary.json "failed").
/// time_phases: the run's wall time split by phase (RunStatistics::phase_seconds; summary.json's
/// stats.seconds; `railcrash run --timings`).
RunReport run_model(const Model& model, const RunSpec& run_spec, const std::string& out_dir, const std::atomic<bool>* stop = nullptr,
                    bool show_progress = false, bool keep_in_memory = false, const std::string& format = "csv",
                    bool time_phases = false);

}  // namespace railcrash
