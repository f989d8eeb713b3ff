#include <catch2/catch.hpp>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "railcrash/model/model_io.hpp"
#include "railcrash/studies/sensitivity.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

// A 1000 kg car end at 2 m/s into a fixed anticlimber: elastic slope k = 1e7 N/m to the
// yield deflection d_y, then 1e5 N/m. Largest crush from energy (2000 J):
//   k d_y^2 / 2 + F_y u + 1e5 u^2 / 2 = 2000,  F_y = k d_y,  crush = d_y + u.
double crush_for(double yield_deflection) {
  const double k = 1e7, kp = 1e5, f = k * yield_deflection;
  const double rest = 2000.0 - 0.5 * k * yield_deflection * yield_deflection;
  const double u = (-f + std::sqrt(f * f + 2.0 * kp * rest)) / kp;
  return yield_deflection + u;
}

struct Files {
  // One folder per process: CTest runs test cases in parallel, and other checkouts on the machine too.
  std::string dir =
      (std::filesystem::temp_directory_path() / ("railcrash_sensitivity_test_" + std::to_string(::getpid()))).string();
  std::string model = dir + "/model.yaml", design = dir + "/design.yaml";
  Files() {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(model) << testing::anticlimber_r1_model_text(0.15);
    std::ofstream(design) << "sensitivity: 1\nfactor: 1.2\nparameters:\n"
                             "  - name: P7\n    description: horizontal yield force (slope held)\n"
                             "    scale: [{key: elements.ac.horizontal_yield_deflection, power: 1}]\n"
                             "  - name: P5\n    description: horizontal elastic slope (yield force held)\n"
                             "    scale: [{key: elements.ac.horizontal_elastic_stiffness, power: 1},\n"
                             "            {key: elements.ac.horizontal_yield_deflection, power: -1}]\n"
                             "  - name: P9\n    description: a parameter whose key does not exist\n"
                             "    scale: [{key: elements.ac.no_such_key, power: 1}]\n";
  }
  ~Files() { std::filesystem::remove_all(dir); }
};

}  // namespace

TEST_CASE("first-order study: each run against the closed-form crush, derivatives and ranking", "[sensitivity]") {
  Files files;
  const SensitivityDesign design = load_design(files.design);
  REQUIRE(design.parameters.size() == 3);
  SensitivityOptions options;
  options.jobs = 2;
  // P9's key does not exist: the study stops before its first run, naming the design's line.
  CHECK_THROWS_WITH(run_sensitivity(files.model, design, options),
                    Catch::StartsWith(files.design + ":13: design parameter 'P9', scale key 'elements.ac.no_such_key'") &&
                        Catch::Contains("no number at 'elements.ac.no_such_key'"));
  options.only = {"P7", "P5"};
  const SensitivityResult result = run_sensitivity(files.model, design, options);
  REQUIRE(result.base.ok);
  CHECK(result.base.responses.r1 == Approx(crush_for(0.01) / 0.02).epsilon(1e-5));
  // P7: +20 % yield force through the yield deflection: less crush.
  REQUIRE(result.runs[0].ok);
  CHECK(result.runs[0].responses.r1 == Approx(crush_for(0.012) / 0.02).epsilon(1e-5));
  CHECK(result.derivatives[0][0] == Approx((crush_for(0.012) - crush_for(0.01)) / 0.02 / 0.2).epsilon(1e-3));
  CHECK(result.derivatives[0][0] < 0.0);
  // P5: stiffer at the same yield force: the elastic part absorbs less, crush changes a little.
  REQUIRE(result.runs[1].ok);
  const double k = 1.2e7, dy = 0.01 / 1.2;
  const double rest = 2000.0 - 0.5 * k * dy * dy, u = (-1e5 + std::sqrt(1e10 + 2.0 * 1e5 * rest)) / 1e5;
  CHECK(result.runs[1].responses.r1 == Approx((dy + u) / 0.02).epsilon(1e-5));
  REQUIRE(result.runs.size() == 2);
  const std::string md = write_sensitivity(result, design, files.dir + "/out");
  CHECK_THAT(md, Catch::Contains("| 1 | P7 | 1.2 |"));
  // Ranked: P7 moves R1 the most.
  const auto p7_row = md.find("| P7 | horizontal yield force"), p5_row = md.find("| P5 | horizontal elastic slope");
  REQUIRE(p5_row != std::string::npos);
  CHECK(p7_row < p5_row);
  std::ifstream csv(files.dir + "/out/sensitivity.csv");
  std::string header;
  std::getline(csv, header);
  CHECK(header == "run,order,parameters,values,status,R1,R2,R3,override,wall_seconds,message,branch,outcomes,integrator_used,euler_from_t");
  // A0 of the first-order form: the base response less the sum of the coefficients (report eq. 1-3).
  CHECK(result.constant[0] ==
        Approx(result.base.responses.r1 - result.derivatives[0][0] - result.derivatives[1][0]).epsilon(1e-12));
}

