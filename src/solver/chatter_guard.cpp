#include "railcrash/solver/chatter_guard.hpp"

namespace railcrash {

bool ChatterGuard::record(const EventRecord& event) {
  Changes& c = changes_[event.element];
  if (c.count > 0 && event.t - c.last_time <= instant_) {
    ++c.count;
  } else {
    c.first_time = event.t;
    c.count = 1;
  }
  c.last_time = event.t;
  if (c.count < limit_) return false;
  tripped_ = c;
  return true;
}

}  // namespace railcrash
