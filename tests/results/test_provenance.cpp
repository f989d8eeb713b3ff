// A run's provenance and its folder (results/provenance.hpp, results/run_files.hpp): the SHA-256
// against the FIPS 180-2 examples, the run id and provenance in every file of a run folder, and a
// run that removes what an earlier run left there. On a model in SI: two 40 t cars of a modern
// multiple unit (crush zones, draft gears, anticlimbers), as a base file and a variant of it.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <unistd.h>

#include "railcrash/core/sha256.hpp"
#include "railcrash/core/version.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/hdf5_file.hpp"
#include "railcrash/results/provenance.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/results/run_files.hpp"

namespace fs = std::filesystem;
using namespace railcrash;

namespace {

// Two cars of 40 t (a 4 t end frame and a 36 t body each), car 1 at 10 m/s into car 2: each
// end frame 0.6 m ahead of its body on a crush zone (crush_spring) and a draft gear, the end
// frames' anticlimbers 0.1 m apart at the start.
const char* const kMultipleUnit = R"(railcrash: 1
name: two 40 t multiple-unit cars, SI
units: SI
gravity: [0, 0]
bodies:
  - {name: car1_end, car: car1, mass: 4000, inertia: 4000, position: [-0.5, 1.0], velocity: [10, 0]}
  - {name: car1_body, car: car1, mass: 36000, inertia: 1.5e6, position: [-11.5, 1.0], velocity: [10, 0]}
  - {name: car2_end, car: car2, mass: 4000, inertia: 4000, position: [0.5, 1.0]}
  - {name: car2_body, car: car2, mass: 36000, inertia: 1.5e6, position: [11.5, 1.0]}
elements:
  - {name: anticlimber, type: anticlimber, horizontal_elastic_stiffness: 5.0e8, horizontal_plastic_stiffness: 1.0e6,
     horizontal_yield_deflection: 0.002, vertical_elastic_stiffness: 5.0e8, vertical_plastic_stiffness: 1.0e6,
     vertical_yield_deflection: 0.002, torsional_elastic_stiffness: 1.0e8, torsional_plastic_stiffness: 1.0e6,
     torsional_yield_deflection: 0.002, face_height: 0.2,
     points: [{body: car1_end, at: [0.45, 0]}, {body: car2_end, at: [-0.45, 0]}]}
  - {name: car1_crush_zone, type: crush_spring, curve: [[0, 0], [0.05, 1.5e6], [0.6, 1.8e6]], unloading_stiffness: 1.0e8,
     points: [{body: car1_body, at: [10.0, 0]}, {body: car1_end, at: [-0.4, 0]}]}
  - {name: car1_draft_gear, type: draft_gear, initial_stiffness: 1.0e7, travel: 0.08, stiffness_after_bottoming: 1.0e9,
     hysteresis_load: 2.0e5, points: [{body: car1_body, at: [10.0, 0.5]}, {body: car1_end, at: [-0.4, 0.5]}]}
  - {name: car2_crush_zone, type: crush_spring, curve: [[0, 0], [0.05, 1.5e6], [0.6, 1.8e6]], unloading_stiffness: 1.0e8,
     points: [{body: car2_end, at: [0.4, 0]}, {body: car2_body, at: [-10.0, 0]}]}
  - {name: car2_draft_gear, type: draft_gear, initial_stiffness: 1.0e7, travel: 0.08, stiffness_after_bottoming: 1.0e9,
     hysteresis_load: 2.0e5, points: [{body: car2_end, at: [0.4, 0.5]}, {body: car2_body, at: [-10.0, 0.5]}]}
simulation: {t_end: 0.1, rtol: 1.0e-6, output_interval: 1.0e-3}
)";

const char* const kVariant = R"(railcrash: 1
variant_of: multiple_unit.yaml
name: two 40 t multiple-unit cars, SI, softer crush zones
set:
  elements.car1_crush_zone.unloading_stiffness: 5.0e7
)";

fs::path fresh_folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("railcrash_provenance_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void write(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string first_line(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::getline(in, line);
  return line;
}

/// summary.json's "provenance" object (one line of JSON).
std::string provenance_in(const std::string& summary) {
  std::smatch match;
  REQUIRE(std::regex_search(summary, match, std::regex("\n  \"provenance\": (\\{[^\n]*\\}),\n")));
  return match[1].str();
}

}  // namespace