TEST_CASE("sensitivity.csv and the runs say which method each run used", "[sensitivity][auto]") {
  Files files;
  const SensitivityDesign design = load_design(files.design);
  SensitivityOptions options;
  options.jobs = 2;
  options.only = {"P7"};
  // The R1 model names no integrator: auto, whose IDA keeps this one-impact run (a hand-over
  // needs 5 mode changes). A model that names ida or euler runs with it.
  for (const std::string integrator : {"", "ida", "euler"}) {
    INFO("integrator " << (integrator.empty() ? "auto" : integrator));
    options.settings.clear();
    if (!integrator.empty()) options.settings = {"simulation.integrator=" + integrator, "simulation.dt=1e-5"};
    const SensitivityResult result = run_sensitivity(files.model, design, options);
    REQUIRE(result.base.ok);
    REQUIRE(result.runs.size() == 1);
    const std::string expected = integrator == "euler" ? "euler" : "ida";
    CHECK(result.base.integrator.method == expected);
    CHECK(result.runs[0].integrator.method == expected);
    CHECK(std::isnan(result.runs[0].integrator.euler_from_t));
    const std::string folder = files.dir + "/methods_" + expected + integrator;
    write_sensitivity(result, design, folder);
    std::ifstream csv(folder + "/sensitivity.csv");
    std::string line;
    std::getline(csv, line);
    int rows = 0;
    while (std::getline(csv, line)) {
      ++rows;
      CHECK_THAT(line, Catch::EndsWith("," + expected + ","));  // integrator_used, then euler_from_t empty
    }
    CHECK(rows == 2);
  }
}

TEST_CASE("central differences and a subset of parameters", "[sensitivity]") {
  Files files;
  const SensitivityDesign design = load_design(files.design);
  SensitivityOptions options;
  options.central_step = 0.05;
  options.only = {"P7"};
  const SensitivityResult result = run_sensitivity(files.model, design, options);
  REQUIRE(result.runs.size() == 2);
  const double expected = (crush_for(0.0105) - crush_for(0.0095)) / 0.02 / 0.1;
  CHECK(result.derivatives[0][0] == Approx(expected).epsilon(1e-3));
  options.only = {"P99"};
  CHECK_THROWS_WITH(run_sensitivity(files.model, design, options), Catch::Contains("no parameter 'P99'"));
}

TEST_CASE("scaling overrides multiply a model number", "[sensitivity]") {
  Files files;
  const LoadedModel loaded = load_model(files.model, {"elements.ac.horizontal_yield_deflection*=1.5", "simulation.t_end*=2"});
  CHECK(loaded.run_spec.simulation.t_end == Approx(0.3));
  CHECK_THROWS_WITH(load_model(files.model, {"elements.ac.face_height*=x"}), Catch::Contains("KEY*=FACTOR"));
  CHECK_THROWS_AS(load_model(files.model, {"elements.ac.horizontal_yield_deflection=0", "elements.ac.horizontal_yield_deflection*=1.2"}),
                  ZeroScaledError);
}

TEST_CASE("a design parameter whose model value is 0 stops the study before any run", "[sensitivity]") {
  Files files;
  std::ofstream(files.design) << "sensitivity: 1\nfactor: 1.2\nparameters:\n"
                                 "  - name: P4\n    description: vertical plastic slope\n"
                                 "    scale: [{key: elements.ac.vertical_plastic_stiffness, power: 1}]\n";
  const SensitivityDesign design = load_design(files.design);
  SensitivityOptions options;
  options.settings = {"elements.ac.vertical_plastic_stiffness=0"};  // a valid model in which P4 is 0
  CHECK_NOTHROW(load_model(files.model, options.settings));
  CHECK_THROWS_WITH(run_sensitivity(files.model, design, options),
                    Catch::Contains("'elements.ac.vertical_plastic_stiffness' is 0 in the model, so a factor changes "
                                    "nothing") &&
                        Catch::Contains("design.yaml:6: design parameter 'P4', scale key 'elements.ac.vertical_plastic_stiffness'"));
}

TEST_CASE("a scale key the model does not have stops the study before any run, naming the design line", "[sensitivity]") {
  Files files;
  std::ofstream(files.design) << "sensitivity: 1\nfactor: 1.2\nparameters:\n"
                                 "  - name: P7\n    scale:\n"
                                 "      - {key: elements.ac.horizontal_yield_deflection}\n"
                                 "      - {key: elements.nothing.stiffness, power: 2}\n";
  const SensitivityDesign design = load_design(files.design);
  REQUIRE(design.parameters[0].scale_sources.size() == 2);
  CHECK(design.parameters[0].scale_sources[1].line == 7);
  SensitivityOptions options;
  options.progress = [](const SensitivityRun&, std::size_t, std::size_t, std::size_t) { FAIL("a run started"); };
  CHECK_THROWS_WITH(run_sensitivity(files.model, design, options),
                    Catch::StartsWith(files.design + ":7: design parameter 'P7', scale key 'elements.nothing.stiffness' does "
                                                     "not fit the model: ") &&
                        Catch::Contains("there is no number at 'elements.nothing.stiffness'"));
  // A bad --set of the study (a reading level's) names the base run.
  options.settings = {"elements.ac.no_such_key=1"};
  CHECK_THROWS_WITH(run_sensitivity(files.model, design, options), Catch::EndsWith("(the base run)"));
}

