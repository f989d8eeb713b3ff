// Parameter studies in the manner of the report's Section 4 (Tables 9-11, equations 1-3):
// a base run and one run per parameter with that parameter scaled (1.2 in the report), or
// two runs at 1 +- h (central differences), each giving R1-R3; then the first-order
// coefficients dR/dP (P nondimensional, 1.0 = the model's value) and the parameters ranked
// by them, as in Tables 15-17.
//
// A design file says what each nondimensional parameter scales in the model:
//   sensitivity: 1
//   factor: 1.2                         # first-order runs (default 1.2)
//   parameters:
//     - name: P7
//       description: anticlimber horizontal yield force
//       scale:                          # key *= factor^power for every entry
//         - {key: elements.anticlimber.horizontal_yield_deflection, power: 1}
// so a derived quantity (a yield force = slope x yield deflection) is varied through the
// inputs it is made of. Runs go in parallel; a failed run is reported and the others go on.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "railcrash/responses.hpp"

namespace railcrash {

struct SensitivityParameter {
  std::string name;
  std::string description;
  std::vector<std::pair<std::string, double>> scales;  // (model key, power)
};

struct SensitivityDesign {
  double factor = 1.2;
  std::vector<SensitivityParameter> parameters;
};

/// Reads a design file (errors name the file and line).
SensitivityDesign load_design(const std::string& path);

struct SensitivityRun {
  std::string parameter;  // "" for the base run
  double factor = 1.0;
  bool ok = false;
  std::string message;
  Responses responses;
  double wall_seconds = 0.0;
};

struct SensitivityResult {
  SensitivityRun base;
  std::vector<SensitivityRun> runs;               // per parameter (central: +h then -h)
  std::vector<std::array<double, 3>> derivatives; // dR1/dP, dR2/dP, dR3/dP per parameter (NaN if a run failed)
  bool central = false;
};

struct SensitivityOptions {
  int jobs = 1;
  double central_step = 0.0;         // > 0: central differences at 1 +- this
  std::vector<std::string> only;     // parameter names to run (empty: all)
};

SensitivityResult run_sensitivity(const std::string& model_path, const SensitivityDesign& design,
                                  const SensitivityOptions& options);

/// Writes DIR/sensitivity.csv and DIR/sensitivity.md; returns the Markdown.
std::string write_sensitivity(const SensitivityResult& result, const SensitivityDesign& design, const std::string& directory);

}  // namespace railcrash
