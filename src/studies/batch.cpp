#include "railcrash/studies/batch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cerrno>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>

#include "railcrash/core/error.hpp"
#include "railcrash/results/run.hpp"

namespace railcrash {

namespace {

using Clock = std::chrono::steady_clock;
// How often the supervisor looks at the runs in progress [ms]: the resolution of the run limit.
constexpr int kSupervisorPeriodMs = 10;

namespace fs = std::filesystem;

/// The folder without trailing slashes ("out/" -> "out"; "/" stays).
fs::path without_trailing_slash(std::string text) {
  while (text.size() > 1 && text.back() == '/') text.pop_back();
  return fs::path(text);
}

/// What the OS says when `path` is opened for writing ("" if it could be: the file is removed
/// again unless it existed before).
std::string write_refusal(const fs::path& path) {
  std::error_code error;
  const bool existed = fs::exists(path, error);
  std::FILE* file = std::fopen(path.c_str(), "a");
  if (!file) return std::strerror(errno);
  std::fclose(file);
  if (!existed) fs::remove(path, error);
  return "";
}

/// The type of `path`, or InputError with the OS's reason when it cannot be looked at.
fs::file_status status_of(const fs::path& path, const std::string& what) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (error && status.type() != fs::file_type::not_found)
    throw InputError(what + " '" + path.string() + "': cannot look at it: " + error.message());
  return status;
}

/// InputError unless `folder` (the parent of a --out) is an existing folder.
void require_parent_folder(const fs::path& folder, const std::string& what, const std::string& out) {
  const fs::path parent = folder.empty() ? fs::path(".") : folder;
  const fs::file_status status = status_of(parent, what);
  if (!fs::exists(status))
    throw InputError(what + " '" + out + "': its folder '" + parent.string() + "' does not exist (" + std::strerror(ENOENT) +
                     "); create it first or give another path");
  if (!fs::is_directory(status))
    throw InputError(what + " '" + out + "': '" + parent.string() + "' is a file, not a folder (" + std::strerror(ENOTDIR) + ")");
}

}  // namespace

std::size_t finished_runs(const std::vector<BatchRunState>& states) {
  return static_cast<std::size_t>(std::count(states.begin(), states.end(), BatchRunState::finished));
}

std::string read_model_text(const std::string& model_path) {
  std::ifstream in(model_path);
  if (!in) throw InputError(model_path + ": cannot open the model file (check the path)");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

void check_output_folder(const std::string& folder) {
  if (folder.empty()) throw InputError("--out is empty; give the output folder, e.g. --out results");
  const fs::path path = without_trailing_slash(folder);
  const fs::file_status status = status_of(path, "--out");
  if (fs::exists(status) && !fs::is_directory(status))
    throw InputError("--out '" + folder + "' is a file, not a folder (" + std::strerror(ENOTDIR) + "); give a folder");
  bool created = false;
  if (!fs::exists(status)) {
    require_parent_folder(path.parent_path(), "--out", folder);
    std::error_code error;
    if (!fs::create_directory(path, error) && error)
      throw InputError("--out '" + folder + "': cannot create the folder: " + error.message());
    created = true;
  }
  const std::string refusal = write_refusal(path / ".railcrash_write_check");
  if (created) {
    std::error_code error;
    fs::remove(path, error);
  }
  if (!refusal.empty()) throw InputError("--out '" + folder + "': cannot write in the folder: " + refusal);
}

void check_output_file(const std::string& file) {
  if (file.empty()) throw InputError("--out is empty; give the file to write, or leave --out out for standard output");
  const fs::path path(file);
  const fs::file_status status = status_of(path, "--out");
  if (fs::is_directory(status))
    throw InputError("--out '" + file + "' is a folder (" + std::strerror(EISDIR) + "); give a file name, e.g. " +
                     (path / "model.yaml").string());
  require_parent_folder(path.parent_path(), "--out", file);
  const std::string refusal = write_refusal(path);
  if (!refusal.empty()) throw InputError("--out '" + file + "': cannot write it: " + refusal);
}

/// Raises a run's stop flag once it has had its time limit, or every run's when the caller's
/// stop flag rises. One thread for the whole batch, and none when there is nothing to watch.
class BatchSupervisor {
 public:
  BatchSupervisor(std::vector<std::unique_ptr<RunControl>>& slots, const BatchOptions& options)
      : slots_(slots), options_(options) {
    if (options.run_time_limit > 0.0 || options.stop) {
      try {
        thread_ = std::thread([this] { watch(); });
      } catch (const std::system_error& e) {  // not even one more thread: nothing could stop the runs
        throw std::runtime_error("cannot start the thread that watches the runs' time limit and interrupts (" +
                                 e.code().message() + "); lower --jobs, or raise the process limit (ulimit -u)");
      }
    }
  }
  ~BatchSupervisor() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

 private:
  void watch() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_for(lock, std::chrono::milliseconds(kSupervisorPeriodMs), [this] { return done_; })) {
      const bool interrupted = options_.stop && options_.stop->load();
      for (const std::unique_ptr<RunControl>& slot : slots_) {
        RunControl& run = *slot;
        const std::lock_guard<std::mutex> run_lock(run.mutex_);
        if (!run.active_ || run.stop_.load()) continue;
        if (interrupted) {
          run.interrupted_ = true;
          run.stop_ = true;
        } else if (options_.run_time_limit > 0.0 && std::chrono::duration<double>(Clock::now() - run.start_).count() > options_.run_time_limit) {
          run.timed_out_ = true;
          run.stop_ = true;
        }
      }
    }
  }

  std::vector<std::unique_ptr<RunControl>>& slots_;
  const BatchOptions& options_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::thread thread_;
};

