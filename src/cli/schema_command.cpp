// `railcrash schema`: the JSON Schema of the model file (README "Editor support").
#include <string>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/model/element_registry.hpp"
#include "railcrash/model/model_schema.hpp"
#include "railcrash/studies/batch.hpp"

namespace railcrash::cli {

namespace {

class SchemaCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    command_ = program.add_subcommand("schema", "write the JSON Schema of the model file (for editors: README \"Editor support\")");
    command_->add_option("-o,--out", out_, "file to write (default: standard output)");
    return command_;
  }

  int run(char** /*argv*/) override {
    if (command_->count("--out") > 0) check_output_file(out_);
    return write_generated_model(model_schema_json(ElementRegistry::instance()), out_, "the model file's JSON Schema");
  }

 private:
  CLI::App* command_ = nullptr;
  std::string out_;
};

}  // namespace

std::unique_ptr<Command> make_schema_command() { return std::make_unique<SchemaCommand>(); }

}  // namespace railcrash::cli
