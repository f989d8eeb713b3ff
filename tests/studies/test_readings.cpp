#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include "railcrash/core/error.hpp"
#include "railcrash/studies/readings.hpp"
#include "support.hpp"

using namespace railcrash;
using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

namespace {

std::string temporary_file(const std::string& name, const std::string& text) {
  const auto path = testing::temp_path("railcrash_test_readings_" + name);
  std::ofstream(path) << text;
  return path.string();
}

std::string error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

}  // namespace

TEST_CASE("Spearman's rank correlation with average ranks for ties, by hand", "[readings]") {
  // b's ranks with the tie of the two 7s: 1, 2, 3.5, 5, 3.5; a's 1..5. Deviations from the mean
  // rank 3: (-2 -1 0 1 2) and (-2 -1 0.5 2 0.5): rho = 8 / sqrt(10 x 9.5).
  CHECK(spearman_correlation({1, 2, 3, 4, 5}, {5, 6, 7, 8, 7}) == Approx(8.0 / std::sqrt(95.0)));
  CHECK(spearman_correlation({1, 2, 3}, {30, 20, 10}) == Approx(-1.0));
  CHECK(spearman_correlation({0.1, 0.5, 0.2, 0.9}, {1, 3, 2, 4}) == Approx(1.0));  // ranks only
  CHECK(std::isnan(spearman_correlation({1, 1, 1}, {1, 2, 3})));                    // constant side
  CHECK(std::isnan(spearman_correlation({1, 2}, {1, 2})));                          // too few pairs
}

TEST_CASE("combinations: factorial odometer and one at a time", "[readings]") {
  ReadingsPlan plan;
  plan.readings.resize(3);
  for (std::size_t r = 0; r < 3; ++r) plan.readings[r].name = "r" + std::to_string(r);
  plan.readings[0].levels.resize(2);
  plan.readings[1].levels.resize(3);
  plan.readings[2].levels.resize(1);
  const auto factorial = plan.combinations();
  REQUIRE(factorial.size() == 6);
  CHECK(factorial.front() == std::vector<int>{0, 0, 0});
  CHECK(factorial[1] == std::vector<int>{0, 1, 0});
  CHECK(factorial.back() == std::vector<int>{1, 2, 0});
  plan.one_at_a_time = true;
  const auto single = plan.combinations();
  REQUIRE(single.size() == 4);  // the first levels, then 1 + 2 other levels alone
  CHECK(single[1] == std::vector<int>{1, 0, 0});
  CHECK(single[3] == std::vector<int>{0, 2, 0});
}

TEST_CASE("combinations are counted without overflow and generated one at a time in the listed order", "[readings]") {
  ReadingsPlan plan;
  plan.readings.resize(3);
  plan.readings[0].levels.resize(2);
  plan.readings[1].levels.resize(3);
  plan.readings[2].levels.resize(4);
  REQUIRE(plan.combination_count() == std::optional<std::size_t>(24));  // 2 x 3 x 4
  const auto listed = plan.combinations();
  for (std::size_t k = 0; k < listed.size(); ++k) CHECK(plan.combination(k) == listed[k]);
  CHECK(plan.combination(23) == std::vector<int>{1, 2, 3});
  CHECK(plan.combination(5) == std::vector<int>{0, 1, 1});  // 5 = (0 x 3 + 1) x 4 + 1
  plan.one_at_a_time = true;
  REQUIRE(plan.combination_count() == std::optional<std::size_t>(7));  // 1 + 1 + 2 + 3
  const auto single = plan.combinations();
  for (std::size_t k = 0; k < single.size(); ++k) CHECK(plan.combination(k) == single[k]);
  CHECK(plan.combination(6) == std::vector<int>{0, 0, 3});
  // 64 readings of two levels: 2^64 combinations, one more than std::size_t holds.
  plan.one_at_a_time = false;
  plan.readings.assign(64, Reading{});
  for (Reading& r : plan.readings) r.levels.resize(2);
  CHECK_FALSE(plan.combination_count().has_value());
  plan.readings.pop_back();  // 2^63 fits
  CHECK(plan.combination_count() == std::optional<std::size_t>(std::size_t{1} << 63));
}

