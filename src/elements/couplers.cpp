#include "railcrash/element_registry.hpp"

namespace railcrash {

void register_couplers_elements(ElementRegistry& /*registry*/) {}

}  // namespace railcrash
