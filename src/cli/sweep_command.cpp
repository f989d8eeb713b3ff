// `railcrash sweep MODEL --plan PLAN`: the study over model keys; under mpirun or srun the runs go
// to all ranks (railcrash-mpi, built from this file with RAILCRASH_MPI; CMakeLists.txt).
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "command.hpp"
#include "common.hpp"
#include "railcrash/core/error.hpp"
#include "railcrash/studies/batch.hpp"
#include "railcrash/studies/run_count.hpp"
#include "railcrash/studies/sweep.hpp"
#include "railcrash/studies/sweep_mpi.hpp"

namespace railcrash::cli {

namespace {

#ifdef RAILCRASH_MPI_PROGRAM
/// `railcrash sweep` started by mpirun or srun: the same command line, run by the MPI build
/// installed beside this executable (CMakeLists.txt: railcrash links no MPI, so that its other
/// commands start without loading it). Returns only when that program cannot be started.
[[noreturn]] void exec_mpi_program(char** argv) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::filesystem::path program = self.parent_path() / RAILCRASH_MPI_PROGRAM;
  execv(program.c_str(), argv);
  throw railcrash::InputError("sweep under an MPI launcher: cannot start " + program.string() + " (" + std::strerror(errno) +
                              "), the MPI build of railcrash that is built and installed beside it when MPI is found; "
                              "build and install railcrash again, or run the sweep without mpirun (--jobs)");
}
#endif

/// `sweep --dry-run`: the plan's run count and the levels of the runs listed, generated one at a
/// time (a plan of any size under --max-runs 0), nothing run or written. Under a launcher only
/// its first process prints them (and reports a bad plan): the others would print the same.
int sweep_dry_run_command(const std::string& path, const std::string& plan_path, std::size_t max_runs,
                          std::vector<std::size_t> show_runs) {
  using namespace railcrash;
  if (launched_by_mpi() && launcher_rank() != 0) return 0;
  const SweepPlan plan = load_sweep_plan(plan_path, path);
  require_sweep_run_count(plan, max_runs);
  const SweepRunGenerator generator(plan, path, read_model_text(path));
  if (show_runs.empty()) {
    for (std::size_t k = 0; k < std::min<std::size_t>(10, generator.count()); ++k) show_runs.push_back(k);
    if (generator.count() > 10) show_runs.push_back(generator.count() - 1);
  }
  std::fputs(sweep_dry_run_text(plan, generator, show_runs).c_str(), stdout);
  return 0;
}

int run_sweep_study(const std::string& path, const std::string& plan_path, int jobs, double run_limit, bool resume,
                    bool keep_runs, std::size_t max_runs, const std::string& out_dir) {
  using namespace railcrash;
  SweepOptions options;
  options.jobs = jobs_to_run(jobs);
  options.run_time_limit = run_limit;
  options.resume = resume;
  options.keep_runs = keep_runs;
  options.max_runs = max_runs;
  options.stop = &interrupted();
  options.progress = [](std::size_t number, const SweepRow& row, std::size_t done, std::size_t total) {
    std::fprintf(stderr, "[%zu/%zu] run %zu %s %.2f s%s%s\n", done, total, number, row.status.c_str(), row.wall_seconds,
                 row.message.empty() ? "" : ": ", row.message.c_str());
  };
  options.note = [](const std::string& text) {
    std::fputs(text.c_str(), stdout);
    std::fflush(stdout);
  };
  catch_interrupts();
#ifdef RAILCRASH_MPI
  if (launched_by_mpi()) return sweep_with_mpi(path, plan_path, out_dir, options);
#endif
  check_output_folder(out_dir);
  const SweepPlan plan = load_sweep_plan(plan_path, path);  // every key and level checked before any run
  const auto start = std::chrono::steady_clock::now();
  const SweepResult result = run_sweep(path, plan, out_dir, options);
  const std::size_t failed = failed_sweep_runs(plan, result);
  std::printf("%zu of %zu runs done (%zu resumed), %zu failed, with %d jobs in %.1f s; results in %s/ (runs.csv, summary.md)\n",
              result.done(), result.total, result.resumed, failed, options.jobs,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), out_dir.c_str());
  if (result.done() < result.total) std::printf("interrupted: run again with --resume to finish\n");
  if (failed > 0) std::printf("%zu run%s failed (status and message in runs.csv)\n", failed, failed == 1 ? "" : "s");
  return result.done() == result.total && failed == 0 && !interrupted().load() ? 0 : 1;
}

class SweepCommand final : public Command {
 public:
  CLI::App* add_to(CLI::App& program) override {
    CLI::App* command = program.add_subcommand("sweep", "study over model keys (factorial, one at a time, Latin hypercube, Monte Carlo, "
                                                        "run lists): DIR/runs.csv and summary.md; under mpirun the runs go to all ranks");
    command->add_option("model", model_path_, "model file (YAML)")->required();
    command->add_option("--plan", plan_path_, "plan file (YAML: sweep: 1, design, factors, responses; README \"Sweeps\")")->required();
    add_jobs_option(*command, jobs_, JobsDefault::AllCores);
    add_run_limit_option(*command, run_limit_);
    command->add_flag("--resume", resume_, "keep the rows of DIR/runs.csv whose run is in the plan (by hash) and run the rest");
    command->add_flag("--keep-runs", keep_runs_, "also write each run's files to DIR/runs/NNNN/");
    add_max_runs_option(*command, max_runs_);
    add_out_folder_option(*command, out_dir_);
    CLI::Option* dry_run_option = command->add_flag("--dry-run", dry_run_,
                    "run nothing: print the plan's run count and the levels of the runs --show-runs lists (default: the "
                    "first 10 and the last), as runs.csv's first columns");
    command->add_option("--show-runs", show_runs_, "with --dry-run: the run numbers to print (e.g. 0,1,9999999)")
        ->delimiter(',')
        ->needs(dry_run_option);
    return command;
  }

  int run([[maybe_unused]] char** argv) override {
#ifdef RAILCRASH_MPI_PROGRAM
    if (launched_by_mpi()) exec_mpi_program(argv);
#endif
    if (dry_run_) return sweep_dry_run_command(model_path_, plan_path_, max_runs_, show_runs_);
    return run_sweep_study(model_path_, plan_path_, jobs_, run_limit_, resume_, keep_runs_, max_runs_, out_dir_);
  }

 private:
  std::string model_path_, plan_path_, out_dir_;
  int jobs_ = 0;
  double run_limit_ = 0.0;
  bool resume_ = false, keep_runs_ = false, dry_run_ = false;
  std::size_t max_runs_ = kDefaultMaxRuns;
  std::vector<std::size_t> show_runs_;
};

}  // namespace

std::unique_ptr<Command> make_sweep_command() { return std::make_unique<SweepCommand>(); }

}  // namespace railcrash::cli
