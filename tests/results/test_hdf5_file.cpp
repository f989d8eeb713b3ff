// The HDF5 run output (results/hdf5_file.hpp, `run --format hdf5`): the same tables as the CSV
// files, read back here with the HDF5 C API and compared value by value; the layout of a table
// too wide for one compound type; a run that fails, and a write that fails, mid-run.
#include <catch2/catch.hpp>

#include <sys/resource.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/hdf5_file.hpp"
#include "railcrash/results/run.hpp"
#include "support.hpp"

#ifdef RAILCRASH_HDF5
#include <hdf5.h>
#endif

using namespace railcrash;

namespace {

std::string temporary_folder(const std::string& name) {
  const auto path = testing::temp_path("railcrash_test_hdf5_" + name);
  std::filesystem::remove_all(path);
  return path.string();
}

LoadedModel two_car_model(double t_end) {
  RunOverrides overrides;
  overrides.t_end = t_end;
  overrides.output_interval = 1e-3;
  return load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml", {}, option_settings(overrides));
}

}  // namespace

#ifndef RAILCRASH_HDF5

TEST_CASE("without HDF5, --format hdf5 is an input error that says how to get it", "[results][hdf5]") {
  CHECK_FALSE(hdf5_available());
  const std::string dir = temporary_folder("absent");
  const LoadedModel loaded = two_car_model(0.001);
  CHECK_THROWS_WITH(run_model(loaded.model, loaded.run_spec, dir, nullptr, false, false, "hdf5"),
                    Catch::Contains("built without HDF5") && Catch::Contains("libhdf5-dev"));
  std::filesystem::remove_all(dir);
}

#else

namespace {

/// A CSV file's lines split at commas (the names here have no quotes or commas).
std::vector<std::vector<std::string>> csv_fields(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("# railcrash provenance ", 0) == 0) continue;  // the run's provenance, before the header
    std::vector<std::string> fields;
    std::stringstream split(line);
    for (std::string field; std::getline(split, field, ',');) fields.push_back(field);
    rows.push_back(fields);
  }
  return rows;
}

/// value as the CSV files write it (printf's "%.12g").
std::string csv_text(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.12g", value);
  return text;
}

/// Opens an HDF5 object and closes it at the end of the scope.
struct Id {
  hid_t id;
  explicit Id(hid_t value) : id(value) { REQUIRE(id >= 0); }
  ~Id() { H5Idec_ref(id); }
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
};

/// Rows of a dataset of one dimension.
hsize_t row_count(hid_t dataset) {
  const Id space(H5Dget_space(dataset));
  hsize_t rows = 0;
  REQUIRE(H5Sget_simple_extent_ndims(space.id) == 1);
  H5Sget_simple_extent_dims(space.id, &rows, nullptr);
  return rows;
}

/// A compound table's field names, and its values read field by field by name as doubles.
std::vector<std::string> field_names(hid_t dataset) {
  const Id type(H5Dget_type(dataset));
  REQUIRE(H5Tget_class(type.id) == H5T_COMPOUND);
  std::vector<std::string> names;
  for (int k = 0; k < H5Tget_nmembers(type.id); ++k) {
    char* name = H5Tget_member_name(type.id, static_cast<unsigned>(k));
    names.emplace_back(name);
    H5free_memory(name);
  }
  return names;
}

std::vector<double> read_doubles(hid_t dataset, const std::vector<std::string>& names) {
  const Id memory(H5Tcreate(H5T_COMPOUND, sizeof(double) * names.size()));
  for (std::size_t k = 0; k < names.size(); ++k)
    REQUIRE(H5Tinsert(memory.id, names[k].c_str(), sizeof(double) * k, H5T_NATIVE_DOUBLE) >= 0);
  std::vector<double> values(row_count(dataset) * names.size());
  REQUIRE(H5Dread(dataset, memory.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) >= 0);
  return values;
}

/// Every value of the table `name` of the .h5 file against the CSV file's text.
void check_table_matches_csv(hid_t file, const std::string& name, const std::string& csv_path) {
  INFO("table " << name);
  const std::vector<std::vector<std::string>> csv = csv_fields(csv_path);
  REQUIRE(csv.size() > 2);
  const Id dataset(H5Dopen2(file, name.c_str(), H5P_DEFAULT));
  const std::vector<std::string> names = field_names(dataset.id);
  CHECK(names == csv.front());
  REQUIRE(row_count(dataset.id) == csv.size() - 1);
  const std::vector<double> values = read_doubles(dataset.id, names);
  std::size_t mismatches = 0;
  for (std::size_t row = 1; row < csv.size(); ++row)
    for (std::size_t column = 0; column < names.size(); ++column)
      if (csv_text(values[(row - 1) * names.size() + column]) != csv[row][column]) ++mismatches;
  CHECK(mismatches == 0);
}

}  // namespace

