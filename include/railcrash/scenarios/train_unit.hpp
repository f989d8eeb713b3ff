// A train unit read from any car model whose bodies declare `car: NAME` (e.g. the barrier test's
// two coupled cars, models/barrier/two_car_barrier.yaml), for the EN 15227 scenarios
// (scenario/en15227.hpp). Nothing is found by name: the unit's striking end comes from the
// elements' output roles (element.hpp's OutputRole) and the bodies' car declarations:
//   front crush element  the element with a crush output (OutputRole::Crush) between bodies of
//                        one car whose foremost point lies furthest ahead (+x, the direction of
//                        travel): the structure that crushes at the striking end;
//   front body           the body of that element's foremost point (the end that is struck);
//   front face           the foremost point of any element on the front body (e.g. where the
//                        model's barrier contact acts), at the start;
//   striking car         the car the front body declares;
//   leading wheels       the wheel_rail elements of the striking car's foremost wheel-carrying body;
//   fixed-surface contacts  elements of type contact (one body point against a fixed line or
//                        circle: the test's barrier) belong to the test, not to the unit, and
//                        are left out of the scenario.
#pragma once

#include <yaml-cpp/yaml.h>

#include <functional>
#include <string>
#include <vector>

#include "railcrash/model/yaml_reader.hpp"

namespace railcrash {

/// The reader of a scenario's train model (a unit's model file or a car template): the one YAML
/// reader (model/yaml_reader.hpp) whose messages read "FILE:LINE: scenario train model: ...".
class ScenarioModelReader : public YamlReader {
 public:
  using YamlReader::YamlReader;
  [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const override;
};

struct TrainUnit {
  std::string path;
  YAML::Node root;                   // the model file as read
  std::string striking_car;          // `car:` of the front body
  std::string front_crush;           // front crush element
  std::string front_body;
  double front_body_x = 0.0, front_body_y = 0.0;  // [length] its centre of gravity at the start
  double face_x = 0.0, face_y = 0.0;              // [length] the front face at the start
  std::vector<std::string> leading_wheels;
  std::vector<std::string> fixed_surface_contacts;  // left out

  /// Throws InputError naming the file and line of `node` (its top when undefined).
  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const;
  /// The body named `name`, or an InputError naming `option` that gave it.
  YAML::Node body(const std::string& name, const std::string& option) const;
};

/// Reads `path` (its text already parsed as `root`) and finds the unit's striking end; throws
/// InputError naming what is missing (no car declared, no crush element at the front, no
/// wheels) and where it goes.
TrainUnit read_train_unit(const std::string& path, const YAML::Node& root);

/// How a copy of the unit is placed in a scenario model.
struct UnitPlacement {
  std::string prefix;       // every body, element and car name gets it (e.g. "s_")
  bool mirrored = false;    // x -> -x about the front face (the unit then faces -x)
  double raise = 0.0;       // [length] bodies, rails and fixed points raised by this
  double velocity = 0.0;    // [length/time] every body's vx (along the unit's direction of travel)
};

/// Appends the unit's bodies and elements (without the fixed-surface contacts), renamed and
/// moved so that its front face is at x = 0.
void append_unit(const TrainUnit& unit, const UnitPlacement& placement, YAML::Node& bodies, YAML::Node& elements);

/// Deep copy of a model node with every scalar passed through `rename(key, scalar)` (key: the
/// map key the scalar is under; list items get "") and, when `mirror`, the x component of every
/// position, velocity, body point and direction negated and a body's angle and angular velocity negated
/// (element parameters that are angles, e.g. a torsional spring's, are not: none of the
/// shipped unit models has one).
YAML::Node transformed_node(const YAML::Node& node, const std::function<std::string(const std::string&, const std::string&)>& rename,
                            bool mirror, const std::string& key = "");

}  // namespace railcrash
