// The batch runner every study uses (sensitivity, readings, converge, sweep): runs numbered
// 0..count-1 over a pool of threads, each with a stop flag that a supervisor raises at the
// per-run wall limit or when the caller's stop flag rises (SIGINT/SIGTERM in the command
// line). A run writes its result into the caller's slot for its number, so the results come
// back in run order and are the same whatever the number of jobs: the pool only decides when
// a run starts, never what it computes.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <mutex>
#include <string>
#include <vector>

namespace railcrash {

struct RunReport;

/// The method a study's run used, for the studies' columns integrator_used and euler_from_t:
/// "ida" or "euler" (the one the model names; integrator auto whose IDA kept the run: "ida"), or
/// "ida+euler" (integrator auto: IDA handed the run to Euler at euler_from_t [the model's time
/// unit], as summary.json's integrator_used says), or "ida+euler+ida" (and IDA took it back
/// later, summary.json's euler_until_t). "" and NaN for a run that did not start.
struct IntegratorUsed {
  std::string method;
  double euler_from_t = std::numeric_limits<double>::quiet_NaN();
  /// euler_from_t as a CSV field: the shortest text that reads back as the same number, "" for NaN.
  std::string euler_from_t_text() const;
};
IntegratorUsed integrator_used(const RunReport& report);

/// What a study says of a run its run time limit stopped (every study alike): "stopped at the run
/// time limit of LIMIT s (--run-limit), at t = T" (T: how far the run got, in the model's time unit).
std::string run_limit_message(double limit_seconds, double t_reached);

struct BatchOptions {
  int jobs = 1;                              // threads (at most one per run)
  double run_time_limit = 0.0;               // [s] wall time after which a run's stop flag rises (0: none)
  const std::atomic<bool>* stop = nullptr;   // raised by the caller: runs in progress are stopped, no new run starts
};

/// What a run sees of the batch: its stop flag, and why it rose.
class RunControl {
 public:
  /// The flag to hand to the integrator (run_model, Integrator::run).
  const std::atomic<bool>* stop_flag() const { return &stop_; }
  /// The run limit raised the flag (the run went on too long).
  bool timed_out() const { return timed_out_.load(); }
  /// The caller's stop flag raised it (the study was interrupted).
  bool interrupted() const { return interrupted_.load(); }
  /// [s] the per-run wall limit the supervisor applies (0: none), for run_limit_message.
  double run_time_limit() const { return run_time_limit_; }

 private:
  friend class BatchSupervisor;
  friend struct BatchAccess;
  std::atomic<bool> stop_{false};
  std::atomic<bool> timed_out_{false};
  std::atomic<bool> interrupted_{false};
  double run_time_limit_ = 0.0;                // [s] set before each run (BatchOptions::run_time_limit)
  bool active_ = false;                        // guarded by mutex_, as start_
  std::chrono::steady_clock::time_point start_{};
  std::mutex mutex_;                           // the supervisor's checks against a run starting or ending
};

/// What became of each run.
enum class BatchRunState {
  not_started,  // the study was interrupted before the run's turn
  finished,     // the task returned (its own result says whether the run succeeded)
  interrupted,  // the task returned after the caller's stop flag stopped it: its result is partial
};

/// Runs task(number, control) for every number in [0, count), up to options.jobs at a time,
/// starting them in increasing order. on_finished(number, state) is called one call at a time
/// (under a lock) as each run returns. A task must not throw (it records its own failure).
std::vector<BatchRunState> run_batch(std::size_t count, const std::function<void(std::size_t, const RunControl&)>& task,
                                     const BatchOptions& options,
                                     const std::function<void(std::size_t, BatchRunState)>& on_finished = {});

/// run_batch for a study of any size: the run numbers come from next_run (called one call at a
/// time, in the order runs start; nullopt: no more runs), so the batch holds nothing per run.
/// Threads: options.jobs, but no more than most_runs (the most runs next_run will give).
void run_batch_stream(std::size_t most_runs, const std::function<std::optional<std::size_t>()>& next_run,
                      const std::function<void(std::size_t, const RunControl&)>& task, const BatchOptions& options,
                      const std::function<void(std::size_t, BatchRunState)>& on_finished = {});

/// How many runs ended by themselves (fewer than states.size() when the batch was interrupted).
std::size_t finished_runs(const std::vector<BatchRunState>& states);

/// The model file's text, read once at the start of a study so that every run sees the same
/// model even if the file is edited while the study runs (InputError if it cannot be read).
std::string read_model_text(const std::string& model_path);

/// Checks a study's output folder (--out) before any run, so that a study never runs for hours
/// and then cannot write: InputError naming the folder and the OS's reason if it is empty, is a
/// file, has no parent folder, or cannot be written (a file is created in it and removed). A
/// missing folder is created for the check and removed again (a rejected study leaves nothing).
void check_output_folder(const std::string& folder);

/// The same for a file a command writes (--out of consist and scenario): its folder exists, it
/// is not a folder, and it can be written (a new file is created for the check and removed).
void check_output_file(const std::string& file);

}  // namespace railcrash