TEST_CASE("a study is scored against published results: errors, signs, rank correlation, top five", "[readings]") {
  SensitivityDesign design;
  for (int i = 1; i <= 6; ++i) design.parameters.push_back({"P" + std::to_string(i), "", {}, {}});
  PublishedResults published;
  published.base = {1.0, 0.5, 1.5};
  // Published R1 changes: -0.1, -0.05, 0, +0.01, +0.002, -0.02 (P5's is below 0.005: no sign).
  const double r1_changes[6] = {-0.1, -0.05, 0.0, 0.01, 0.002, -0.02};
  for (int i = 0; i < 6; ++i)
    published.first_order.push_back({"P" + std::to_string(i + 1), {1.0 + r1_changes[i], 0.5, 1.5 + r1_changes[i]}});
  published.ranking[0] = {"P1", "P2", "P6", "P4", "P5"};
  design.reference = published;

  SensitivityResult result;
  result.base.ok = true;
  result.base.responses.r1 = 1.1;  // +10 % against the published 1.0
  result.base.responses.r2 = 0.46;
  result.base.responses.r3 = 1.55;
  // Ours: -0.2, -0.01, +0.001, -0.01 (wrong sign), 0, -0.03.
  const double ours[6] = {-0.2, -0.01, 0.001, -0.01, 0.0, -0.03};
  for (int i = 0; i < 6; ++i) {
    SensitivityRun run;
    run.ok = true;
    run.parameter = "P" + std::to_string(i + 1);
    run.responses.r1 = 1.1 + ours[i];
    run.responses.r2 = 0.46;
    run.responses.r3 = 1.55 + ours[i];
    result.runs.push_back(run);
    result.derivatives.push_back({ours[i] / 0.2, 0.0, ours[i] / 0.2});
  }
  const Agreement a = score_agreement(result, design);
  const ResponseAgreement& r1 = a.responses[0];
  CHECK(r1.value == Approx(1.1));
  CHECK(r1.relative_error == Approx(0.1));
  CHECK(a.responses[1].relative_error == Approx(-0.08));
  CHECK(r1.significant_runs == 4);  // P1, P2, P4, P6
  CHECK(r1.sign_agreements == 3);   // P4 disagrees
  // Ranks of ours (-0.2 -0.01 0.001 -0.01 0 -0.03): 1, 3.5, 6, 3.5, 5, 2; published
  // (-0.1 -0.05 0 0.01 0.002 -0.02): 1, 2, 4, 6, 5, 3.
  CHECK(r1.spearman == Approx(spearman_correlation({1, 3.5, 6, 3.5, 5, 2}, {1, 2, 4, 6, 5, 3})));
  double sum = 0.0;
  for (int i = 0; i < 6; ++i) sum += (ours[i] - r1_changes[i]) * (ours[i] - r1_changes[i]);
  CHECK(r1.rms == Approx(std::sqrt(sum / 6.0)));
  // Our top five by |A|: P1 (1.0), P6 (0.15), P2 and P4 (0.05, design order), P3 (0.005).
  CHECK(r1.top_five == std::vector<std::string>{"P1", "P6", "P2", "P4", "P3"});
  CHECK(r1.top_five_shared == 4);  // P5 is the published one we miss
  CHECK(a.responses[1].significant_runs == 0);  // no published R2 change
  CHECK(a.responses[1].top_five_shared == -1);  // no published R2 ranking
  // Goals: R2 within 10 % yes (8 %), R3 within 5 % yes (3.3 %), R1 signs 75 % no,
  // R1 rho (0.60) no, R1 top five 4 yes, R2 signs no (none), R2 rho no (NaN), R2 top five no.
  CHECK(r1.spearman == Approx(0.6).margin(0.05));
  CHECK(a.goals_met == 3);
}

