#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "railcrash/model_io.hpp"
#include "railcrash/sensitivity.hpp"
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
  std::string dir = (std::filesystem::temp_directory_path() / "railcrash_sensitivity_test").string();
  std::string model = dir + "/model.yaml", design = dir + "/design.yaml";
  Files() {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(model)
        << "railcrash: 1\nname: r1\nunits: SI\ngravity: [0, 0]\nbodies:\n"
           "  - {name: car, mass: 1000, inertia: 100, position: [0.1, 0], velocity: [-2, 0]}\nelements:\n"
           "  - name: ac\n    type: anticlimber\n"
           "    horizontal_elastic_stiffness: 1.0e7\n    horizontal_plastic_stiffness: 1.0e5\n    horizontal_yield_deflection: 0.01\n"
           "    vertical_elastic_stiffness: 1.0e6\n    vertical_plastic_stiffness: 1.0e4\n    vertical_yield_deflection: 0.01\n"
           "    torsional_elastic_stiffness: 1.0e6\n    torsional_plastic_stiffness: 1.0e4\n    torsional_yield_deflection: 0.01\n"
           "    face_height: 0.1\n    points: [{body: ground, at: [0, 0]}, {body: car, at: [0, 0]}]\n"
           "responses:\n  crush: anticlimber\n  reference_crush: 0.02\n  anticlimber: ac\n  reference_velocity: 4.0\n"
           "simulation: {t_end: 0.15, rtol: 1e-9, output_interval: 0.0001}\n";
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
  // A failed run is reported, the others go on.
  CHECK_FALSE(result.runs[2].ok);
  CHECK_THAT(result.runs[2].message, Catch::Contains("no number at 'elements.ac.no_such_key'"));
  CHECK(std::isnan(result.derivatives[2][0]));
  const std::string md = write_sensitivity(result, design, files.dir + "/out");
  CHECK_THAT(md, Catch::Contains("| 1 | P7 | 1.2 |"));
  // Ranked: P7 moves R1 the most.
  CHECK(md.find("| P7 | horizontal yield force") < md.find("| P5 | horizontal elastic slope"));
  std::ifstream csv(files.dir + "/out/sensitivity.csv");
  std::string header;
  std::getline(csv, header);
  CHECK(header == "run,parameter,factor,status,R1,R2,R3,override,message");
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
  const Model model = load_model(files.model, {"elements.ac.horizontal_yield_deflection*=1.5", "simulation.t_end*=2"});
  CHECK(model.simulation.t_end == Approx(0.3));
  CHECK_THROWS_WITH(load_model(files.model, {"elements.ac.face_height*=x"}), Catch::Contains("KEY*=FACTOR"));
}