TEST_CASE("an interrupted study keeps its finished runs and marks the others", "[sensitivity]") {
  Files files;
  const SensitivityDesign design = load_design(files.design);
  SensitivityOptions options;
  options.only = {"P7", "P5"};  // P9's key does not exist
  std::atomic<bool> stop{false};
  options.stop = &stop;
  options.jobs = 1;
  // The stop flag rises as the base run finishes: runs already started finish or stop, none starts after it.
  options.progress = [&](const SensitivityRun&, std::size_t number, std::size_t, std::size_t) {
    if (number == 0) stop = true;
  };
  const SensitivityResult result = run_sensitivity(files.model, design, options);
  CHECK(result.interrupted);
  CHECK(result.runs_total == 3);
  CHECK(result.runs_finished == 1);
  CHECK(result.base.ok);
  CHECK(result.base.responses.r1 > 0.0);
  for (const SensitivityRun& run : result.runs) {
    CHECK_FALSE(run.ok);
    CHECK(run.interrupted);
    CHECK(run.message == "not run: the study was interrupted");
    CHECK(std::isnan(run.responses.r1));
  }
  const std::string folder = files.design + ".out";
  const std::string table = write_sensitivity(result, design, folder);
  CHECK(table.rfind("**Interrupted after 1 of 3 runs**", 0) == 0);
  std::ifstream csv(folder + "/sensitivity.csv");
  const std::string text((std::istreambuf_iterator<char>(csv)), std::istreambuf_iterator<char>());
  CHECK(text.find("\n0,0,,,ok,") != std::string::npos);
  CHECK(text.find("\n1,1,P") != std::string::npos);
  CHECK(text.find(",interrupted,,,,0,0.00,\"not run: the study was interrupted\"") != std::string::npos);
  std::filesystem::remove_all(folder);
}

namespace {

std::string report_design_path() { return std::string(RAILCRASH_SOURCE_DIR) + "/models/report/sensitivity_design.yaml"; }

// The runs the report's reduced second-order form is solved from: the base, the first-order run
// (at the design's factor) of every parameter of the form, and the design's second-order runs.
std::vector<SensitivityPoint> report_fit_points(const SensitivityDesign& design) {
  std::vector<SensitivityPoint> points{{}};
  for (const char* name : {"P6", "P7", "P16", "P17", "P20", "P21", "P24", "P25"}) points.push_back({{name, design.factor}});
  for (const SensitivityPoint& p : design.second_order.runs) points.push_back(p);
  return points;
}

double value_of(const SensitivityPoint& point, const std::string& name) {
  for (const auto& [n, v] : point)
    if (n == name) return v;
  return 1.0;
}

// A response that is exactly a polynomial of the reduced form, written out term by term
// (independently of SensitivityTerm::value).
struct KnownPolynomial {
  double a0 = 0.75;
  std::vector<std::pair<std::string, double>> linear{{"P6", -0.31}, {"P7", 0.47}, {"P16", 0.12}, {"P17", -0.93},
                                                     {"P20", 0.58}, {"P21", -0.21}, {"P24", 0.36}, {"P25", -0.66}};
  double b66 = 0.29, b67 = -0.41, b77 = 0.17, b1617 = 0.83, b2020 = -0.52, b2021 = 0.64, b2121 = 0.11, b2425 = -0.37;
  double operator()(const SensitivityPoint& p) const {
    double r = a0;
    for (const auto& [name, a] : linear) r += a * value_of(p, name);
    const auto v = [&](const char* name) { return value_of(p, name); };
    return r + b66 * v("P6") * v("P6") + b67 * v("P6") * v("P7") + b77 * v("P7") * v("P7") + b1617 * v("P16") * v("P17") +
           b2020 * v("P20") * v("P20") + b2021 * v("P20") * v("P21") + b2121 * v("P21") * v("P21") +
           b2425 * v("P24") * v("P25");
  }
  // In the design file's term order (P6 .. P25, P6^2, P6*P7, P7^2, P16*P17, P20^2, P20*P21, P21^2, P24*P25).
  std::vector<double> coefficients() const {
    std::vector<double> c;
    for (const auto& entry : linear) c.push_back(entry.second);
    for (double b : {b66, b67, b77, b1617, b2020, b2021, b2121, b2425}) c.push_back(b);
    return c;
  }
};

std::vector<SensitivitySample> samples_of(const std::vector<SensitivityPoint>& points, const KnownPolynomial& r1) {
  std::vector<SensitivitySample> samples;
  for (const SensitivityPoint& p : points) {
    const double value = r1(p);
    samples.push_back({"", p, {value, 2.0 * value, -value}});
  }
  return samples;
}

}  // namespace