TEST_CASE("readings files: errors name the file and line before any run", "[readings]") {
  const std::string model = temporary_file("model.yaml", testing::anticlimber_r1_model_text(0.05));
  const auto plan_error = [&](const std::string& text) {
    const std::string path = temporary_file("plan.yaml", text);
    return error_of([&] { check_readings(load_readings(path), model); });
  };
  CHECK_THAT(plan_error("readings: []\n"), Contains("reading_study: 1"));
  CHECK_THAT(plan_error("reading_study: 1\nreadings: []\n"), Contains("at least one reading"));
  CHECK_THAT(plan_error("reading_study: 1\nreadingz: []\n"), Contains(":2: ") && Contains("unknown key 'readingz'"));
  CHECK_THAT(plan_error("reading_study: 1\nreadings:\n  - {name: a, levels: []}\n"), Contains(":3: ") && Contains("at least one level"));
  CHECK_THAT(plan_error("reading_study: 1\nreadings:\n  - {name: a, levels: [{name: x}, {name: x}]}\n"),
             Contains("level 'x' is listed twice"));
  CHECK_THAT(plan_error("reading_study: 1\nreadings:\n  - {name: a, levels: [{name: x, colour: red}]}\n"),
             Contains("unknown key 'colour'"));
  CHECK_THAT(plan_error("reading_study: 1\ncombinations: some\nreadings:\n  - {name: a, levels: [{name: x}]}\n"),
             Contains(":2: ") && Contains("factorial or one_at_a_time"));
  // A level that names a key the model does not have: the readings file's line, then why.
  const std::string missing = plan_error(
      "reading_study: 1\nreadings:\n  - name: a\n    levels:\n      - {name: x}\n"
      "      - {name: y, set: {elements.nothing.stiffness: 2}}\n");
  CHECK_THAT(missing, StartsWith(std::filesystem::temp_directory_path().string()) && Contains("plan.yaml:6: ") &&
                          Contains("level 'y'") && Contains("no element named 'nothing'"));
  const std::string not_a_number =
      plan_error("reading_study: 1\nreadings:\n  - name: a\n    levels:\n      - {name: y, set: {elements.ac.face_height*: x}}\n");
  CHECK_THAT(not_a_number, Contains("plan.yaml:5: ") && Contains("KEY*=FACTOR"));
}

