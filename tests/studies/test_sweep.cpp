// `railcrash sweep` (sweep.hpp): the design generators against their definitions, plan errors
// with file:line before any run, and a sweep end to end against the closed-form crush.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "railcrash/core/error.hpp"
#include "railcrash/core/table_text.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/studies/sweep.hpp"
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
    fields.erase(fields.end() - 6);  // wall_seconds (then message, outcomes, branch, integrator_used, euler_from_t)
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

namespace {

/// A plan made in memory (no model check: the generator only reads the levels): factors named
/// f0, f1, ... with levels "F.J" (factor F, level J), or distributions for the sampled designs.
SweepPlan plan_in_memory(SweepDesignKind design, const std::vector<std::size_t>& level_counts) {
  SweepPlan plan;
  plan.path = "plan.yaml";
  plan.design = design;
  plan.settings = {"simulation.t_end=0.1"};
  for (std::size_t f = 0; f < level_counts.size(); ++f) {
    SweepFactor factor;
    factor.key = "f" + std::to_string(f);
    for (std::size_t j = 0; j < level_counts[f]; ++j) factor.levels.push_back(std::to_string(f) + "." + std::to_string(j));
    plan.factors.push_back(factor);
  }
  return plan;
}

}  // namespace

TEST_CASE("sweep runs one at a time: run k of a 21.6-million-run factorial from its digits, without a list of runs", "[sweep]") {
  Files files;
  const std::string model_text = read(files.model);
  const std::vector<std::size_t> counts{10, 7, 13, 4, 11, 9, 3, 20};  // 21,621,600 runs
  const SweepPlan plan = plan_in_memory(SweepDesignKind::full_factorial, counts);
  const SweepRunGenerator generator(plan, files.model, model_text);
  REQUIRE(generator.count() == 21621600u);
  // Run k's level of factor f is digit f of k in the mixed radix of the level counts, the last
  // factor fastest: (k / (product of the counts after f)) mod count_f.
  for (const std::size_t k : {std::size_t{0}, std::size_t{1}, std::size_t{20}, std::size_t{1234567}, std::size_t{9999999},
                              std::size_t{21621599}}) {
    INFO("run " << k);
    const SweepRunSpec spec = generator.spec(k);
    REQUIRE(spec.levels.size() == counts.size());
    REQUIRE(spec.settings.size() == 1 + counts.size());
    CHECK(spec.settings[0] == "simulation.t_end=0.1");
    std::size_t stride = 1;
    for (std::size_t f = counts.size(); f-- > 0;) {
      const std::size_t digit = k / stride % counts[f];
      CHECK(spec.levels[f] == std::to_string(f) + "." + std::to_string(digit));
      CHECK(spec.settings[1 + f] == "f" + std::to_string(f) + "=" + spec.levels[f]);
      stride *= counts[f];
    }
  }
  // 1234567 = ((((((0 7 + 3) 13 + 12) 4 + 3) 11 + 9) 9 + 2) 3 + 0) 20 + 7, worked by hand.
  CHECK(generator.levels(1234567) == std::vector<std::string>{"0.0", "1.3", "2.12", "3.3", "4.9", "5.2", "6.0", "7.7"});
  CHECK(generator.spec(5).hash == generator.spec(5).hash);
  CHECK(generator.spec(5).hash != generator.spec(6).hash);
}

