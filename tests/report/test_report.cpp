// The run report: min/max decimation, and what `railcrash report` does with good and bad run
// folders (the page itself is checked in a browser by test_report_browser.sh).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <system_error>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "railcrash/core/error.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/report/decimate.hpp"
#include "railcrash/report/folder_file.hpp"
#include "railcrash/report/report.hpp"
#include "railcrash/results/hdf5_file.hpp"
#include "railcrash/results/run.hpp"

namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The run folders small_run made, removed when the test program ends (the tests read them
/// after small_run returns; each name holds the process id, so they would pile up in /tmp).
struct RunFolders {
  std::vector<fs::path> made;
  ~RunFolders() {
    std::error_code ignored;
    for (const fs::path& dir : made) fs::remove_all(dir, ignored);
  }
};
RunFolders run_folders;

/// A fresh run folder of the small two-car crash (tests/report/two_car.yaml), CSV files or timeseries.h5.
fs::path small_run(const std::string& name, const std::string& format = "csv") {
  const fs::path dir = fs::temp_directory_path() / ("railcrash_report_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  run_folders.made.push_back(dir);
  const railcrash::LoadedModel loaded = railcrash::load_model(std::string(RAILCRASH_SOURCE_DIR) + "/tests/report/two_car.yaml");
  const railcrash::Model& model = loaded.model;
  const railcrash::RunReport run = railcrash::run_model(model, loaded.run_spec, dir.string(), nullptr, false, false, format);
  REQUIRE(run.outcome.ok);
  return dir;
}

/// The report's data block (report-data) of a page, parsed.
nlohmann::json page_data(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"report-data\">";
  const std::size_t begin = page.find(open);
  REQUIRE(begin != std::string::npos);
  const std::size_t end = page.find("</script>", begin);
  return nlohmann::json::parse(page.substr(begin + open.size(), end - begin - open.size()));
}

/// Compares two data blocks: the same keys, lengths and texts; every number of a list equal
/// within a unit of the page's sixth digit (1e-5 of itself) plus series_tolerance of the
/// largest magnitude in its list (null where the other is null). Counts the numbers compared;
/// the differences go into `differences`.
void compare_data(const nlohmann::json& a, const nlohmann::json& b, const std::string& where, double series_tolerance,
                  std::size_t& numbers, std::vector<std::string>& differences) {
  if (differences.size() > 20) return;
  if (a.type() != b.type() && !(a.is_number() && b.is_number())) {
    differences.push_back(where + ": " + a.dump().substr(0, 60) + " against " + b.dump().substr(0, 60));
    return;
  }
  if (a.is_object()) {
    for (const auto& [key, value] : a.items())
      if (!b.contains(key)) differences.push_back(where + "." + key + " only in the first");
      else compare_data(value, b.at(key), where + "." + key, series_tolerance, numbers, differences);
    for (const auto& [key, value] : b.items())
      if (!a.contains(key)) differences.push_back(where + "." + key + " only in the second");
  } else if (a.is_array()) {
    if (a.size() != b.size()) {
      differences.push_back(where + ": " + std::to_string(a.size()) + " entries against " + std::to_string(b.size()));
      return;
    }
    const bool numeric = std::all_of(a.begin(), a.end(), [](const nlohmann::json& v) { return v.is_number() || v.is_null(); });
    if (numeric && !a.empty()) {
      double largest = 0.0;
      for (const nlohmann::json& v : a)
        if (v.is_number()) largest = std::max(largest, std::abs(v.get<double>()));
      for (std::size_t k = 0; k < a.size(); ++k) {
        ++numbers;
        if (a[k].is_null() != b[k].is_null() ||
            (a[k].is_number() && std::abs(a[k].get<double>() - b[k].get<double>()) >
                                     1e-5 * std::abs(a[k].get<double>()) + series_tolerance * largest))
          differences.push_back(where + "[" + std::to_string(k) + "]: " + a[k].dump() + " against " + b[k].dump());
      }
    } else {
      for (std::size_t k = 0; k < a.size(); ++k) compare_data(a[k], b[k], where + "[" + std::to_string(k) + "]", series_tolerance, numbers, differences);
    }
  } else if (a.is_number()) {
    ++numbers;
    if (std::abs(a.get<double>() - b.get<double>()) > 1e-5 * std::abs(a.get<double>()))
      differences.push_back(where + ": " + a.dump() + " against " + b.dump());
  } else if (a != b) {
    differences.push_back(where + ": " + a.dump().substr(0, 60) + " against " + b.dump().substr(0, 60));
  }
}

}  // namespace

TEST_CASE("Min/max decimation keeps every peak and at most the points asked for", "[report]") {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  const std::size_t n = 100003;
  std::vector<double> t(n), a(n), b(n);
  for (std::size_t k = 0; k < n; ++k) {
    t[k] = 1e-5 * static_cast<double>(k);
    a[k] = std::sin(40.0 * t[k]) + 0.1 * noise(rng);
    b[k] = 0.0;
  }
  a[12345] = 50.0;   // one-sample spikes
  a[99999] = -70.0;
  b[500] = 3.0;
  const railcrash::report::Decimated d = railcrash::report::decimate_minmax(t, {a, b}, 4000);
  REQUIRE(d.x.size() <= 4000);
  REQUIRE(d.series.size() == 2);
  REQUIRE(d.series[0].size() == d.x.size());
  CHECK(*std::max_element(d.series[0].begin(), d.series[0].end()) == 50.0);
  CHECK(*std::min_element(d.series[0].begin(), d.series[0].end()) == -70.0);
  CHECK(*std::max_element(d.series[1].begin(), d.series[1].end()) == 3.0);
  CHECK(std::is_sorted(d.x.begin(), d.x.end()));
  // The spike's time moves by at most one bucket.
  const auto spike = std::max_element(d.series[0].begin(), d.series[0].end()) - d.series[0].begin();
  CHECK(std::abs(d.x[static_cast<std::size_t>(spike)] - t[12345]) <= 2.0 * (t.back() - t.front()) / 2000.0);
  // Short series are unchanged.
  const railcrash::report::Decimated same = railcrash::report::decimate_minmax({0, 1, 2}, {{5, -1, 4}}, 4000);
  CHECK(same.x == std::vector<double>{0, 1, 2});
  CHECK(same.series[0] == std::vector<double>{5, -1, 4});
  // Loops: the extremes of both coordinates are kept.
  const std::vector<std::size_t> keep = railcrash::report::decimate_path(a, t, 1000);
  CHECK(keep.size() <= 1001);
  CHECK(std::find(keep.begin(), keep.end(), 12345u) != keep.end());
  CHECK(std::find(keep.begin(), keep.end(), 99999u) != keep.end());
  CHECK(std::is_sorted(keep.begin(), keep.end()));
}

TEST_CASE("Run folders hold model geometry, accelerations, energy and filtered peaks", "[report]") {
  const fs::path dir = small_run("files");
  const std::string model = slurp(dir / "model.json"), summary = slurp(dir / "summary.json");
  CHECK_THAT(model, Catch::Contains("\"name\": \"car1_body\", \"mass\": 5000") && Catch::Contains("\"type\": \"anticlimber\""));
  // The model name's markup and quotes are escaped as JSON, not left raw.
  CHECK_THAT(summary, Catch::Contains(R"(two cars <script>document.title=\"injected\"</script> & \"quotes\", commas)"));
  CHECK_THAT(summary, Catch::Contains("\"x_cfc\"") && Catch::Contains("\"collision\"") && Catch::Contains("\"cfc\": 60"));
  std::ifstream energy(dir / "energy.csv");
  std::string header, row, last;
  std::getline(energy, header);
  CHECK(header.rfind("# railcrash provenance {\"run_id\": ", 0) == 0);
  std::getline(energy, header);
  CHECK(header.rfind("t,kinetic,elastic,gravity,external_work,dissipated,dissipated.anticlimber", 0) == 0);
  while (std::getline(energy, row)) last = row;
  // The balance closes: the last column, relative to the initial kinetic energy (0.5 (500 + 5000) 25).
  const double balance = std::stod(last.substr(last.rfind(',') + 1));
  CHECK(std::abs(balance) < 1e-5 * 0.5 * 5500.0 * 25.0);
  std::ifstream accelerations(dir / "accelerations.csv");
  std::getline(accelerations, header);  // the provenance
  std::getline(accelerations, header);
  CHECK(header == "t,car1_end.ax,car1_end.ay,car1_end.alpha,car1_body.ax,car1_body.ay,car1_body.alpha,car2_end.ax,car2_end.ay,"
                  "car2_end.alpha,car2_body.ax,car2_body.ay,car2_body.alpha");
}

TEST_CASE("The mean deceleration of a car body equals its momentum change over the collision", "[report]") {
  // Car 2 (5500 kg) gains what car 1 loses; its car body's mean deceleration is its velocity
  // change over the collision's duration, both from the velocity samples.
  const fs::path dir = small_run("pulse");
  const std::string summary = slurp(dir / "summary.json");
  const auto number_after = [&](const std::string& body, const std::string& key) {
    const std::size_t at = summary.find(key, summary.find("\"" + body + "\": {\"x\""));
    return std::stod(summary.substr(at + key.size()));
  };
  const double dv = number_after("car2_body", "\"velocity_change\": ");
  const double t0 = number_after("car2_body", "\"t_start\": "), t1 = number_after("car2_body", "\"t_end\": ");
  const double mean = number_after("car2_body", "\"mean_deceleration\": ");
  CHECK(mean == Approx(std::abs(dv) / (t1 - t0)).epsilon(1e-9));
  // Elastic-plastic crush: car 2 ends faster than the 2.5 m/s common speed, below 5 m/s.
  CHECK(dv > 2.5);
  CHECK(dv < 5.0);
  CHECK(t0 < 0.02);  // contact at 8 ms (gap 0.04 m at 5 m/s); the car body follows through its springs
}

TEST_CASE("railcrash report: a good run, a truncated one, one without summary, and folders that are not runs", "[report]") {
  using railcrash::report::write_report;
  const fs::path dir = small_run("bad");
  railcrash::report::ReportResult good = write_report(dir.string());
  CHECK(good.problems.empty());
  CHECK(good.rows == 1501);
  const std::string page = slurp(good.path);
  CHECK(page.size() > 20000);
  CHECK_THAT(page, !Catch::Contains("<script>document.title"));  // the model's name never appears as markup
  CHECK_THAT(page, Catch::Contains("\\u003cscript>document.title"));
  CHECK_THAT(page, !Catch::Contains("src=\"http") && !Catch::Contains("<link"));  // nothing fetched
  CHECK((page.find("uPlot") != std::string::npos) == railcrash::report::have_plotting_library());
  // The acceleration plots say that their filtered curves' last 8.3 ms are the filter's end zone.
  CHECK_THAT(page, Catch::Contains("the last 8.3 ms of each filtered curve follow the record's last row"));

  // A failed run: the failure comes first.
  {
    std::string summary = slurp(dir / "summary.json");
    summary.replace(summary.find("\"status\": \"ok\""), 14, "\"status\": \"failed\"");
    summary.replace(summary.find("\"message\": \"\""), 13, "\"message\": \"IDA: error test failed \\\"repeatedly\\\"\"");
    std::ofstream(dir / "summary.json", std::ios::trunc) << summary;
    const railcrash::report::ReportResult failed = write_report(dir.string());
    REQUIRE_FALSE(failed.problems.empty());
    CHECK(failed.problems[0] == "The run FAILED at t = 0.3 s: IDA: error test failed \"repeatedly\"; the report shows the results up to then");
  }

  // The run's accuracy warnings (summary.json) are listed at the top, after a failure.
  {
    std::string summary = slurp(dir / "summary.json");
    const std::string none = "\"accuracy_warnings\": []";
    REQUIRE(summary.find(none) != std::string::npos);
    summary.replace(summary.find(none), none.size(), "\"accuracy_warnings\": [\"joints open by up to 0.44 m\"]");
    std::ofstream(dir / "summary.json", std::ios::trunc) << summary;
    const railcrash::report::ReportResult warned = write_report(dir.string());
    REQUIRE(warned.problems.size() == 2);
    CHECK_THAT(warned.problems[0], Catch::StartsWith("The run FAILED"));
    CHECK(warned.problems[1] == "Accuracy: joints open by up to 0.44 m");
  }

  // Cut timeseries.csv in the middle of a row and remove the summary: a run killed half-way.
  const std::string series = slurp(dir / "timeseries.csv");
  {
    std::ofstream cut(dir / "timeseries.csv", std::ios::binary | std::ios::trunc);
    cut << series.substr(0, series.size() / 2);
  }
  fs::remove(dir / "summary.json");
  const railcrash::report::ReportResult truncated = write_report(dir.string());
  REQUIRE(truncated.problems.size() >= 2);
  CHECK_THAT(truncated.problems[0], Catch::Contains("no summary.json"));
  CHECK_THAT(truncated.problems[1], Catch::Contains("timeseries.csv line") && Catch::Contains("complete rows before it"));
  CHECK(truncated.rows > 100);
  CHECK(truncated.rows < 1501);

  // A folder without a timeseries, a header only, and a missing folder: errors (exit status 2).
  const fs::path empty = fs::temp_directory_path() / ("railcrash_report_test_empty_" + std::to_string(::getpid()));
  fs::remove_all(empty);
  fs::create_directories(empty);
  CHECK_THROWS_WITH(write_report(empty.string()), Catch::Contains("no timeseries.csv") && Catch::Contains("not a run folder"));
  { std::ofstream header_only(empty / "timeseries.csv"); header_only << "t,a.x\n"; }
  CHECK_THROWS_AS(write_report(empty.string()), railcrash::InputError);
  CHECK_THROWS_WITH(write_report(empty.string()), Catch::Contains("no complete row"));
  CHECK_THROWS_WITH(write_report((empty / "missing").string()), Catch::Contains("does not exist"));
  fs::remove_all(empty);
  fs::remove_all(dir);
}

TEST_CASE("railcrash report: crash elements and their loops come from the output roles, cars from car:", "[report]") {
  using railcrash::report::write_report;
  const fs::path dir = small_run("roles");
  const std::string model = slurp(dir / "model.json"), summary = slurp(dir / "summary.json");
  CHECK_THAT(model, Catch::Contains("\"roles\": {\"crush\": \"horizontal_deformation\", \"contact_force\": \"horizontal_force\""));
  CHECK_THAT(model, Catch::Contains("\"name\": \"car1_body\", \"mass\": 5000, \"inertia\": 5000, \"car\": \"car1\""));
  CHECK_THAT(summary, Catch::Contains("\"car2\": {\"max_crush\": ") && Catch::Contains("\"bodies\": [\"car2_end\", \"car2_body\"]"));
  // The anticlimber (crash_force, crash_deformation) has the only loop; the sills and dampers
  // are listed but not crash elements.
  const railcrash::report::ReportResult good = write_report(dir.string());
  CHECK(good.problems.empty());
  const std::string page = slurp(good.path);
  CHECK_THAT(page, Catch::Contains("\"x_label\": \"anticlimber.horizontal_deformation\", \"y_label\": \"anticlimber.horizontal_force\""));
  CHECK(page.find("\"x_label\": ") == page.rfind("\"x_label\": "));
  // A model.json without roles (an older run folder) shows no crash element and says why.
  std::string old = model;
  for (std::size_t at = old.find(", \"roles\": {"); at != std::string::npos; at = old.find(", \"roles\": {"))
    old.erase(at, old.find('}', at) + 1 - at);
  std::ofstream(dir / "model.json", std::ios::trunc) << old;
  const railcrash::report::ReportResult older = write_report(dir.string());
  REQUIRE(older.problems.size() == 1);
  CHECK_THAT(older.problems[0], Catch::Contains("no output roles"));
  CHECK(slurp(older.path).find("\"x_label\": ") == std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("railcrash report of a sensitivity folder: its summary and tables", "[report]") {
  const fs::path dir = fs::temp_directory_path() / ("railcrash_report_test_study_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "sensitivity.csv") << "run,P1,R1\nbase,1,0.5\n";
  std::ofstream(dir / "sensitivity.md") << "# Sensitivity <b>study</b>\n\n| P | R1 |\n|---|---|\n| P1 | 0.5 |\n";
  const railcrash::report::ReportResult result = railcrash::report::write_report(dir.string());
  CHECK(result.study == "sensitivity");
  CHECK(result.rows == 2);
  const std::string page = slurp(dir / "report.html");
  CHECK_THAT(page, Catch::Contains("run,P1,R1\\nbase,1,0.5") && Catch::Contains("\\u003cb>study"));
  CHECK_THAT(page, !Catch::Contains("<b>study"));
  std::ofstream(dir / "readings.csv") << "combination,score\nA,3\n";  // a readings folder holds its combinations' studies
  CHECK(railcrash::report::write_report(dir.string()).study == "readings");
  fs::remove_all(dir);
}

TEST_CASE("railcrash report of a sweep folder: its summary and runs", "[report]") {
  const fs::path dir = fs::temp_directory_path() / ("railcrash_report_test_sweep_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "runs.csv") << "run,hash,k,status,R1,wall_seconds,message\n0,00000000000000aa,1.5,ok,0.25,0.1,\"\"\n";
  std::ofstream(dir / "summary.md") << "# Sweep plan.yaml\n\n## Main effects\n";
  const railcrash::report::ReportResult result = railcrash::report::write_report(dir.string());
  CHECK(result.study == "sweep");
  CHECK(result.rows == 2);
  CHECK_THAT(slurp(dir / "report.html"), Catch::Contains("0,00000000000000aa,1.5,ok,0.25") && Catch::Contains("Main effects"));
  fs::remove_all(dir);
}

TEST_CASE("Body and element names that would break CSV, JSON or HTML are refused with file and line", "[report]") {
  const std::string head = "railcrash: 1\nname: x\nunits: SI\nbodies:\n  - {name: ";
  const std::string tail = ", mass: 1, inertia: 1, position: [0, 0]}\nelements: []\nsimulation: {t_end: 1}\n";
  for (const std::string& bad : {std::string("'a,b'"), std::string("'<script>'"), std::string("'say \"hi\"'"), std::string("\"a\\nb\""),
                                 std::string("'a") + '\xFF' + "'"}) {  // a raw byte that is not UTF-8
    INFO(bad);
    CHECK_THROWS_WITH(railcrash::load_model_text(head + bad + tail, "names.yaml"), Catch::Contains("names.yaml:5") && Catch::Contains("body name"));
  }
  CHECK_NOTHROW(railcrash::load_model_text(head + "'front end (car 1)'" + tail, "names.yaml"));
}

namespace {

/// The run id summary.json gives ("" when none).
std::string summary_run_id(const fs::path& dir) {
  std::smatch match;
  const std::string summary = slurp(dir / "summary.json");
  return std::regex_search(summary, match, std::regex("\n  \"run_id\": \"([0-9a-f]*)\",\n")) ? match[1].str() : "";
}

}  // namespace

TEST_CASE("The report refuses a folder that holds the files of two runs, naming them", "[report]") {
  const fs::path first = small_run("first_of_two"), second = small_run("second_of_two");
  const std::string first_id = summary_run_id(first), second_id = summary_run_id(second);
  REQUIRE(first_id.size() == 32);
  REQUIRE(second_id.size() == 32);
  REQUIRE(first_id != second_id);
  // The summary of another run over this run's files.
  fs::copy_file(second / "summary.json", first / "summary.json", fs::copy_options::overwrite_existing);
  CHECK_THROWS_WITH(railcrash::report::write_report(first.string()),
                    Catch::Contains("'" + (first / "timeseries.csv").string() + "' is of run " + first_id + " but '" +
                                    (first / "summary.json").string() + "' is of run " + second_id +
                                    ": the folder holds the files of two runs"));
  CHECK_FALSE(fs::exists(first / "report.html"));
  // A data file of another run under this run's summary.
  fs::copy_file(second / "energy.csv", first / "energy.csv", fs::copy_options::overwrite_existing);
  fs::copy_file(second / "summary.json", first / "summary.json", fs::copy_options::overwrite_existing);
  fs::copy_file(second / "timeseries.csv", first / "timeseries.csv", fs::copy_options::overwrite_existing);
  fs::copy_file(second / "model.json", first / "model.json", fs::copy_options::overwrite_existing);
  CHECK_THROWS_WITH(railcrash::report::write_report(first.string()),
                    Catch::Contains("'" + (first / "accelerations.csv").string() + "' is of run " + first_id + " but '" +
                                    (first / "summary.json").string() + "' is of run " + second_id));
  // A file without a run id (an older railcrash's) beside files with one.
  const std::string accelerations = slurp(second / "accelerations.csv");
  std::ofstream(first / "accelerations.csv", std::ios::binary) << accelerations.substr(accelerations.find('\n') + 1);
  CHECK_THROWS_WITH(railcrash::report::write_report(first.string()),
                    Catch::Contains("'" + (first / "accelerations.csv").string() +
                                    "' is of no run id (written by an older railcrash) but '" + (first / "summary.json").string() +
                                    "' is of run " + second_id));
  // The second run's files, all of them: a report.
  fs::copy_file(second / "accelerations.csv", first / "accelerations.csv", fs::copy_options::overwrite_existing);
  fs::copy_file(second / "events.csv", first / "events.csv", fs::copy_options::overwrite_existing);
  CHECK(railcrash::report::write_report(first.string()).problems.empty());
  fs::remove_all(first);
  fs::remove_all(second);
}

TEST_CASE("The report carries the run's provenance", "[report]") {
  const fs::path dir = small_run("provenance");
  const std::string id = summary_run_id(dir);
  REQUIRE(id.size() == 32);
  railcrash::report::write_report(dir.string());
  const std::string page = slurp(dir / "report.html");
  // summary.json's record, and the script that shows it as the page's provenance block.
  CHECK_THAT(page, Catch::Contains("\"provenance\": {\"run_id\": \"" + id + "\", \"version\": ") &&
                       Catch::Contains("/tests/report/two_car.yaml\", \"sha256\": \"") &&
                       Catch::Contains("\"Provenance: run \" + pv.run_id"));
  fs::remove_all(dir);
}

TEST_CASE("railcrash report: the force plot at the channel class asked, the crush zones from summary.json", "[report]") {
  using railcrash::report::write_report;
  const fs::path dir = small_run("force_cfc");
  const std::string summary = slurp(dir / "summary.json");
  // The anticlimber is the crush zone; without a rupture deflection its curve has no last point:
  // drawn on at its plastic slope (1e5 N/m), no capacity.
  CHECK_THAT(summary, Catch::Contains("\"crush_zones\": {") &&
                          Catch::Contains("{\"element\": \"anticlimber\", \"type\": \"anticlimber\", \"cars\": [{\"car\": \"car1\", \"share\": 0.5}, "
                                          "{\"car\": \"car2\", \"share\": 0.5}]") &&
                          Catch::Contains("\"capacity\": null") && Catch::Contains("\"beyond_last_slope\": 100000, \"open_ended\": true"));
  CHECK(slurp(dir / "energy_zones.csv").find("zone,anticlimber,anticlimber,car1 car2,") != std::string::npos);
  railcrash::report::ReportOptions options;  // default: CFC 60
  CHECK_THAT(slurp(write_report(dir.string(), options).path), Catch::Contains("\"title\": \"Element forces (CFC 60; crash elements shown"));
  options.force_cfc = 0.0;
  CHECK_THAT(slurp(write_report(dir.string(), options).path), Catch::Contains("\"title\": \"Element forces (unfiltered; crash elements shown"));
  options.force_cfc = 1.0e6;  // beyond what the output interval can carry: unfiltered, and says so
  const railcrash::report::ReportResult coarse = write_report(dir.string(), options);
  REQUIRE(coarse.problems.size() == 1);
  CHECK_THAT(coarse.problems[0], Catch::Contains("too long for CFC 1e+06: the force plot is unfiltered"));
  fs::remove_all(dir);
}

TEST_CASE("The report reads regular files only and follows no link and keeps to its size limits", "[report]") {
  using railcrash::report::read_folder_file;
  const fs::path dir = fs::temp_directory_path() / ("railcrash_report_test_files_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "small.json") << "{\"a\": 1}";
  CHECK(read_folder_file((dir / "small.json").string(), 100, "advice").text == "{\"a\": 1}");
  CHECK_FALSE(read_folder_file((dir / "none.json").string(), 100, "advice").found);
  CHECK_THROWS_WITH(read_folder_file((dir / "small.json").string(), 5, "move it away"),
                    Catch::Contains("small.json' is 0.0 MB (8 bytes), more than the report's limit of 0.0 MB for this file: move it away"));
  REQUIRE(::mkfifo((dir / "fifo.json").c_str(), 0600) == 0);  // would block a plain open for reading
  CHECK_THROWS_WITH(read_folder_file((dir / "fifo.json").string(), 100, ""), Catch::Contains("fifo.json' is a FIFO (named pipe), not a regular file"));
  fs::create_symlink("/dev/zero", dir / "zero.json");  // would be read until memory runs out
  CHECK_THROWS_WITH(read_folder_file((dir / "zero.json").string(), 100, ""), Catch::Contains("zero.json' is a symbolic link"));
  fs::create_symlink(dir / "small.json", dir / "link.json");
  CHECK_THROWS_WITH(read_folder_file((dir / "link.json").string(), 100, ""), Catch::Contains("link.json' is a symbolic link"));
  CHECK(railcrash::report::read_folder_file_head((dir / "small.json").string(), 3).text == "{\"a");
  CHECK(railcrash::report::max_table_bytes() >= (std::uint64_t{64} << 20));
  fs::remove_all(dir);
}

TEST_CASE("railcrash report: a summary.json that is not JSON is a problem and the page shows the rest", "[report]") {
  const fs::path dir = small_run("not_json");
  const std::string summary = slurp(dir / "summary.json");
  std::ofstream(dir / "summary.json") << summary.substr(0, summary.size() / 2);  // cut short (its run id kept)
  const railcrash::report::ReportResult result = railcrash::report::write_report(dir.string());
  REQUIRE_FALSE(result.problems.empty());
  CHECK_THAT(result.problems.front(), Catch::StartsWith("summary.json is not valid JSON (parse error at line "));
  CHECK_THAT(slurp(result.path), Catch::Contains("<script type=\"application/json\" id=\"summary-json\">null</script>"));
  fs::remove_all(dir);
}

#ifdef RAILCRASH_HDF5
TEST_CASE("railcrash report of a --format hdf5 run folder shows the series of the CSV run of the same model", "[report][hdf5]") {
  using railcrash::report::write_report;
  const fs::path csv = small_run("csv_twin"), hdf5 = small_run("hdf5_twin", "hdf5");
  REQUIRE(fs::exists(hdf5 / "timeseries.h5"));
  REQUIRE_FALSE(fs::exists(hdf5 / "timeseries.csv"));
  const railcrash::report::ReportResult from_csv = write_report(csv.string()), from_hdf5 = write_report(hdf5.string());
  CHECK(from_hdf5.problems.empty());
  CHECK(from_hdf5.rows == 1501);
  nlohmann::json a = page_data(slurp(from_csv.path)), b = page_data(slurp(from_hdf5.path));
  CHECK(b.at("run_dir").get<std::string>() == fs::absolute(hdf5).lexically_normal().string());
  a.erase("run_dir");
  b.erase("run_dir");
  // The CSV files carry 12 significant digits, timeseries.h5 the doubles: the page's 6 digits
  // agree but where the two round apart (a unit of the sixth digit) or the 12 digits show in a
  // difference (x - x(0)): measured within 1.4e-10 of the series' largest value on
  // final_two_car.yaml, 7e-9 on models/examples/mu_3plus3_si.yaml.
  std::size_t numbers = 0;
  std::vector<std::string> differences;
  compare_data(a, b, "data", 1e-8, numbers, differences);
  INFO("differences: " << differences.size() << (differences.empty() ? std::string() : ", first " + differences.front()));
  CHECK(differences.empty());
  CHECK(numbers > 20000);  // every plot, loop, frame and event was compared
  CHECK(b.at("plots").size() == 5);  // displacement, velocity, two accelerations, forces
  CHECK(b.at("events").size() == a.at("events").size());
  CHECK_FALSE(b.at("events").empty());

  // A timeseries.h5 cut short (a copy that stopped half-way) or not HDF5 at all: an error naming the file.
  const fs::path h5 = hdf5 / "timeseries.h5";
  const std::string bytes = slurp(h5);
  std::ofstream(h5, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 2);
  CHECK_THROWS_AS(write_report(hdf5.string()), railcrash::InputError);
  CHECK_THROWS_WITH(write_report(hdf5.string()), Catch::StartsWith("'" + h5.string() + "' cannot be opened as an HDF5 file (HDF5: ") &&
                                                     Catch::Contains("truncated file") && Catch::Contains("run the model again"));
  std::ofstream(h5, std::ios::binary | std::ios::trunc) << "t,x\n0,1\n";
  CHECK_THROWS_WITH(write_report(hdf5.string()), Catch::StartsWith("'" + h5.string() + "' cannot be opened as an HDF5 file") &&
                                                     Catch::Contains("signature"));
  // An HDF5 file without the timeseries table: named.
  fs::remove(h5);
  { railcrash::Hdf5File other(h5.string()); other.attribute("run_id", "x"); }
  CHECK_THROWS_WITH(write_report(hdf5.string()), Catch::Contains(h5.string() + "' has no table timeseries"));
  fs::remove_all(csv);
  fs::remove_all(hdf5);
}
#endif

TEST_CASE("railcrash report side by side: the default page path and fewer than two runs", "[report]") {
  using railcrash::report::default_comparison_path;
  const fs::path base = fs::absolute("out").lexically_normal();
  CHECK(default_comparison_path({"out/a", "out/b"}) == (base / "compare_a_b.html").string());
  CHECK(default_comparison_path({"out/a/", "out/speed 12"}) == (base / "compare_a_speed_12.html").string());
  CHECK(default_comparison_path({"out/a", "elsewhere/b", "c"}) == (base / "compare_a_b_c.html").string());
  const std::string long_name(60, 'x');
  CHECK(default_comparison_path({"out/" + long_name, "out/b"}) == (base / ("compare_" + long_name.substr(0, 40) + "_b.html")).string());
  CHECK_THROWS_AS(railcrash::report::write_comparison({"out/a"}, ""), railcrash::InputError);
}
