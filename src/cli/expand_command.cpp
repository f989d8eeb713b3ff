// `railcrash expand MODEL`: the model with its car types and trains expanded into flat bodies and elements.
#include <string>
#include <vector>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/studies/batch.hpp"

namespace railcrash::cli {

namespace {

int write_expanded_model(const std::string& path, const std::vector<std::string>& settings, const std::string& out_path, bool out_given) {
  if (out_given) railcrash::check_output_file(out_path);
  const railcrash::ExpandedModel expanded = railcrash::expand_model_file(path, settings);
  return write_generated_model(expanded.text, out_path, "the expanded model (" + std::to_string(expanded.cars.size()) + " cars)");
}

class ExpandCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    command_ = program.add_subcommand("expand", "write the model with its car types and trains expanded into flat bodies and elements");
    command_->add_option("model", model_path_, "model file (YAML)")->required();
    add_set_option(*command_, settings_);
    command_->add_option("--out", out_, "model file to write (default: standard output)");
    return command_;
  }

  int run(char** /*argv*/) override { return write_expanded_model(model_path_, settings_, out_, command_->count("--out") > 0); }

 private:
  CLI::App* command_ = nullptr;
  std::string model_path_, out_;
  std::vector<std::string> settings_;
};

}  // namespace

std::unique_ptr<Command> make_expand_command() { return std::make_unique<ExpandCommand>(); }

}  // namespace railcrash::cli
