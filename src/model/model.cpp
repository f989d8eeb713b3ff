#include "railcrash/model/model.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace railcrash {

double standard_gravity(UnitSystem units) {
  return units == UnitSystem::SI ? 9.80665 : 386.088;  // [m/s^2] | [in/s^2] (9.80665 / 0.0254)
}

double metres_per_length_unit(UnitSystem units) { return units == UnitSystem::SI ? 1.0 : 0.0254; }  // [m]

const char* unit_system_name(UnitSystem units) { return units == UnitSystem::SI ? "SI" : "in-lbf-s"; }

std::array<double, 2> TimeTable::at(double t) const {
  RAILCRASH_DEMAND(!times.empty() && times.size() == values.size());
  if (times.size() == 1 || t <= times.front()) return values.front();
  if (t >= times.back()) return values.back();
  const auto upper = std::upper_bound(times.begin(), times.end(), t);
  const std::size_t i = static_cast<std::size_t>(upper - times.begin());
  const double w = (t - times[i - 1]) / (times[i] - times[i - 1]);
  std::array<double, 2> out{};
  for (std::size_t c = 0; c < 2; ++c) out[c] = (1.0 - w) * values[i - 1][c] + w * values[i][c];
  return out;
}

void Model::require_editable(const char* what) const {
  if (finalized_) throw std::logic_error(std::string("Model::") + what + " after finalize()");
}

int Model::add_body(Body body) {
  require_editable("add_body");
  if (body.name == "ground")
    throw InputError(body.where.prefix() + "body name 'ground' is reserved for the fixed ground; rename the body");
  if (body_index_.count(body.name))
    throw InputError(body.where.prefix() + "body '" + body.name + "' is defined twice; body names must be unique");
  const int index = static_cast<int>(bodies_.size());
  body_index_[body.name] = index;
  bodies_.push_back(std::move(body));
  return index;
}

Element& Model::add_element(std::unique_ptr<Element> element) {
  require_editable("add_element");
  // A name index, not a walk over the elements added so far: that walk made loading a
  // 200 + 200-car consist (12,000 elements) quadratic in its length.
  const auto [it, added] = element_index_.emplace(element->name(), static_cast<int>(elements_.size()));
  if (!added)
    throw InputError(element->where().prefix() + "element '" + element->name() + "' is defined twice (first at line " +
                     std::to_string(elements_[static_cast<std::size_t>(it->second)]->where().line) +
                     "); element names must be unique");
  elements_.push_back(std::move(element));
  return *elements_.back();
}

void Model::add_load(Load load) {
  require_editable("add_load");
  loads_.push_back(std::move(load));
}

std::vector<Body>& Model::bodies_for_edit() {
  require_editable("bodies_for_edit");
  return bodies_;
}

std::optional<int> Model::find_body(const std::string& body_name) const {
  if (body_name == "ground") return kGround;
  const auto it = body_index_.find(body_name);
  if (it == body_index_.end()) return std::nullopt;
  return it->second;
}

void Model::finalize() {
  require_editable("finalize");
  if (bodies_.empty()) throw InputError(SourceLocation{file, 0}.prefix() + "the model has no bodies; add at least one under 'bodies'");
  constraint_offset_.assign(elements_.size(), 0);
  constraint_rows_ = 0;
  double extent = 0.0;
  double min_x = bodies_[0].x, max_x = min_x, min_y = bodies_[0].y, max_y = min_y;
  for (const Body& b : bodies_) {
    min_x = std::min(min_x, b.x); max_x = std::max(max_x, b.x);
    min_y = std::min(min_y, b.y); max_y = std::max(max_y, b.y);
  }
  extent = std::hypot(max_x - min_x, max_y - min_y);
  double body_offset = 0.0;  // [length] the largest offset of an element's point on a body
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    Element& el = *elements_[e];
    for (const PointRef& p : el.points()) {
      RAILCRASH_DEMAND(p.body >= kGround && p.body < body_count());
      extent = std::max(extent, std::hypot(p.sx, p.sy));
      if (p.body == kGround) {
        min_x = std::min(min_x, p.sx); max_x = std::max(max_x, p.sx);
        min_y = std::min(min_y, p.sy); max_y = std::max(max_y, p.sy);
      } else {
        body_offset = std::max(body_offset, std::hypot(p.sx, p.sy));
      }
      if (p.body != kGround && bodies_[static_cast<std::size_t>(p.body)].inertia == 0.0 &&
          (p.sx != 0.0 || p.sy != 0.0 || el.applies_moment()) && el.constraint_count() == 0)
        throw InputError(el.where().prefix() + "element '" + el.name() + "' acts at an offset point of body '" +
                         bodies_[static_cast<std::size_t>(p.body)].name +
                         "', which has zero inertia; give the body a positive inertia" +
                         (el.applies_moment() ? "" : " or attach at [0, 0]"));
    }
    el.bind_bodies();
    ElementState<double> initial;
    for (int k = 0; k < 2; ++k) {
      const int b = el.slot_body(k);
      if (b == kGround) continue;
      const Body& body = bodies_[static_cast<std::size_t>(b)];
      initial.q[static_cast<std::size_t>(k)] = {body.x, body.y, body.angle};
      initial.v[static_cast<std::size_t>(k)] = {body.vx, body.vy, body.angular_velocity};
      initial.rotation[static_cast<std::size_t>(k)] = rotation_of(body.angle);
    }
    el.initialize(initial);
    constraint_offset_[e] = constraint_rows_;
    constraint_rows_ += el.constraint_count();
  }
  for (const Load& l : loads_) {
    const Body& b = bodies_[static_cast<std::size_t>(l.body)];
    if (b.inertia == 0.0 && (l.kind == Load::Kind::Moment || l.sx != 0.0 || l.sy != 0.0))
      throw InputError(l.where.prefix() + "a load turns body '" + b.name +
                       "', which has zero inertia; give the body a positive inertia or apply the force at [0, 0]");
  }
  length_scale_ = extent > 0.0 ? extent : 1.0;
  const double origin_free = std::max(std::hypot(max_x - min_x, max_y - min_y), body_offset);
  origin_free_length_scale_ = origin_free > 0.0 ? origin_free : 1.0;
  finalized_ = true;
}

ElementStates::ElementStates(const Model& model) : model_(&model) {
  RAILCRASH_DEMAND(model.finalized());
  constexpr std::size_t kBlock = sizeof(std::max_align_t);
  std::size_t blocks = 0;
  for (const auto& element : model.elements()) {
    const std::size_t bytes = element->mode_bytes();
    offset_.push_back(blocks);
    bytes_.push_back(bytes);
    blocks += (bytes + kBlock - 1) / kBlock;
  }
  block_.resize(blocks);
  reset();
}

void ElementStates::reset() {
  const auto& elements = model_->elements();
  for (std::size_t e = 0; e < elements.size(); ++e)
    if (bytes_[e] > 0) elements[e]->write_start_mode(block_.data() + offset_[e]);
}

bool ElementStates::same_as(const Snapshot& snapshot) const {
  if (snapshot.block.size() != block_.size()) return false;
  // (No element with modes: both empty, and memcmp may not be given their null data.)
  return block_.empty() || std::memcmp(snapshot.block.data(), block_.data(), block_.size() * sizeof(std::max_align_t)) == 0;
}

void ElementStates::restore(const Snapshot& snapshot) {
  RAILCRASH_DEMAND(snapshot.block.size() == block_.size());
  block_ = snapshot.block;
}

}  // namespace railcrash