TEST_CASE("second-order fit recovers a known polynomial from the report's design points", "[sensitivity]") {
  const SensitivityDesign design = load_design(report_design_path());
  REQUIRE(design.second_order.terms.size() == 16);
  REQUIRE(design.second_order.runs.size() == 8);
  const KnownPolynomial polynomial;
  const std::vector<double> expected = polynomial.coefficients();
  const QuadraticFit fit = fit_quadratic(design.second_order.terms, samples_of(report_fit_points(design), polynomial));
  REQUIRE(fit.determined());
  CHECK(fit.equations == 17);
  CHECK(fit.unknowns == 17);
  CHECK(fit.condition_number > 1.0);
  CHECK(fit.condition_number < 1e6);
  CHECK(fit.constant[0] == Approx(polynomial.a0).margin(1e-10));
  for (std::size_t k = 0; k < expected.size(); ++k) {
    INFO(fit.terms[k].label());
    CHECK(fit.coefficients[k][0] == Approx(expected[k]).margin(1e-10));
    CHECK(fit.coefficients[k][1] == Approx(2.0 * expected[k]).margin(1e-10));
    CHECK(fit.coefficients[k][2] == Approx(-expected[k]).margin(1e-10));
  }
  // First derivatives at P = 1 against a central difference of the polynomial (exact for a
  // quadratic up to round-off); second derivatives against the second difference.
  const double h = 1e-3;
  for (const SensitivityDerivative& d : fit.derivatives) {
    INFO(d.label());
    if (d.second.empty()) {
      const double slope = (polynomial({{d.first, 1.0 + h}}) - polynomial({{d.first, 1.0 - h}})) / (2.0 * h);
      CHECK(d.value[0] == Approx(slope).margin(1e-8));
    } else if (d.first == d.second) {
      const double curvature =
          (polynomial({{d.first, 1.0 + h}}) - 2.0 * polynomial({}) + polynomial({{d.first, 1.0 - h}})) / (h * h);
      CHECK(d.value[0] == Approx(curvature).margin(1e-5));
    } else {
      const double mixed = (polynomial({{d.first, 1.0 + h}, {d.second, 1.0 + h}}) - polynomial({{d.first, 1.0 + h}}) -
                            polynomial({{d.second, 1.0 + h}}) + polynomial({})) /
                           (h * h);
      CHECK(d.value[0] == Approx(mixed).margin(1e-5));
    }
  }
  CHECK(fit.derivatives.size() == 8 + 8);

  // More runs than constants (central runs added): least squares, still exact for an exact polynomial.
  std::vector<SensitivityPoint> more = report_fit_points(design);
  for (const char* name : {"P6", "P20", "P25"}) more.push_back({{name, 0.95}});
  const QuadraticFit least_squares = fit_quadratic(design.second_order.terms, samples_of(more, polynomial));
  REQUIRE(least_squares.determined());
  CHECK(least_squares.equations == 20);
  CHECK(least_squares.largest_residual < 1e-10);
  for (std::size_t k = 0; k < expected.size(); ++k) CHECK(least_squares.coefficients[k][0] == Approx(expected[k]).margin(1e-9));
}

TEST_CASE("second-order fit names the terms a missing run leaves undetermined", "[sensitivity]") {
  const SensitivityDesign design = load_design(report_design_path());
  const KnownPolynomial polynomial;
  std::vector<SensitivityPoint> points = report_fit_points(design);
  // Without run 32 (P6 = 0.8) P6 takes only the values 1.0 and 1.2, where (P6 - 1)(P6 - 1.2) =
  // P6^2 - 2.2 P6 + 1.2 vanishes: the constant, P6 and P6^2 cannot be separated; the others can.
  points.erase(std::find(points.begin(), points.end(), SensitivityPoint{{"P6", 0.8}}));
  const QuadraticFit fit = fit_quadratic(design.second_order.terms, samples_of(points, polynomial));
  CHECK_FALSE(fit.determined());
  CHECK(fit.rank == 16);
  CHECK(fit.undetermined == std::vector<std::string>{"1", "P6", "P6^2"});
  CHECK(std::isinf(fit.condition_number));
  CHECK(std::isnan(fit.constant[0]));
  const std::vector<double> expected = polynomial.coefficients();
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const std::string label = fit.terms[k].label();
    INFO(label);
    if (label == "P6" || label == "P6^2")
      CHECK(std::isnan(fit.coefficients[k][0]));
    else
      CHECK(fit.coefficients[k][0] == Approx(expected[k]).margin(1e-9));
  }
  CHECK(std::isnan(fit.derivatives[0].value[0]));       // d/dP6 needs A6 and B6,6
  CHECK(fit.derivatives[1].value[0] == Approx(0.47 + 2 * 0.17 - 0.41).margin(1e-9));  // d/dP7
}

