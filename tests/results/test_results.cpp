// Cars in the run summary (results.hpp): declared by the bodies' `car:` key, never guessed;
// results that survive faults (a full disk, a vanished folder).
#include <catch2/catch.hpp>

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <yaml-cpp/yaml.h>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

std::string temporary_folder(const std::string& name) {
  const auto path = testing::temp_path("railcrash_test_" + name);
  std::filesystem::remove_all(path);
  return path.string();
}

// Two cars of two bodies each and a crush spring in each car and one between them; the
// bodies' car keys (CAR_A, CAR_B) are filled in by the test.
std::string two_car_text(const std::string& car_a, const std::string& car_b) {
  return "railcrash: 1\nname: cars\nunits: SI\ngravity: [0, 0]\nbodies:\n"
         "  - {name: striker_rear, " + car_a + "mass: 10, inertia: 1, position: [-2, 0], velocity: [5, 0]}\n"
         "  - {name: striker_end, " + car_a + "mass: 10, inertia: 1, position: [0, 0], velocity: [5, 0]}\n"
         "  - {name: struck_end, " + car_b + "mass: 10, inertia: 1, position: [1, 0]}\n"
         "  - {name: struck_rear, " + car_b + "mass: 10, inertia: 1, position: [3, 0]}\nelements:\n"
         "  - {name: between, type: crush_spring, free_length: 1.0, curve: [[0, 0], [0.01, 1000], [1, 1000]], "
         "unloading_stiffness: 1.0e5, points: [{body: striker_end, at: [0, 0]}, {body: struck_end, at: [0, 0]}]}\n"
         "  - {name: inside, type: crush_spring, free_length: 2.0, curve: [[0, 0], [0.01, 1000], [1, 1000]], "
         "unloading_stiffness: 1.0e5, points: [{body: struck_end, at: [0, 0]}, {body: struck_rear, at: [0, 0]}]}\n"
         "  - {name: striker_spring, type: linear_spring, stiffness: 1.0e4, "
         "points: [{body: striker_rear, at: [0, 0]}, {body: striker_end, at: [0, 0]}]}\n"
         "simulation: {t_end: 0.05, output_interval: 0.001}\n";
}

// A mass on a spring (period 2 pi sqrt(2 / 200) = 0.63 s) for T seconds, sampled every millisecond.
std::string spring_mass_text(double t_end) {
  return "railcrash: 1\nname: osc\nunits: SI\ngravity: [0, 0]\nbodies:\n"
         "  - {name: mass, mass: 2.0, inertia: 0.1, position: [1.1, 0]}\nelements:\n"
         "  - {name: spring, type: linear_spring, stiffness: 200, free_length: 1.0, "
         "points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n"
         "simulation: {t_end: " + std::to_string(t_end) + ", output_interval: 0.001}\n";
}

std::string file_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Forwards to the writer; at sample `look_at` keeps summary.json's text, at sample `remove_at` removes the folder.
struct FolderRemover : RunObserver {
  ResultWriter* writer;
  std::string folder;
  int look_at, remove_at;
  int samples = 0;
  std::string summary_mid_run;
  void sample(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs) override {
    writer->sample(t, y, lambda, quadratures, outputs);
    if (++samples == look_at) summary_mid_run = file_text(folder + "/summary.json");
    if (samples == remove_at) std::filesystem::remove_all(folder);
  }
  std::string failure() const override { return writer->failure(); }
};

}  // namespace

TEST_CASE("cars are the bodies' car: keys and an element between two cars counts half for each", "[results]") {
  const Model model = testing::model_from_text(two_car_text("car: striking, ", "car: struck, "));
  DaeSystem system(model);
  const std::vector<CarCrush> cars = cars_of(system);
  REQUIRE(cars.size() == 2);
  CHECK(cars[0].car == "striking");
  CHECK(cars[0].bodies == std::vector<int>{0, 1});
  CHECK(cars[0].elements == std::vector<std::string>{"between"});
  CHECK(cars[0].shares == std::vector<double>{0.5});
  CHECK(cars[1].car == "struck");
  CHECK(cars[1].bodies == std::vector<int>{2, 3});
  CHECK(cars[1].elements == std::vector<std::string>{"between", "inside"});
  CHECK(cars[1].shares == std::vector<double>{0.5, 1.0});
  // Ends: each car meets the other through `between` (half each); its other end is the centre
  // of gravity of its outermost body. `inside` lies between the struck car's ends.
  CHECK(cars[0].ends[0].point.body == 0);
  CHECK(cars[0].ends[0].column < 0);
  CHECK(cars[0].ends[1].point.body == 1);
  CHECK(cars[0].ends[1].element == "between");
  CHECK(cars[0].ends[1].share == 0.5);
  CHECK(cars[1].ends[0].point.body == 2);
  CHECK(cars[1].ends[0].element == "between");
  CHECK(cars[1].ends[1].point.body == 3);
  CHECK(cars[1].ends[1].column < 0);
  CHECK(cars[0].initial_length == 2.0);
  CHECK(cars[1].initial_length == 2.0);
}

