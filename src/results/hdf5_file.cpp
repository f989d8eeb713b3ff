// DIR/timeseries.h5 of `railcrash run --format hdf5` (see the header).
#include "railcrash/results/hdf5_file.hpp"

#include "railcrash/core/error.hpp"

#ifdef RAILCRASH_HDF5
#include <hdf5.h>

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <type_traits>

#include "railcrash/results/results.hpp"
#endif

namespace railcrash {

void require_hdf5() {
  if (!hdf5_available())
    throw InputError("--format hdf5: this railcrash was built without HDF5; install Debian's libhdf5-dev "
                     "(scripts/install-deps.sh does), configure and build again, or leave out --format hdf5 for the CSV files");
}

#ifndef RAILCRASH_HDF5

bool hdf5_available() { return false; }

struct Hdf5File::Table {};

Hdf5File::Hdf5File(const std::string& path) : path_(path) { require_hdf5(); }
Hdf5File::~Hdf5File() = default;
void Hdf5File::attribute(const std::string&, const std::string&) {}
int Hdf5File::add_table(const std::string&, const std::vector<std::string>&, const std::string&) { return -1; }
int Hdf5File::add_event_table(const std::string&) { return -1; }
void Hdf5File::append(int, const double*) {}
void Hdf5File::append_event(int, double, const std::string&, const std::string&, double) {}
bool Hdf5File::flush() { return false; }
bool Hdf5File::compound(int) const { return false; }
void Hdf5File::write_block(Table&) {}
bool Hdf5File::fail(const std::string&) { return false; }

Hdf5Reader::Hdf5Reader(const std::string& path) : path_(path) {
  throw InputError("'" + path + "' is an HDF5 file (a run with --format hdf5) and this railcrash was built without HDF5; "
                   "install Debian's libhdf5-dev (scripts/install-deps.sh does), configure and build again, or run the "
                   "model again with --format csv (the default)");
}
Hdf5Reader::~Hdf5Reader() = default;
std::string Hdf5Reader::attribute(const std::string&) const { return ""; }
Hdf5Table Hdf5Reader::table(const std::string&, std::uint64_t) const { return {}; }
std::vector<Hdf5Event> Hdf5Reader::events(const std::string&, std::size_t, bool* found) const {
  *found = false;
  return {};
}
void Hdf5Reader::fail(const std::string& what) const { throw InputError("'" + path_ + "': " + what); }

#else

static_assert(std::is_same_v<hid_t, std::int64_t>, "the header keeps hid_t as std::int64_t (HDF5 1.10 and later)");

bool hdf5_available() { return true; }

namespace {

/// One row of the events table as HDF5 reads it from memory.
struct EventRow {
  double t;             // [time]
  const char* element;  // UTF-8, owned by Table::texts until written
  const char* event;
  double value;
};

/// A variable-length UTF-8 string type (to close with H5Tclose), or a negative id.
hid_t utf8_string_type() {
  const hid_t type = H5Tcopy(H5T_C_S1);
  if (type < 0) return type;
  if (H5Tset_size(type, H5T_VARIABLE) < 0 || H5Tset_cset(type, H5T_CSET_UTF8) < 0) {
    H5Tclose(type);
    return -1;
  }
  return type;
}

/// Closes an HDF5 identifier of any kind when it goes out of scope.
class Handle {
 public:
  explicit Handle(hid_t id) : id_(id) {}
  ~Handle() {
    if (id_ >= 0) H5Idec_ref(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_;
};

/// HDF5's innermost error message (the first one walking up the stack).
herr_t keep_innermost(unsigned depth, const H5E_error2_t* error, void* message) {
  if (depth == 0 && error->desc) *static_cast<std::string*>(message) = error->desc;
  return 0;
}

/// The reason in an HDF5 message: a failed write's "error message = '...'" (the OS's text), else all of it.
std::string reason_in(const std::string& message) {
  const std::string key = "error message = '";
  const std::size_t start = message.find(key);
  if (start == std::string::npos) return message.empty() ? "unknown HDF5 error" : message;
  const std::size_t end = message.find('\'', start + key.size());
  return message.substr(start + key.size(), end == std::string::npos ? std::string::npos : end - start - key.size());
}

/// A text attribute of an HDF5 object; false on failure.
bool object_attribute(hid_t object, const char* name, const std::string& value) {
  const Handle type(utf8_string_type());
  const Handle space(H5Screate(H5S_SCALAR));
  if (!type.valid() || !space.valid()) return false;
  const Handle attribute(H5Acreate2(object, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT));
  const std::string text = valid_utf8(value);
  const char* data = text.c_str();
  return attribute.valid() && H5Awrite(attribute.get(), type.get(), &data) >= 0;
}

/// A 1-D dataset of rows of file_type, empty, chunked by block_rows and extendible; extra_columns > 0
/// makes it 2-D (rows x extra_columns). A negative id on failure.
hid_t extendible_dataset(hid_t file, const std::string& name, hid_t file_type, hsize_t block_rows, hsize_t extra_columns) {
  const int rank = extra_columns > 0 ? 2 : 1;
  const hsize_t empty[2] = {0, extra_columns}, unlimited[2] = {H5S_UNLIMITED, extra_columns};
  const hsize_t chunk[2] = {block_rows, extra_columns};
  const Handle space(H5Screate_simple(rank, empty, unlimited));
  const Handle properties(H5Pcreate(H5P_DATASET_CREATE));
  if (!space.valid() || !properties.valid() || H5Pset_chunk(properties.get(), rank, chunk) < 0) return -1;
  return H5Dcreate2(file, name.c_str(), file_type, space.get(), H5P_DEFAULT, properties.get(), H5P_DEFAULT);
}

}  // namespace

struct Hdf5File::Table {
  std::string name;
  hid_t dataset = -1;
  hid_t event_type = -1;        // events: the row type in memory (numeric chunks go in as they are)
  bool compound = true;         // false: a rows x columns matrix
  std::size_t columns = 0;      // float64 values per row (0 for events)
  hsize_t first_pending_row = 0;  // events: rows written; numeric: first row of the chunk being filled
  std::size_t block_rows = 1;   // rows per chunk and per write
  std::vector<double> pending;  // numeric: the rows of the chunk being filled, one after another
  std::vector<EventRow> pending_events;
  std::deque<std::string> texts;  // the strings of pending_events (a deque keeps them in place)