TEST_CASE("SHA-256 gives the digests of the FIPS 180-2 examples", "[results][provenance]") {
  CHECK(sha256_hex("abc") == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  CHECK(sha256_hex("") == "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  // 56 bytes: the length no longer fits the first block, the padding takes a second.
  CHECK(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq") ==
        "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  CHECK(sha256_hex(std::string(1000000, 'a')) == "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST_CASE("Every file of a run carries its run id and provenance, with both files of a variant", "[results][provenance]") {
  const fs::path models = fresh_folder("models");
  write(models / "multiple_unit.yaml", kMultipleUnit);
  write(models / "softer.yaml", kVariant);
  const LoadedModel loaded = load_model((models / "softer.yaml").string(), {"simulation.t_end=0.03"},
                                 {{"simulation.output_interval=0.002", "--output-interval 0.002"}});
  const Model& model = loaded.model;
  const fs::path dir = fresh_folder("files");
  const RunReport run = run_model(model, loaded.run_spec, dir.string());
  REQUIRE(run.outcome.ok);
  REQUIRE(std::regex_match(run.run_id, std::regex("[0-9a-f]{32}")));

  const std::string summary = slurp(dir / "summary.json");
  CHECK_THAT(summary, Catch::Contains("\n  \"run_id\": \"" + run.run_id + "\",\n"));
  const std::string provenance = provenance_in(summary);
  const std::string commit = build_commit();
  CHECK_THAT(provenance, Catch::StartsWith("{\"run_id\": \"" + run.run_id + "\", \"version\": \"" + version_number() +
                                           "\", \"commit\": \"" + commit + "\", \"command_line\": \"\""));
  // The variant and its base, in the order read, each with the digest of its bytes.
  CHECK_THAT(provenance, Catch::Contains("\"model_files\": [{\"path\": " + json_string((models / "softer.yaml").string()) +
                                         ", \"sha256\": \"" + sha256_hex(kVariant) + "\"}, {\"path\": " +
                                         json_string((models / "multiple_unit.yaml").string()) + ", \"sha256\": \"" +
                                         sha256_hex(kMultipleUnit) + "\"}]"));
  CHECK_THAT(provenance, Catch::Contains("\"settings\": [\"simulation.t_end=0.03\", \"simulation.output_interval=0.002\"], "
                                         "\"simulation\": {\"integrator\": \"auto\", \"t_end\": 0.03, \"output_interval\": 0.002, "
                                         "\"max_steps\": 10000000, \"dt\": \"0.5 x stability limit\", \"force_dt\": false, "
                                         "\"rtol\": 1e-06, \"atol\": \"from the model\""));  // auto: both methods' settings
  for (const char* name : {"timeseries.csv", "events.csv", "accelerations.csv", "energy.csv"})
    CHECK(first_line(dir / name) == "# railcrash provenance " + provenance);
  CHECK_THAT(slurp(dir / "model.json"), Catch::StartsWith("{\n  \"format\": 1,\n  \"run_id\": \"" + run.run_id + "\",\n"));

  // Another run of the same model has another id.
  const RunReport again = run_model(model, loaded.run_spec, dir.string());
  CHECK(again.run_id != run.run_id);
  CHECK(run_id_in(slurp(dir / "summary.json")) == again.run_id);
  fs::remove_all(dir);
  fs::remove_all(models);
}

TEST_CASE("A run removes the files an earlier run left in its folder and nothing else", "[results][provenance]") {
  const fs::path models = fresh_folder("owner_model");
  write(models / "multiple_unit.yaml", kMultipleUnit);
  const LoadedModel loaded = load_model((models / "multiple_unit.yaml").string(), {"simulation.t_end=0.01"});
  const Model& model = loaded.model;
  const fs::path dir = fresh_folder("owner");
  REQUIRE(run_model(model, loaded.run_spec, dir.string()).outcome.ok);
  write(dir / "report.html", "a report of the earlier run");
  write(dir / "notes.txt", "the user's own file");
  fs::create_symlink("notes.txt", dir / "summary.json.tmp");  // a link in a file's place is not the run's to remove

  // The HDF5 run where the CSV run was (the case of the issue), or a CSV run where an HDF5 run left its file.
  const std::string format = hdf5_available() ? "hdf5" : "csv";
  if (format == "csv") write(dir / "timeseries.h5", "an earlier HDF5 run's file");
  const DaeSystem system(model);
  const ResultWriter writer(dir.string(), system, loaded.run_spec, false, format);
  const std::vector<std::string> expected =
      format == "hdf5"
          ? std::vector<std::string>{"timeseries.csv", "events.csv", "accelerations.csv", "energy.csv", "summary.json", "model.json",
                                     "report.html", "energy_zones.csv"}
          : std::vector<std::string>{"timeseries.csv", "events.csv", "accelerations.csv", "energy.csv", "timeseries.h5",
                                     "summary.json", "model.json", "report.html", "energy_zones.csv"};
  CHECK(writer.removed_files() == expected);
  CHECK(slurp(dir / "notes.txt") == "the user's own file");
  CHECK(fs::is_symlink(dir / "summary.json.tmp"));
  CHECK_FALSE(fs::exists(dir / "report.html"));
  CHECK_FALSE(fs::exists(dir / "summary.json"));
  if (format == "hdf5")
    for (const char* name : {"timeseries.csv", "events.csv", "accelerations.csv", "energy.csv"}) CHECK_FALSE(fs::exists(dir / name));
  else
    CHECK_FALSE(fs::exists(dir / "timeseries.h5"));
  fs::remove_all(dir);
  fs::remove_all(models);
}
