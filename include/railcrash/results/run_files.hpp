// The run folder's files beside timeseries.csv, events.csv and summary.json, written for the
// report (`railcrash report`) and for users' own post-processing:
//   DIR/model.json         geometry: units, every body (name, mass, inertia, its car if it
//                          declares one, its connection points in its own frame) and every
//                          element (name, type, its points as {body index or -1 for ground,
//                          offset}, its output columns, the roles of its outputs as
//                          {"crush": "horizontal_deformation", ...}; element.hpp OutputRole). With
//                          the body poses of timeseries.csv this places every point at every row.
//   DIR/accelerations.csv  t, then <body>.ax,<body>.ay,<body>.alpha for every body: the
//                          accelerations v' of results.hpp, unfiltered, at every output row.
//   DIR/energy.csv         t, kinetic, elastic, gravity (change from t = 0), external_work,
//                          dissipated, then dissipated.<element type> for each type present,
//                          then integration_drift = (initial kinetic + elastic) + external_work
//                          - (kinetic + elastic + gravity + dissipated) [energy]: what the
//                          integration lost, attributed to no element. The dissipation of an
//                          element that can dissipate (Element::conservative false) is the work
//                          done on it less the change of its stored energy; a conservative one
//                          (elastic springs, frictionless joints) dissipates exactly zero. Under
//                          Euler the penalty joints are one more class, `penalty` (their work:
//                          their springs' stored energy is not in `elastic` here).
#pragma once

#include <string>
#include <vector>

#include "railcrash/solver/dae_system.hpp"

namespace railcrash {

/// Writes DIR/model.json (see above), with the run's id (results/provenance.hpp) when given.
/// Throws InputError if it cannot be written.
void write_model_geometry(const DaeSystem& system, const std::string& path, const std::string& run_id = "");

/// The files a run writes into its folder (any output format: the formats' folder_files,
/// results/output_sink.hpp) and `railcrash report` adds: timeseries.csv, events.csv,
/// accelerations.csv, energy.csv, timeseries.h5, summary.json (and its summary.json.tmp),
/// model.json, report.html, energy_zones.csv. A run owns them: it starts by removing those
/// an earlier run left (remove_earlier_run_files), so that its folder never mixes two runs.
const std::vector<std::string>& run_folder_files();

/// Removes the run_folder_files() in `directory` that are regular files (nothing else: a
/// user's other files stay, and so does a link or a device put in a file's place) and returns
/// the names removed, in run_folder_files() order. Throws InputError naming the file when one
/// cannot be removed.
std::vector<std::string> remove_earlier_run_files(const std::string& directory);

/// Computes energy.csv's row at every sample (the output sinks write it: results/output_sink.hpp).
class EnergyWriter {
 public:
  explicit EnergyWriter(const DaeSystem& system);
  void sample(double t, const double* y, const double* quadratures);
  /// energy.csv's column names.
  const std::vector<std::string>& columns() const { return columns_; }
  /// The last sample's row, one value per column.
  const std::vector<double>& row() const { return row_; }

 private:
  const DaeSystem& system_;
  std::vector<std::string> columns_;
  std::vector<double> row_;
  std::vector<std::string> types_;       // element types, in first-appearance order
  std::vector<int> type_of_element_;     // index into types_
  std::vector<double> initial_elastic_;  // per element [energy]
  double initial_gravity_ = 0.0, initial_total_ = 0.0;
  bool first_ = true;
  std::vector<double> dissipated_;       // per type, scratch
};

}  // namespace railcrash