TEST_CASE("a reading study ranks first the reading that reproduces the published study", "[readings]") {
  // The published results are this very model's responses with the anticlimber's plastic
  // slope at 1e5 N/m: the level 'printed' reproduces them (errors 0, every sign, rho 1), the
  // level 'stronger' (yield at 0.025 m: the 2000 J are taken elastically, crush 0.02 m against
  // 0.0249 m) does not.
  const std::string model = temporary_file("model2.yaml", testing::anticlimber_r1_model_text(0.2));
  const std::string design_text =
      "sensitivity: 1\nfactor: 1.2\nparameters:\n"
      "  - {name: P1, scale: [{key: elements.ac.horizontal_plastic_stiffness}]}\n"
      "  - {name: P2, scale: [{key: elements.ac.horizontal_yield_deflection}]}\n"
      "  - {name: P3, scale: [{key: elements.ac.face_height}]}\n";
  SensitivityDesign design = load_design(temporary_file("design.yaml", design_text));
  SensitivityOptions options;
  options.jobs = 2;
  const SensitivityResult truth = run_sensitivity(model, design, options);
  REQUIRE(truth.base.ok);
  PublishedResults published;
  published.base = {truth.base.responses.r1, truth.base.responses.r2, truth.base.responses.r3};
  for (const SensitivityRun& run : truth.runs)
    published.first_order.push_back({run.parameter, {run.responses.r1, run.responses.r2, run.responses.r3}});
  design.reference = published;

  const ReadingsPlan plan = load_readings(temporary_file(
      "plan2.yaml", "reading_study: 1\nreadings:\n  - name: plastic_slope\n    levels:\n"
                    "      - {name: stronger, set: {elements.ac.horizontal_yield_deflection*: 2.5}}\n"
                    "      - {name: printed}\n"));
  ReadingsOptions readings_options;
  readings_options.study.jobs = 2;
  const auto results = run_readings(model, design, plan, readings_options);
  REQUIRE(results.size() == 2);
  const Agreement& printed = results[1].agreement;
  CHECK(printed.responses[0].relative_error == Approx(0.0).margin(1e-12));
  CHECK(printed.responses[0].spearman == Approx(1.0));  // P1 and P2 lower the crush, P3 changes nothing
  CHECK(printed.responses[0].sign_agreements == printed.responses[0].significant_runs);
  CHECK(results[0].agreement.responses[0].value == Approx(0.02 / 0.02).epsilon(1e-4));  // crush 0.02 m / reference 0.02 m
  const std::string out = (testing::temp_path("railcrash_test_readings_out")).string();
  std::filesystem::remove_all(out);
  const std::string md = write_readings(results, plan, design, out);
  CHECK_THAT(md, Contains("| 1 | 1 | printed |"));  // ranked first: combination 1
  CHECK(std::filesystem::exists(out + "/readings.csv"));
  {
    // The methods of each combination's runs: the model names none (auto), and IDA keeps these
    // one-impact runs: "ida", no hand-over, none of the runs handed over.
    std::ifstream csv(out + "/readings.csv");
    std::string header, line;
    std::getline(csv, header);
    CHECK_THAT(header, Catch::EndsWith(",failed_runs,wall_seconds,integrator_used,euler_from_t,handed_over_runs"));
    int rows = 0;
    while (std::getline(csv, line)) {
      ++rows;
      CHECK_THAT(line, Catch::EndsWith(",ida,,0"));
    }
    CHECK(rows == 2);
  }
  CHECK(std::filesystem::exists(out + "/combination_001/sensitivity.csv"));
  CHECK(std::filesystem::exists(out + "/combination_001/comparison.md"));
  // The side by side of the matching combination: no error, every sign kept, ours = published.
  const std::string comparison = comparison_markdown(results[1].study, design);
  CHECK_THAT(comparison, Contains("| run 0, relative error | +0.0 % |"));
  CHECK_THAT(comparison, Contains("(sign kept)") && !Contains("sign differs"));
  char r1[16];
  std::snprintf(r1, sizeof r1, "%.3f", truth.base.responses.r1);
  CHECK_THAT(comparison, Contains("| run 0, ours | " + std::string(r1)) && Contains("| run 0, published | " + std::string(r1)));

  // Interrupted (SIGINT/SIGTERM in the command line) as the first run of combination 0
  // finishes: that combination is kept, partial, with its finished run; no other starts.
  std::atomic<bool> stop{false};
  ReadingsOptions interrupted_options;
  interrupted_options.study.jobs = 1;
  interrupted_options.study.stop = &stop;
  interrupted_options.study.progress = [&](const SensitivityRun&, std::size_t, std::size_t, std::size_t) { stop = true; };
  const auto partial = run_readings(model, design, plan, interrupted_options);
  REQUIRE(partial.size() == 1);
  CHECK(partial[0].study.interrupted);
  CHECK(partial[0].study.runs_finished == 1);
  CHECK(partial[0].study.runs_total == 4);
  REQUIRE(partial[0].study.base.ok);
  CHECK(partial[0].study.base.responses.r1 == Approx(results[0].study.base.responses.r1).epsilon(1e-12));
  CHECK(partial[0].failed_runs == 0);  // the runs not run are not failures
  const std::string partial_md = write_readings(partial, plan, design, out + "_partial");
  CHECK_THAT(partial_md, StartsWith("# Reading study\n\n**Interrupted after 0 of 2 combinations** (SIGINT/SIGTERM); the last "
                                    "one listed is partial"));
  CHECK(std::filesystem::exists(out + "_partial/combination_000/sensitivity.csv"));
  CHECK_FALSE(std::filesystem::exists(out + "_partial/combination_001"));
  std::filesystem::remove_all(out + "_partial");
}

TEST_CASE("a reading level may change what a design parameter scales", "[readings]") {
  SensitivityDesign design;
  design.parameters.push_back({"P5", "elastic slope", {{"elements.a.k", 1.0}}, {}});
  design.parameters.push_back({"P7", "yield force", {{"elements.a.d", 1.0}}, {}});
  const ReadingsPlan plan = load_readings(temporary_file(
      "plan3.yaml", "reading_study: 1\nreadings:\n  - name: slope_holds\n    levels:\n      - {name: deflection}\n"
                    "      - name: force\n        scale: {P5: [{key: elements.a.k}, {key: elements.a.d, power: -1}]}\n"
                    "      - name: typo\n        scale: {P55: [{key: elements.a.k}]}\n"));
  const SensitivityDesign same = plan.design_for({0}, design);
  CHECK(same.parameters[0].scales == design.parameters[0].scales);
  const SensitivityDesign force = plan.design_for({1}, design);
  REQUIRE(force.parameters[0].scales.size() == 2);
  CHECK(force.parameters[0].scales[1] == std::pair<std::string, double>{"elements.a.d", -1.0});
  CHECK(force.parameters[1].scales == design.parameters[1].scales);  // P7 untouched
  CHECK_THAT(error_of([&] { (void)plan.design_for({2}, design); }), Contains("plan3.yaml:8: ") && Contains("no parameter 'P55'"));
}