TEST_CASE("second-order fit of the report's own Tables 11 and 13 gives its printed constants and Table 14", "[sensitivity]") {
  // Report Tables 11 and 13 (models/report/TRANSCRIPTION.md sections 12-13), runs in the order of
  // report_fit_points: 0, 6, 7, 16, 17, 20, 21, 24, 25, 32-39.
  const double table[17][3] = {{1.255, 0.610, 1.865}, {1.219, 0.654, 1.873}, {1.210, 0.652, 1.862}, {1.254, 0.628, 1.882},
                               {1.254, 0.570, 1.824}, {1.236, 0.645, 1.881}, {1.236, 0.626, 1.862}, {1.244, 0.617, 1.861},
                               {1.243, 0.561, 1.804}, {1.302, 0.547, 1.849}, {1.304, 0.553, 1.857}, {1.181, 0.642, 1.823},
                               {1.254, 0.609, 1.863}, {1.255, 0.623, 1.878}, {1.255, 0.623, 1.878}, {1.253, 0.601, 1.854},
                               {1.253, 0.600, 1.853}};
  const SensitivityDesign design = load_design(report_design_path());
  const std::vector<SensitivityPoint> points = report_fit_points(design);
  std::vector<SensitivitySample> samples;
  for (std::size_t i = 0; i < points.size(); ++i) samples.push_back({"", points[i], {table[i][0], table[i][1], table[i][2]}});
  const QuadraticFit fit = fit_quadratic(design.second_order.terms, samples);
  REQUIRE(fit.determined());
  // The exact solution (TRANSCRIPTION.md section 13; the report prints these rounded half away from zero).
  const double constant[3] = {3.2550, -0.6350, 2.6200};
  const double coefficients[16][3] = {
      {-0.6575, 2.0925, 1.4350}, {-0.5100, 1.9725, 1.4625}, {-0.030, -0.435, -0.465}, {-0.030, -0.725, -0.755},
      {-0.4725, 0.3550, -0.1175}, {-0.4725, 0.7825, 0.3100}, {-0.580, -0.765, -1.345}, {-0.585, -1.045, -1.630},
      {0.1375, -0.2375, -0.1000}, {0.175, -1.350, -1.175},   {0.0500, -0.1875, -0.1375}, {0.025, 0.525, 0.550},
      {-0.2375, 0.6000, 0.3625}, {0.900, -1.500, -0.600},    {-0.2375, 0.3625, 0.1250},  {0.525, 0.800, 1.325}};
  for (int r = 0; r < 3; ++r) {
    CHECK(fit.constant[r] == Approx(constant[r]).margin(1e-9));
    for (std::size_t k = 0; k < 16; ++k) {
      INFO("R" << r + 1 << " " << fit.terms[k].label());
      CHECK(fit.coefficients[k][r] == Approx(coefficients[k][r]).margin(1e-9));
    }
  }
  // Table 14 as printed (computed there from the rounded constants: compare at +-0.002, reading
  // T14-2; dR2/dP25 read -0.245, reading T14-3).
  const double table14[16][3] = {{-0.207, 0.267, 0.060},  {-0.235, 0.247, 0.012},  {-0.005, 0.090, 0.085},
                                 {-0.005, -0.200, -0.205}, {-0.049, 0.055, 0.008},  {-0.049, 0.009, -0.040},
                                 {-0.055, 0.035, -0.020},  {-0.060, -0.245, -0.305}, {0.276, -0.476, -0.200},
                                 {0.100, -0.376, -0.276},  {-0.476, 1.200, 0.726},  {-0.476, 0.726, 0.250},
                                 {0.175, -1.350, -1.175},  {0.025, 0.525, 0.550},   {0.900, -1.500, -0.600},
                                 {0.525, 0.800, 1.325}};
  const char* const labels[16] = {"d/dP6",      "d/dP7",      "d/dP16",       "d/dP17",        "d/dP20",        "d/dP21",
                                  "d/dP24",     "d/dP25",     "d2/dP6^2",     "d2/dP7^2",      "d2/dP20^2",     "d2/dP21^2",
                                  "d2/dP6dP7", "d2/dP16dP17", "d2/dP20dP21", "d2/dP24dP25"};
  REQUIRE(fit.derivatives.size() == 16);
  for (std::size_t k = 0; k < 16; ++k) {
    CHECK(fit.derivatives[k].label() == labels[k]);
    for (int r = 0; r < 3; ++r) CHECK(fit.derivatives[k].value[r] == Approx(table14[k][r]).margin(0.002));
  }
}