  std::size_t pending_rows() const { return columns > 0 ? pending.size() / columns : pending_events.size(); }
};

bool Hdf5File::fail(const std::string& what) {
  std::string message;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, keep_innermost, &message);
  H5Eclear2(H5E_DEFAULT);
  if (error_.empty()) error_ = what + ": " + reason_in(message);
  return false;
}

Hdf5File::Hdf5File(const std::string& path) : path_(path) {
  // No HDF5 clean-up at exit: a file whose close failed (its last flush hit a full disk) stays
  // open inside HDF5, and 1.10.8 crashes closing it again from its atexit handler. Every file
  // that can be is closed by the destructor; the OS closes the rest. (A no-op once HDF5 runs.)
  H5dont_atexit();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported through error(), not printed
  // The 1.8 file format at least: its compact encoding of compound types (datatype message
  // version 3) fits more named columns in the 64 KiB a type may take than the older padded one.
  // Not the 1.10 format: its superblock (version 3) marks the file open for writing, and after a
  // kill -9 no reader opens it until `h5clear -s`; the 1.8 superblock has no such mark, so a
  // killed run's file opens, with the rows of its last flush (summary.json's output.valid_rows).
  const Handle access(H5Pcreate(H5P_FILE_ACCESS));
  if (access.valid() && H5Pset_libver_bounds(access.get(), H5F_LIBVER_V18, H5F_LIBVER_V18) >= 0)
    file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access.get());
  if (file_ < 0) {
    fail("cannot create " + path);
    throw InputError(error_);
  }
}

Hdf5File::~Hdf5File() {
  if (file_ < 0) return;
  flush();
  for (const auto& table : tables_) {
    if (table->dataset >= 0) H5Dclose(table->dataset);
    if (table->event_type >= 0) H5Tclose(table->event_type);
  }
  H5Fclose(file_);
  H5Eclear2(H5E_DEFAULT);
}

void Hdf5File::attribute(const std::string& name, const std::string& value) {
  if (error_.empty() && !object_attribute(file_, name.c_str(), value)) fail("cannot write the attribute " + name + " of " + path_);
}

int Hdf5File::add_table(const std::string& name, const std::vector<std::string>& columns, const std::string& units) {
  assert(!columns.empty());
  auto table = std::make_unique<Table>();
  table->name = name;
  table->columns = columns.size();
  const std::size_t row_bytes = sizeof(double) * columns.size();
  table->block_rows = std::max<std::size_t>(1, kBlockBytes / row_bytes);
  const Handle row_type(H5Tcreate(H5T_COMPOUND, row_bytes));
  bool ok = row_type.valid();
  for (std::size_t k = 0; ok && k < columns.size(); ++k)
    ok = H5Tinsert(row_type.get(), columns[k].c_str(), sizeof(double) * k, H5T_NATIVE_DOUBLE) >= 0;
  if (ok) table->dataset = extendible_dataset(file_, name, row_type.get(), table->block_rows, 0);
  if (table->dataset < 0) {  // too wide for one compound type (or a repeated name): a matrix
    H5Eclear2(H5E_DEFAULT);
    table->compound = false;
    table->dataset = extendible_dataset(file_, name, H5T_NATIVE_DOUBLE, table->block_rows, columns.size());
    if (table->dataset >= 0) {
      // The names as a dataset beside it: an attribute of that many strings can outgrow 64 KiB too.
      const Handle type(utf8_string_type());
      const hsize_t count = columns.size();
      const Handle space(H5Screate_simple(1, &count, nullptr));
      const Handle names(type.valid() && space.valid()
                             ? H5Dcreate2(file_, (name + "_columns").c_str(), type.get(), space.get(), H5P_DEFAULT,
                                          H5P_DEFAULT, H5P_DEFAULT)
                             : -1);
      std::vector<std::string> texts;
      std::vector<const char*> pointers;
      for (const std::string& column : columns) texts.push_back(valid_utf8(column));
      for (const std::string& text : texts) pointers.push_back(text.c_str());
      if (!names.valid() || H5Dwrite(names.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, pointers.data()) < 0 ||
          !object_attribute(table->dataset, "columns", "the dataset " + name + "_columns"))
        fail("cannot write the column names of " + path_ + ":/" + name);
    }
  }
  if (table->dataset < 0) fail("cannot create the table " + name + " in " + path_);
  if (table->dataset >= 0 && (!object_attribute(table->dataset, "layout", table->compound ? "compound" : "matrix") ||
                              (!units.empty() && !object_attribute(table->dataset, "units", units))))
    fail("cannot write the attributes of " + path_ + ":/" + name);
  tables_.push_back(std::move(table));
  return static_cast<int>(tables_.size()) - 1;
}

int Hdf5File::add_event_table(const std::string& name) {
  auto table = std::make_unique<Table>();
  table->name = name;
  table->block_rows = 1024;
  const Handle text(utf8_string_type());
  table->event_type = H5Tcreate(H5T_COMPOUND, sizeof(EventRow));
  bool ok = text.valid() && table->event_type >= 0;
  ok = ok && H5Tinsert(table->event_type, "t", offsetof(EventRow, t), H5T_NATIVE_DOUBLE) >= 0;
  ok = ok && H5Tinsert(table->event_type, "element", offsetof(EventRow, element), text.get()) >= 0;
  ok = ok && H5Tinsert(table->event_type, "event", offsetof(EventRow, event), text.get()) >= 0;
  ok = ok && H5Tinsert(table->event_type, "value", offsetof(EventRow, value), H5T_NATIVE_DOUBLE) >= 0;
  if (ok) table->dataset = extendible_dataset(file_, name, table->event_type, table->block_rows, 0);
  if (table->dataset < 0 || !object_attribute(table->dataset, "layout", "compound"))
    fail("cannot create the table " + name + " in " + path_);
  tables_.push_back(std::move(table));
  return static_cast<int>(tables_.size()) - 1;
}

bool Hdf5File::compound(int table) const { return tables_[static_cast<std::size_t>(table)]->compound; }

void Hdf5File::append(int number, const double* values) {
  Table& table = *tables_[static_cast<std::size_t>(number)];
  table.pending.insert(table.pending.end(), values, values + table.columns);
  if (table.pending_rows() >= table.block_rows) write_block(table);
}

void Hdf5File::append_event(int number, double t, const std::string& element, const std::string& event, double value) {
  Table& table = *tables_[static_cast<std::size_t>(number)];
  const char* element_text = table.texts.emplace_back(valid_utf8(element)).c_str();
  const char* event_text = table.texts.emplace_back(valid_utf8(event)).c_str();
  table.pending_events.push_back(EventRow{t, element_text, event_text, value});
  if (table.pending_rows() >= table.block_rows) write_block(table);
}

void Hdf5File::write_block(Table& table) {
  const hsize_t rows = table.pending_rows();
  if (rows == 0 || !error_.empty() || table.dataset < 0) {  // nothing more after a failure
    table.pending.clear();
    table.pending_events.clear();
    table.texts.clear();
    return;
  }
  const hsize_t extent[2] = {table.first_pending_row + rows, table.columns};
  bool ok = H5Dset_extent(table.dataset, extent) >= 0;
  if (table.columns > 0) {
    // A numeric table's chunk is written whole, as it is in memory (H5Dwrite_chunk), its rows
    // past the extent unused until a later write of the same chunk fills them: no conversion
    // path, whose lookup compares a compound type's N field names at every H5Dwrite (15 % of a
    // consist's run when written with H5Dwrite).
    const hsize_t offset[2] = {table.first_pending_row, 0};
    table.pending.resize(table.block_rows * table.columns, 0.0);
    ok = ok && H5Dwrite_chunk(table.dataset, H5P_DEFAULT, 0, offset, sizeof(double) * table.pending.size(),
                              table.pending.data()) >= 0;
    table.pending.resize(rows * table.columns);
    if (ok && rows == table.block_rows) {  // the chunk is full: the next rows start the next one
      table.first_pending_row += rows;
      table.pending.clear();
    }
  } else {
    const hsize_t start = table.first_pending_row;
    const Handle file_space(ok ? H5Dget_space(table.dataset) : -1);
    const Handle memory_space(H5Screate_simple(1, &rows, nullptr));
    ok = ok && file_space.valid() && memory_space.valid() &&
         H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, &start, nullptr, &rows, nullptr) >= 0 &&
         H5Dwrite(table.dataset, table.event_type, memory_space.get(), file_space.get(), H5P_DEFAULT,
                  table.pending_events.data()) >= 0;
    if (ok) table.first_pending_row += rows;
    table.pending_events.clear();
    table.texts.clear();
  }
  if (!ok) fail("cannot write " + path_);
}

