// The run folder's binary output (`railcrash run --format hdf5`, src/results/hdf5_sink.cpp): DIR/timeseries.h5, one HDF5
// file in place of the per-row CSV files, for large runs. Each table is one dataset, chunked and
// extendible along its rows, filled in blocks of rows as the run goes (the run is never held in
// memory):
//   /timeseries     the columns of timeseries.csv, same names and order, as float64
//   /accelerations  the columns of accelerations.csv
//   /energy         the columns of energy.csv
//   /events         t (float64), element, event (UTF-8 strings), value (float64): events.csv's
// A table is one compound dataset (one named field per column), so that h5py reads it as a
// numpy record array and pandas.DataFrame(h5py.File(p)["timeseries"][:]) is the CSV's table.
// HDF5 keeps a compound type's description in an object header message of at most 64 KiB
// (some thousand columns of consist-length names): a wider table (a consist's timeseries) is
// written as a 2-D float64 dataset instead (rows x columns), its column names in the dataset
// "<table>_columns"; the attribute "layout" of every table says which ("compound" or "matrix").
// File attributes: railcrash_version, model_file, model, units, run_id and provenance (the
// run's, results/provenance.hpp, as JSON); each table's "units" attribute.
//
// Every HDF5 call's result is checked: the first failure (with HDF5's innermost message, which
// for a failed write names the OS's reason) is kept in error(), and after it nothing more is
// written. flush() writes the buffered rows and flushes the file, so a run that fails or is
// interrupted leaves a readable file holding the rows up to then; the destructor closes it.
//
// Built only when CMake finds Debian's serial HDF5 (libhdf5-dev, RAILCRASH_HDF5 defined);
// otherwise hdf5_available() is false and opening a file throws an InputError saying how to get it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace railcrash {

/// Whether this build writes HDF5 (CMake found libhdf5-dev).
bool hdf5_available();
/// Throws InputError saying how to get HDF5 (install libhdf5-dev, build again) when this build has none.
void require_hdf5();

class Hdf5File {
 public:
  /// Rows collected in memory before they are written, and a chunk of the dataset: at most this
  /// many bytes of them (at least one row). Within HDF5's 1 MiB chunk cache.
  static constexpr std::size_t kBlockBytes = 128 * 1024;

  /// Creates (or truncates) path. Throws InputError when it cannot, or when this build has no HDF5.
  explicit Hdf5File(const std::string& path);
  ~Hdf5File();  // writes the rows left and closes the file
  Hdf5File(const Hdf5File&) = delete;
  Hdf5File& operator=(const Hdf5File&) = delete;

  /// A text attribute of the file (root group).
  void attribute(const std::string& name, const std::string& value);
  /// A table of float64 columns; returns its number for append(). units: its "units" attribute ("" none).
  int add_table(const std::string& name, const std::vector<std::string>& columns, const std::string& units);
  /// The events table (t, element, event, value); returns its number for append_event().
  int add_event_table(const std::string& name);
  /// One row: as many values as the table has columns.
  void append(int table, const double* values);
  void append_event(int table, double t, const std::string& element, const std::string& event, double value);
  /// Writes every table's buffered rows and flushes the file; false (and error() set) on failure.
  bool flush();
  /// The first failure ("what: HDF5's reason"), "" while all went well.
  const std::string& error() const { return error_; }
  const std::string& path() const { return path_; }
  /// Whether table was written as a compound dataset (false: a 2-D matrix, see above).
  bool compound(int table) const;

 private:
  struct Table;
  std::string path_;
  [[maybe_unused]] std::int64_t file_ = -1;  // hid_t (a build without HDF5 never opens one)
  std::vector<std::unique_ptr<Table>> tables_;
  std::string error_;

  void write_block(Table& table);
  /// Records the first failure with HDF5's innermost error message; returns false.
  bool fail(const std::string& what);
};

/// A numeric table of timeseries.h5 read back (compound or matrix layout alike).
struct Hdf5Table {
  bool found = false;                       // false: the file has no dataset of that name
  std::vector<std::string> columns;         // names, in the CSV file's order
  std::vector<std::vector<double>> values;  // per column, one value per row
  std::size_t rows = 0;
};

/// One row of the events table read back.
struct Hdf5Event {
  double t = 0.0;  // [time]
  std::string element, event;
  double value = 0.0;
};

/// Reads back what Hdf5File wrote (`railcrash report` of a --format hdf5 run folder), with the
/// library loaded as for writing. Every failure is an InputError naming the file (and the
/// table) with HDF5's innermost message and what to do: a truncated or damaged file cannot be
/// opened, a table of the wrong kind is refused.
class Hdf5Reader {
 public:
  /// Opens path read-only. Throws InputError when it cannot (not an HDF5 file, truncated, no HDF5 in this build).
  explicit Hdf5Reader(const std::string& path);
  ~Hdf5Reader();
  Hdf5Reader(const Hdf5Reader&) = delete;
  Hdf5Reader& operator=(const Hdf5Reader&) = delete;

  /// A text attribute of the file (root group); "" when there is none.
  std::string attribute(const std::string& name) const;
  /// A numeric table whole; found false when the file has none of that name. A table of more
  /// than max_bytes of values is an InputError (the report's memory limit, report/folder_file.hpp).
  Hdf5Table table(const std::string& name, std::uint64_t max_bytes) const;
  /// The events table (t, element, event, value), at most max_rows of its first rows; found false when there is none.
  std::vector<Hdf5Event> events(const std::string& name, std::size_t max_rows, bool* found) const;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  [[maybe_unused]] std::int64_t file_ = -1;  // hid_t
  /// Throws InputError "'path' [table]: what (HDF5: reason); advice".
  [[noreturn]] void fail(const std::string& what) const;
};

}  // namespace railcrash
