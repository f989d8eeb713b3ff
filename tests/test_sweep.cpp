// `railcrash sweep` (sweep.hpp): the design generators against their definitions, plan errors
// with file:line before any run, and a sweep end to end against the closed-form crush.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "railcrash/error.hpp"
#include "railcrash/sweep.hpp"
#include "railcrash/table_text.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

// Largest crush of the R1 test model (support.hpp) with yield deflection d_y, from energy
// (2000 J): k d_y^2 / 2 + F_y u + k_p u^2 / 2 = 2000, F_y = k d_y, crush = d_y + u.
double crush_for(double yield_deflection) {
  const double k = 1e7, kp = 1e5, f = k * yield_deflection;
  const double rest = 2000.0 - 0.5 * k * yield_deflection * yield_deflection;
  return yield_deflection + (-f + std::sqrt(f * f + 2.0 * kp * rest)) / kp;
}

struct Files {
  // One folder per process: CTest runs test cases in parallel.
  std::string dir = (std::filesystem::temp_directory_path() / ("railcrash_sweep_test_" + std::to_string(::getpid()))).string();
  std::string model = dir + "/model.yaml", plan = dir + "/plan.yaml";
  Files() {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(model) << testing::anticlimber_r1_model_text(0.15);
  }
  ~Files() { std::filesystem::remove_all(dir); }
  void write_plan(const std::string& text) const { std::ofstream(plan) << text; }
  std::string error_of_plan(const std::string& text) const {
    write_plan(text);
    try {
      load_sweep_plan(plan, model);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
};

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// runs.csv without its wall_seconds column (the last but one).
std::string without_timing(const std::string& csv) {
  std::string out, line;
  std::istringstream in(csv);
  while (std::getline(in, line)) {
    std::vector<std::string> fields = csv_fields(line);
    fields.erase(fields.end() - 4);  // wall_seconds (then message, outcomes, branch)
    for (const std::string& f : fields) out += f + "|";
    out += "\n";
  }
  return out;
}

}  // namespace

TEST_CASE("sweep designs: full factorial has every combination once, the first factor slowest", "[sweep]") {
  const auto rows = full_factorial({3, 2, 4});
  REQUIRE(rows.size() == 24);
  CHECK(std::set<std::vector<std::size_t>>(rows.begin(), rows.end()).size() == 24);
  CHECK(rows[0] == std::vector<std::size_t>{0, 0, 0});
  CHECK(rows[1] == std::vector<std::size_t>{0, 0, 1});
  CHECK(rows[4] == std::vector<std::size_t>{0, 1, 0});
  CHECK(rows[23] == std::vector<std::size_t>{2, 1, 3});
  CHECK(full_factorial({}).empty());
}

TEST_CASE("sweep designs: one at a time varies one factor per run from the model's values", "[sweep]") {
  const auto rows = one_at_a_time({2, 3});
  REQUIRE(rows.size() == 1 + 2 + 3);
  CHECK(rows[0] == std::vector<long>{-1, -1});
  CHECK(rows[2] == std::vector<long>{1, -1});
  CHECK(rows[5] == std::vector<long>{-1, 2});
}

TEST_CASE("sweep designs: Latin hypercube puts one sample in each of N strata per factor, reproducibly", "[sweep]") {
  for (std::size_t n : {1, 7, 50}) {
    const auto rows = latin_hypercube(n, 3, 42);
    REQUIRE(rows.size() == n);
    for (std::size_t f = 0; f < 3; ++f) {
      std::vector<std::size_t> strata;
      for (const auto& row : rows) {
        REQUIRE(row[f] > 0.0);
        REQUIRE(row[f] < 1.0);
        strata.push_back(static_cast<std::size_t>(row[f] * static_cast<double>(n)));
      }
      std::sort(strata.begin(), strata.end());
      for (std::size_t k = 0; k < n; ++k) CHECK(strata[k] == k);
    }
  }
  CHECK(latin_hypercube(20, 2, 42) == latin_hypercube(20, 2, 42));
  CHECK(latin_hypercube(20, 2, 42) != latin_hypercube(20, 2, 43));
}

TEST_CASE("sweep designs: the generator and transforms are fixed by their definitions", "[sweep]") {
  // The C++ standard fixes std::mt19937_64: its 10000th output from the default seed is
  // 9981545732273789042 ([rand.predef]); unit_uniform takes its top 52 bits k: (k + 0.5) / 2^52.
  std::mt19937_64 generator;
  generator.discard(9999);
  CHECK(unit_uniform(generator) == (static_cast<double>(9981545732273789042ull >> 12) + 0.5) / 4503599627370496.0);
  // Monte Carlo: the mean of 20000 uniforms is 1/2 within 4 standard errors (sqrt(1/12/20000)).
  const auto rows = monte_carlo(20000, 1, 7);
  double sum = 0.0;
  for (const auto& row : rows) sum += row[0];
  CHECK(std::abs(sum / 20000.0 - 0.5) < 4.0 * std::sqrt(1.0 / 12.0 / 20000.0));
  CHECK(monte_carlo(5, 2, 7) == monte_carlo(5, 2, 7));
  // Normal quantiles (Abramowitz and Stegun Table 26.5 / any statistics table).
  CHECK(normal_quantile(0.5) == Approx(0.0).margin(1e-14));
  CHECK(normal_quantile(0.975) == Approx(1.959963984540054).epsilon(1e-13));
  CHECK(normal_quantile(0.001) == Approx(-3.090232306167814).epsilon(1e-13));
  SweepDistribution normal{SweepDistribution::Kind::normal, 10.0, 2.0};
  CHECK(normal.value_at(0.975) == Approx(10.0 + 2.0 * 1.959963984540054).epsilon(1e-13));
  SweepDistribution uniform{SweepDistribution::Kind::uniform, -5.0, 3.0};
  CHECK(uniform.value_at(0.25) == -3.0);
}

TEST_CASE("sweep plans: an unknown key, a level of the wrong type and an empty design name the plan's line", "[sweep]") {
  Files files;
  const std::string head = "sweep: 1\ndesign: full_factorial\nfactors:\n";
  CHECK_THAT(files.error_of_plan(head + "  - {key: elements.ac.horizontal_yield_deflection, levels: [0.01]}\n"
                                        "  - {key: elements.ac.no_such_key, levels: [1]}\n"),
             Catch::StartsWith(files.plan + ":5: factor 'elements.ac.no_such_key'") && Catch::Contains("no_such_key"));
  CHECK_THAT(files.error_of_plan(head + "  - {key: elements.ac.horizontal_yield_deflection, levels: [0.01, soft]}\n"),
             Catch::StartsWith(files.plan + ":4: factor 'elements.ac.horizontal_yield_deflection' at level 'soft'"));
  CHECK_THAT(files.error_of_plan(head + "  - {key: elements.ac.horizontal_yield_deflection, levels: []}\n"),
             Catch::StartsWith(files.plan + ":4:") && Catch::Contains("the design is empty"));
  CHECK_THAT(files.error_of_plan("sweep: 1\ndesign: monte_carlo\nsamples: 0\nfactors:\n"
                                 "  - {key: simulation.t_end, distribution: {uniform: [0.1, 0.2]}}\n"),
             Catch::StartsWith(files.plan + ":3:") && Catch::Contains("the design is empty"));
  CHECK_THAT(files.error_of_plan("sweep: 1\ndesign: runs\nfactors:\n  - {key: simulation.t_end}\nruns: []\n"),
             Catch::StartsWith(files.plan + ":5:") && Catch::Contains("the design is empty"));
  CHECK_THAT(files.error_of_plan("sweep: 1\ndesign: factorial\nfactors: []\n"),
             Catch::StartsWith(files.plan + ":2:") && Catch::Contains("full_factorial"));
  CHECK_THAT(files.error_of_plan(head + "  - {key: 'bodies.car.velocity[2]', levels: [-1]}\n"),
             Catch::StartsWith(files.plan + ":4:") && Catch::Contains("has 2 entries"));
  CHECK(files.error_of_plan(head + "  - {key: 'gravity[1]', levels: [-9.81]}\n") == "no error");  // a top-level list
  CHECK_THAT(files.error_of_plan(head + "  - {key: simulation.t_end, levels: [0.1]}\nresponses: [R1, {R2: 1}]\n"),
             Catch::StartsWith(files.plan + ":5:") && Catch::Contains("a response is a name"));
}

TEST_CASE("sweep: R1 of each run against the closed-form crush, and 1 and 2 jobs and a resume give the same rows", "[sweep]") {
  Files files;
  files.write_plan("sweep: 1\ndesign: full_factorial\nfactors:\n"
                   "  - {key: elements.ac.horizontal_yield_deflection, scale: true, levels: [0.8, 1.2]}\n"
                   "  - {key: 'bodies.car.velocity[0]', levels: [-2, -1.5]}\n"
                   "responses: [R1, status, responses.max_anticlimber_crush, car.x@0.052]\n");
  const SweepPlan plan = load_sweep_plan(files.plan, files.model);
  REQUIRE(plan.responses.size() == 3);
  SweepOptions options;
  const SweepResult one = run_sweep(files.model, plan, files.dir + "/one", options);
  REQUIRE(one.done() == 4);
  // Rows: (0.8, -2), (0.8, -1.5), (1.2, -2), (1.2, -1.5). Energy 2000 J at -2 m/s; at -1.5 m/s
  // only the elastic range is not left for d_y = 0.008 (k d_y^2 / 2 = 320 J < 1125 J): plastic too.
  const std::vector<std::string> lines = [&] {
    std::vector<std::string> v;
    for (const auto& l : one.lines) v.push_back(*l);
    return v;
  }();
  const auto field = [&](std::size_t run, std::size_t column) { return std::stod(csv_fields(lines[run])[column]); };
  CHECK(field(0, 5) == Approx(crush_for(0.008) / 0.02).epsilon(1e-5));
  CHECK(field(2, 5) == Approx(crush_for(0.012) / 0.02).epsilon(1e-5));
  CHECK(field(0, 6) == Approx(crush_for(0.008)).epsilon(1e-5));
  // The car meets the anticlimber at x = 0 (t = 0.1 m / 2 m/s = 0.05 s); 2 ms later it is still
  // elastic (deflection < d_y): x = -(v0 / w) sin(w 0.002 s), w = sqrt(1e7 N/m / 1000 kg) = 100 rad/s.
  CHECK(field(0, 7) == Approx(-0.02 * std::sin(0.2)).epsilon(1e-4));
  CHECK(field(2, 7) == Approx(-0.02 * std::sin(0.2)).epsilon(1e-4));
  CHECK(field(1, 7) == Approx(0.1 - 1.5 * 0.052).epsilon(1e-9));  // at 1.5 m/s: not yet there
  CHECK(csv_fields(lines[1])[3] == "-1.5");
  CHECK(csv_fields(lines[0])[4] == "ok");

  options.jobs = 2;
  run_sweep(files.model, plan, files.dir + "/two", options);
  const std::string reference = without_timing(read(files.dir + "/one/runs.csv"));
  CHECK(without_timing(read(files.dir + "/two/runs.csv")) == reference);

  // An interrupted sweep: rows 1 and 3 kept, the rest run on --resume.
  std::filesystem::create_directories(files.dir + "/cut");
  std::ofstream(files.dir + "/cut/runs.csv") << sweep_csv_header(plan) << '\n' << lines[3] << '\n' << lines[1] << '\n'
                                             << lines[2].substr(0, 30) << '\n';  // a line cut short by a kill
  options.resume = true;
  const SweepResult resumed = run_sweep(files.model, plan, files.dir + "/cut", options);
  CHECK(resumed.resumed == 2);
  CHECK(without_timing(read(files.dir + "/cut/runs.csv")) == reference);
  CHECK_THAT(read(files.dir + "/cut/summary.md"), Catch::Contains("| elements.ac.horizontal_yield_deflection* | 0.8: "));
}
