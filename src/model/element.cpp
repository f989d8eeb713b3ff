#include "railcrash/model/element.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

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

namespace {

/// Memory for element objects: carved in order from large blocks, so the elements a model
/// creates one after another sit next to each other; a freed object's bytes go to a list per
/// size and serve the next element of that size. Blocks are kept for the process's life (a
/// study's models reuse them). Thread-safe: a sweep loads its runs' models in parallel.
class ElementPool {
 public:
  void* allocate(std::size_t bytes) {
    bytes = rounded(bytes);
    const std::lock_guard<std::mutex> lock(mutex_);
    std::vector<void*>& reusable = freed_[bytes];
    if (!reusable.empty()) {
      void* element = reusable.back();
      reusable.pop_back();
      return element;
    }
    if (bytes > left_) {
      const std::size_t block = std::max(kBlockBytes, bytes);
      // Not std::make_unique, which value-initializes the block: that wrote all 1 MiB with x87
      // stores (max_align_t holds a long double) and faulted in its 256 pages at the first
      // element, 7 % of a slider-crank run (bench/HISTORY.md, "Start-up"). Default-initialized,
      // a page is touched when an element is first carved from it.
      blocks_.push_back(std::unique_ptr<std::max_align_t[]>(new std::max_align_t[block / sizeof(std::max_align_t)]));
      next_ = reinterpret_cast<char*>(blocks_.back().get());
      left_ = block;
    }
    void* element = next_;
    next_ += bytes;
    left_ -= bytes;
    return element;
  }
  void release(void* element, std::size_t bytes) {
    const std::lock_guard<std::mutex> lock(mutex_);
    freed_[rounded(bytes)].push_back(element);
  }

 private:
  static constexpr std::size_t kBlockBytes = std::size_t{1} << 20;
  static std::size_t rounded(std::size_t bytes) {
    constexpr std::size_t align = alignof(std::max_align_t);
    return (bytes + align - 1) / align * align;
  }
  std::mutex mutex_;
  std::vector<std::unique_ptr<std::max_align_t[]>> blocks_;
  char* next_ = nullptr;
  std::size_t left_ = 0;
  std::map<std::size_t, std::vector<void*>> freed_;  // by rounded size
};

/// Never destroyed: elements of static models may outlive other statics.
ElementPool& element_pool() {
  static ElementPool* pool = new ElementPool;
  return *pool;
}

}  // namespace

// Under AddressSanitizer the elements come from the ordinary heap, so that a use after free
// of an element is still caught.
#if defined(__SANITIZE_ADDRESS__)
#define RAILCRASH_ELEMENT_POOL 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RAILCRASH_ELEMENT_POOL 0
#endif
#endif
#ifndef RAILCRASH_ELEMENT_POOL
#define RAILCRASH_ELEMENT_POOL 1
#endif

void* Element::operator new(std::size_t bytes) {
  return RAILCRASH_ELEMENT_POOL ? element_pool().allocate(bytes) : ::operator new(bytes);
}

void Element::operator delete(void* element, std::size_t bytes) {
  if (!element) return;
  if (RAILCRASH_ELEMENT_POOL) element_pool().release(element, bytes);
  else ::operator delete(element);  // (unsized: Clang declares the sized form only with -fsized-deallocation)
}

bool Element::allocated_from_pool() { return RAILCRASH_ELEMENT_POOL; }

void* Element::operator new(std::size_t bytes, std::align_val_t alignment) { return ::operator new(bytes, alignment); }

void Element::operator delete(void* element, std::size_t, std::align_val_t alignment) {
  ::operator delete(element, alignment);
}

std::string Element::output_with_role(OutputRole role) const {
  for (const RoleOfOutput& r : output_roles())
    if (r.role == role) return r.output;
  return "";
}

Element::Element(std::string name, std::string type, std::vector<PointRef> points, SourceLocation where)
    : description_(std::make_unique<Description>(
          Description{std::move(name), std::move(type), std::move(points), std::move(where), {}, {}})) {
  const std::vector<PointRef>& all = description_->points;
  for (std::size_t p = 0; p < all.size() && p < near_points_.size(); ++p) near_points_[p] = all[p];
}

void Element::bind_bodies() {
  // Slots in order of first appearance of a distinct body; ground always gets the slot
  // it first appears in too, so point p's slot is stable whatever the bodies are.
  slot_body_ = {kGround, kGround};
  const std::vector<PointRef>& all = description_->points;
  std::vector<int>& point_slot = description_->point_slot;
  point_slot.assign(all.size(), 0);
  int used = 0;
  for (std::size_t p = 0; p < all.size(); ++p) {
    const int body = all[p].body;
    int slot = -1;
    for (int k = 0; k < used; ++k)
      if (slot_body_[static_cast<std::size_t>(k)] == body) slot = k;
    if (slot < 0) {
      if (used == 2)
        throw InputError(where().prefix() + "element '" + name() + "' (" + type() +
                         ") connects more than two bodies; give its points on at most two bodies");
      slot = used++;
      slot_body_[static_cast<std::size_t>(slot)] = body;
    }
    point_slot[p] = slot;
    if (p < near_point_slot_.size()) near_point_slot_[p] = slot;
  }
  // A joint whose points all lie on one body (or all on ground) constrains nothing: its
  // constraint rows are identically zero and the system would be singular.
  if (constraint_count() > 0 && used < 2) {
    const std::string body = slot_body_[0] == kGround ? std::string("ground") : "one body";
    throw InputError(where().prefix() + "joint '" + name() + "' (" + type() + ") has all its points on " + body +
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
