// `railcrash consist MODEL --cars N`: a model of N coupled striking cars into N standing cars, from a two-car model.
#include <string>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/scenarios/consist.hpp"
#include "railcrash/studies/batch.hpp"

namespace railcrash::cli {

namespace {

int write_consist_model(const std::string& template_path, int cars, const std::string& out_path, bool out_given) {
  if (out_given) railcrash::check_output_file(out_path);
  return write_generated_model(railcrash::make_consist_model(template_path, cars), out_path,
                               std::to_string(cars) + " + " + std::to_string(cars) + " cars");
}

class ConsistCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    command_ = program.add_subcommand("consist", "write a model of N coupled striking cars into N standing cars, "
                                                 "built from a two-car model (car1_* striking, car2_* standing)");
    command_->add_option("model", model_path_, "two-car template, e.g. models/report/final_two_car.yaml")->required();
    command_->add_option("--cars", cars_, "cars per consist")->capture_default_str()->check(finite_number(1, 100000, false, false));
    command_->add_option("--out", out_, "model file to write (default: standard output)");
    return command_;
  }

  int run(char** /*argv*/) override { return write_consist_model(model_path_, cars_, out_, command_->count("--out") > 0); }

 private:
  CLI::App* command_ = nullptr;
  std::string model_path_, out_;
  int cars_ = 2;
};

}  // namespace

std::unique_ptr<Command> make_consist_command() { return std::make_unique<ConsistCommand>(); }

}  // namespace railcrash::cli