bool Hdf5File::flush() {
  for (const auto& table : tables_) write_block(*table);
  if (error_.empty() && H5Fflush(file_, H5F_SCOPE_LOCAL) < 0) fail("cannot write " + path_);
  return error_.empty();
}

// ---- Reading back (the report) ----

namespace {

/// HDF5's innermost message of the error stack, cleared ("" when there is none).
std::string innermost_message() {
  std::string message;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, keep_innermost, &message);
  H5Eclear2(H5E_DEFAULT);
  return message;
}

/// Frees a string HDF5 allocated (a member name, a variable-length string read).
struct HdfText {
  char* text = nullptr;
  ~HdfText() {
    if (text) H5free_memory(text);
  }
  std::string get() const { return text ? std::string(text) : std::string(); }
};

}  // namespace

void Hdf5Reader::fail(const std::string& what) const {
  const std::string message = innermost_message();
  throw InputError("'" + path_ + "' " + what + (message.empty() ? std::string() : " (HDF5: " + message + ")") +
                   ": the file is damaged or was not written by `railcrash run --format hdf5` (a run killed before its "
                   "first flush, or a copy cut short); run the model again");
}

Hdf5Reader::Hdf5Reader(const std::string& path) : path_(path) {
  H5dont_atexit();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are thrown with their message, not printed
  file_ = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file_ < 0) fail("cannot be opened as an HDF5 file");
}

