#include "railcrash/element_registry.hpp"

namespace railcrash {

void register_nonlinear_elements(ElementRegistry& /*registry*/) {}

}  // namespace railcrash
