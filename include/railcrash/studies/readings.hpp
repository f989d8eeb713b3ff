// The reading study (`railcrash readings`): which readings of what a report leaves open make
// a model reproduce the report's own parameter study?
//
// A readings file lists the open readings, each with its levels; a level is a set of model
// changes in the KEY: VALUE form of --set (KEY*=FACTOR scalings too: write the key as
// "elements.x.stiffness*"):
//   reading_study: 1
//   combinations: factorial        # every combination of levels (default), or
//                                  # one_at_a_time: the first level of every reading, then
//                                  # each other level alone
//   readings:
//     - name: gravity
//       description: what the report says and why the levels are candidates
//       levels:
//         - {name: on}                               # no changes: the model as it is
//         - {name: off, set: {gravity: [0, 0]}}
//     - name: slope_holds
//       levels:                      # a level may also change what design parameters scale
//         - {name: deflection}
//         - name: force
//           scale: {P5: [{key: elements.a.horizontal_elastic_stiffness, power: 1},
//                        {key: elements.a.horizontal_yield_deflection, power: -1}]}
// For every combination the design's whole study runs (base, first-order and second-order
// runs; sensitivity.hpp) with the combination's changes applied to every run before the
// parameters' scaling, and the study is scored against the design's published results
// (SensitivityDesign::reference; for the report: Tables 11, 13 and 15-17):
//   run 0           each response and its relative error against the published run 0;
//   changes         for every first-order run (and separately for all first- and
//                   second-order runs) the change of each response against run 0, ours and
//                   published:
//                     sign agreement   among the runs whose published change is at least
//                                      kSignificantChange in size, the share whose change
//                                      has the published sign (a zero change of ours
//                                      does not agree);
//                     Spearman rho     rank correlation of ours with the published changes
//                                      (average ranks for ties; NaN when either is constant);
//                     RMS              of the difference of the changes;
//   rankings        our five largest |first-order coefficient| against the published top
//                   five (Tables 15-17): how many are shared.
// Goals (issue 10): R2 within 10 % and R3 within 5 % of run 0; for R1 and R2 a sign agreement
// of at least 80 % and a Spearman rho of at least 0.7 over the first-order runs and at least
// four of the top five: 8 goals. Combinations are ranked by goals met, then by
//   score = sum over R1, R2 of (sign agreement + rho + overlap / 5)
//           - |R2 error| / 0.10 - |R3 error| / 0.05
// (each run-0 error in units of its goal; a NaN rho counts as 0).
#pragma once

#include <array>
#include <functional>
#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/studies/sensitivity.hpp"

namespace railcrash {

/// A published change of at least this size (in the dimensionless response) has a sign to agree with.
inline constexpr double kSignificantChange = 0.005;

struct ReadingLevel {
  std::string name;
  std::vector<std::string> settings;  // KEY=VALUE or KEY*=FACTOR
  /// Design parameters whose scaling this level replaces: parameter -> (model key, power).
  std::vector<std::pair<std::string, std::vector<std::pair<std::string, double>>>> scales;
  int line = 0;                       // in the readings file
};

struct Reading {
  std::string name, description;
  std::vector<ReadingLevel> levels;
  int line = 0;
};

struct ReadingsPlan {
  std::string path;
  std::vector<Reading> readings;
  bool one_at_a_time = false;
  /// The combinations to run: each one level index per reading (all at once: for small plans;
  /// the study generates them one at a time with combination()).
  std::vector<std::vector<int>> combinations() const;
  /// How many combinations there are, or nullopt when the number does not fit in std::size_t
  /// (a factorial over many readings): counted without generating them.
  std::optional<std::size_t> combination_count() const;
  /// Combination number `index` (0 <= index < combination_count()) in the order of combinations().
  std::vector<int> combination(std::size_t index) const;
  /// The model changes of a combination, in reading order.
  std::vector<std::string> settings(const std::vector<int>& combination) const;
  /// "gravity=off, inertia=printed"
  std::string label(const std::vector<int>& combination) const;
  /// The design with the combination's replaced parameter scalings (InputError naming the
  /// readings file's line for a parameter the design does not have).
  SensitivityDesign design_for(const std::vector<int>& combination, const SensitivityDesign& design) const;
};

/// Reads a readings file; errors name the file and line.
ReadingsPlan load_readings(const std::string& path);

/// Loads the model with every level's changes (and with each combination's) without running it,
/// so that a key the model does not have fails before any run starts, naming the readings
/// file's line.
/// The checks stop early, returning false, when `stop` rises (SIGINT/SIGTERM); true when all were made.
bool check_readings(const ReadingsPlan& plan, const std::string& model_path, const std::atomic<bool>* stop = nullptr);

struct ResponseAgreement {
  double value = 0.0, published = 0.0, relative_error = 0.0;  // run 0
  int significant_runs = 0, sign_agreements = 0;               // first-order runs
  double spearman = 0.0, rms = 0.0;                            // first-order runs
  int significant_runs_all = 0, sign_agreements_all = 0;       // first- and second-order runs
  double spearman_all = 0.0, rms_all = 0.0;
  std::vector<std::string> top_five;                           // ours, largest |A_i| first
  int top_five_shared = -1;                                    // with the published ranking (-1: none published)
  double sign_share() const { return significant_runs ? static_cast<double>(sign_agreements) / significant_runs : 0.0; }
};

struct Agreement {
  std::array<ResponseAgreement, 3> responses;  // R1-R3
  int goals_met = 0;
  static constexpr int kGoals = 8;
  double score = 0.0;
  std::vector<std::string> goals_missed;
};

/// Scores a study against the design's published results (the design must have a reference;
/// failed runs are left out of the changes).
Agreement score_agreement(const SensitivityResult& result, const SensitivityDesign& design);

/// The study side by side with the design's published results (Markdown): the agreement
/// scores, every run against its published counterpart, the rankings (Tables 15-17 for the
/// report) and, when the design has a second-order form, its derivatives at P = 1 from our runs
/// and from the published ones (Table 14), fitted the same way.
std::string comparison_markdown(const SensitivityResult& result, const SensitivityDesign& design);

/// Spearman's rank correlation (average ranks for ties); NaN if fewer than 3 pairs or either
/// side is constant.
double spearman_correlation(const std::vector<double>& a, const std::vector<double>& b);

struct ReadingsCombinationResult {
  std::vector<int> levels;
  SensitivityResult study;
  Agreement agreement;
  int failed_runs = 0;
  double wall_seconds = 0.0;
};

struct ReadingsOptions {
  SensitivityOptions study;  // jobs, run limit, first/second order; settings are the combination's
  /// Called as each combination finishes: its result, its number (from 0), combinations in all.
  std::function<void(const ReadingsCombinationResult&, std::size_t, std::size_t)> progress;
};

std::vector<ReadingsCombinationResult> run_readings(const std::string& model_path, const SensitivityDesign& design,
                                                    const ReadingsPlan& plan, const ReadingsOptions& options);

/// Writes DIR/readings.csv (one row per combination), DIR/readings.md (ranked) and each
/// combination's study in DIR/combination_NNN/ (write_sensitivity); returns the Markdown.
std::string write_readings(const std::vector<ReadingsCombinationResult>& results, const ReadingsPlan& plan,
                           const SensitivityDesign& design, const std::string& directory);

}  // namespace railcrash
