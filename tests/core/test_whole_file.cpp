// The shared whole-file writer (include/railcrash/core/whole_file.hpp) and the overflow-checked run
// counting (include/railcrash/studies/run_count.hpp), and the output folder lock (folder_lock.hpp).
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "railcrash/core/error.hpp"
#include "railcrash/core/folder_lock.hpp"
#include "railcrash/core/whole_file.hpp"
#include "railcrash/studies/run_count.hpp"

using namespace railcrash;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

struct ScratchFolder {
  fs::path path;
  ScratchFolder() {
    char name[] = "/tmp/railcrash_test_whole_file_XXXXXX";
    path = ::mkdtemp(name);
  }
  ~ScratchFolder() {
    std::error_code error;
    fs::remove_all(path, error);
  }
};

std::string text_of(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::size_t entries_in(const fs::path& folder) {
  std::size_t count = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(folder)) ++count;
  return count;
}

}  // namespace

TEST_CASE("write_whole_file writes the text, replaces an old file and leaves nothing else", "[whole_file]") {
  ScratchFolder folder;
  const fs::path file = folder.path / "table.csv";
  write_whole_file(file.string(), "a,b\n1,2\n");
  CHECK(text_of(file) == "a,b\n1,2\n");
  write_whole_file(file.string(), "new\n");
  CHECK(text_of(file) == "new\n");
  write_whole_file(file.string(), "");
  CHECK(fs::file_size(file) == 0);
  CHECK(entries_in(folder.path) == 1);  // no temporary file left
}

TEST_CASE("write_whole_file replaces a planted link instead of writing through it", "[whole_file]") {
  ScratchFolder folder;
  const fs::path victim = folder.path / "victim.txt", link = folder.path / "summary.md";
  std::ofstream(victim) << "precious";
  fs::create_symlink(victim, link);
  write_whole_file(link.string(), "study\n");
  CHECK(text_of(victim) == "precious");
  CHECK_FALSE(fs::is_symlink(link));
  CHECK(text_of(link) == "study\n");
}

TEST_CASE("write_whole_file names the file and the reason when it cannot write", "[whole_file]") {
  ScratchFolder folder;
  const std::string missing = (folder.path / "no_such_folder" / "table.csv").string();
  try {
    write_whole_file(missing, "x");
    FAIL("no FileWriteError");
  } catch (const FileWriteError& e) {
    CHECK(e.path() == missing);
    CHECK(e.error_number() == ENOENT);
    CHECK_THAT(e.what(), Contains("cannot write '" + missing + "'") && Contains(std::strerror(ENOENT)));
  }
  // A folder in the way: the rename fails (EISDIR) and the temporary file is removed again.
  fs::create_directory(folder.path / "table.csv");
  CHECK_THROWS_AS(write_whole_file((folder.path / "table.csv").string(), "x"), FileWriteError);
  CHECK(entries_in(folder.path) == 1);  // the folder table.csv and nothing else (no_such_folder was never made)
}

TEST_CASE("write_all reports the errno of a failed write: ENOSPC on /dev/full", "[whole_file]") {
  const int descriptor = ::open("/dev/full", O_WRONLY | O_CLOEXEC);
  REQUIRE(descriptor >= 0);  // Linux has /dev/full
  const std::string text(100000, 'x');
  CHECK(write_all(descriptor, text.data(), text.size()) == ENOSPC);
  ::close(descriptor);
}

TEST_CASE("run counts: products and sums without overflow, and the limit's message", "[run_count]") {
  constexpr std::size_t kLargest = std::numeric_limits<std::size_t>::max();
  CHECK(multiply_counts(std::size_t{1} << 32, std::size_t{1} << 31) == std::optional<std::size_t>(std::size_t{1} << 63));
  CHECK_FALSE(multiply_counts(std::size_t{1} << 32, std::size_t{1} << 32).has_value());  // 2^64
  CHECK(multiply_counts(std::nullopt, 0) == std::optional<std::size_t>(0));  // none of too many is none
  CHECK(add_counts(kLargest - 1, 1) == std::optional<std::size_t>(kLargest));
  CHECK_FALSE(add_counts(kLargest, 1).has_value());
  CHECK(factorial_count({}) == std::optional<std::size_t>(0));
  CHECK(factorial_count({3, 4, 5}) == std::optional<std::size_t>(60));
  CHECK_FALSE(factorial_count(std::vector<std::size_t>(64, 2)).has_value());   // 2^64
  CHECK(factorial_count(std::vector<std::size_t>(63, 2)) == std::optional<std::size_t>(std::size_t{1} << 63));
  CHECK_NOTHROW(require_run_count(1000, 1000, "plan"));
  CHECK_NOTHROW(require_run_count(std::nullopt, 0, "plan"));  // 0: no limit
  CHECK_THROWS_WITH(require_run_count(1001, 1000, "plan.yaml"),
                    Contains("plan.yaml: 1001 runs, more than the limit of 1000 (--max-runs)"));
  CHECK_THROWS_WITH(require_run_count(std::nullopt, 1000, "plan.yaml"),
                    Contains("plan.yaml: more than 18446744073709551615 runs"));
}

