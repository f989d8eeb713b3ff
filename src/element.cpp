#include "railcrash/element.hpp"

#include <cstdio>
#include <cstdlib>

namespace railcrash {

void demand_failed(const char* condition, const char* file, int line) {
  std::fprintf(stderr, "railcrash internal error: %s failed at %s:%d (please report this)\n", condition, file, line);
  std::abort();
}

const char* output_role_name(OutputRole role) {
  switch (role) {
    case OutputRole::Crush: return "crush";
    case OutputRole::ContactForce: return "contact_force";
    case OutputRole::CouplerForce: return "coupler_force";
    case OutputRole::VerticalInterlockForce: return "vertical_interlock_force";
    case OutputRole::CrashForce: return "crash_force";
    case OutputRole::CrashDeformation: return "crash_deformation";
  }
  return "";
}

std::string Element::output_with_role(OutputRole role) const {
  for (const RoleOfOutput& r : output_roles())
    if (r.role == role) return r.output;
  return "";
}

Element::Element(std::string name, std::string type, std::vector<PointRef> points, SourceLocation where)
    : name_(std::move(name)), type_(std::move(type)), points_(std::move(points)), where_(std::move(where)) {}

void Element::bind_bodies() {
  // Slots in order of first appearance of a distinct body; ground always gets the slot
  // it first appears in too, so point p's slot is stable whatever the bodies are.
  slot_body_ = {kGround, kGround};
  point_slot_.assign(points_.size(), 0);
  int used = 0;
  for (std::size_t p = 0; p < points_.size(); ++p) {
    const int body = points_[p].body;
    int slot = -1;
    for (int k = 0; k < used; ++k)
      if (slot_body_[static_cast<std::size_t>(k)] == body) slot = k;
    if (slot < 0) {
      if (used == 2)
        throw InputError(where_.prefix() + "element '" + name_ + "' (" + type_ +
                         ") connects more than two bodies; give its points on at most two bodies");
      slot = used++;
      slot_body_[static_cast<std::size_t>(slot)] = body;
    }
    point_slot_[p] = slot;
  }
  // A joint whose points all lie on one body (or all on ground) constrains nothing: its
  // constraint rows are identically zero and the system would be singular.
  if (constraint_count() > 0 && used < 2) {
    const std::string body = slot_body_[0] == kGround ? std::string("ground") : "one body";
    throw InputError(where_.prefix() + "joint '" + name_ + "' (" + type_ + ") has all its points on " + body +
                     ", so it constrains nothing; give its points on two different bodies (or one body and ground)");
  }
}

void Element::constraint_gradient(const std::array<Pose<double>, 2>&, double*, double[kMaxConstraintRows][6]) const {
  RAILCRASH_DEMAND(constraint_count() == 0);
}

void Element::constraint_hessian(const std::array<Pose<double>, 2>&, double*, double[kMaxConstraintRows][6],
                                 double[kMaxConstraintRows][6][6]) const {
  RAILCRASH_DEMAND(constraint_count() == 0);
}

void Element::add_force_jacobian(double, const ElementState<double>&, std::array<Pose<double>, 2>&, ForceBlock&,
                                 ForceBlock&) const {}

ElementState<double> gather_state(const Element& e, const double* q, const double* v, const void* mode) {
  return gather_state(e, q, v, mode, [](int, double theta) { return rotation_of(theta); });
}

ElementState<double> gather_state(const Element& e, const double* q, const double* v) {
  RAILCRASH_DEMAND(e.mode_bytes() == 0);
  return gather_state(e, q, v, nullptr);
}

}  // namespace railcrash