TEST_CASE("second-order runs end to end: the parabola through 0.8 1.0 1.2 against the closed-form crush",
          "[sensitivity]") {
  Files files;
  std::ofstream(files.design, std::ios::app) << "second_order:\n  terms: [P7, P7^2]\n  runs:\n    - {P7: 0.8}\n"
                                                "    - {P5: 1.2}\n";
  const SensitivityDesign design = load_design(files.design);
  SensitivityOptions options;
  options.jobs = 2;
  options.only = {"P7"};  // P5 and P9 left out: their second-order runs and terms are too
  const SensitivityResult result = run_sensitivity(files.model, design, options);
  REQUIRE(result.second_order_runs.size() == 1);
  REQUIRE(result.second_order_runs[0].ok);
  CHECK(result.second_order_runs[0].responses.r1 == Approx(crush_for(0.008) / 0.02).epsilon(1e-5));
  // Fit from runs 0 (base), 1 (P7 = 1.2) and 2 (P7 = 0.8): 3 constants, 3 runs.
  const QuadraticFit& fit = result.fit;
  REQUIRE(fit.determined());
  CHECK(fit.equations == 3);
  const double low = crush_for(0.008) / 0.02, mid = crush_for(0.01) / 0.02, high = crush_for(0.012) / 0.02;
  REQUIRE(fit.derivatives.size() == 2);
  CHECK(fit.derivatives[0].value[0] == Approx((high - low) / 0.4).epsilon(1e-4));
  CHECK(fit.derivatives[1].value[0] == Approx((high - 2.0 * mid + low) / 0.04).epsilon(1e-3));
  const std::string md = write_sensitivity(result, design, files.dir + "/out2");
  CHECK_THAT(md, Catch::Contains("3 constants (terms 1, P7, P7^2) from 3 runs: square system"));
  CHECK_THAT(md, Catch::Contains("| d/dP7 |"));
  for (const char* file : {"sensitivity_second_order.csv", "sensitivity_derivatives.csv", "sensitivity_ranking.csv",
                           "sensitivity_first_order.csv"})
    CHECK(std::filesystem::exists(files.dir + "/out2/" + file));
}

TEST_CASE("design files: unknown parameters in the second-order study are refused with file and line", "[sensitivity]") {
  Files files;
  const std::string base = "sensitivity: 1\nparameters:\n  - {name: P6, scale: [{key: a.b, power: 1}]}\n"
                           "  - {name: P7, scale: [{key: a.c, power: 1}]}\n";
  const auto refused = [&](const std::string& second_order, const std::string& message) {
    const std::string path = files.dir + "/bad_design.yaml";
    std::ofstream(path) << base << second_order;
    CHECK_THROWS_AS(load_design(path), InputError);
    CHECK_THROWS_WITH(load_design(path), Catch::Contains(message));
  };
  refused("second_order:\n  terms: [P6]\n  runs:\n    - {P6: 0.8}\n    - {P6: 1.2, P99: 1.2}\n",
          "bad_design.yaml:9: second_order run 2: no parameter 'P99' in 'parameters' (use one of P6, P7)");
  refused("second_order:\n  terms: [P6, P6*P8]\n  runs: [{P6: 0.8}]\n", "bad_design.yaml:6: second_order term 'P6*P8': no parameter 'P8'");
  refused("second_order:\n  terms: [P6^3]\n  runs: [{P6: 0.8}]\n", "only squares are allowed");
  refused("second_order:\n  terms: [P6*P7, P7*P6]\n  runs: [{P6: 0.8}]\n", "'P7*P6' is listed twice");
  refused("second_order:\n  terms: [P6]\n  runs: [{P6: -0.8}]\n", "the value of P6 must be positive");
  refused("second_order:\n  - {P6: 0.8}\n", "'second_order' needs 'terms'");
  // Parameter names head CSV columns and term labels: a comma, a star or a leading digit is refused at its line.
  for (const char* name : {"\"P,6\"", "P*8", "8P", "\"\""}) {
    const std::string path = files.dir + "/bad_name.yaml";
    std::ofstream(path) << "sensitivity: 1\nparameters:\n  - name: " << name << "\n    scale: [{key: a.b}]\n";
    CHECK_THROWS_WITH(load_design(path), Catch::StartsWith(path + ":3: parameter name '") &&
                                             Catch::Contains("use letters, digits, _ - and . only"));
  }
  // The report's design is the file beside the model.
  const std::string report_model = std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml";
  CHECK(std::filesystem::equivalent(default_design_path(report_model), report_design_path()));
  CHECK_THROWS_WITH(default_design_path(files.model), Catch::Contains("pass --design FILE"));
}

