// The output sinks (results/output_sink.hpp): the registered formats and what --format takes,
// the CSV sink's bytes for given rows and events, and a run whose one computed row goes to the
// CSV files and to memory alike. On a model in SI: two 40 t cars on a crush zone and a draft gear.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/crush_zones.hpp"
#include "railcrash/results/output_sink.hpp"
#include "railcrash/results/provenance.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/results/run_files.hpp"
#include "railcrash/solver/dae_system.hpp"

namespace fs = std::filesystem;
using namespace railcrash;

namespace {

// Two cars of 40 t of a modern multiple unit, car 1 at 10 m/s into a standing car 2: their
// ends 0.2 m apart on a crush zone (1.5 MN after 50 mm) beside a draft gear (10 MN/m, 80 mm travel).
const char* const kTwoCars = R"(railcrash: 1
name: two 40 t cars on a crush zone and a draft gear, SI
units: SI
gravity: [0, 0]
bodies:
  - {name: car1, car: car1, mass: 40000, inertia: 1.7e6, position: [-10.1, 1.0], velocity: [10, 0]}
  - {name: car2, car: car2, mass: 40000, inertia: 1.7e6, position: [10.1, 1.0]}
elements:
  - {name: crush_zone, type: crush_spring, curve: [[0, 0], [0.05, 1.5e6], [0.6, 1.8e6]], unloading_stiffness: 1.0e8,
     points: [{body: car1, at: [10.0, 0]}, {body: car2, at: [-10.0, 0]}]}
  - {name: draft_gear, type: draft_gear, initial_stiffness: 1.0e7, travel: 0.08, stiffness_after_bottoming: 1.0e9,
     hysteresis_load: 2.0e5, points: [{body: car1, at: [10.0, 0.5]}, {body: car2, at: [-10.0, 0.5]}]}
simulation: {t_end: 0.05, rtol: 1.0e-6, output_interval: 1.0e-3}
)";

fs::path fresh_folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("railcrash_sink_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string general12(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.12g", value);
  return text;
}

}  // namespace

TEST_CASE("Output formats: csv, hdf5 and memory are registered, and --format takes the two that write files") {
  std::vector<std::string> names;
  for (const OutputFormat& format : output_formats()) names.push_back(format.name);
  CHECK(names == std::vector<std::string>{"csv", "hdf5", "memory"});
  CHECK(file_output_format_names() == std::vector<std::string>{"csv", "hdf5"});
  // --format's help is the one railcrash run --help printed before the formats were registered.
  CHECK(output_format_help() == "csv, or hdf5: DIR/timeseries.h5 in place of the per-row CSV files (README \"Binary output\")");
  CHECK(std::string(output_format("csv").files) ==
        "timeseries.csv, events.csv, accelerations.csv, energy.csv, energy_zones.csv");
  // A run owns every file a format writes: an earlier run's are removed (run_folder_files).
  for (const OutputFormat& format : output_formats())
    for (const std::string& file : format.folder_files)
      CHECK(std::count(run_folder_files().begin(), run_folder_files().end(), file) == 1);
  CHECK(output_format("hdf5").folder_files == std::vector<std::string>{"timeseries.h5"});
  CHECK(output_format("memory").folder_files.empty());
  CHECK_THROWS_WITH(output_format("parquet"), "no output format 'parquet'; the formats are csv, hdf5, memory");
  CHECK_NOTHROW(require_output_format("csv"));
  REQUIRE(make_output_sink("memory") != nullptr);
  CHECK(make_output_sink("memory")->kept_columns() != nullptr);
  CHECK(make_output_sink("csv")->kept_columns() == nullptr);
}

TEST_CASE("CSV sink: each row as printf's %.12g after the provenance line and the header, events quoted") {
  const fs::path dir = fresh_folder("csv");
  const Model model = load_model_text(kTwoCars, "two_cars.yaml").model;
  Provenance provenance;
  provenance.run_id = "0123456789abcdef0123456789abcdef";
  OutputLayout layout;
  layout.directory = dir.string();
  layout.model = &model;
  layout.provenance = &provenance;
  layout.tables = {OutputTableLayout{"timeseries", {"t", "car1_end.x"}, ""}, OutputTableLayout{"accelerations", {"t", "a"}, ""},
                   OutputTableLayout{"energy", {"t", "kinetic", "elastic"}, ""}};
  const std::unique_ptr<OutputSink> sink = make_output_sink("csv");
  sink->begin(layout);
  CHECK(sink->takes(OutputTable::Energy));
  const double timeseries[] = {0.001, 1.0 / 3.0};
  const double energy[] = {0.001, 2.0e6, -1.5e-300};
  sink->row(OutputTable::Timeseries, timeseries);
  sink->row(OutputTable::Energy, energy);
  CHECK(sink->event(EventRecord{0.0005, "car1,crush", "yield \"first\"", 0.05}) == "");
  CHECK(sink->check(/*flush=*/true) == "");
  const std::string first = provenance_comment(provenance);
  CHECK(read(dir / "timeseries.csv") == first + "t,car1_end.x\n0.001,0.333333333333\n");
  CHECK(read(dir / "energy.csv") == first + "t,kinetic,elastic\n0.001,2000000,-1.5e-300\n");
  CHECK(read(dir / "accelerations.csv") == first + "t,a\n");
  CHECK(read(dir / "events.csv") == first + "t,element,event,value\n0.0005,\"car1,crush\",\"yield \"\"first\"\"\",0.05\n");
  fs::remove_all(dir);
}

TEST_CASE("Output sinks: a run's rows go to the CSV files and to memory alike, on two 40 t SI cars") {
  const fs::path dir = fresh_folder("run");
  const LoadedModel loaded = load_model_text(kTwoCars, "two_cars.yaml");
  const Model& model = loaded.model;
  const RunReport report = run_model(model, loaded.run_spec, dir.string(), nullptr, false, /*keep_in_memory=*/true);
  REQUIRE(report.outcome.ok);
  REQUIRE(report.columns == timeseries_columns(DaeSystem(model), loaded.run_spec.output_points));
  REQUIRE(report.series.size() == report.columns.size());
  CHECK(report.series[0].size() == 51);  // t = 0, 0.001, ..., 0.05
  // timeseries.csv after its provenance line and header, as the kept columns print.
  std::string expected;
  for (std::size_t row = 0; row < report.series[0].size(); ++row)
    for (std::size_t column = 0; column < report.series.size(); ++column)
      expected += general12(report.series[column][row]) + (column + 1 < report.series.size() ? "," : "\n");
  const std::string text = read(dir / "timeseries.csv");
  const std::size_t header_end = text.find('\n', text.find('\n') + 1);
  REQUIRE(header_end != std::string::npos);
  CHECK(text.substr(header_end + 1) == expected);
  // Car 1 at 10 m/s hits a standing car 2: its end frame has slowed by the end, and car 2's moves.
  // Car 1 at 10 m/s pushes a standing car 2 of its mass: their momentum stays 40 t x 10 m/s.
  const std::vector<double>& vx1 = report.series[4], &vx2 = report.series[10];
  CHECK(report.columns[4] == "car1.vx");
  CHECK(report.columns[10] == "car2.vx");
  CHECK(vx1.front() == 10.0);
  CHECK(vx2.front() == 0.0);
  CHECK(vx1.back() < 9.0);
  CHECK(vx1.back() + vx2.back() == Approx(10.0).epsilon(1e-6));
  fs::remove_all(dir);
}
