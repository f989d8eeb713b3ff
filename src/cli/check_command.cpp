// `railcrash check MODEL`: the model validated and summarised, nothing run.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "railcrash/solver/stability_limit.hpp"
#include "railcrash/solver/initial_conditions.hpp"

namespace railcrash::cli {

namespace {

int check_model(const std::string& path, const std::vector<std::string>& settings) {
  using namespace railcrash;
  const LoadedModel loaded = load_model(path, settings);
  const Model& model = loaded.model;
  const DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  AssemblyReport assembly;
  try {
    assembly = assemble_initial_state(system, y);
  } catch (const SolverError& e) {  // exit 1 as in `run`, with the file named
    throw SolverError(SourceLocation{path, 0}.prefix() + e.what());
  }
  // What `run` does next: consistent accelerations and joint reactions at the start. A model
  // whose equations are singular there (a body with zero inertia that no joint holds) cannot
  // run, so `check` refuses it as input.
  std::vector<double> y_start = y, yp_start;
  try {
    consistent_rates(system, 0.0, y_start, yp_start);
  } catch (const SolverError& e) {
    SourceLocation where{path, 0};
    for (const Body& b : model.bodies())
      if (b.inertia == 0.0 && where.line == 0) where = b.where;  // the first body the message names
    throw InputError(where.prefix() + e.what());
  }
  // The element outputs at the start: a run whose first sample has a non-finite one fails.
  std::vector<double> outputs(system.output_names().size());
  system.outputs(y_start.data(), y_start.data() + 2 * system.body_unknowns(), outputs.data());
  for (std::size_t k = 0; k < outputs.size(); ++k)
    if (!std::isfinite(outputs[k])) {
      const std::string& column = system.output_names()[k];  // "<element>.<output>"
      const std::string element = column.substr(0, column.rfind('.'));
      SourceLocation where{path, 0};
      for (const auto& e : model.elements())
        if (e->name() == element) where = e->where();
      throw InputError(where.prefix() + "element '" + element + "': its output '" + column.substr(column.rfind('.') + 1) + "' is " +
                       std::to_string(outputs[k]) + " at t = 0; check the element's numbers (a value too large or too small)");
    }
  int constraint_elements = 0;
  for (const auto& e : model.elements()) constraint_elements += e->constraint_count() > 0;
  std::printf("model      %s  (%s)\n", model.name.c_str(), path.c_str());
  std::printf("units      %s%s, gravity [%g, %g]\n", unit_system_name(model.units),
              model.file_units == unit_system_name(model.units) ? "" : (" (the file's " + model.file_units + ", converted when read)").c_str(),
              model.gravity_x, model.gravity_y);
  const ExpandedModel expanded = expand_model_file(path, settings);  // the cars the file's trains placed
  if (!expanded.cars.empty()) {
    std::printf("cars       %zu placed from car types (railcrash expand writes the flat model)\n", expanded.cars.size());
    for (const ExpandedCar& car : expanded.cars)
      std::printf("  %-20s type %-14s%s leading end x %-10.6g trailing end x %-10.6g %zu bodies, %zu elements\n", car.name.c_str(),
                  car.type.c_str(), car.reversed ? " reversed" : "         ", car.leading_x, car.trailing_x, car.bodies, car.elements);
  }
  std::printf("bodies     %d\n", model.body_count());
  for (const Body& b : model.bodies())
    std::printf("  %-20s mass %-12.6g inertia %-12.6g at [%g, %g]\n", b.name.c_str(), b.mass, b.inertia, b.x, b.y);
  std::printf("elements   %zu (%d constraints)\n", model.elements().size(), constraint_elements);
  for (const auto& e : model.elements())
    std::printf("  %-20s %-20s%s\n", e->name().c_str(), e->type().c_str(),
                e->constraint_count() ? (" " + std::to_string(e->constraint_count()) + " equations").c_str() : "");
  std::printf("loads      %zu\n", model.loads().size());
  std::printf("unknowns   %d  (3 x %d positions, 3 x %d velocities, %d multipliers lambda, %d mu)\n", system.size(),
              model.body_count(), model.body_count(), model.constraint_rows(), model.constraint_rows());
  std::printf("degrees of freedom  %d\n", model.degrees_of_freedom());
  std::printf("jacobian   %d nonzeros (%.3g%% of %d x %d)\n", system.pattern().nonzeros(),
              100.0 * system.pattern().nonzeros() / (static_cast<double>(system.size()) * system.size()), system.size(),
              system.size());
  std::printf("assembly   initial positions moved by at most %.3g, velocities by %.3g\n", assembly.largest_position_change,
              assembly.largest_velocity_change);
  bool all_inertia = true;
  for (const Body& b : model.bodies()) all_inertia = all_inertia && b.inertia > 0.0;
  if (all_inertia) {
    const double limit = explicit_stability_limit(system, y, nullptr);
    std::printf("euler      stability limit of the elements alone: dt < %.4g (joints add penalty springs)\n", limit);
  }
  const SimulationSettings& simulation = loaded.run_spec.simulation;
  std::printf("simulation t_end %g, integrator %s\n", simulation.t_end, integrator_name(simulation.integrator));
  return 0;
}

class CheckCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    CLI::App* command = program.add_subcommand("check", "validate a model and print a summary");
    command->add_option("model", model_path_, "model file (YAML)")->required();
    add_set_option(*command, settings_);
    return command;
  }

  int run(char** /*argv*/) override { return check_model(model_path_, settings_); }

 private:
  std::string model_path_;
  std::vector<std::string> settings_;
};

}  // namespace

std::unique_ptr<Command> make_check_command() { return std::make_unique<CheckCommand>(); }

}  // namespace railcrash::cli
