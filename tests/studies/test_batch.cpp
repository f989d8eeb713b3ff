// The batch runner (batch.hpp): order, the per-run limit, interruption, job count.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "railcrash/studies/batch.hpp"

using namespace railcrash;

namespace {

/// A stand-in run that waits for its stop flag or `seconds`, whichever comes first.
bool wait_or_stop(const RunControl& control, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end)
    if (control.stop_flag()->load()) return false;
  return true;
}

}  // namespace

TEST_CASE("batch: every run once, results in run order whatever the job count", "[batch]") {
  for (int jobs : {1, 2, 5}) {
    std::vector<long> results(40, -1);
    std::vector<int> calls(40, 0);
    std::vector<std::size_t> finished;
    BatchOptions options;
    options.jobs = jobs;
    const auto states = run_batch(
        results.size(),
        [&](std::size_t k, const RunControl&) {
          ++calls[k];
          results[k] = static_cast<long>(k * k);  // each run computes from its number only
        },
        options, [&](std::size_t k, BatchRunState) { finished.push_back(k); });
    for (std::size_t k = 0; k < results.size(); ++k) {
      CHECK(calls[k] == 1);
      CHECK(results[k] == static_cast<long>(k * k));
      CHECK(states[k] == BatchRunState::finished);
    }
    CHECK(finished.size() == results.size());
  }
}

TEST_CASE("batch: a run over the limit is stopped and only that run", "[batch]") {
  BatchOptions options;
  options.jobs = 2;
  options.run_time_limit = 0.1;
  std::vector<int> completed(4, -1), timed_out(4, -1);
  run_batch(
      4,
      [&](std::size_t k, const RunControl& control) {
        completed[k] = wait_or_stop(control, k == 2 ? 30.0 : 0.01);
        timed_out[k] = control.timed_out();
      },
      options);
  CHECK(completed == std::vector<int>{1, 1, 0, 1});
  CHECK(timed_out == std::vector<int>{0, 0, 1, 0});
}

TEST_CASE("batch: the caller's stop flag stops the runs in progress and starts no more", "[batch]") {
  std::atomic<bool> stop{false};
  BatchOptions options;
  options.jobs = 2;
  options.stop = &stop;
  std::atomic<int> started{0};
  const auto states = run_batch(
      10,
      [&](std::size_t k, const RunControl& control) {
        ++started;
        if (k == 3) stop = true;  // as SIGTERM would, during run 3
        wait_or_stop(control, k >= 3 ? 30.0 : 0.0);
      },
      options);
  CHECK(started.load() <= 5);  // runs 0-3, and at most one more already taken by the other job
  CHECK(states[3] == BatchRunState::interrupted);
  CHECK(states[9] == BatchRunState::not_started);
  for (std::size_t k = 0; k < 3; ++k) CHECK(states[k] == BatchRunState::finished);
}

TEST_CASE("batch: --out is checked before any run, with the path and the OS's reason", "[batch]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("railcrash_out_check_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string file = (dir / "a_file").string();
  std::ofstream(file) << "x";
  CHECK_THROWS_WITH(check_output_folder(""), Catch::StartsWith("--out is empty"));
  CHECK_THROWS_WITH(check_output_folder(file), "--out '" + file + "' is a file, not a folder (Not a directory); give a folder");
  CHECK_THROWS_WITH(check_output_folder(file + "/sub"), Catch::Contains("'" + file + "' is a file, not a folder"));
  const std::string missing = (dir / "missing" / "out").string();
  CHECK_THROWS_WITH(check_output_folder(missing), "--out '" + missing + "': its folder '" + (dir / "missing").string() +
                                                      "' does not exist (No such file or directory); create it first or give another path");
  CHECK_THROWS_WITH(check_output_folder("/proc"), Catch::StartsWith("--out '/proc': cannot write in the folder: "));
  // A new folder is fine, and the check leaves nothing behind; an existing folder keeps its files.
  const std::string fresh = (dir / "fresh").string();
  CHECK_NOTHROW(check_output_folder(fresh + "/"));
  CHECK_FALSE(fs::exists(fresh));
  CHECK_NOTHROW(check_output_folder(dir.string()));
  CHECK(fs::exists(file));
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);
  // A file to write (consist, scenario).
  CHECK_THROWS_WITH(check_output_file(dir.string()), Catch::StartsWith("--out '" + dir.string() + "' is a folder (Is a directory)"));
  CHECK_THROWS_WITH(check_output_file(missing), Catch::Contains("does not exist (No such file or directory)"));
  CHECK_THROWS_WITH(check_output_file(""), Catch::StartsWith("--out is empty"));
  CHECK_NOTHROW(check_output_file((dir / "model.yaml").string()));
  CHECK_FALSE(fs::exists(dir / "model.yaml"));
  CHECK_NOTHROW(check_output_file(file));
  CHECK(fs::file_size(file) == 1);  // an existing file is not truncated by the check
  fs::remove_all(dir);
}
