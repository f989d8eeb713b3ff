// The model: bodies, elements and loads (the physical model). The run's settings are not part
// of it: they are a RunSpec beside it (run_spec.hpp; the loader returns both, model_io.hpp).
//
// Build, then finalize: a Model is edited (add_body / add_element / add_load) until
// finalize(); then topology and the layout of the unknowns are frozen. Unknowns are
//   y = [ q (3 n_bodies) | v (3 n_bodies) | lambda (m) | mu (m) ]
// with body i at q[3i .. 3i+2] = (x, y, theta) and m = total constraint rows.
#pragma once

#include <array>
#include <cassert>
#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "railcrash/core/error.hpp"
#include "railcrash/model/element.hpp"

namespace railcrash {

enum class UnitSystem { SI, InLbfS };

/// Standard gravity in the unit system's length unit per s^2.
double standard_gravity(UnitSystem units);
/// The system's length unit in metres: 1 (SI) or 0.0254 (in-lbf-s).
double metres_per_length_unit(UnitSystem units);
const char* unit_system_name(UnitSystem units);

struct Body {
  std::string name;
  double mass = 0.0;              // [mass] (in-lbf-s: lbf*s^2/in)
  double inertia = 0.0;           // [mass*length^2] centroidal; 0 = point mass (IDA only, needs constraints)
  double x = 0.0, y = 0.0;        // [length] centre of mass, global
  double angle = 0.0;             // [rad]
  double vx = 0.0, vy = 0.0;      // [length/time]
  double angular_velocity = 0.0;  // [rad/time]
  std::string car;                // the car the body belongs to (the model file's `car:`); "" = none
  SourceLocation where;
};

/// A piecewise-linear function of time: constant when it has one point.
struct TimeTable {
  std::vector<double> times;                // [time] strictly increasing
  std::vector<std::array<double, 2>> values;  // one value (force: Fx, Fy; moment: M, 0) per time
  std::array<double, 2> at(double t) const;   // linear in between, held constant outside
};

/// Applied load on a body: a force (global axes) at a body point, or a moment.
struct Load {
  enum class Kind { Force, Moment } kind = Kind::Force;
  int body = 0;
  double sx = 0.0, sy = 0.0;  // [length] application point (force only), body frame
  TimeTable value;            // force: [force] (Fx, Fy); moment: [force*length]
  SourceLocation where;
};

/// A model file read to build a model and the SHA-256 of the text read (a run's provenance).
struct ModelSource {
  std::string path;
  std::string sha256;  // 64 hexadecimal digits
};

class Model {
 public:
  Model() = default;
  Model(Model&&) = default;
  Model& operator=(Model&&) = default;

  std::string name;
  std::string file;  // model file the model came from ("" when built in code)
  std::vector<ModelSource> sources;   // every model file read: the file given, then a variant's base
  std::vector<std::string> settings;  // KEY=VALUE settings applied over the files (--set, then the run options)
  UnitSystem units = UnitSystem::SI;  // of the numbers held here
  std::string file_units;             // the model file's `units` ("mm-t-s-N" is converted to SI when read)
  double gravity_x = 0.0, gravity_y = -9.80665;  // [length/time^2]

  int add_body(Body body);
  Element& add_element(std::unique_ptr<Element> element);
  void add_load(Load load);

  /// Freezes the model: checks names, binds points to bodies, lays out the unknowns.
  void finalize();
  bool finalized() const { return finalized_; }

  const std::vector<Body>& bodies() const { return bodies_; }
  std::vector<Body>& bodies_for_edit();
  const std::vector<std::unique_ptr<Element>>& elements() const { return elements_; }
  const std::vector<Load>& loads() const { return loads_; }

  /// Body index by name: kGround for "ground", nullopt if unknown.
  std::optional<int> find_body(const std::string& body_name) const;

