// Where a run's results came from (README "Run results"): one record, gathered once per run by
// the result writer and written into every file of the run folder, so that a file can be told
// apart from another run's and traced to the program, model files and settings that made it:
//   run_id        32 hexadecimal digits (128 bits from std::random_device), new for every run
//   version       the program's version, and commit: the git commit it was built from ("" when
//                 not built from a checkout; "-dirty" when tracked files differed)
//   command_line  the program's arguments as the shell would need them quoted ("" when the run
//                 comes from the library or the Python module)
//   model_files   every model file read (the file given, then a variant's base), each with the
//                 SHA-256 of the text read (what `sha256sum FILE` prints for it)
//   settings      the KEY=VALUE settings applied over the files (--set, then the run options)
//   simulation    the simulation settings the run used (after the settings)
// summary.json has it as "provenance", model.json as "run_id", each CSV file as its first line
// ("# railcrash provenance {JSON}"), timeseries.h5 as the file attributes run_id and provenance,
// and report.html shows it (report.hpp).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "railcrash/model/model.hpp"
#include "railcrash/model/run_spec.hpp"

namespace railcrash {

struct Provenance {
  std::string run_id;
  std::string version;
  std::string commit;
  std::string command_line;
  std::vector<ModelSource> model_files;
  std::vector<std::string> settings;
  SimulationSettings simulation;
};

/// A new run id: 32 hexadecimal digits from std::random_device.
std::string new_run_id();

/// Keeps the program's arguments for the provenance of the runs it makes (main() calls it once).
void set_command_line(int argc, const char* const* argv);
/// The arguments kept, each quoted for a POSIX shell where it needs to be ("" when never set).
const std::string& command_line();

/// The provenance of a run of `model` with the run's simulation settings and the id `run_id`.
Provenance run_provenance(const Model& model, const SimulationSettings& simulation, const std::string& run_id);

/// The record as one line of JSON: {"run_id": ..., "version": ..., "commit": ..., "command_line": ...,
/// "model_files": [{"path": ..., "sha256": ...}], "settings": [...], "simulation": {...}}.
std::string provenance_json(const Provenance& provenance);

/// The first line of each CSV file of the run: "# railcrash provenance " + provenance_json + "\n".
std::string provenance_comment(const Provenance& provenance);

/// The run id in a text holding a provenance record ("run_id": "..."), if any.
std::optional<std::string> run_id_in(const std::string& text);

}  // namespace railcrash