TEST_CASE("sweep runs one at a time: every design's run k equals its design generator's row k, taken in any order", "[sweep]") {
  Files files;
  const std::string model_text = read(files.model);
  const std::vector<std::size_t> order{7, 3, 4, 0, 11, 5, 6, 1, 2, 10, 8, 9};  // runs out of turn: a generator keeps no cursor state wrong
  SECTION("full factorial") {
    const SweepPlan plan = plan_in_memory(SweepDesignKind::full_factorial, {3, 2, 2});
    const SweepRunGenerator generator(plan, files.model, model_text);
    const auto rows = full_factorial({3, 2, 2});
    REQUIRE(generator.count() == rows.size());
    for (const std::size_t k : order)
      for (std::size_t f = 0; f < 3; ++f) CHECK(generator.levels(k)[f] == plan.factors[f].levels[rows[k][f]]);
  }
  SECTION("one at a time") {
    const SweepPlan plan = plan_in_memory(SweepDesignKind::one_at_a_time, {3, 5, 3});
    const SweepRunGenerator generator(plan, files.model, model_text);
    const auto rows = one_at_a_time({3, 5, 3});
    REQUIRE(generator.count() == 12);
    for (const std::size_t k : order)
      for (std::size_t f = 0; f < 3; ++f)
        CHECK(generator.levels(k)[f] == (rows[k][f] < 0 ? "" : plan.factors[f].levels[static_cast<std::size_t>(rows[k][f])]));
    CHECK(generator.spec(0).settings == std::vector<std::string>{"simulation.t_end=0.1"});  // the model's values
  }
  for (const SweepDesignKind design : {SweepDesignKind::latin_hypercube, SweepDesignKind::monte_carlo}) {
    SweepPlan plan = plan_in_memory(design, {0, 0});
    plan.samples = 12;
    plan.seed = 9;
    plan.factors[0].distribution = SweepDistribution{SweepDistribution::Kind::uniform, -3.0, 5.0};
    plan.factors[1].distribution = SweepDistribution{SweepDistribution::Kind::normal, 2.0, 0.5};
    const SweepRunGenerator generator(plan, files.model, model_text);
    const auto rows = design == SweepDesignKind::latin_hypercube ? latin_hypercube(12, 2, 9) : monte_carlo(12, 2, 9);
    REQUIRE(generator.count() == 12);
    for (const std::size_t k : order) {
      INFO("run " << k);
      CHECK(std::stod(generator.levels(k)[0]) == -3.0 + 8.0 * rows[k][0]);
      CHECK(std::stod(generator.levels(k)[1]) == 2.0 + 0.5 * normal_quantile(rows[k][1]));
    }
  }
}