TEST_CASE("a model whose bodies declare no car has no per-car crush, and its summary says why", "[results]") {
  // Names that once made cars (car1_, car2_) make none now: only the car: key does.
  const std::string text = two_car_text("", "");
  std::string named = text;
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"striker_", "car1_"}, {"struck_", "car2_"}})
    for (std::size_t at = named.find(from); at != std::string::npos; at = named.find(from, at)) named.replace(at, from.size(), to);
  for (const std::string& yaml : {text, named}) {
    const LoadedModel loaded = testing::loaded_from_text(yaml);
    const Model& model = loaded.model;
    CHECK(cars_of(DaeSystem(model)).empty());
    const RunReport report = run_model(model, loaded.run_spec, temporary_folder("no_cars"));
    REQUIRE(report.outcome.ok);
    CHECK(report.car_crush.empty());
    CHECK_THAT(report.summary_json, Catch::Contains("\"car_crush\": {}") && Catch::Contains("\"cars_note\": \"no body declares a car"));
  }
  // With cars declared the note is gone and each car has its row.
  const LoadedModel with_cars = testing::loaded_from_text(two_car_text("car: striking, ", "car: struck, "));
  const RunReport report = run_model(with_cars.model, with_cars.run_spec, temporary_folder("cars"));
  REQUIRE(report.outcome.ok);
  CHECK_THAT(report.summary_json, !Catch::Contains("cars_note") &&
                                      Catch::Contains("\"striking\": {\"max_crush\": ") &&
                                      Catch::Contains("\"bodies\": [\"striker_rear\", \"striker_end\"]"));
}

TEST_CASE("the barrier model's two cars are summarised separately", "[results]") {
  // models/barrier/two_car_barrier.yaml: the leading car's bodies are lead_*, the trailing
  // car's trail_*; the shared coupler belongs to neither. Its crush elements are crush
  // springs: lead_crush and lead_draft_sill within the leading car, trail_draft_sill within
  // the trailing one.
  const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/barrier/two_car_barrier.yaml").model;
  DaeSystem system(model);
  const std::vector<CarCrush> cars = cars_of(system);
  REQUIRE(cars.size() == 2);
  const auto prefixed = [&](const std::string& prefix) {
    std::vector<int> bodies;
    for (int i = 0; i < model.body_count(); ++i)
      if (model.bodies()[static_cast<std::size_t>(i)].name.rfind(prefix, 0) == 0) bodies.push_back(i);
    return bodies;
  };
  const auto crush_springs_within = [&](const std::vector<int>& bodies) {
    std::vector<std::string> names;
    for (const auto& e : model.elements()) {
      const auto in = [&](int slot) { return std::find(bodies.begin(), bodies.end(), e->slot_body(slot)) != bodies.end(); };
      if (e->type() == "crush_spring" && in(0) && in(1)) names.push_back(e->name());
    }
    return names;
  };
  CHECK(cars[0].car == "lead");
  CHECK(cars[0].bodies == prefixed("lead_"));
  CHECK(cars[0].elements == crush_springs_within(prefixed("lead_")));
  CHECK(cars[0].elements == std::vector<std::string>{"lead_crush", "lead_draft_sill"});
  CHECK(cars[0].shares == std::vector<double>{1.0, 1.0});
  CHECK(cars[1].car == "trail");
  CHECK(cars[1].bodies == prefixed("trail_"));
  CHECK(cars[1].elements == std::vector<std::string>{"trail_draft_sill"});
  CHECK(cars[0].bodies.size() + cars[1].bodies.size() + 1 == static_cast<std::size_t>(model.body_count()));  // + coupler
}

