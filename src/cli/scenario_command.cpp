// `railcrash scenario N --train MODEL`: a model of an EN 15227 design collision scenario (1, 2 or 3)
// built from a car model, with the criteria evaluated after the run.
#include <cmath>
#include <cstdlib>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/core/error.hpp"
#include "railcrash/scenarios/en15227.hpp"
#include "railcrash/studies/batch.hpp"

namespace railcrash::cli {

namespace {

/// "mm:kN,mm:kN,..." -> pairs; InputError naming the option otherwise.
std::vector<std::pair<double, double>> parse_curve(const std::string& text, const std::string& option) {
  std::vector<std::pair<double, double>> points;
  std::stringstream items(text);
  std::string item;
  // Each number whole and finite: a stroke from 0 to 10000 mm, a force from 0 to 1e6 kN.
  const auto number = [](const std::string& field, double high, double& value) {
    char* end = nullptr;
    value = std::strtod(field.c_str(), &end);
    return !field.empty() && *end == '\0' && std::isfinite(value) && value >= 0.0 && value <= high;
  };
  while (std::getline(items, item, ',')) {
    const auto colon = item.find(':');
    double stroke = 0.0, force = 0.0;
    if (colon == std::string::npos || !number(item.substr(0, colon), 10000.0, stroke) || !number(item.substr(colon + 1), 1e6, force))
      throw railcrash::InputError(option + ": '" + item + "' is not a point stroke:force (mm:kN) with a stroke from 0 to 10000 mm " +
                                  "and a force from 0 to 1e+06 kN, e.g. 0:0,75:600,105:1500");
    points.emplace_back(stroke, force);
  }
  return points;
}

class ScenarioCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    command_ = program.add_subcommand("scenario", "write a model of an EN 15227 design collision scenario (1, 2 or 3) "
                                                   "built from a car model, with the criteria evaluated after the run");
    command_->add_option("number", request_.number, "scenario number (1: two identical trains, 2: 80 t wagon, 3: deformable obstacle)")
        ->required()->check(finite_number(1, 4, false, false));
    command_->add_option("--train", request_.train_path, "a model with car types and trains (e.g. models/examples/emu3_wall.yaml), a two-car template (car1_* striking, e.g. models/report/final_two_car.yaml) or a model whose bodies declare their cars (e.g. models/barrier/two_car_barrier.yaml)")
        ->required();
    command_->add_option("--unit", request_.unit, "model with trains: the train to use (default: its first)");
    command_->add_option("--interface", request_.interface,
                         "model with trains, scenario 1: the interface type joining the two trains' fronts (default: the model's connection there)");
    command_->add_option("--cars", request_.cars, "cars per train")->capture_default_str()->check(finite_number(1, 1000, false, false));
    command_->add_option("--category", request_.category, "C-I, C-II, C-III or C-IV")->capture_default_str();
    command_->add_option("--passenger-bodies", request_.passenger_bodies,
                         "comma list of the passenger-area bodies (template names without car1_), e.g. center_body")->delimiter(',');
    command_->add_option("--survival-gauge", request_.survival_gauge,
                         "FRONT,REAR: template bodies (without car1_) at the ends of the survival space")->delimiter(',');
    command_->add_option("--crush-zones", request_.crush_zones,
                         "comma list of declared crush zones NAME or NAME:STROKE [mm]: their crush up to the stroke (default: the end of "
                         "the declared curve) does not count as survival-space loss")->delimiter(',');
    command_->add_option("--buffer-curve", buffer_curve_, "scenario 2: one side buffer's force-stroke curve mm:kN,mm:kN,...");
    command_->add_option("--wagon-mass", request_.wagon_mass, "scenario 2: wagon mass [t]")->capture_default_str()
        ->check(finite_number(0, 10000, true, false, "t"));
    command_->add_option("--obstacle-curve", obstacle_curve_, "scenario 3: the obstacle's force-crush curve mm:kN,mm:kN,... (required)");
    command_->add_option("--obstacle-mass", request_.obstacle_mass, "scenario 3: obstacle mass [t]")->capture_default_str()
        ->check(finite_number(0, 10000, true, false, "t"));
    // Each value's valid range: speeds up to 1000 km/h, lengths within 10 m, decelerations up to
    // 100 g, stiffnesses up to 1e6 kN/mm, run times up to 1000 s (EN 15227's collisions last a
    // fraction of a second).
    struct ScenarioValue {
      const char* option;
      const char* help;
      CLI::Validator range;
    };
    const CLI::Validator length_mm = finite_number(0, 10000, false, false, "mm");
    const CLI::Validator stiffness = finite_number(0, 1e6, true, false, "kN/mm");
    for (const ScenarioValue& value : std::vector<ScenarioValue>{
             {"--speed", "closing speed [km/h] (default 36 for C-I)", finite_number(0, 1000, true, false, "km/h")},
             {"--offset", "scenario 1: vertical offset of the standing train [mm] (required)", length_mm},
             {"--deceleration-limit", "mean longitudinal deceleration limit [g] (required)", finite_number(0, 100, true, false, "g")},
             {"--survival-space-limit", "largest allowed shortening of the survival space [mm] (required)", finite_number(0, 10000, true, false, "mm")},
             {"--override-limit", "largest allowed vertical relative displacement at the interface [mm] (required)", finite_number(0, 10000, true, false, "mm")},
             {"--wheel-lift-limit", "largest allowed wheel lift of the leading bogies [mm] (required)", finite_number(0, 10000, true, false, "mm")},
             {"--buffer-unloading-stiffness", "scenario 2: one buffer's unloading stiffness [kN/mm] (required)", stiffness},
             {"--buffer-height", "scenario 2: buffer height above the rail [mm] (required)", length_mm},
             {"--face-stiffness", "scenario 1 from a model declaring its cars: each front face's stiffness [kN/mm] (required)", stiffness},
             {"--face-height", "scenario 1 from a model declaring its cars: each front face's height [mm] (required)", length_mm},
             {"--face-friction", "scenario 1 from a model declaring its cars: friction coefficient between the front faces (required with an offset)",
              finite_number(0, 10, false, false)},
             {"--obstacle-unloading-stiffness", "scenario 3: the obstacle's unloading stiffness [kN/mm] (required)", stiffness},
             {"--obstacle-height", "scenario 3: height of the obstacle's contact point above the rail [mm] (required)", length_mm},
             {"--t-end", "end time of the run [s] (default: the train model's)", finite_number(0, 1000, true, false, "s")}})
      command_->add_option(value.option, values_[value.option], value.help)->check(value.range);
    command_->add_option("--out", out_, "model file to write (default: standard output)");
    return command_;
  }

