#include "railcrash/element_registry.hpp"

namespace railcrash {

void register_anticlimber_elements(ElementRegistry& /*registry*/) {}

}  // namespace railcrash