TEST_CASE("a failed write stops the run at once with the OS reason and the rows on disk and the summary says failed",
          "[results][faults]") {
  // Files past 32 KiB cannot grow (RLIMIT_FSIZE: write(2) fails with EFBIG, as it fails with
  // ENOSPC on a full disk; SIGXFSZ ignored). A link to /dev/full would not do: result files
  // are opened without following links.
  const std::string dir = temporary_folder("full_disk");
  std::filesystem::create_directories(dir);
  const LoadedModel loaded = testing::loaded_from_text(spring_mass_text(10.0));
  const Model& model = loaded.model;
  rlimit old_limit{};
  REQUIRE(::getrlimit(RLIMIT_FSIZE, &old_limit) == 0);
  rlimit small = old_limit;
  small.rlim_cur = 32 * 1024;
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  REQUIRE(::setrlimit(RLIMIT_FSIZE, &small) == 0);
  const RunReport report = run_model(model, loaded.run_spec, dir);
  ::setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  CHECK_FALSE(report.outcome.ok);
  CHECK_THAT(report.outcome.message, Catch::Contains("cannot write " + dir + "/timeseries.csv: File too large") &&
                                         Catch::Contains("the run stopped at t = "));
  // What is on disk: the rows whose last byte the OS took, the last of them named by its t.
  INFO(report.outcome.message);
  const std::string key = "timeseries.csv holds the first ";
  const std::size_t at = report.outcome.message.find(key);
  REQUIRE(at != std::string::npos);
  const std::size_t rows = std::stoul(report.outcome.message.substr(at + key.size()));
  const std::string t_key = "rows whole, up to t = ";
  const double t_held = std::stod(report.outcome.message.substr(report.outcome.message.find(t_key) + t_key.size()));
  std::ifstream csv(dir + "/timeseries.csv");
  std::string line, last_whole;
  std::size_t data_rows = 0;
  while (std::getline(csv, line))
    if (!line.empty() && line[0] != '#' && line[0] != 't' && ++data_rows == rows) last_whole = line;
  CHECK(data_rows >= rows);  // (a row after them may be there in part)
  CHECK(rows > 100);
  REQUIRE_FALSE(last_whole.empty());
  CHECK(std::stod(last_whole.substr(0, last_whole.find(','))) == Approx(t_held).margin(1e-12));
  // Stopped once the writer's 64 kB buffer (some 500 rows of 120 bytes) reached the file, not at t_end.
  CHECK(report.outcome.t_reached < 1.0);
  const std::string summary = file_text(dir + "/summary.json");
  CHECK_THAT(summary, Catch::Contains("\"status\": \"failed\"") && Catch::Contains("File too large"));
  CHECK_FALSE(std::filesystem::exists(dir + "/summary.json.tmp"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("a link planted under a result file's name is refused, not written through", "[results][faults]") {
  const std::string dir = temporary_folder("planted_link");
  std::filesystem::create_directories(dir);
  { std::ofstream(dir + "/../planted_link_target.txt") << "precious\n"; }
  std::filesystem::create_symlink("../planted_link_target.txt", dir + "/timeseries.csv");
  const LoadedModel loaded = testing::loaded_from_text(spring_mass_text(0.05));
  const Model& model = loaded.model;
  CHECK_THROWS_WITH(run_model(model, loaded.run_spec, dir), Catch::Contains("timeseries.csv: Too many levels of symbolic links"));
  CHECK(file_text(dir + "/../planted_link_target.txt") == "precious\n");
  std::filesystem::remove(dir + "/../planted_link_target.txt");
  std::filesystem::remove_all(dir);
}

TEST_CASE("summary.json says running while the run goes and a vanished folder stops the run", "[results][faults]") {
  const std::string dir = temporary_folder("vanishing");
  const LoadedModel loaded = testing::loaded_from_text(spring_mass_text(10.0));
  const Model& model = loaded.model;
  DaeSystem system(model);
  ResultWriter writer(dir, system, loaded.run_spec);
  writer.set_folder_check_interval(std::chrono::steady_clock::duration::zero());  // look at every sample
  writer.write_running_summary("ida");
  FolderRemover observer;
  observer.writer = &writer;
  observer.folder = dir;
  observer.look_at = 3;
  observer.remove_at = 100;  // t = 0.099
  const RunOutcome outcome = make_integrator(system, loaded.run_spec.simulation)->run(10.0, 0.001, observer);
  CHECK_THAT(observer.summary_mid_run, Catch::Contains("\"status\": \"running\"") && Catch::Contains("\"integrator\": \"ida\""));
  CHECK_FALSE(outcome.ok);
  CHECK_THAT(outcome.message, Catch::Contains("the output folder " + dir + " is gone: No such file or directory"));
  // Looking at every sample, the run stops at the first one after the removal and ends at
  // the last sample written whole.
  CHECK(outcome.t_reached == Approx(0.099).margin(1e-9));
  CHECK(observer.samples == 101);
  // The final summary cannot be written; the writer says why instead of throwing.
  CHECK_THAT(writer.write_summary(outcome, "ida"), Catch::Contains("\"status\": \"failed\""));
  CHECK_FALSE(std::filesystem::exists(dir));
}

TEST_CASE("with the default folder check a vanished folder stops the run or fails its summary", "[results][faults]") {
  // The folder is looked at every 250 ms of wall time and at the end: a run shorter than that
  // (10,000 samples of a spring-mass take some 0.1 s) finishes its steps, and the final
  // summary finds the folder gone.
  const std::string dir = temporary_folder("vanishing_later");
  const LoadedModel loaded = testing::loaded_from_text(spring_mass_text(10.0));
  const Model& model = loaded.model;
  DaeSystem system(model);
  ResultWriter writer(dir, system, loaded.run_spec);
  FolderRemover observer;
  observer.writer = &writer;
  observer.folder = dir;
  observer.look_at = 3;
  observer.remove_at = 100;
  const RunOutcome outcome = make_integrator(system, loaded.run_spec.simulation)->run(10.0, 0.001, observer);
  const std::string summary = writer.write_summary(outcome, "ida");
  CHECK_THAT(writer.failure(), Catch::Contains("the output folder " + dir + " is gone: No such file or directory"));
  if (!outcome.ok) {  // the periodic check came first (a slow machine)
    CHECK_THAT(outcome.message, Catch::Contains("is gone"));
  } else {
    CHECK(observer.samples == 10001);
  }
  CHECK_FALSE(std::filesystem::exists(dir));
}

TEST_CASE("a finished run's summary.json replaces the running one and leaves no temporary file", "[results][faults]") {
  const std::string dir = temporary_folder("finished");
  const LoadedModel loaded = testing::loaded_from_text(spring_mass_text(0.05));
  const Model& model = loaded.model;
  const RunReport report = run_model(model, loaded.run_spec, dir);
  REQUIRE(report.outcome.ok);
  const std::string summary = file_text(dir + "/summary.json");
  CHECK(summary == report.summary_json);
  CHECK_THAT(summary, Catch::StartsWith("{\n  \"status\": \"ok\"") && Catch::EndsWith("}\n"));
  CHECK_FALSE(std::filesystem::exists(dir + "/summary.json.tmp"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("JSON strings stay valid UTF-8 and escaped whatever bytes a name or path holds", "[results]") {
  // Well-formed UTF-8 is kept: e-acute (2 bytes), the euro sign (3), U+1F682 steam locomotive (4).
  CHECK(json_string("caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x9A\x82") == "\"caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x9A\x82\"");
  // RFC 3629's ill-formed sequences become U+FFFD, one per byte that cannot start a character.
  const std::string replacement = "\xEF\xBF\xBD";
  CHECK(json_string("run_\xE9.yaml") == "\"run_" + replacement + ".yaml\"");            // Latin-1 e-acute
  CHECK(json_string("\xC0\xAF") == "\"" + replacement + replacement + "\"");            // overlong '/'
  CHECK(json_string("\xED\xA0\x80") == "\"" + replacement + replacement + replacement + "\"");  // surrogate D800
  CHECK(json_string("\xF4\x90\x80\x80") == "\"" + replacement + replacement + replacement + replacement + "\"");  // > U+10FFFF
  CHECK(json_string("end\xE2\x82") == "\"end" + replacement + replacement + "\"");      // truncated
  // Quotes, backslashes and control bytes are escaped (RFC 8259, section 7).
  CHECK(json_string("a\"b\\c\nd\te\x01") == "\"a\\\"b\\\\c\\nd\\te\\u0001\"");
}

// ---- peaks from every accepted step and event, not from the output rows ----

namespace {

/// Largest value of summary.json's "peaks" entry of one element output.
double summary_peak(const std::string& summary, const std::string& output) {
  const std::string key = "\"" + output + "\": {\"max\": ";
  const std::size_t at = summary.find(key, summary.find("\"peaks\""));
  REQUIRE(at != std::string::npos);
  return std::stod(summary.substr(at + key.size()));
}

}  // namespace

TEST_CASE("an element output's peak between two output rows does not depend on the output interval", "[results]") {
  // A 1 kg mass at the spring's free length moving at 1 m/s on a 1e4 N/m spring: x = (v0 / w)
  // sin(w t), w = 100 rad/s, so the force peaks at k v0 / w = v0 sqrt(k m) = 100 N at
  // t = pi / 200 = 15.7 ms. Rows every 10 ms see 100 sin(2) = 90.9 N at most.
  const std::string text =
      "railcrash: 1\nname: bounce\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: mass, mass: 1.0, inertia: 0.1, position: [1.0, 0], velocity: [1.0, 0]}\nelements:\n"
      "  - {name: spring, type: linear_spring, stiffness: 1.0e4, free_length: 1.0, "
      "points: [{body: ground, at: [0, 0]}, {body: mass, at: [0, 0]}]}\n"
      "simulation: {t_end: 0.03, rtol: 1.0e-8, dt: 1.0e-6}\n";
  const double exact = 100.0;  // [N]
  for (const IntegratorKind integrator : {IntegratorKind::Ida, IntegratorKind::Euler}) {
    std::vector<double> peaks;
    for (const double output_interval : {0.01, 1.0e-5}) {
      LoadedModel loaded = testing::loaded_from_text(text);
      Model& model = loaded.model;
      loaded.run_spec.simulation.integrator = integrator;
      loaded.run_spec.simulation.output_interval = output_interval;
      const RunReport report = run_model(model, loaded.run_spec, "", nullptr, false, /*keep_in_memory=*/true);
      REQUIRE(report.outcome.ok);
      peaks.push_back(summary_peak(report.summary_json, "spring.force"));
    }
    INFO((integrator == IntegratorKind::Ida ? "ida" : "euler") << ": peaks " << peaks[0] << " (10 ms rows), " << peaks[1]
                                                                << " (10 us rows)");
    // The peak is the largest value at the ends of the steps (not located between them): below
    // the true one by about (w h)^2 / 8 for a step h across it, 2.4e-5 here for IDA at rtol
    // 1e-8; Euler adds its O(w dt) amplitude error. The 10 ms rows alone gave 90.9 N.
    const double tolerance = integrator == IntegratorKind::Ida ? 1e-4 : 1e-3;
    CHECK(peaks[0] == Approx(exact).epsilon(tolerance));
    CHECK(peaks[1] == Approx(exact).epsilon(tolerance));
    CHECK(peaks[0] == Approx(peaks[1]).epsilon(tolerance));
  }
}

TEST_CASE("the barrier model's crush-element peak is its force-crush curve's peak with 1 ms and 10 us rows", "[results]") {
  // models/barrier/two_car_barrier.yaml: lead_crush's curve peaks at 1.67e6 lbf at 5 in of
  // crush, which it passes at about 12 ms; its 1 ms rows alone saw 1.651e6 lbf.
  std::vector<double> peaks, crush;
  for (const double output_interval : {1.0e-3, 1.0e-5}) {
    const LoadedModel loaded = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/barrier/two_car_barrier.yaml",
                                   {"simulation.t_end=0.03", "simulation.output_interval=" + std::to_string(output_interval)});
    const Model& model = loaded.model;
    const RunReport report = run_model(model, loaded.run_spec, "", nullptr, false, /*keep_in_memory=*/true);
    REQUIRE(report.outcome.ok);
    peaks.push_back(summary_peak(report.summary_json, "lead_crush.force"));
    crush.push_back(report.car_crush.at(0).max_crush);
  }
  INFO("peaks " << peaks[0] << ", " << peaks[1] << "; lead car crush " << crush[0] << ", " << crush[1]);
  CHECK(peaks[0] == Approx(1.67e6).epsilon(1e-6));
  CHECK(peaks[1] == Approx(1.67e6).epsilon(1e-6));
  CHECK(crush[0] == Approx(crush[1]).epsilon(1e-6));
}

namespace {

/// Passes every call on to a ResultWriter and, at each of them, evaluates every element output
/// at the state itself: the cars' crush (car_crush) from one instant, over all the instants the
/// writer is shown, over those where it is shown every output of the car's end elements, and
/// over those where it is shown at least one of them (every instant for a car without one).
class CrushWitness : public RunObserver {
 public:
  CrushWitness(const DaeSystem& system, ResultWriter& writer)
      : cars_(cars_of(system)), every_instant_(cars_.size(), 0.0), full_instants_(cars_.size(), 0.0),
        touched_instants_(cars_.size(), 0.0), system_(system), writer_(writer), all_(system.output_names().size()) {}
  void sample(double t, const double* y, const double* lambda, const double* quadratures, const double* outputs) override {
    writer_.sample(t, y, lambda, quadratures, outputs);
    witness(y, lambda, outputs, FreshOutputs{});
  }
  void event(const EventRecord& record, const double* y) override { writer_.event(record, y); }
  void step(double t, const double* y, const double* lambda, const double* outputs, const FreshOutputs& fresh) override {
    writer_.step(t, y, lambda, outputs, fresh);
    witness(y, lambda, outputs, fresh);
  }
  bool observes_steps() const override { return true; }

  std::vector<CarCrush> cars_;
  // [length] largest crush per car: all instants; whole sums; sums with a fresh column
  std::vector<double> every_instant_, full_instants_, touched_instants_;
  long partial_calls = 0, fresh_mismatches = 0;

 private:
  void witness(const double* y, const double* lambda, const double* outputs, const FreshOutputs& fresh) {
    system_.outputs(y, lambda, all_.data());
    bool full = true;
    for (std::size_t k = 0; k < all_.size(); ++k) {
      if (!fresh.has(static_cast<int>(k))) full = false;
      else if (outputs[k] != all_[k]) ++fresh_mismatches;  // a column said fresh must be this state's
    }
    partial_calls += full ? 0 : 1;
    if (!lengths_measured_)  // L(0) from the first state, as the writer takes it
      for (CarCrush& car : cars_) car.initial_length = car_length(car, y);
    lengths_measured_ = true;
    for (std::size_t c = 0; c < cars_.size(); ++c) {
      const double crush = car_crush(cars_[c], y, all_.data());  // [length]
      std::vector<int> end_columns;
      for (const CarEnd& end : cars_[c].ends)
        if (end.column >= 0) end_columns.push_back(end.column);
      every_instant_[c] = std::max(every_instant_[c], crush);
      if (fresh.has_all(end_columns)) full_instants_[c] = std::max(full_instants_[c], crush);
      bool touched = end_columns.empty();
      for (const int column : end_columns) touched = touched || fresh.has(column);
      if (touched) touched_instants_[c] = std::max(touched_instants_[c], crush);
    }
  }
  const DaeSystem& system_;
  ResultWriter& writer_;
  std::vector<double> all_;
  bool lengths_measured_ = false;
};

}  // namespace

TEST_CASE("a car's largest crush is of one instant, its interface elements evaluated at located mode changes", "[results]") {
  // At a mode change located inside an IDA step only the changed element's outputs are
  // evaluated (RunObserver::step's `fresh`). A car's crush adds its ends' interface elements'
  // outputs to its shortening, so at such an instant the writer evaluates them at that state
  // (car_crush_at) and the crush is of one instant. Scenario 2 of the barrier cars: the
  // leading car's front end is the wagon's buffers (a crush spring against a body of no car);
  // scenario 1: the cars meet through coupler faces (coupler_end, no crush element), each car's crush is its
  // length from the state alone, at every instant the writer is shown.
  for (const char* scenario : {"scenario2_barrier_cars", "scenario1_barrier_cars"}) {
    INFO(scenario);
    LoadedModel loaded = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/scenarios/" + scenario + ".yaml");
    Model& model = loaded.model;
    loaded.run_spec.simulation.integrator = IntegratorKind::Ida;
    DaeSystem system(model);
    ResultWriter writer("", system, loaded.run_spec);
    CrushWitness witness(system, writer);
    const RunOutcome outcome =
        make_integrator(system, loaded.run_spec.simulation)->run(loaded.run_spec.simulation.t_end, output_interval_of(loaded.run_spec.simulation), witness);
    REQUIRE(outcome.ok);
    CHECK(witness.fresh_mismatches == 0);
    CHECK(witness.partial_calls > 100);  // located mode changes, each with one element's outputs
    const std::vector<CarCrush>& cars = writer.car_crush();
    REQUIRE(cars.size() == witness.cars_.size());
    bool some_crush = false;
    for (std::size_t c = 0; c < cars.size(); ++c) {
      INFO("car " << cars[c].car);
      CHECK(cars[c].max_crush == witness.touched_instants_[c]);  // every instant with a fresh column, exactly
      CHECK(cars[c].max_crush >= witness.full_instants_[c]);     // the steps' whole sums among them
      CHECK(cars[c].max_crush <= witness.every_instant_[c]);     // never above what one instant reaches
      some_crush = some_crush || cars[c].max_crush > 4.0;
    }
    CHECK(some_crush);  // the leading car crushes 17.5 in (scenario 2), 4.5 in (scenario 1)
  }
}

TEST_CASE("the running summary is written every 2 s, or every 50 times what the last one took", "[results]") {
  using std::chrono::milliseconds;
  const SummarySchedule::Clock::time_point start{};
  SummarySchedule schedule(start);
  CHECK_FALSE(schedule.due(start + milliseconds(1999)));
  CHECK(schedule.due(start + milliseconds(2001)));
  // A summary that took 100 ms: the next one 5 s after it ended, not 2 s.
  schedule.written(start + milliseconds(2001), start + milliseconds(2101));
  CHECK(schedule.interval() == milliseconds(5000));
  CHECK_FALSE(schedule.due(start + milliseconds(4200)));
  CHECK_FALSE(schedule.due(start + milliseconds(7100)));
  CHECK(schedule.due(start + milliseconds(7102)));
  // A quick one (10 ms): back to 2 s.
  schedule.written(start + milliseconds(7102), start + milliseconds(7112));
  CHECK(schedule.interval() == milliseconds(2000));
  CHECK_FALSE(schedule.due(start + milliseconds(9100)));
  CHECK(schedule.due(start + milliseconds(9113)));
}

// ---- each car's own crush (results.hpp "Car crush") ----

namespace {

/// Timeseries column `name` of a run kept in memory.
const std::vector<double>& series_of(const RunReport& report, const std::string& name) {
  const auto it = std::find(report.columns.begin(), report.columns.end(), name);
  REQUIRE(it != report.columns.end());
  return report.series[static_cast<std::size_t>(it - report.columns.begin())];
}

/// x of a body point [length] at output row k, from the body's x and theta columns.
double point_x(const RunReport& report, const std::string& body, double sx, double sy, std::size_t k) {
  const double theta = series_of(report, body + ".theta")[k];
  return series_of(report, body + ".x")[k] + std::cos(theta) * sx - std::sin(theta) * sy;
}

}  // namespace

TEST_CASE("each car of the report's two-car model crushes by its own shortening, not half of the shared anticlimber", "[results]") {
  // models/report/final_two_car.yaml: the anticlimber (one law for the two identical ends in
  // series) is the only crush element and joins the cars; f654aee gave each car half of it,
  // 19.55 in, at one instant. Each car's crush, computed here from the rows' body columns
  // alone: the shortening along x between its anticlimber face (car1_front_end (42.375,
  // -13.17), car2_front_end (-40.625, -11.90)) and its rear body's centre of gravity, plus half
  // of the anticlimber's horizontal deformation. The writer takes every step and event, the
  // rows every 0.5 ms: its maxima lie at or just above the rows'. Measured from the front end's
  // centre of gravity instead of its face the two cars crush 20.79 and 20.59 in: the face, 13 in
  // below that centre, moves back a little more as the front end pitches.
  const LoadedModel loaded = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml");
  const Model& model = loaded.model;
  const RunReport report = run_model(model, loaded.run_spec, "", nullptr, false, /*keep_in_memory=*/true);
  REQUIRE(report.outcome.ok);
  REQUIRE(report.car_crush.size() == 2);
  const std::vector<double>& deformation = series_of(report, "anticlimber.horizontal_deformation");
  struct Face {
    const char* car;
    const char* front;
    double sx, sy;  // [in] the anticlimber point on the front end
    const char* rear;
    double outward;  // +1: the face is at the car's +x end
  };
  const Face faces[] = {{"car1", "car1_front_end", 42.375, -13.17, "car1_rear_body", 1.0},
                        {"car2", "car2_front_end", -40.625, -11.90, "car2_rear_body", -1.0}};
  double rows_max[2] = {0.0, 0.0};  // [in]
  for (int c = 0; c < 2; ++c) {
    const Face& f = faces[c];
    const auto length = [&](std::size_t k) { return f.outward * (point_x(report, f.front, f.sx, f.sy, k) - series_of(report, f.rear + std::string(".x"))[k]); };
    for (std::size_t k = 0; k < deformation.size(); ++k)
      rows_max[c] = std::max(rows_max[c], length(0) - length(k) + 0.5 * std::max(0.0, deformation[k]));
  }
  INFO("writer: car1 " << report.car_crush[0].max_crush << " in at " << report.car_crush[0].t << " s, car2 "
                       << report.car_crush[1].max_crush << " in at " << report.car_crush[1].t << " s; rows: "
                       << rows_max[0] << ", " << rows_max[1]);
  for (int c = 0; c < 2; ++c) {
    CHECK(report.car_crush[static_cast<std::size_t>(c)].car == faces[c].car);
    CHECK(report.car_crush[static_cast<std::size_t>(c)].max_crush >= rows_max[c] - 1e-9);
    CHECK(report.car_crush[static_cast<std::size_t>(c)].max_crush == Approx(rows_max[c]).margin(0.01));  // [in]
  }
  // (21.03 and 20.66 in before issue 40 made the anticlimber's 1-in misalignment geometric:
  // the struck car's face 1 in above its point, where the crush force now acts.)
  CHECK(rows_max[0] == Approx(20.97).margin(0.01));
  CHECK(rows_max[1] == Approx(20.63).margin(0.01));
  CHECK(report.car_crush[0].max_crush - report.car_crush[1].max_crush > 0.3);  // [in] the loaded car crushes more
  // R1 is the anticlimber's: unchanged.
  CHECK(report.responses.max_anticlimber_crush == Approx(39.111).margin(0.001));  // 39.109 before issue 40
}

TEST_CASE("two SI cars whose crush zones differ in stiffness crush F / k each under the one force of the series", "[results]") {
  // models/examples/crush_zone_cars.yaml: two 40 t cars, crush zones of 5e6 and 1e7 N/m, faces
  // of 1e9 N/m between them, 5 m/s. The three springs are in series: at the largest
  // compression F = v sqrt(mu k), 1 / k = 1 / 5e6 + 1 / 1e7 + 1 / 1e9, mu = 20,000 kg, and each
  // car's crush is its zone's F / k_i plus half of the faces' F / 1e9. The zones as crush
  // springs (crush elements within the car), and as linear springs (structure, as the
  // report's sills: no crush element but the shared faces; f654aee gave each car half of the
  // faces' 1.3 mm).
  const double series_stiffness = 1.0 / (1.0 / 5.0e6 + 1.0 / 1.0e7 + 1.0 / 1.0e9);  // [N/m]
  const double force = 5.0 * std::sqrt(20000.0 * series_stiffness);                    // [N] 1.289e6
  const double expected[2] = {force / 5.0e6 + 0.5 * force / 1.0e9, force / 1.0e7 + 0.5 * force / 1.0e9};  // [m]
  std::ifstream file(std::string(RAILCRASH_SOURCE_DIR) + "/models/examples/crush_zone_cars.yaml");
  std::stringstream read;
  read << file.rdbuf();
  const std::string crush_zones = read.str();
  std::string structure = crush_zones;
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"type: crush_spring, curve: [[0, 0], [1, 5.0e6]], unloading_stiffness: 5.0e6",
                                                                     "type: linear_spring, stiffness: 5.0e6"},
                                 {"type: crush_spring, curve: [[0, 0], [1, 1.0e7]], unloading_stiffness: 1.0e7",
                                  "type: linear_spring, stiffness: 1.0e7"}}) {
    const std::size_t at = structure.find(from);
    REQUIRE(at != std::string::npos);
    structure.replace(at, from.size(), to);
  }
  for (const bool zones_are_crush_springs : {true, false}) {
    INFO((zones_are_crush_springs ? "crush springs" : "linear springs"));
    const LoadedModel loaded = testing::loaded_from_text(zones_are_crush_springs ? crush_zones : structure);
    const RunReport report = run_model(loaded.model, loaded.run_spec, "", nullptr, false, /*keep_in_memory=*/true);
    REQUIRE(report.outcome.ok);
    REQUIRE(report.car_crush.size() == 2);
    for (int c = 0; c < 2; ++c) {
      INFO("car " << report.car_crush[static_cast<std::size_t>(c)].car);
      CHECK(report.car_crush[static_cast<std::size_t>(c)].max_crush == Approx(expected[c]).epsilon(3e-3));
    }
  }
}

TEST_CASE("an output's peaks are its signed largest and smallest values with their times", "[results]") {
  // 1000 kg at 2 m/s into a wall (contact, 3.673e6 N/m, no damping) that it touches at t = 0:
  // the penetration is v0 sqrt(m/k) sin(w t), w = sqrt(k/m), largest 0.033 m at pi / (2 w) =
  // 25.9 ms; the mass leaves at pi / w = 51.8 ms at 2 m/s, so the penetration at t_end = 0.36 s
  // is -2 (0.36 - pi / w) = -0.616 m, its smallest. f654aee gave only the largest |value|, the
  // gap's 0.616 m. Checked in summary.json and against timeseries.csv of the same run.
  const double m = 1000.0, k = 3.673e6, v0 = 2.0;  // [kg], [N/m], [m/s]
  const double w = std::sqrt(k / m);                // [rad/s]
  const std::string text =
      "railcrash: 1\nname: wall\nunits: SI\ngravity: [0, 0]\nbodies:\n"
      "  - {name: car, car: car, mass: 1000, inertia: 100, position: [0, 0], velocity: [2, 0]}\nelements:\n"
      "  - {name: wall, type: contact, stiffness: 3.673e6, line_point: [0, 0], line_normal: [-1, 0], points: [{body: car, at: [0, 0]}]}\n"
      "simulation: {t_end: 0.36, output_interval: 0.001}\n";
  const std::string folder = temporary_folder("signed_peaks");
  const LoadedModel loaded = testing::loaded_from_text(text);
  const RunReport report = run_model(loaded.model, loaded.run_spec, folder);
  REQUIRE(report.outcome.ok);
  const YAML::Node peak = YAML::LoadFile(folder + "/summary.json")["peaks"]["wall.penetration"];
  REQUIRE(peak);
  // A smooth peak inside a step reads low by about (w h)^2 / 8 (README "What the maxima are taken over").
  CHECK(peak["max"].as<double>() == Approx(v0 * std::sqrt(m / k)).epsilon(1e-4));
  CHECK(peak["max"].as<double>() == Approx(0.033).epsilon(1e-3));
  CHECK(peak["t_max"].as<double>() == Approx(0.5 * M_PI / w).margin(1e-3));  // [s] within an output interval
  CHECK(peak["min"].as<double>() == Approx(-v0 * (0.36 - M_PI / w)).epsilon(1e-5));
  CHECK(peak["t_min"].as<double>() == Approx(0.36).epsilon(1e-9));
  CHECK_FALSE(peak["abs_max"]);
  // timeseries.csv: the rows' extremes lie within what the run's steps saw.
  std::ifstream rows(folder + "/timeseries.csv");
  std::string line;
  while (std::getline(rows, line) && line.rfind('#', 0) == 0) {}  // the run's provenance line first
  std::vector<std::string> header;
  for (std::stringstream names(line); std::getline(names, line, ',');) header.push_back(line);
  const std::size_t column = static_cast<std::size_t>(std::find(header.begin(), header.end(), "wall.penetration") - header.begin());
  REQUIRE(column < header.size());
  double rows_max = -1.0, rows_min = 1.0;  // [m]
  while (std::getline(rows, line)) {
    std::stringstream fields(line);
    std::string field;
    for (std::size_t field_index = 0; field_index <= column; ++field_index) std::getline(fields, field, ',');
    rows_max = std::max(rows_max, std::stod(field));
    rows_min = std::min(rows_min, std::stod(field));
  }
  CHECK(rows_max <= peak["max"].as<double>());
  CHECK(rows_max == Approx(peak["max"].as<double>()).epsilon(1e-3));
  CHECK(rows_min == Approx(peak["min"].as<double>()).epsilon(1e-9));
}
