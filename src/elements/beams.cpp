#include "railcrash/element_registry.hpp"

namespace railcrash {

void register_beams_elements(ElementRegistry& /*registry*/) {}

}  // namespace railcrash
