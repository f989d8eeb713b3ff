// railcrash command line: `railcrash run MODEL ...`, `railcrash check MODEL` and the other
// subcommands, one file each in src/cli/ (cli/command.hpp). This file lists them, parses the
// command line and runs the one it names.
// Exit status: 0 success, 1 the run failed or was interrupted (results up to then are
// written), 2 bad input (the message names file, line and what to change).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <initializer_list>
#include <memory>
#include <vector>

#include "command.hpp"
#include "railcrash/core/error.hpp"
#include "railcrash/core/version.hpp"
#include "railcrash/results/provenance.hpp"

int main(int argc, char** argv) {
  using namespace railcrash::cli;
  railcrash::set_command_line(argc, argv);  // the runs' provenance
  CLI::App app{"railcrash: planar rail-vehicle crash dynamics (IDA + KLU, or explicit Euler)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", railcrash::version_text());

  // In the order `railcrash --help` lists them.
  std::vector<std::unique_ptr<Command>> commands;
  for (const auto make : {make_run_command, make_report_command, make_sensitivity_command, make_readings_command,
                          make_converge_command, make_sweep_command, make_consist_command, make_scenario_command,
                          make_check_command, make_expand_command, make_schema_command, make_elements_command})
    commands.push_back(make());
  std::vector<CLI::App*> subcommands;
  for (const std::unique_ptr<Command>& command : commands) subcommands.push_back(command->add_to(app));

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    for (std::size_t k = 0; k < commands.size(); ++k)
      if (*subcommands[k]) return commands[k]->run(argv);
    return 2;  // not reached: require_subcommand(1) refuses a command line that names none
  } catch (const railcrash::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "railcrash failed: %s\n", e.what());
    return 1;
  }
}
