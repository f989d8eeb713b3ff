#include "railcrash/batch.hpp"

#include <algorithm>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "railcrash/error.hpp"

namespace railcrash {

namespace {

using Clock = std::chrono::steady_clock;
// How often the supervisor looks at the runs in progress [ms]: the resolution of the run limit.
constexpr int kSupervisorPeriodMs = 10;

}  // namespace

/// Raises a run's stop flag once it has had its time limit, or every run's when the caller's
/// stop flag rises. One thread for the whole batch, and none when there is nothing to watch.
class BatchSupervisor {
 public:
  BatchSupervisor(std::vector<std::unique_ptr<RunControl>>& slots, const BatchOptions& options)
      : slots_(slots), options_(options) {
    if (options.run_time_limit > 0.0 || options.stop) thread_ = std::thread([this] { watch(); });
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
  static void start(RunControl& run) {
    const std::lock_guard<std::mutex> lock(run.mutex_);
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

std::vector<BatchRunState> run_batch(std::size_t count, const std::function<void(std::size_t, const RunControl&)>& task,
                                     const BatchOptions& options,
                                     const std::function<void(std::size_t, BatchRunState)>& on_finished) {
  std::vector<BatchRunState> states(count, BatchRunState::not_started);
  if (count == 0) return states;
  const std::size_t threads = std::min<std::size_t>(static_cast<std::size_t>(std::max(1, options.jobs)), count);
  // One control per thread, reused by that thread's runs; the supervisor reads them all.
  std::vector<std::unique_ptr<RunControl>> slots;
  for (std::size_t t = 0; t < threads; ++t) slots.push_back(std::make_unique<RunControl>());
  std::atomic<std::size_t> next{0};
  std::mutex report;
  const BatchSupervisor supervisor(slots, options);
  const auto worker = [&](RunControl& control) {
    for (std::size_t k = next++; k < count; k = next++) {
      if (options.stop && options.stop->load()) break;
      BatchAccess::start(control);
      task(k, control);
      BatchAccess::finish(control);
      // A run stopped by the caller's flag has a partial result; one that ended by itself
      // before the supervisor noticed the flag is complete.
      states[k] = control.interrupted() ? BatchRunState::interrupted : BatchRunState::finished;
      if (on_finished) {
        const std::lock_guard<std::mutex> lock(report);
        on_finished(k, states[k]);
      }
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(worker, std::ref(*slots[t]));
  worker(*slots[0]);
  for (std::thread& t : pool) t.join();
  return states;
}

}  // namespace railcrash