TEST_CASE("sweep runs one at a time: Monte Carlo run k of ten million from draws 2k and 2k + 1 of the seed's sequence", "[sweep]") {
  Files files;
  SweepPlan plan = plan_in_memory(SweepDesignKind::monte_carlo, {0, 0});
  plan.samples = 10000000;
  plan.seed = 77;
  plan.factors[0].distribution = SweepDistribution{SweepDistribution::Kind::uniform, 10.0, 20.0};
  plan.factors[1].distribution = SweepDistribution{SweepDistribution::Kind::uniform, 0.0, 1.0};
  const SweepRunGenerator generator(plan, files.model, read(files.model));
  REQUIRE(generator.count() == 10000000u);
  for (const std::size_t k : {std::size_t{9999999}, std::size_t{5000000}, std::size_t{5000001}, std::size_t{0}}) {
    INFO("run " << k);
    std::mt19937_64 draws(77);
    draws.discard(2 * k);
    const double u0 = (static_cast<double>(draws() >> 12) + 0.5) / 4503599627370496.0;  // 2^52
    const double u1 = (static_cast<double>(draws() >> 12) + 0.5) / 4503599627370496.0;
    CHECK(std::stod(generator.levels(k)[0]) == 10.0 + 10.0 * u0);
    CHECK(std::stod(generator.levels(k)[1]) == u1);
  }
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

TEST_CASE("sweep plans: a misspelt or repeated key is named with the closest key and the allowed ones", "[sweep]") {
  // The plan's keys go through the one YAML key check (before: a repeated key was taken, a factor's key had no suggestion).
  Files files;
  const std::string factor = "  - {key: simulation.t_end, levels: [0.1]}\n";
  CHECK(files.error_of_plan("sweep: 1\ndesing: full_factorial\nfactors:\n" + factor) ==
        files.plan + ":2: plan: unknown key 'desing' (did you mean 'design'?); allowed keys: sweep, design, samples, seed, set, "
                     "factors, runs, responses");
  CHECK(files.error_of_plan("sweep: 1\ndesign: full_factorial\ndesign: one_at_a_time\nfactors:\n" + factor) ==
        files.plan + ":3: plan: key 'design' is given twice; keep only one");
  CHECK(files.error_of_plan("sweep: 1\ndesign: full_factorial\nfactors:\n  - {key: simulation.t_end, level: [0.1]}\n") ==
        files.plan + ":4: factor 'simulation.t_end': unknown key 'level' (did you mean 'levels'?); allowed keys: key, scale, "
                     "levels, distribution");
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
    for (const auto& [number, l] : one.lines) v.push_back(l);
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

namespace {

/// The rows of runs.csv as maps column -> field.
std::vector<std::map<std::string, std::string>> csv_rows(const std::string& path) {
  std::istringstream in(read(path));
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = csv_fields(line);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    const std::vector<std::string> fields = csv_fields(line);
    rows.emplace_back();
    for (std::size_t k = 0; k < header.size() && k < fields.size(); ++k) rows.back()[header[k]] = fields[k];
  }
  return rows;
}

double number_in(const std::map<std::string, std::string>& row, const std::string& column) {
  const auto it = row.find(column);
  REQUIRE(it != row.end());
  REQUIRE(!it->second.empty());
  return std::stod(it->second);
}

/// Two 40 t cars of a modern multiple unit, each at 5 m/s into its own crush zone on a fixed
/// barrier (SI). Both zones have one curve: written twice, or with `shared` written once (&zone)
/// and used again (*zone), as PyYAML writes a list object a generator reuses.
std::string two_zone_model(bool shared) {
  const std::string zone = "[[0, 0], [0.01, 1.5e6], [0.6, 1.5e6]]";
  return std::string("railcrash: 1\nname: two cars\nunits: SI\ngravity: [0, 0]\nbodies:\n"
         "  - {name: car_a, mass: 40000, inertia: 1.0e6, position: [1.0, 0], velocity: [-5, 0]}\n"
         "  - {name: car_b, mass: 40000, inertia: 1.0e6, position: [1.0, 10], velocity: [-5, 0]}\n"
         "elements:\n"
         "  - {name: crush_a, type: crush_spring, free_length: 1.0, unloading_stiffness: 4.0e8, curve: ") +
         (shared ? "&zone " : "") + zone + ",\n     points: [{body: ground, at: [0, 0]}, {body: car_a, at: [0, 0]}]}\n" +
         "  - {name: crush_b, type: crush_spring, free_length: 1.0, unloading_stiffness: 4.0e8, curve: " +
         (shared ? "*zone" : zone) + ",\n     points: [{body: ground, at: [0, 10]}, {body: car_b, at: [0, 0]}]}\n" +
         "simulation: {t_end: 0.2, rtol: 1.0e-8, output_interval: 0.0001}\n";
}

/// Permanent crush of a zone [[0, 0], [0.01, F], [0.6, F]] that stops 40 t at 5 m/s (500 kJ):
/// the largest crush d from F 0.01 / 2 + F (d - 0.01) = 500 kJ, less the elastic F / k_u that
/// unloading at k_u = 4e8 N/m gives back (at least the steepest level's first slope, 4e6 N / 0.01 m,
/// as crush_spring requires).
double zone_permanent_crush(double plateau_force) { return 500000.0 / plateau_force + 0.005 - plateau_force / 4.0e8; }

}  // namespace

TEST_CASE("sweep: factors on two elements that share a curve through an alias each change their own element", "[sweep]") {
  Files files;
  const std::string plan = "sweep: 1\ndesign: full_factorial\nfactors:\n"
                           "  - {key: elements.crush_a.curve, levels: [[[0, 0], [0.01, 1.5e6], [0.6, 1.5e6]], [[0, 0], [0.01, 3.0e6], [0.6, 3.0e6]]]}\n"
                           "  - {key: elements.crush_b.curve, levels: [[[0, 0], [0.01, 2.0e6], [0.6, 2.0e6]], [[0, 0], [0.01, 4.0e6], [0.6, 4.0e6]]]}\n"
                           "responses: [peaks.crush_a.permanent_crush.max, peaks.crush_b.permanent_crush.max]\n";
  files.write_plan(plan);
  std::vector<std::vector<std::map<std::string, std::string>>> sweeps;
  for (const bool shared : {true, false}) {
    std::ofstream(files.model) << two_zone_model(shared);
    const std::string out = files.dir + (shared ? "/shared" : "/written_out");
    run_sweep(files.model, load_sweep_plan(files.plan, files.model), out, SweepOptions{});
    sweeps.push_back(csv_rows(out + "/runs.csv"));
  }
  const std::vector<std::map<std::string, std::string>>& rows = sweeps[0];
  REQUIRE(rows.size() == 4);
  // Rows (a, b): (1.5, 2), (1.5, 4), (3, 2), (3, 4) MN plateaus.
  const double force_a[] = {1.5e6, 1.5e6, 3.0e6, 3.0e6}, force_b[] = {2.0e6, 4.0e6, 2.0e6, 4.0e6};
  for (std::size_t k = 0; k < rows.size(); ++k) {
    INFO("run " << k);
    CHECK(rows[k].at("status") == "ok");
    CHECK(number_in(rows[k], "peaks.crush_a.permanent_crush.max") == Approx(zone_permanent_crush(force_a[k])).epsilon(1e-4));
    CHECK(number_in(rows[k], "peaks.crush_b.permanent_crush.max") == Approx(zone_permanent_crush(force_b[k])).epsilon(1e-4));
    CHECK(number_in(rows[k], "peaks.crush_a.permanent_crush.max") == number_in(sweeps[1][k], "peaks.crush_a.permanent_crush.max"));
    CHECK(number_in(rows[k], "peaks.crush_b.permanent_crush.max") == number_in(sweeps[1][k], "peaks.crush_b.permanent_crush.max"));
  }
  // The main effect of crush_a's curve on crush_a: the two means differ by the analytic difference.
  CHECK_THAT(read(files.dir + "/shared/summary.md"), Catch::Contains("| elements.crush_a.curve |"));
  CHECK(number_in(rows[0], "peaks.crush_a.permanent_crush.max") - number_in(rows[2], "peaks.crush_a.permanent_crush.max") ==
        Approx(zone_permanent_crush(1.5e6) - zone_permanent_crush(3.0e6)).epsilon(1e-3));
}

TEST_CASE("sweep: factors on entries of one list, a plan's set of the list and a scaled entry give each run its row's values", "[sweep]") {
  Files files;
  // The values each run used, read back from its time series at t = 0.
  const std::string responses = "responses: [car.vx@0, car.vy@0]\n";
  SECTION("two entries of one list") {
    files.write_plan("sweep: 1\ndesign: full_factorial\nset: [simulation.t_end=0.01]\nfactors:\n"
                     "  - {key: 'bodies.car.velocity[0]', levels: [-2.5, -1.5]}\n"
                     "  - {key: 'bodies.car.velocity[1]', levels: [0.25, 0.5]}\n" + responses);
    run_sweep(files.model, load_sweep_plan(files.plan, files.model), files.dir + "/out", SweepOptions{});
    const auto rows = csv_rows(files.dir + "/out/runs.csv");
    REQUIRE(rows.size() == 4);
    for (const auto& row : rows) {
      CHECK(number_in(row, "car.vx@0") == number_in(row, "bodies.car.velocity[0]"));
      CHECK(number_in(row, "car.vy@0") == number_in(row, "bodies.car.velocity[1]"));
    }
  }
  SECTION("the plan's set of the whole list, then an entry set and an entry scaled") {
    files.write_plan("sweep: 1\ndesign: one_at_a_time\nset: [simulation.t_end=0.01, 'bodies.car.velocity=[-3, 0.25]']\nfactors:\n"
                     "  - {key: 'bodies.car.velocity[0]', levels: [-2.5]}\n"
                     "  - {key: 'bodies.car.velocity[1]', scale: true, levels: [2]}\n" + responses);
    run_sweep(files.model, load_sweep_plan(files.plan, files.model), files.dir + "/out", SweepOptions{});
    const auto rows = csv_rows(files.dir + "/out/runs.csv");
    REQUIRE(rows.size() == 3);
    const double vx[] = {-3.0, -2.5, -3.0}, vy[] = {0.25, 0.25, 0.5};
    for (std::size_t k = 0; k < rows.size(); ++k) {
      INFO("run " << k);
      CHECK(number_in(rows[k], "car.vx@0") == vx[k]);
      CHECK(number_in(rows[k], "car.vy@0") == vy[k]);
    }
  }
  SECTION("a scaled factor on an entry that is 0 is refused, as on a key that is 0") {
    const std::string message = files.error_of_plan("sweep: 1\ndesign: full_factorial\nfactors:\n"
                                                    "  - {key: 'bodies.car.velocity[1]', scale: true, levels: [0.5, 2]}\n" + responses);
    CHECK_THAT(message, Catch::StartsWith(files.plan + ":4: factor 'bodies.car.velocity[1]' at level '0.5': ") &&
                            Catch::Contains("is 0 in the model, so a factor changes nothing"));
  }
}

TEST_CASE("sweep: --resume reruns the rows of an edited base model and --keep-runs folders follow runs.csv", "[sweep]") {
  Files files;
  const std::string base = files.dir + "/base.yaml";
  std::ofstream(base) << testing::anticlimber_r1_model_text(0.15);
  std::ofstream(files.model) << "railcrash: 1\nvariant_of: base.yaml\nset:\n  name: r1 variant\n";
  const auto plan_with = [&](const std::string& levels) {
    files.write_plan("sweep: 1\ndesign: full_factorial\nfactors:\n"
                     "  - {key: elements.ac.horizontal_yield_deflection, scale: true, levels: " + levels + "}\nresponses: [R1]\n");
    return load_sweep_plan(files.plan, files.model);
  };
  const std::string out = files.dir + "/out";
  SweepOptions options;
  options.keep_runs = true;
  std::string notes;
  options.note = [&](const std::string& text) { notes += text; };
  const SweepPlan first_plan = plan_with("[0.8, 1.2]");
  run_sweep(files.model, first_plan, out, options);
  REQUIRE(csv_rows(out + "/runs.csv").size() == 2);
  CHECK(notes.empty());

  SECTION("an edited base model: every row runs again") {
    // The base's anticlimber 10 % stiffer: other crushes (R1 = crush / 0.02 m).
    std::string text = testing::anticlimber_r1_model_text(0.15);
    text.replace(text.find("horizontal_elastic_stiffness: 1.0e7"), 35, "horizontal_elastic_stiffness: 1.1e7");
    std::ofstream(base) << text;
    options.resume = true;
    const SweepResult resumed = run_sweep(files.model, first_plan, out, options);
    CHECK(resumed.resumed == 0);
    CHECK(resumed.stale_rows == 2);
    CHECK_THAT(notes, Catch::StartsWith("2 rows of " + out + "/runs.csv ran with other inputs"));
    const auto rows = csv_rows(out + "/runs.csv");
    REQUIRE(rows.size() == 2);
    // The 0.8 run against the closed form with k = 1.1e7 N/m: k d_y^2 / 2 + F_y u + k_p u^2 / 2 = 2000 J.
    const double k = 1.1e7, kp = 1e5, dy = 0.008, f = k * dy, rest = 2000.0 - 0.5 * k * dy * dy;
    CHECK(number_in(rows[0], "R1") == Approx((dy + (-f + std::sqrt(f * f + 2.0 * kp * rest)) / kp) / 0.02).epsilon(1e-5));
  }
  SECTION("an edited plan: the kept rows' folders follow them, the others are removed") {
    options.resume = true;
    const SweepResult resumed = run_sweep(files.model, plan_with("[1.2, 1.0]"), out, options);
    CHECK(resumed.resumed == 1);     // 1.2, run 1 before, run 0 now
    CHECK(resumed.stale_rows == 1);  // 0.8
    CHECK(resumed.stale_folders == 1);
    CHECK_THAT(notes, Catch::Contains("1 row of " + out + "/runs.csv ran with other inputs") &&
                          Catch::Contains("1 folder of " + out + "/runs/ belonged to no row of runs.csv"));
    const auto rows = csv_rows(out + "/runs.csv");
    REQUIRE(rows.size() == 2);
    std::size_t folders = 0;
    for (const auto& entry : std::filesystem::directory_iterator(out + "/runs")) folders += entry.is_directory() ? 1 : 0;
    CHECK(folders == 2);
    for (std::size_t k = 0; k < rows.size(); ++k) {
      INFO("run " << k);
      char folder[32];
      std::snprintf(folder, sizeof folder, "/runs/%04zu", k);
      const std::string summary = read(out + folder + "/summary.json");
      const std::size_t at = summary.find("\"R1\": ");
      REQUIRE(at != std::string::npos);
      CHECK(std::stod(summary.substr(at + 6)) == Approx(number_in(rows[k], "R1")).epsilon(1e-6));
    }
    CHECK(number_in(rows[0], "R1") == Approx(crush_for(0.012) / 0.02).epsilon(1e-5));
    CHECK(number_in(rows[1], "R1") == Approx(crush_for(0.010) / 0.02).epsilon(1e-5));
  }
}

TEST_CASE("sweep: runs.csv says which method each run used, and an older runs.csv without the columns resumes", "[sweep][auto]") {
  Files files;
  // A 1 kg ball dropped 5 cm onto a floor (contact 1e5 N/m): ten bounces in 2 s, a lift-off and a
  // touch-down each. With Euler's step 1 ms, integrator auto hands the run to Euler after the
  // fifth mode change (IDA's mean step about 2 ms, each restart dearer than Euler's steps), and
  // takes it back when Euler's drift passes 0.5 % of the energy turned over (at 0.35 s: Euler
  // alone creates 55.6 %); with 1e-5 s Euler's steps cost far more and IDA keeps the run.
  const std::string ball = files.dir + "/ball.yaml";
  std::ofstream(ball) << "railcrash: 1\nname: ball\nunits: SI\ngravity: [0, -9.81]\nbodies:\n"
                         "  - {name: ball, mass: 1.0, inertia: 0.01, position: [0, 0.05]}\nelements:\n"
                         "  - {name: floor, type: contact, stiffness: 1.0e5, damping: 20, friction: 0, line_point: [0, 0], "
                         "line_normal: [0, 1], points: [{body: ball, at: [0, 0]}]}\n"
                         "simulation: {t_end: 2.0, output_interval: 0.01, dt: 1.0e-3}\n";
  files.write_plan("sweep: 1\ndesign: runs\nfactors:\n  - key: simulation.integrator\n  - key: simulation.dt\nruns:\n"
                   "  - {simulation.integrator: ida}\n  - {simulation.integrator: euler}\n  - {simulation.integrator: auto}\n"
                   "  - {simulation.integrator: auto, simulation.dt: 1.0e-5}\nresponses: [t_reached]\n");
  const SweepPlan plan = load_sweep_plan(files.plan, ball);
  SweepOptions options;
  const SweepResult result = run_sweep(ball, plan, files.dir + "/methods", options);
  REQUIRE(result.done() == 4);
  // The hand-over time from the same run made outside the sweep (summary.json's integrator_used).
  const LoadedModel auto_ball = load_model(ball, {"simulation.integrator=auto"});
  const RunReport auto_run = run_model(auto_ball.model, auto_ball.run_spec, "");
  REQUIRE(auto_run.outcome.stats.handed_over_at > 0.0);
  const auto rows = csv_rows(files.dir + "/methods/runs.csv");
  REQUIRE(rows.size() == 4);
  CHECK(rows[0].at("integrator_used") == "ida");
  CHECK(rows[0].at("euler_from_t").empty());
  CHECK(rows[1].at("integrator_used") == "euler");
  CHECK(rows[1].at("euler_from_t").empty());
  CHECK(rows[2].at("integrator_used") == "ida+euler+ida");
  CHECK(std::stod(rows[2].at("euler_from_t")) == auto_run.outcome.stats.handed_over_at);
  CHECK(std::stod(rows[2].at("euler_from_t")) > 0.05);  // after the first bounces (the fall alone takes 0.1 s)
  CHECK(rows[3].at("integrator_used") == "ida");
  CHECK(rows[3].at("euler_from_t").empty());

  // runs.csv as railcrash wrote it before the two columns: its rows are kept, the columns empty.
  const std::string header = sweep_csv_header(plan);
  const std::string old_header = header.substr(0, header.size() - std::string(",integrator_used,euler_from_t").size());
  std::istringstream written(read(files.dir + "/methods/runs.csv"));
  std::string line, old_text = old_header + "\n";
  std::getline(written, line);
  for (int k = 0; k < 2 && std::getline(written, line); ++k) old_text += line.substr(0, line.rfind(',', line.rfind(',') - 1)) + "\n";
  std::filesystem::create_directories(files.dir + "/old");
  std::ofstream(files.dir + "/old/runs.csv") << old_text;
  options.resume = true;
  const SweepResult resumed = run_sweep(ball, plan, files.dir + "/old", options);
  CHECK(resumed.resumed == 2);
  CHECK(resumed.done() == 4);
  const auto resumed_rows = csv_rows(files.dir + "/old/runs.csv");
  REQUIRE(resumed_rows.size() == 4);
  CHECK(resumed_rows[0].at("integrator_used").empty());  // resumed: not recorded then
  CHECK(resumed_rows[1].at("integrator_used").empty());
  CHECK(resumed_rows[2].at("integrator_used") == "ida+euler+ida");
  CHECK(resumed_rows[0].at("t_reached") == rows[0].at("t_reached"));
}

TEST_CASE("sweep: a run its run time limit stops says so in the words of every study", "[sweep]") {
  // A 1 kg mass ringing on a 1e8 N/m spring (period 0.63 ms) for 99 s at rtol 1e-9: some
  // 160,000 periods, far beyond a 0.2 s limit. The message is the one converge and sensitivity
  // give (run_limit_message; sweep said "stopped at the run time limit (t = ...)" without the limit).
  Files files;
  std::ofstream(files.model) << "railcrash: 1\nname: ringing bell\nunits: SI\ngravity: [0, 0]\n"
                                "bodies:\n  - {name: bell, mass: 1, inertia: 1, position: [0, 1.001]}\n"
                                "elements:\n  - {name: ringing, type: linear_spring, stiffness: 1.0e8, free_length: 0.998, "
                                "points: [{body: ground, at: [0, 2]}, {body: bell, at: [0, 0]}]}\n"
                                "simulation: {t_end: 99.0, integrator: ida, rtol: 1.0e-9, output_interval: 0.001}\n";
  files.write_plan("sweep: 1\ndesign: full_factorial\nfactors:\n  - {key: bodies.bell.mass, levels: [1.0]}\nresponses: [status]\n");
  SweepOptions options;
  options.run_time_limit = 0.2;
  const SweepResult result = run_sweep(files.model, load_sweep_plan(files.plan, files.model), files.dir + "/out", options);
  REQUIRE(result.done() == 1);
  const std::string& line = result.lines.begin()->second;
  CHECK_THAT(line, Catch::Contains("stopped at the run time limit of 0.2 s (--run-limit), at t = "));
  CHECK(run_limit_message(0.25, 0.0123456789) == "stopped at the run time limit of 0.25 s (--run-limit), at t = 0.0123457");
}

TEST_CASE("sweep: a response reads summary.json's true as 1, false as 0, and a null, a text or a missing key as no value", "[sweep]") {
  // The R1 model's car is stopped by the anticlimber without override (responses.override:
  // false, its time null); its CFC 60 filter is adequately sampled (true); units.system is "SI".
  Files files;
  files.write_plan("sweep: 1\ndesign: full_factorial\nfactors:\n  - {key: elements.ac.horizontal_yield_deflection, scale: true, levels: [1.0]}\n"
                   "responses: [responses.override, peak_accelerations.filter.adequately_sampled, responses.override_time, units.system, "
                   "responses.no_such_key, R1]\n");
  run_sweep(files.model, load_sweep_plan(files.plan, files.model), files.dir + "/out", SweepOptions{});
  const std::vector<std::map<std::string, std::string>> rows = csv_rows(files.dir + "/out/runs.csv");
  REQUIRE(rows.size() == 1);
  CHECK(rows[0].at("status") == "ok");
  CHECK(rows[0].at("responses.override") == "0");
  CHECK(rows[0].at("peak_accelerations.filter.adequately_sampled") == "1");
  CHECK(rows[0].at("responses.override_time").empty());
  CHECK(rows[0].at("units.system").empty());
  CHECK(rows[0].at("responses.no_such_key").empty());
  CHECK(number_in(rows[0], "R1") == Approx(crush_for(0.01) / 0.02).epsilon(1e-5));  // (2 m/s, the model's d_y)
}
