// railcrash's subcommands. Each one lives in its own file (src/cli/<name>_command.cpp): it adds
// its CLI11 subcommand and options, which write into the command object, and runs when the
// command line names it. src/cli/main.cpp only lists them, parses and dispatches.
#pragma once

#include <CLI/CLI.hpp>

#include <memory>

namespace railcrash::cli {

class Command {
 public:
  virtual ~Command() = default;
  /// Adds this command's subcommand and its options to `program` and returns the subcommand
  /// (true after parsing when the command line named it).
  virtual CLI::App* add_to(CLI::App& program) = 0;
  /// Runs the command once the command line is parsed. Returns the exit status: 0 success,
  /// 1 a run failed or was interrupted; bad input throws InputError (main.cpp: exit 2).
  /// argv: the command line as given (a sweep under mpirun runs it again in railcrash-mpi).
  virtual int run(char** argv) = 0;
};

// One factory per file, in the order `railcrash --help` lists the commands (main.cpp).
std::unique_ptr<Command> make_run_command();
std::unique_ptr<Command> make_report_command();
std::unique_ptr<Command> make_sensitivity_command();
std::unique_ptr<Command> make_readings_command();
std::unique_ptr<Command> make_converge_command();
std::unique_ptr<Command> make_sweep_command();
std::unique_ptr<Command> make_consist_command();
std::unique_ptr<Command> make_scenario_command();
std::unique_ptr<Command> make_check_command();
std::unique_ptr<Command> make_expand_command();
std::unique_ptr<Command> make_schema_command();
std::unique_ptr<Command> make_elements_command();

}  // namespace railcrash::cli
