// `railcrash elements [TYPE]`: the element reference from the element types' declarations.
#include <cstdio>
#include <string>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/core/error.hpp"
#include "railcrash/model/element_reference.hpp"
#include "railcrash/model/element_registry.hpp"
#include "railcrash/model/model_io.hpp"

namespace railcrash::cli {

namespace {

/// `railcrash elements [TYPE] [--markdown]`: the element reference from the declarations.
int print_element_reference(const std::string& type_name, bool markdown) {
  using namespace railcrash;
  const ElementRegistry& registry = ElementRegistry::instance();
  if (markdown) {
    if (!type_name.empty()) throw InputError("elements: --markdown prints the whole reference; leave out '" + type_name + "'");
    std::fputs(element_reference_markdown(registry).c_str(), stdout);
    return 0;
  }
  if (type_name.empty()) {
    std::fputs(element_type_list(registry).c_str(), stdout);
    return 0;
  }
  const ElementType* type = registry.find(type_name);
  if (!type) {
    std::string known;
    for (const std::string& name : registry.types()) known += (known.empty() ? "" : ", ") + name;
    throw InputError("elements: unknown element type '" + type_name + "'" + suggestion(type_name, registry.types()) +
                     "; known types: " + known);
  }
  std::fputs(element_type_reference(*type).c_str(), stdout);
  return 0;
}

class ElementsCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    CLI::App* command = program.add_subcommand("elements", "element reference: the types, or one type's points and parameters");
    command->add_option("type", type_name_, "element type (default: list all types)");
    command->add_flag("--markdown", markdown_, "print the whole reference as Markdown (docs/elements.md)");
    return command;
  }

  int run(char** /*argv*/) override { return print_element_reference(type_name_, markdown_); }

 private:
  std::string type_name_;
  bool markdown_ = false;
};

}  // namespace

std::unique_ptr<Command> make_elements_command() { return std::make_unique<ElementsCommand>(); }

}  // namespace railcrash::cli