TEST_CASE("timeseries.h5 holds the CSV files' tables, every value and name alike", "[results][hdf5]") {
  REQUIRE(hdf5_available());
  const LoadedModel loaded = two_car_model(0.02);
  const Model& model = loaded.model;  // 21 rows of 390 columns, wheel contact events at t = 0
  const std::string csv_dir = temporary_folder("csv"), hdf5_dir = temporary_folder("h5");
  const RunReport csv_run = run_model(model, loaded.run_spec, csv_dir);
  const RunReport hdf5_run = run_model(model, loaded.run_spec, hdf5_dir, nullptr, false, false, "hdf5");
  REQUIRE(csv_run.outcome.ok);
  REQUIRE(hdf5_run.outcome.ok);
  for (const char* csv_file : {"timeseries.csv", "events.csv", "accelerations.csv", "energy.csv"})
    CHECK_FALSE(std::filesystem::exists(hdf5_dir + "/" + csv_file));
  CHECK_THAT(hdf5_run.summary_json, Catch::Contains("\"output\": {\"format\": \"hdf5\", \"files\": [\"timeseries.h5\"]"));

  const Id file(H5Fopen((hdf5_dir + "/timeseries.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
  for (const char* table : {"timeseries", "accelerations", "energy"})
    check_table_matches_csv(file.id, table, csv_dir + "/" + table + ".csv");

  // Events: t, element, event, value, with the element and event names as UTF-8 strings.
  struct EventRow {
    double t;
    char* element;
    char* event;
    double value;
  };
  const Id events(H5Dopen2(file.id, "events", H5P_DEFAULT));
  CHECK(field_names(events.id) == std::vector<std::string>{"t", "element", "event", "value"});
  const Id text(H5Tcopy(H5T_C_S1));
  H5Tset_size(text.id, H5T_VARIABLE);
  H5Tset_cset(text.id, H5T_CSET_UTF8);
  const Id memory(H5Tcreate(H5T_COMPOUND, sizeof(EventRow)));
  H5Tinsert(memory.id, "t", HOFFSET(EventRow, t), H5T_NATIVE_DOUBLE);
  H5Tinsert(memory.id, "element", HOFFSET(EventRow, element), text.id);
  H5Tinsert(memory.id, "event", HOFFSET(EventRow, event), text.id);
  H5Tinsert(memory.id, "value", HOFFSET(EventRow, value), H5T_NATIVE_DOUBLE);
  const std::vector<std::vector<std::string>> csv = csv_fields(csv_dir + "/events.csv");
  std::vector<EventRow> rows(row_count(events.id));
  REQUIRE(rows.size() == csv.size() - 1);
  REQUIRE(rows.size() == csv_run.outcome.events.size());
  REQUIRE(H5Dread(events.id, memory.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows.data()) >= 0);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    CHECK(std::vector<std::string>{csv_text(rows[k].t), rows[k].element, rows[k].event, csv_text(rows[k].value)} ==
          csv[k + 1]);
  }
  const Id space(H5Dget_space(events.id));
  H5Dvlen_reclaim(memory.id, space.id, H5P_DEFAULT, rows.data());

  // The file's attributes: the version and model file.
  const Id version(H5Aopen(file.id, "model_file", H5P_DEFAULT));
  char* model_file = nullptr;
  REQUIRE(H5Aread(version.id, text.id, &model_file) >= 0);
  CHECK(std::string(model_file) == model.file);
  H5free_memory(model_file);
  std::filesystem::remove_all(csv_dir);
  std::filesystem::remove_all(hdf5_dir);
}

TEST_CASE("a table too wide for one compound type becomes a rows x columns matrix with its names beside it",
          "[results][hdf5]") {
  const std::string dir = temporary_folder("wide");
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/wide.h5";
  // 3,000 columns of 28-character names: some 100 kB of type description, over HDF5's 64 KiB.
  std::vector<std::string> names;
  for (int k = 0; k < 3000; ++k) names.push_back("car" + std::to_string(1000 + k) + "_center_body.omega_k");
  const std::vector<std::string> narrow{"t", "x"};
  const int rows = 70;  // more than one block (128 KiB / 24 kB = 5 rows)
  {
    Hdf5File file(path);
    const int wide = file.add_table("wide", names, "");
    const int small = file.add_table("small", narrow, "");
    CHECK_FALSE(file.compound(wide));
    CHECK(file.compound(small));
    std::vector<double> row(names.size());
    for (int r = 0; r < rows; ++r) {
      for (std::size_t k = 0; k < row.size(); ++k) row[k] = r * 10000.0 + static_cast<double>(k);
      file.append(wide, row.data());
      file.append(small, row.data());
      if (r == 32) CHECK(file.flush());  // a chunk written part-full, then again when full
    }
    CHECK(file.flush());
    CHECK(file.error().empty());
  }
  const Id file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
  const Id matrix(H5Dopen2(file.id, "wide", H5P_DEFAULT));
  const Id space(H5Dget_space(matrix.id));
  hsize_t dims[2] = {0, 0};
  REQUIRE(H5Sget_simple_extent_ndims(space.id) == 2);
  H5Sget_simple_extent_dims(space.id, dims, nullptr);
  CHECK(dims[0] == static_cast<hsize_t>(rows));
  CHECK(dims[1] == names.size());
  std::vector<double> values(dims[0] * dims[1]);
  REQUIRE(H5Dread(matrix.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) >= 0);
  CHECK(values[0] == 0.0);
  CHECK(values[2999] == 2999.0);
  CHECK(values[32 * 3000 + 5] == 320005.0);
  CHECK(values[34 * 3000 + 5] == 340005.0);
  CHECK(values[69 * 3000 + 17] == 690017.0);
  const Id column_names(H5Dopen2(file.id, "wide_columns", H5P_DEFAULT));
  CHECK(row_count(column_names.id) == names.size());
  const Id small(H5Dopen2(file.id, "small", H5P_DEFAULT));
  CHECK(field_names(small.id) == narrow);
  const std::vector<double> small_values = read_doubles(small.id, narrow);
  CHECK(small_values.size() == 2 * rows);
  for (int r = 0; r < rows; ++r) CHECK(small_values[2 * r] == r * 10000.0);
  CHECK(small_values[2 * 69 + 1] == 690001.0);
  std::filesystem::remove_all(dir);
}

TEST_CASE("a run that fails leaves timeseries.h5 closed and readable with the rows up to the failure",
          "[results][hdf5][faults]") {
  LoadedModel loaded = two_car_model(0.05);
  loaded.run_spec.simulation.max_steps = 150;  // IDA stops there: a failed run
  const std::string dir = temporary_folder("failed");
  const RunReport report = run_model(loaded.model, loaded.run_spec, dir, nullptr, false, false, "hdf5");
  REQUIRE_FALSE(report.outcome.ok);
  const Id file(H5Fopen((dir + "/timeseries.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
  const Id timeseries(H5Dopen2(file.id, "timeseries", H5P_DEFAULT));
  const std::vector<double> t = read_doubles(timeseries.id, {"t"});
  REQUIRE(t.size() > 2);
  CHECK(t.front() == 0.0);
  CHECK(t.back() == Approx(report.outcome.t_reached).margin(1e-3));  // the last output row before the failure
  CHECK(t.back() < 0.05);
  std::filesystem::remove_all(dir);
}

TEST_CASE("a write that fails mid-run stops the run with the file and the OS's reason", "[results][hdf5][faults]") {
  const std::string dir = temporary_folder("too_large");
  std::filesystem::create_directories(dir);
  // Files of this process may grow to 200 kB: the first blocks fit, a later one gets EFBIG.
  rlimit old_limit{};
  REQUIRE(getrlimit(RLIMIT_FSIZE, &old_limit) == 0);
  rlimit limit = old_limit;
  limit.rlim_cur = 200 * 1024;
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);  // a write past the limit fails instead of killing
  REQUIRE(setrlimit(RLIMIT_FSIZE, &limit) == 0);
  const LoadedModel loaded = two_car_model(0.1);
  const RunReport report = run_model(loaded.model, loaded.run_spec, dir, nullptr, false, false, "hdf5");
  setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  CHECK_FALSE(report.outcome.ok);
  CHECK_THAT(report.outcome.message, Catch::Contains("cannot write " + dir + "/timeseries.h5: File too large"));
  CHECK(report.outcome.t_reached < 0.1);
  std::ifstream summary(dir + "/summary.json");
  std::stringstream text;
  text << summary.rdbuf();
  CHECK_THAT(text.str(), Catch::Contains("\"status\": \"failed\"") && Catch::Contains("File too large"));
  std::filesystem::remove_all(dir);
}

#endif