TEST_CASE("a run that exceeds the run time limit is stopped and reported failed", "[sensitivity]") {
  Files files;
  // The same car end run for 99 s with output every 1e-4 s (990,000 rows, just under the
  // output limit), beside a 1 kg mass ringing on a 1e8 N/m spring (period 0.63 ms, about
  // 160,000 periods at rtol 1e-9): far longer than the run time limit. (The car alone flies
  // off after its rebound, which IDA now crosses in a few large steps.)
  std::ifstream in(files.model);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find("t_end: 0.15");
  REQUIRE(at != std::string::npos);
  text.replace(at, 11, "t_end: 99.0");
  const auto bodies = text.find("bodies:\n"), elements = text.find("elements:\n");
  REQUIRE((bodies != std::string::npos && elements != std::string::npos));
  text.insert(elements + 10, "  - {name: ringing, type: linear_spring, stiffness: 1.0e8, free_length: 0.998, points: [{body: ground, at: [0, 2]}, "
                             "{body: bell, at: [0, 0]}]}\n");
  text.insert(bodies + 8, "  - {name: bell, mass: 1, inertia: 1, position: [0, 1.001]}\n");
  std::ofstream(files.model) << text;
  const SensitivityDesign design = load_design(files.design);
  SensitivityOptions options;
  options.only = {"P7"};
  options.run_time_limit = 0.2;
  const SensitivityResult result = run_sensitivity(files.model, design, options);
  CHECK_FALSE(result.base.ok);
  CHECK_THAT(result.base.message, Catch::Contains("stopped at the run time limit of 0.2 s"));
  CHECK(result.base.wall_seconds < 5.0);
  CHECK(std::isnan(result.derivatives[0][0]));
}

// ---- discrete outcomes and branch changes (issue 40) ----

TEST_CASE("outcome signature: outcomes only, first occurrence, near-simultaneous outcomes as a set", "[sensitivity][branch]") {
  const std::vector<EventRecord> events{
      {0.010, "gear1", "sliding (buff)", 0.0},
      {0.012, "gear1", "bottomed (buff)", 0.0},
      {0.013, "ends", "contact", 0.0},
      {0.015307, "gear1", "fracture", 0.0},
      {0.015348, "gear2", "fracture", 0.0},
      {0.016, "gear1", "off bottom (buff)", 0.0},
      {0.017, "gear1", "bottomed (draft)", 0.0},            // second bottoming: not a new outcome
      {0.020, "ac", "horizontal unloading, override", 0.0}, // joined texts are split
      {0.021, "ac", "separation", 0.0}};
  const OutcomeSignature s = outcome_signature(events, 1e-4);  // order asked: groups within 0.1 ms
  REQUIRE(s.events.size() == 4);
  CHECK(s.text() == "gear1:bottomed@12.000ms>gear1:fracture@15.307ms>gear2:fracture@15.348ms>ac:override@20.000ms");
  CHECK(s.order() == "gear1:bottomed>gear1:fracture+gear2:fracture>ac:override");
  // By default the set: order aside.
  CHECK(outcome_signature(events).order() == "ac:override+gear1:bottomed+gear1:fracture+gear2:fracture");
  CHECK(outcome_of_event("horizontal unloading, override") == "override");
  CHECK(outcome_of_event("contact, crushing").empty());
  CHECK(outcome_of_event("pin shear") == "pin shear");
  // The two fractures 41 us apart in the other order: the same branch (one group, within 0.1 ms).
  std::vector<EventRecord> swapped = events;
  swapped[3].element = "gear2";
  swapped[4].element = "gear1";
  CHECK(same_branch(outcome_signature(swapped, 1e-4), s));
  CHECK(same_branch(outcome_signature(swapped), outcome_signature(events)));
  // A window below their distance makes the order count.
  CHECK_FALSE(same_branch(outcome_signature(swapped, 1e-5), outcome_signature(events, 1e-5)));
  // The override before the fractures: another order, the same set.
  std::vector<EventRecord> early = events;
  early[7].t = 0.014;
  std::stable_sort(early.begin(), early.end(), [](const EventRecord& a, const EventRecord& b) { return a.t < b.t; });
  CHECK(same_branch(outcome_signature(early), outcome_signature(events)));
  CHECK_FALSE(same_branch(outcome_signature(early, 1e-4), s));
  // One gear fractures only: another branch, in either form.
  std::vector<EventRecord> one = events;
  one.erase(one.begin() + 4);
  CHECK_FALSE(same_branch(outcome_signature(one, 1e-4), s));
  CHECK_FALSE(same_branch(outcome_signature(one), outcome_signature(events)));
  CHECK(outcome_signature({}).text() == "none");
  CHECK(s.json().find("\"branch\": \"gear1:bottomed>gear1:fracture+gear2:fracture>ac:override\"") != std::string::npos);
  CHECK(outcome_signature(events).json().find("\"window\": null") != std::string::npos);  // no window: the set
}

