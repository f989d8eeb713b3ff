// Where a run's rows go: an output sink. The result writer (results.hpp) computes each row once
// (timeseries, accelerations, energy) and hands it to every sink of the run; the sinks only
// format and store it. Three are registered (src/results/output_formats.cpp):
//   csv     DIR/timeseries.csv, events.csv, accelerations.csv, energy.csv, energy_zones.csv
//           (src/results/csv_sink.cpp; the default of `railcrash run`)
//   hdf5    DIR/timeseries.h5 in place of the per-row CSV files (src/results/hdf5_sink.cpp,
//           results/hdf5_file.hpp; written only by a build that found HDF5)
//   memory  the timeseries columns kept in memory, for the library and the Python module
//           (src/results/memory_sink.cpp; api.hpp)
// `railcrash run --format NAME` takes the registered sinks that write files; the library's
// runs take "memory". A new format is one new file (its sink and its make function) and one
// row in the table of src/results/output_formats.cpp (and the file in CMakeLists.txt's
// railcrash_output_sinks); the row names the files it writes, which a run then owns
// (results/run_files.hpp run_folder_files: an earlier run's are removed).
//
// What the writer keeps for itself, whatever the sinks: summary.json, model.json, the folder
// lock and the check that the folder still exists. A sink's failed write (file and the OS's
// reason) stops the run at that sample, and what the sink holds up to then stays readable.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace railcrash {

class Model;
struct EventRecord;
struct Provenance;
class CrushZoneTracker;

/// The per-row tables of a run, each row beginning with t [time].
enum class OutputTable {
  Timeseries,     // t, <body>.x|y|theta|vx|vy|omega, the element outputs, the output points' columns (results.hpp)
  Accelerations,  // t, <body>.ax|ay|alpha (results/run_files.hpp)
  Energy,         // t, kinetic, elastic, ... (results/run_files.hpp)
};
constexpr std::size_t kOutputTableCount = 3;

/// One table's name (the CSV file's without ".csv", the HDF5 dataset's), columns and units.
struct OutputTableLayout {
  std::string name;
  std::vector<std::string> columns;
  std::string units;  // a line of text: which columns are in which unit
};

/// What a sink is told when the run begins.
struct OutputLayout {
  std::string directory;  // the run folder ("" for a sink that writes no files)
  const Model* model = nullptr;
  const Provenance* provenance = nullptr;
  std::array<OutputTableLayout, kOutputTableCount> tables;  // indexed by OutputTable
  const OutputTableLayout& table(OutputTable t) const { return tables[static_cast<std::size_t>(t)]; }
};

class OutputSink {
 public:
  virtual ~OutputSink() = default;
  /// Opens the sink's files in layout.directory and writes their headers. Throws InputError
  /// naming the file and the OS's reason when it cannot.
  virtual void begin(const OutputLayout& layout) = 0;
  /// Whether the sink takes the table's rows (a table no sink takes is not computed).
  virtual bool takes(OutputTable table) const = 0;
  /// One row: as many values as the table has columns.
  virtual void row(OutputTable table, const double* values) = 0;
  /// One committed mode change. Returns a failed write that must stop the run now ("" none).
  virtual std::string event(const EventRecord& record) = 0;
  /// Checks every write so far and, with `flush`, hands the buffered rows to the OS. Returns ""
  /// while all is well, else the first failed write (file and the OS's reason) and which rows
  /// the files hold whole.
  virtual std::string check(bool flush) = 0;
  /// At the end of the run, whatever its outcome: what is known only then (the energy per
  /// crush zone). Returns a failed write ("" none).
  virtual std::string finish(const CrushZoneTracker& zones) = 0;
  /// summary.json's entry for the sink ("  \"output\": {...},\n"), or "" for none.
  virtual std::string summary_entry() const { return ""; }
  /// The timeseries kept in memory, per column (the memory sink); nullptr for a sink of files.
  virtual std::vector<std::vector<double>>* kept_columns() { return nullptr; }
};

/// A registered output format (src/results/output_formats.cpp).
struct OutputFormat {
  const char* name;        // --format's value, or "memory"
  bool writes_files;       // false: kept in memory, not a --format
  const char* help;        // --format's help text for it
  const char* files;       // what `railcrash run` says the folder holds
  std::vector<std::string> folder_files;  // the files it writes into the run folder (results/run_files.hpp run_folder_files)
  void (*require)();       // throws InputError saying how to get the format when this build has none (nullptr: always there)
  std::unique_ptr<OutputSink> (*make)();
};

/// Every registered format, in --format's order.
const std::vector<OutputFormat>& output_formats();
/// The format of that name; InputError naming the registered ones when there is none.
const OutputFormat& output_format(const std::string& name);
/// The names --format takes (the formats that write files).
std::vector<std::string> file_output_format_names();
/// --format's help: each format that writes files with its help text.
std::string output_format_help();
/// Throws InputError when the format is unknown or this build cannot write it.
void require_output_format(const std::string& name);
/// A new sink of the named format (after require_output_format's checks).
std::unique_ptr<OutputSink> make_output_sink(const std::string& name);

}  // namespace railcrash
