// Car types and trains in the model file (README "Car types and trains"): a car is defined
// once, in its own coordinates, and placed several times. The expansion turns the document's
// `car_types`, `interface_types`, `trains` and `connections` into the flat `bodies` and
// `elements` of format 1 (global positions, generated names) before the loader reads them, so
// everything after the expansion (checks, elements, outputs, sweeps) sees an ordinary model.
//
//   car_types:
//     coach:                               # bodies, elements: as in a flat model, car coordinates
//       bodies: [...]                      #   (x forward: the front interface at larger x)
//       elements: [...]                    # points on the car's bodies or on ground
//       interfaces:                        # the car's two ends
//         front: {body: front_end, at: [0.4, 0.0]}
//         rear: {body: rear_end, at: [-0.4, 0.0]}
//   interface_types:                       # what joins two ends: elements whose points are
//     semi_permanent:                      #   {end: 1 | 2, at: [dx, dy]}: end 1 is the end at the
//       elements: [...]                    #   smaller global x; at: offset from it, global axes
//   trains:
//     - name: unitA
//       front: 0.0                         # [length] global x of the first car's leading end
//       facing: +x                         # +x | -x: where the train's front points
//       speed: 10.0                        # [length/time] initial speed along `facing`
//       coupling: {type: semi_permanent, gap: 0.0}   # between every two cars (gap [length])
//       couplings: [...]                   # optional: one per gap, in order, instead
//       cars:
//         - {type: coach}                  # name car<k> unless given
//         - {type: coach, name: middle}
//         - {type: coach, reversed: true}  # turned round: its rear end leads
//   connections:                           # interfaces between trains (the collision)
//     - {name: impact, type: front_contact, ends: [unitA.car1.front, unitB.car1.front]}
//
// Generated names: body / element <train>.<car>.<name> (the bodies declare car: <train>.<car>),
// coupling elements <train>.coupling<k>.<name> (between car k and k+1), connection elements
// <connection>.<name>. A car of a train facing +x that is not reversed keeps its coordinates
// (shifted); otherwise its x is mirrored (body positions, `at` offsets, angles, `Direction`
// parameters, points on ground and `Position` parameters).
#pragma once

#include <yaml-cpp/yaml.h>

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace railcrash {

/// A car the expansion placed (for `railcrash check`).
struct ExpandedCar {
  std::string name;       // <train>.<car>
  std::string type;       // its car type
  bool reversed = false;  // turned round within its train
  double leading_x = 0.0, trailing_x = 0.0;  // [length] global x of its leading and trailing interfaces
  std::size_t bodies = 0, elements = 0;
};

/// What the expansion made, and where each generated node came from.
class TrainExpansion {
 public:
  /// Where a generated node's text is: the line of the car type's (or interface type's) node it
  /// copies, and the note naming the instance (" (car type 'coach', line 12; instance unitA.car3, line 40)").
  struct Origin {
    int line = 0;                 // 1-based line of the copied text (0: unknown)
    const std::string* note = nullptr;
  };
  /// The origin of a node the expansion made, or nullptr for the file's own nodes.
  const Origin* origin(const YAML::Node& node) const;

  bool expanded = false;  // the document had car types or trains
  std::vector<ExpandedCar> cars;

  // (the expansion's own)
  void add(const YAML::Node& node, int line, const std::string* note);
  void seal();  // sorts the origins (after the last add)
  const std::string* note(std::string text);

 private:
  std::vector<std::pair<const void*, Origin>> origins_;  // by node, sorted once sealed
  std::vector<std::unique_ptr<std::string>> notes_;
};

/// The keys of the model file the expansion reads (the fuzzer's dictionary adds them).
const std::vector<std::string>& train_expansion_keys();

/// The keys the expansion allows in each of its maps, by name: "sections" (its top-level
/// sections), "car_type", "interface_type", "interface", "train", "car", "coupling",
/// "connection", "end_point" (a point of an interface type's element). For `railcrash schema`.
std::vector<std::pair<std::string, std::vector<std::string>>> train_expansion_sections();

/// Whether a KEY=VALUE (or KEY*=FACTOR) setting edits a car type, interface type, train or
/// connection (key starting car_types., interface_types., trains. or connections.): such
/// settings apply before the expansion, so that a type's change reaches every instance.
bool is_train_definition_setting(const std::string& setting);

/// Registers a node as coming from a setting (the loader's own bookkeeping): (node, label).
using MarkSetting = std::function<void(const YAML::Node&, const std::string&)>;
/// The setting a node came from, or nullptr.
using SettingOf = std::function<const std::string*(const YAML::Node&)>;

/// Applies one setting along a path of map keys and list items' names (a list item is
/// addressed by its `name`): car_types.coach.elements.front_crush.curve=[[0, 0], [0.1, 1e6]],
/// trains.unitA.speed=12, or KEY*=FACTOR. `label` names the setting in messages. Throws
/// InputError (ZeroScaledError for a factor on 0).
void apply_train_definition_setting(YAML::Node& root, const std::string& setting, const std::string& label,
                                    const MarkSetting& mark);

/// Applies a setting on one generated body or element of an expanded document, addressed by its
/// generated name: unitA.car3.front_crush.stiffness=2e6 (or *=1.2). Returns false (and changes
/// nothing) when no body or element of the document has the name before the last '.'.
bool apply_instance_setting(YAML::Node& root, const std::string& setting, const std::string& label, const MarkSetting& mark);

/// A copy of `node` in which no node is reached twice: the expansion shares map keys between
/// the instances of a car type, which an emitter would write as anchors (&1) and aliases (*1);
/// the expanded model is emitted from this copy.
YAML::Node unshared_copy(const YAML::Node& node);

/// Expands `root` in place (nothing happens to a document without car_types / trains);
/// `file` names the model in messages; `setting_of`/`mark` carry settings' labels over to copies.
/// Throws InputError "file:line: ..." for a bad definition.
void expand_trains(YAML::Node& root, const std::string& file, TrainExpansion& expansion, const SettingOf& setting_of,
                   const MarkSetting& mark);

}  // namespace railcrash
