// The element reference, written from the element types' declarations (element_registry.hpp):
// `railcrash elements [TYPE] [--markdown]` prints it, docs/elements.md is its Markdown form.
#pragma once

#include <string>

#include "railcrash/model/element_registry.hpp"

namespace railcrash {

/// One line per element type: name, report type, what it is.
std::string element_type_list(const ElementRegistry& registry);
/// The full plain-text reference of one type: points, law, parameters, example.
std::string element_type_reference(const ElementType& type);
/// docs/elements.md: every type's reference in Markdown.
std::string element_reference_markdown(const ElementRegistry& registry);

}  // namespace railcrash