namespace {

// A 500 kg probe at 2 m/s into a draft gear fixed to the ground (k = 1e6 N/m, H = 2e4 N, stick
// slope Kt = 2e7 N/m, travel 0.05 m, never reached): it sticks up to x1 = H / (Kt - k), then
// loads on k x + H to the largest compression xm, where
//   m v0^2 / 2 = Kt x1^2 / 2 + k (xm^2 - x1^2) / 2 + H (xm - x1),
// so the peak gear force is k xm + H. The gear fractures when its fracture_load is below it.
// Beside it, the R1 car of the other tests (responses need an anticlimber), which the gear does not touch.
double gear_peak_force() {
  const double m = 500.0, v0 = 2.0, k = 1e6, h = 2e4, kt = 2e7;
  const double x1 = h / (kt - k);
  const double rest = 0.5 * m * v0 * v0 - 0.5 * kt * x1 * x1 + 0.5 * k * x1 * x1 + h * x1;  // = k xm^2 / 2 + H xm
  const double xm = (-h + std::sqrt(h * h + 2.0 * k * rest)) / k;
  return k * xm + h;
}

std::string gear_fracture_model(double fracture_load) {
  std::string text = testing::anticlimber_r1_model_text(0.15);
  const auto elements = text.find("elements:\n");
  text.insert(text.find("\n", text.find("bodies:\n") + 8) + 1,
              "  - {name: probe, mass: 500, inertia: 1, position: [0, 5], velocity: [-2, 0]}\n");
  char gear[512];
  std::snprintf(gear, sizeof gear,
                "  - name: gear\n    type: draft_gear\n    initial_stiffness: 1.0e6\n    travel: 0.05\n"
                "    stiffness_after_bottoming: 2.0e7\n    hysteresis_load: 2.0e4\n    transition_stiffness: 2.0e7\n"
                "    fracture_load: %.17g\n    points: [{body: ground, at: [-1, 5]}, {body: probe, at: [0, 0]}]\n",
                fracture_load);
  (void)elements;
  text.insert(text.find("elements:\n") + 10, gear);
  return text;
}

}  // namespace

TEST_CASE("branch change: a gear that fractures at run 0 and not at +20 % is flagged and the threshold bracketed",
          "[sensitivity][branch]") {
  Files files;
  const double peak = gear_peak_force(), nominal_load = 45000.0;
  REQUIRE(peak > nominal_load);
  REQUIRE(peak < 1.2 * nominal_load);
  std::ofstream(files.model) << gear_fracture_model(nominal_load);
  std::ofstream(files.design) << "sensitivity: 1\nfactor: 1.2\nparameters:\n"
                                 "  - name: PF\n    description: gear fracture load\n"
                                 "    scale: [{key: elements.gear.fracture_load, power: 1}]\n"
                                 "  - name: P7\n    description: horizontal yield force\n"
                                 "    scale: [{key: elements.ac.horizontal_yield_deflection, power: 1}]\n";
  const SensitivityDesign design = load_design(files.design);
  SensitivityOptions options;
  options.jobs = 2;
  const SensitivityResult result = run_sensitivity(files.model, design, options);
  REQUIRE(result.base.ok);
  REQUIRE(result.base.outcomes.events.size() == 1);
  CHECK(result.base.outcomes.order() == "gear:fracture");
  REQUIRE(result.runs.size() == 2);
  CHECK(result.runs[0].outcomes.order() == "none");  // PF = 1.2: the load stays below it
  CHECK(result.runs[1].outcomes.order() == "gear:fracture");  // P7 leaves the gear alone
  REQUIRE(result.branch_changes.size() == 1);
  const BranchChange& change = result.branch_changes[0];
  CHECK(change.parameter == "PF");
  CHECK(change.run == 0);
  // 4 halvings of the step 0.2: the bracket is 0.2 / 16 wide and holds the threshold peak / load.
  const double threshold = peak / nominal_load;
  CHECK(change.bisection_runs.size() == 4);
  CHECK(result.bisection_runs == 4);
  CHECK(change.on_branch_value < threshold);
  CHECK(change.off_branch_value > threshold);
  CHECK(change.off_branch_value - change.on_branch_value == Approx(0.2 / 16).epsilon(1e-12));
  CHECK(change.off_branch_signature == "none");
  // R1 does not depend on the gear (only through the integrator's steps, which the probe shares):
  // no effect within the branch, no jump.
  CHECK(change.within_branch[0] == Approx(0.0).margin(1e-6));
  CHECK(change.jump[0] == Approx(0.0).margin(1e-6));
  CHECK(change.note.empty());
  const std::string md = write_sensitivity(result, design, files.dir + "/out");
  CHECK_THAT(md, Catch::Contains("Run 0's outcome: `gear:fracture@"));
  CHECK_THAT(md, Catch::Contains("1 of 2 first-order runs end on another branch"));
  std::ifstream csv(files.dir + "/out/sensitivity.csv");
  std::string line;
  std::getline(csv, line);
  std::getline(csv, line);
  CHECK_THAT(line, Catch::Contains(",base,\"gear:fracture@"));
  std::getline(csv, line);
  CHECK_THAT(line, Catch::EndsWith(",changed,\"none\",ida,"));  // then integrator_used (auto, kept by IDA) and euler_from_t
  std::getline(csv, line);
  CHECK_THAT(line, Catch::Contains(",same,\"gear:fracture@"));
  CHECK(std::filesystem::exists(files.dir + "/out/sensitivity_branches.csv"));
}