struct BatchAccess {
  static void start(RunControl& run, double run_time_limit) {
    const std::lock_guard<std::mutex> lock(run.mutex_);
    run.run_time_limit_ = run_time_limit;
    run.stop_ = false;
    run.timed_out_ = false;
    run.interrupted_ = false;
    run.start_ = Clock::now();
    run.active_ = true;
  }
  static void finish(RunControl& run) {
    const std::lock_guard<std::mutex> lock(run.mutex_);
    run.active_ = false;
  }
};

void run_batch_stream(std::size_t most_runs, const std::function<std::optional<std::size_t>()>& next_run,
                      const std::function<void(std::size_t, const RunControl&)>& task, const BatchOptions& options,
                      const std::function<void(std::size_t, BatchRunState)>& on_finished) {
  if (most_runs == 0) return;
  const std::size_t threads = std::min<std::size_t>(static_cast<std::size_t>(std::max(1, options.jobs)), most_runs);
  // One control per thread, reused by that thread's runs; the supervisor reads them all.
  std::vector<std::unique_ptr<RunControl>> slots;
  for (std::size_t t = 0; t < threads; ++t) slots.push_back(std::make_unique<RunControl>());
  std::mutex taking, report;
  bool exhausted = false;  // next_run said there are no more (guarded by taking)
  const BatchSupervisor supervisor(slots, options);
  const auto take = [&]() -> std::optional<std::size_t> {
    const std::lock_guard<std::mutex> lock(taking);
    if (exhausted || (options.stop && options.stop->load())) return std::nullopt;
    const std::optional<std::size_t> k = next_run();
    if (!k) exhausted = true;
    return k;
  };
  const auto worker = [&](RunControl& control) {
    for (std::optional<std::size_t> k = take(); k; k = take()) {
      BatchAccess::start(control, options.run_time_limit);
      task(*k, control);
      BatchAccess::finish(control);
      // A run stopped by the caller's flag has a partial result; one that ended by itself
      // before the supervisor noticed the flag is complete.
      const BatchRunState state = control.interrupted() ? BatchRunState::interrupted : BatchRunState::finished;
      if (on_finished) {
        const std::lock_guard<std::mutex> lock(report);
        on_finished(*k, state);
      }
    }
  };
  // The threads that can be had: past the process or memory limit (ulimit -u, -v) std::thread
  // throws; the batch then runs on the threads it has (this one at least) and says so.
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t) {
    try {
      pool.emplace_back(worker, std::ref(*slots[t]));
    } catch (const std::system_error& e) {
      std::fprintf(stderr, "railcrash: --jobs %zu: only %zu thread%s could be started (%s); running the %zu runs with %zu\n",
                   threads, t, t == 1 ? "" : "s", e.code().message().c_str(), most_runs, t);
      break;
    }
  }
  worker(*slots[0]);
  for (std::thread& t : pool) t.join();
}

std::vector<BatchRunState> run_batch(std::size_t count, const std::function<void(std::size_t, const RunControl&)>& task,
                                     const BatchOptions& options,
                                     const std::function<void(std::size_t, BatchRunState)>& on_finished) {
  std::vector<BatchRunState> states(count, BatchRunState::not_started);
  std::size_t next = 0;
  run_batch_stream(
      count, [&]() -> std::optional<std::size_t> { return next < count ? std::optional<std::size_t>(next++) : std::nullopt; },
      task, options, [&](std::size_t k, BatchRunState state) {
        states[k] = state;
        if (on_finished) on_finished(k, state);
      });
  return states;
}

std::string run_limit_message(double limit_seconds, double t_reached) {
  char text[160];
  std::snprintf(text, sizeof text, "stopped at the run time limit of %g s (--run-limit), at t = %.6g", limit_seconds, t_reached);
  return text;
}

std::string IntegratorUsed::euler_from_t_text() const {
  if (std::isnan(euler_from_t)) return "";
  char text[40];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, euler_from_t);
    if (std::strtod(text, nullptr) == euler_from_t) break;
  }
  return text;
}

IntegratorUsed integrator_used(const RunReport& report) {
  IntegratorUsed used;
  if (report.integrator.empty()) return used;
  if (report.outcome.stats.handed_over_at >= 0.0) {
    used.method = ida_or_auto_method(report.outcome.stats);
    used.euler_from_t = report.outcome.stats.handed_over_at;
  } else {
    used.method = integrator_name(report.integrator == integrator_name(IntegratorKind::Euler) ? IntegratorKind::Euler : IntegratorKind::Ida);
  }
  return used;
}

}  // namespace railcrash