  // ---- layout (valid after finalize) ----
  int body_count() const { return static_cast<int>(bodies_.size()); }
  int constraint_rows() const { return constraint_rows_; }
  int size() const { return 6 * body_count() + 2 * constraint_rows_; }
  int q_index(int body, int component) const { return 3 * body + component; }
  int v_index(int body, int component) const { return 3 * body_count() + 3 * body + component; }
  /// First constraint row of element e (only meaningful for constraint elements).
  int constraint_offset(std::size_t element) const { return constraint_offset_[element]; }
  int lambda_index(int row) const { return 6 * body_count() + row; }
  int mu_index(int row) const { return 6 * body_count() + constraint_rows_ + row; }
  /// Degrees of freedom (3 n - m); constraints may still be redundant, see initial_conditions.
  int degrees_of_freedom() const { return 3 * body_count() - constraint_rows_; }
  /// Characteristic length of the model [length]: its extent, at least one unit. A ground
  /// point counts by its distance from the origin (as an offset), so this grows when the model
  /// is placed far from it; IDA's relative position tolerance uses it (README "Position
  /// tolerances").
  double length_scale() const { return length_scale_; }
  /// The same with ground points counted as positions, inside the box around the bodies: the
  /// model's size wherever it lies (IDA's absolute position tolerance) [length].
  double origin_free_length_scale() const { return origin_free_length_scale_; }

 private:
  void require_editable(const char* what) const;

  std::vector<Body> bodies_;
  std::vector<std::unique_ptr<Element>> elements_;
  std::vector<Load> loads_;
  std::map<std::string, int> body_index_;
  std::map<std::string, int> element_index_;  // element name -> index in elements_ (duplicate check)
  std::vector<int> constraint_offset_;
  int constraint_rows_ = 0;
  double length_scale_ = 1.0;
  double origin_free_length_scale_ = 1.0;
  bool finalized_ = false;
};

/// Everything about a model's elements that changes during a run: each element's mode and
/// history (contact open or closed, plastic offsets, hysteresis memory, permanent set, failed
/// flags, ...), one slot per element (mode_bytes() of it, 0 for an element without modes) in
/// one contiguous block. The Model stays immutable; a run owns one ElementStates (DaeSystem
/// holds it), and events, restarts, the static settle and Euler go back to an earlier state
/// with snapshot() / restore().
class ElementStates {
 public:
  /// Every element of a finalized model in the mode it starts a run in.
  explicit ElementStates(const Model& model);

  /// Back to the starting modes.
  void reset();
  /// Element e's slot (null for an element without modes).
  const void* of(std::size_t e) const { return bytes_[e] == 0 ? nullptr : block_.data() + offset_[e]; }
  void* of(std::size_t e) { return bytes_[e] == 0 ? nullptr : block_.data() + offset_[e]; }
  /// Element e's slot as the State type it declared.
  template <class State>
  const State& as(std::size_t e) const {
    assert(bytes_[e] == sizeof(State));
    return *static_cast<const State*>(of(e));
  }
  template <class State>
  State& as(std::size_t e) {
    assert(bytes_[e] == sizeof(State));
    return *static_cast<State*>(of(e));
  }

  /// A copy of every element's mode, to go back to with restore().
  struct Snapshot {
    std::vector<std::max_align_t> block;
  };
  Snapshot snapshot() const { return {block_}; }
  /// snapshot() into one already made (its storage reused).
  void snapshot_into(Snapshot& snapshot) const { snapshot.block.assign(block_.begin(), block_.end()); }
  /// Every element's mode and history as the snapshot holds them.
  bool same_as(const Snapshot& snapshot) const;
  void restore(const Snapshot& snapshot);

 private:
  const Model* model_;
  std::vector<std::size_t> offset_;  // [blocks] first block of each element's slot
  std::vector<std::size_t> bytes_;   // [bytes] size of each element's slot
  std::vector<std::max_align_t> block_;
};

}  // namespace railcrash