  int run(char** /*argv*/) override {
    if (command_->count("--out") > 0) check_output_file(out_);
    const auto given = [&](const std::string& option) -> std::optional<double> {
      if (command_->count(option) == 0) return std::nullopt;
      return values_[option];
    };
    request_.speed = given("--speed");
    request_.offset = given("--offset");
    request_.deceleration_limit = given("--deceleration-limit");
    request_.survival_limit = given("--survival-space-limit");
    request_.override_limit = given("--override-limit");
    request_.wheel_lift_limit = given("--wheel-lift-limit");
    request_.buffer_unloading_stiffness = given("--buffer-unloading-stiffness");
    request_.buffer_height = given("--buffer-height");
    request_.face_stiffness = given("--face-stiffness");
    request_.face_height = given("--face-height");
    request_.face_friction = given("--face-friction");
    request_.obstacle_unloading_stiffness = given("--obstacle-unloading-stiffness");
    request_.obstacle_height = given("--obstacle-height");
    request_.t_end = given("--t-end");
    if (!buffer_curve_.empty()) request_.buffer_curve = parse_curve(buffer_curve_, "--buffer-curve");
    if (!obstacle_curve_.empty()) request_.obstacle_curve = parse_curve(obstacle_curve_, "--obstacle-curve");
    return write_generated_model(make_scenario_model(request_), out_,
                                 "EN 15227 scenario " + std::to_string(request_.number));
  }

 private:
  CLI::App* command_ = nullptr;
  ScenarioRequest request_;
  std::string out_, buffer_curve_, obstacle_curve_;
  std::map<std::string, double> values_;
};

}  // namespace

std::unique_ptr<Command> make_scenario_command() { return std::make_unique<ScenarioCommand>(); }

}  // namespace railcrash::cli