TEST_CASE("FolderLock refuses a second process naming the folder and its pid and nests within one process", "[whole_file]") {
  const ScratchFolder scratch;
  const std::string folder = (scratch.path / "out").string();
  {
    const FolderLock first(folder);  // creates the folder
    const FolderLock again(folder);  // the same process: nested, not refused
    CHECK(fs::exists(scratch.path / "out" / ".railcrash.lock"));
  }
  int ready[2], release[2];
  REQUIRE(::pipe(ready) == 0);
  REQUIRE(::pipe(release) == 0);
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {  // holds the folder until the parent closes its end of `release`
    ::close(ready[0]);
    ::close(release[1]);  // (else the read below never sees the end of the pipe)
    {
      const FolderLock held(folder);
      char byte = 1;
      (void)!::write(ready[1], &byte, 1);
      (void)!::read(release[0], &byte, 1);
    }
    ::_exit(0);
  }
  ::close(ready[1]);
  ::close(release[0]);
  char byte = 0;
  REQUIRE(::read(ready[0], &byte, 1) == 1);
  CHECK_THROWS_WITH(FolderLock(folder), "the output folder '" + folder + "' is being written by another railcrash process (pid " +
                                            std::to_string(child) +
                                            "): wait until it ends, or give another --out (two writers would mix their files)");
  ::close(release[1]);  // the child lets go and ends
  int status = 0;
  ::waitpid(child, &status, 0);
  ::close(ready[0]);
  CHECK(WIFEXITED(status));
  CHECK_NOTHROW(FolderLock(folder));  // free again
}

TEST_CASE("FolderLock removes the temporary files a killed writer left and nothing else", "[whole_file]") {
  const ScratchFolder scratch;
  const fs::path out = scratch.path / "out";
  fs::create_directories(out);
  const pid_t child = ::fork();  // a process that has ended: its pid names the dead writer's files
  REQUIRE(child >= 0);
  if (child == 0) ::_exit(0);
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  const std::string dead = std::to_string(child), alive = std::to_string(::getppid());
  const auto touch = [&](const std::string& name) { std::ofstream(out / name) << "x"; };
  touch(".summary.json.tmp-" + dead + "-0-1a2b3c-0");   // whole_file.cpp's names: removed
  touch(".converge.csv.tmp-" + dead + "-12-ff-3");
  touch(".runs.csv.tmp-" + alive + "-0-1a-0");           // a writer that still runs: kept
  touch(".notes.tmp-" + dead + "-x-1-0");                // not the form: kept
  touch("summary.json.tmp-" + dead + "-0-1-0");          // no leading dot: kept
  touch(".tmp-" + dead + "-0-1-0");                      // no NAME: kept
  fs::create_directory(out / (".folder.tmp-" + dead + "-0-1-0"));  // a folder: kept
  {
    const FolderLock lock(out.string());
    CHECK(lock.removed_temporary_files() == 2);
    CHECK(lock.removal_note("out") ==
          "removed 2 temporary files of an interrupted railcrash from out/ (.NAME.tmp-PID-...: its writer was killed before it renamed them)");
    const FolderLock nested(out.string());  // held already: removes nothing more, says nothing
    CHECK(nested.removed_temporary_files() == 0);
    CHECK(nested.removal_note("out").empty());
  }
  CHECK_FALSE(fs::exists(out / (".summary.json.tmp-" + dead + "-0-1a2b3c-0")));
  CHECK_FALSE(fs::exists(out / (".converge.csv.tmp-" + dead + "-12-ff-3")));
  for (const std::string& kept : {".runs.csv.tmp-" + alive + "-0-1a-0", ".notes.tmp-" + dead + "-x-1-0",
                                  "summary.json.tmp-" + dead + "-0-1-0", ".tmp-" + dead + "-0-1-0", ".folder.tmp-" + dead + "-0-1-0"})
    CHECK(fs::exists(out / kept));
}
