// A JSON Schema (draft-07) of the model file format, for editors (VS Code's YAML extension
// completes and checks a model against it) and for checking models outside railcrash.
//
// It is generated, never written by hand: the keys of every section are the loader's own lists
// (model_file_sections(), train_expansion_sections()), and an element's parameters are its
// type's declared ParameterSpecs in the ElementRegistry (shape, unit kind, range, default,
// meaning): the same tables that make the loader reject an unknown key. A section key the loader
// allows but the schema cannot describe (or the other way round) is a std::logic_error, so the
// schema cannot fall behind the loader silently. docs/railcrash-model.schema.json is the
// committed output of `railcrash schema`; a test fails when it is out of date.
//
// What the schema cannot check (the loader does): names that refer to bodies, elements, cars
// and interface types; counts that depend on other keys (a train's couplings); numbers written
// as quoted strings (the loader reads "5" as 5, the schema wants 5).
#pragma once

#include <string>
#include <vector>

#include "railcrash/model/element_registry.hpp"

namespace railcrash {

/// The JSON Schema of the model file (and of a model variant), as pretty-printed JSON text
/// ending in a newline.
std::string model_schema_json(const ElementRegistry& registry);

/// The values a choice parameter (unit kind Choice, a number or a word) allows, read from its
/// declared meaning, which lists them as "VALUE: what it means", separated by ", " or "; "
/// (e.g. "1: acts in compression, 2: acts in tension"). Empty for a flag or a parameter that is
/// not a choice.
std::vector<std::string> choice_values(const ParameterSpec& spec);

}  // namespace railcrash
