// EN 15227 design collision scenarios built from a two-car crash model (`railcrash scenario`).
//
// Values from the standard. EN 15227 (Railway applications - Crashworthiness requirements for
// rail vehicles) is not freely published; only what a named public source states is used as a
// default, everything else is a REQUIRED input of the command (README.md, "Collision scenarios"):
//   - scenario 1 is a front-end collision between two identical train units, "typically at
//     36 km/h"; scenario 2 a collision with an 80 t freight wagon with side buffers; scenario 3
//     a heavy (15 t) obstacle at a level crossing; scenario 4 a low obstacle.
//     Source: railwaynews.net, "Designed to Deform: EN 15227 and the Art of Railway
//     Crashworthiness" (its section "The Four Design Collision Scenarios").
//   - scenario 2 at the same 10 m/s (36 km/h) as scenario 1: the open-source
//     railway-impact-simulator (github.com/sflabbe/railway-impact-simulator,
//     configs/en15227/README_EN15227_GENERATED.md: "C1/C2: 10.0 m/s", C1 reference mass
//     80,000 kg wagon).
//   These two defaults apply to category C-I only (the sources do not give the other
//   categories' speeds): for C-II..C-IV, --speed is required.
//   Required, because no public source confirmed them: the vertical offset of scenario 1, the
//   mean-deceleration limit, the survival-space limit, the override and wheel-lift limits, the
//   side buffers' force-stroke characteristic and their height, scenario 3's speed (any
//   category), the obstacle's force-crush characteristic and its contact height.
//   The obstacle mass 15 t: railwaynews.net (above), scenario 3; the default of --obstacle-mass.
//
// Scenario 1 (make_scenario_model, number 1): the template's STRIKING car (car1_*) is the unit's
// car; the standing train is its mirror image about the coupler faces (x -> -x of every
// position, point and axis), so that the two trains are identical. The consist generator
// (consist.hpp) builds N cars per train. Both trains move towards each other at half the
// closing speed (the centre-of-mass frame: with identical trains the interface stays at x = 0
// when there is no offset). The standing train is raised by the vertical offset (its bodies and
// its rails), and the interface anticlimber's initial_misalignment is 0 (the geometry carries
// the offset).
// Scenario 2: the same striking train at the full speed against a wagon at rest: one rigid body
// (80 t) held by a frictionless slider on the track (it moves only along x; its pitch and its
// wheels are not modelled) and the two side buffers as one crush_spring (the buffer curve with
// twice the force: two buffers in parallel) at the buffer height between the train's front end
// (at its anticlimber face) and the wagon.
// Any other car model whose bodies declare `car: NAME` (e.g. the barrier test's two cars) is a
// train unit (scenario/train_unit.hpp: its striking end found from the elements' output roles):
// scenario 1 puts the unit (s_*) against its mirror image (t_*), their front faces meeting at an
// uncoupled coupler_end (front_faces, the face stiffness and height required inputs, and with an
// offset the faces' friction coefficient: without vertical friction the faces slide past each
// other and the offset cannot act); --cars is then the unit's own cars.
// A model with car types and trains (train_expansion.hpp, e.g. models/examples/emu3_*.yaml) is
// used as it composes its train (ScenarioRequest::unit, default its first): the train renamed
// `striking`, facing +x with its leading interface at x = 0; in scenario 1 a copy `standing`
// facing -x, raised with its rails by the offset, joined to it at the leading interfaces by a
// connection `impact` of the interface type the model's own connection there uses (or
// ScenarioRequest::interface). The document is expanded by the generator (the raise applies to
// the expanded bodies and ground points); the model's own flat bodies and elements, other trains
// and connections are left out. With an offset, the interface type must contain an anticlimber:
// without a vertical interlock (or friction) the faces slide past each other and the offset
// cannot produce override, so the request is refused. Car-type names reach every instance:
// passenger bodies (default: each car's heaviest body, its car body) and crush zones (TYPE.NAME:
// only car type TYPE's instances). The leading
// cars' wheels are their foremost wheel_rail elements or, without any, their foremost
// slider_joints on ground (the rail supports of results/scenario_criteria.hpp's wheel unloading).
// Crush zones (--crush-zones NAME[:STROKE mm]) become the section's `zones` with their strokes
// in the model's units (without a stroke: the end of the element's declared curve).
// Scenario 3: the train at --speed (required: the speed per category was not confirmed) into an
// obstacle of 15 t (railwaynews.net, scenario 3) built like the wagon: one body on a frictionless
// slider and a crush_spring with the obstacle's force-crush curve (required) at its contact height
// (required). No interface: override is judged by the leading bogie's wheel lift.
// The struck body's spring (wagon_buffers, obstacle_crush) is left out of the survival-space loss
// (the cars' crush outputs, results/scenario_criteria.hpp), and the --crush-zones count only beyond their
// strokes.
// Scenario 4 is refused with the reason: its obstacle is pushed sideways, out of the plane.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace railcrash {

struct ScenarioRequest {
  int number = 0;                    // 1..4
  std::string train_path;            // two-car template (car1_* striking, car2_* standing) or a unit model (cars declared)
  int cars = 1;                      // cars per train
  std::string category = "C-I";
  std::optional<double> speed;                  // [km/h] closing speed
  std::optional<double> offset;                 // [mm] scenario 1: standing train raised by this
  std::optional<double> deceleration_limit;     // [g]
  std::optional<double> survival_limit;         // [mm] largest shortening of a survival-space gauge
  std::optional<double> override_limit;         // [mm] largest vertical relative displacement
  std::optional<double> wheel_lift_limit;       // [mm]
  std::vector<std::string> passenger_bodies;    // train model bodies (a template's without the car1_ prefix)
  std::vector<std::string> crush_zones;         // declared crush zones NAME or NAME:STROKE [mm] (named as passenger_bodies;
                                                // a car type's element name reaches every instance): their crush up
                                                // to the stroke (default: the end of the declared curve) is allowed
  std::vector<std::string> survival_gauge;      // optional: two bodies (front, rear), named as passenger_bodies
  double wagon_mass = 80.0;                     // [t] scenario 2
  std::vector<std::pair<double, double>> buffer_curve;  // [mm, kN] one buffer's force-stroke curve
  std::optional<double> buffer_unloading_stiffness;     // [kN/mm] one buffer
  std::optional<double> buffer_height;                  // [mm] above the rail
  std::optional<double> face_stiffness;                 // [kN/mm] scenario 1 from a unit model: each front face
  std::optional<double> face_height;                    // [mm] scenario 1 from a unit model: each front face
  std::optional<double> face_friction;                  // [-] scenario 1 from a unit model: friction between the faces
                                                        // (required with an offset: it is what lets the offset act)
  double obstacle_mass = 15.0;                          // [t] scenario 3
  std::vector<std::pair<double, double>> obstacle_curve;  // [mm, kN] scenario 3: the obstacle's force-crush curve
  std::optional<double> obstacle_unloading_stiffness;   // [kN/mm] scenario 3
  std::optional<double> obstacle_height;                // [mm] scenario 3: its contact point above the rail
  std::optional<double> t_end;                          // [s] default: the template's
  std::string unit;       // model with car types and trains: the train to use (default: its first)
  std::string interface;  // model with car types and trains, scenario 1: the interface type joining the two
                          // trains (default: that of the model's connection at the train's leading end)
};

/// YAML text of the scenario's model. Throws InputError naming the missing option, or what
/// the template lacks (file and element), or why the scenario cannot be built.
std::string make_scenario_model(const ScenarioRequest& request);

}  // namespace railcrash
