#include "railcrash/element_registry.hpp"

namespace railcrash {

void register_contact_elements(ElementRegistry& /*registry*/) {}

}  // namespace railcrash