Hdf5Reader::~Hdf5Reader() {
  if (file_ >= 0) H5Fclose(file_);
  H5Eclear2(H5E_DEFAULT);
}

std::string Hdf5Reader::attribute(const std::string& name) const {
  const htri_t exists = H5Aexists(file_, name.c_str());
  if (exists < 0) fail("cannot be read (the attribute " + name + ")");
  if (exists == 0) return "";
  const Handle attribute(H5Aopen(file_, name.c_str(), H5P_DEFAULT));
  const Handle type(utf8_string_type());
  HdfText text;
  if (!attribute.valid() || !type.valid() || H5Aread(attribute.get(), type.get(), &text.text) < 0)
    fail("has an attribute " + name + " that is not a text");
  return text.get();
}

Hdf5Table Hdf5Reader::table(const std::string& name, std::uint64_t max_bytes) const {
  Hdf5Table table;
  const htri_t exists = H5Lexists(file_, name.c_str(), H5P_DEFAULT);
  if (exists < 0) fail("cannot be read (looking for the table " + name + ")");
  if (exists == 0) return table;
  table.found = true;
  const Handle dataset(H5Dopen2(file_, name.c_str(), H5P_DEFAULT));
  if (!dataset.valid()) fail("cannot open its table " + name);
  const Handle file_type(H5Dget_type(dataset.get()));
  const Handle file_space(H5Dget_space(dataset.get()));
  if (!file_type.valid() || !file_space.valid()) fail("cannot read the type of its table " + name);
  const int rank = H5Sget_simple_extent_ndims(file_space.get());
  hsize_t extent[2] = {0, 0};
  if (rank < 1 || rank > 2 || H5Sget_simple_extent_dims(file_space.get(), extent, nullptr) < 0)
    fail("has a table " + name + " that is neither a table of rows nor a matrix");
  const H5T_class_t type_class = H5Tget_class(file_type.get());
  // The memory type of one row: a compound of float64 fields of the file's names, or float64 (a matrix).
  hid_t row_type_id = -1;
  if (rank == 1 && type_class == H5T_COMPOUND) {
    const int members = H5Tget_nmembers(file_type.get());
    if (members <= 0) fail("has a table " + name + " without columns");
    row_type_id = H5Tcreate(H5T_COMPOUND, sizeof(double) * static_cast<std::size_t>(members));
    for (int k = 0; k < members && row_type_id >= 0; ++k) {
      HdfText member;
      member.text = H5Tget_member_name(file_type.get(), static_cast<unsigned>(k));
      const H5T_class_t member_class = H5Tget_member_class(file_type.get(), static_cast<unsigned>(k));
      if (!member.text || (member_class != H5T_FLOAT && member_class != H5T_INTEGER)) {
        H5Tclose(row_type_id);
        fail("has a column " + member.get() + " in its table " + name + " that is not a number");
      }
      table.columns.push_back(member.get());
      if (H5Tinsert(row_type_id, member.text, sizeof(double) * static_cast<std::size_t>(k), H5T_NATIVE_DOUBLE) < 0) {
        H5Tclose(row_type_id);
        row_type_id = -1;
      }
    }
  } else if (rank == 2 && type_class == H5T_FLOAT) {
    // A matrix: its column names in the dataset <name>_columns.
    const std::string names_name = name + "_columns";
    const Handle names(H5Lexists(file_, names_name.c_str(), H5P_DEFAULT) > 0 ? H5Dopen2(file_, names_name.c_str(), H5P_DEFAULT) : -1);
    const Handle names_space(names.valid() ? H5Dget_space(names.get()) : -1);
    hsize_t count = 0;
    if (!names_space.valid() || H5Sget_simple_extent_ndims(names_space.get()) != 1 ||
        H5Sget_simple_extent_dims(names_space.get(), &count, nullptr) < 0 || count != extent[1])
      fail("has a matrix " + name + " without the column names " + names_name + " of its " + std::to_string(extent[1]) + " columns");
    const Handle text_type(utf8_string_type());
    std::vector<char*> pointers(count, nullptr);
    if (!text_type.valid() || H5Dread(names.get(), text_type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, pointers.data()) < 0)
      fail("has column names " + names_name + " that are not texts");
    for (char* text : pointers) table.columns.emplace_back(text ? text : "");
    H5Dvlen_reclaim(text_type.get(), names_space.get(), H5P_DEFAULT, pointers.data());
    row_type_id = H5Tcopy(H5T_NATIVE_DOUBLE);
  } else {
    fail("has a table " + name + " that is not numeric");
  }
  const Handle row_type(row_type_id);
  if (!row_type.valid()) fail("cannot read its table " + name);
  const std::size_t columns = table.columns.size();
  table.rows = static_cast<std::size_t>(extent[0]);
  const std::uint64_t bytes = std::uint64_t{sizeof(double)} * columns * table.rows;
  if (bytes > max_bytes)
    throw InputError("'" + path_ + "': its table " + name + " holds " + std::to_string(table.rows) + " rows of " + std::to_string(columns) +
                     " columns, " + std::to_string(bytes / 1000000) + " MB of values, more than the report's limit of " +
                     std::to_string(max_bytes / 1000000) + " MB (an eighth of this machine's memory); run again with a "
                     "longer --output-interval (fewer rows), or read the file with other tools (h5py)");
  table.values.assign(columns, std::vector<double>(table.rows));
  // Blocks of rows (about 4 MB), each a hyperslab of the file's rows, copied into the columns.
  const hsize_t block_rows = std::max<hsize_t>(1, (hsize_t{4} << 20) / (sizeof(double) * columns));
  std::vector<double> block;
  for (hsize_t first = 0; first < extent[0]; first += block_rows) {
    const hsize_t rows = std::min(block_rows, extent[0] - first);
    const hsize_t start[2] = {first, 0}, count[2] = {rows, extent[1]};
    block.resize(static_cast<std::size_t>(rows) * columns);
    const Handle memory_space(H5Screate_simple(rank, count, nullptr));
    if (!memory_space.valid() || H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr) < 0 ||
        H5Dread(dataset.get(), row_type.get(), memory_space.get(), file_space.get(), H5P_DEFAULT, block.data()) < 0)
      fail("cannot read rows " + std::to_string(first) + " to " + std::to_string(first + rows - 1) + " of its table " + name);
    for (std::size_t r = 0; r < rows; ++r)
      for (std::size_t c = 0; c < columns; ++c) table.values[c][static_cast<std::size_t>(first) + r] = block[r * columns + c];
  }
  return table;
}

std::vector<Hdf5Event> Hdf5Reader::events(const std::string& name, std::size_t max_rows, bool* found) const {
  std::vector<Hdf5Event> out;
  *found = false;
  const htri_t exists = H5Lexists(file_, name.c_str(), H5P_DEFAULT);
  if (exists < 0) fail("cannot be read (looking for the table " + name + ")");
  if (exists == 0) return out;
  *found = true;
  const Handle dataset(H5Dopen2(file_, name.c_str(), H5P_DEFAULT));
  const Handle file_space(dataset.valid() ? H5Dget_space(dataset.get()) : -1);
  hsize_t rows = 0;
  if (!file_space.valid() || H5Sget_simple_extent_ndims(file_space.get()) != 1 || H5Sget_simple_extent_dims(file_space.get(), &rows, nullptr) < 0)
    fail("has no table of rows " + name);
  rows = std::min<hsize_t>(rows, max_rows);
  if (rows == 0) return out;
  struct Row {
    double t;
    char* element;
    char* event;
    double value;
  };
  const Handle text(utf8_string_type());
  const Handle row_type(H5Tcreate(H5T_COMPOUND, sizeof(Row)));
  bool ok = text.valid() && row_type.valid();
  ok = ok && H5Tinsert(row_type.get(), "t", offsetof(Row, t), H5T_NATIVE_DOUBLE) >= 0;
  ok = ok && H5Tinsert(row_type.get(), "element", offsetof(Row, element), text.get()) >= 0;
  ok = ok && H5Tinsert(row_type.get(), "event", offsetof(Row, event), text.get()) >= 0;
  ok = ok && H5Tinsert(row_type.get(), "value", offsetof(Row, value), H5T_NATIVE_DOUBLE) >= 0;
  const hsize_t start = 0;
  const Handle memory_space(H5Screate_simple(1, &rows, nullptr));
  std::vector<Row> data(static_cast<std::size_t>(rows), Row{0.0, nullptr, nullptr, 0.0});
  ok = ok && memory_space.valid() && H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, &start, nullptr, &rows, nullptr) >= 0 &&
       H5Dread(dataset.get(), row_type.get(), memory_space.get(), file_space.get(), H5P_DEFAULT, data.data()) >= 0;
  if (!ok) fail("cannot read its table " + name + " (t, element, event, value)");
  for (const Row& row : data)
    out.push_back({row.t, row.element ? row.element : "", row.event ? row.event : "", row.value});
  H5Dvlen_reclaim(row_type.get(), memory_space.get(), H5P_DEFAULT, data.data());
  return out;
}

#endif

}  // namespace railcrash
