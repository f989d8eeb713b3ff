// `railcrash report --pdf`: the page printed to PDF by headless Chromium (see report/pdf.hpp).
#include "railcrash/report/pdf.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include "railcrash/core/error.hpp"

extern char** environ;

namespace railcrash::report {

namespace {

namespace fs = std::filesystem;

/// A file: URL of an absolute path, every byte outside the unreserved set and '/' percent-encoded.
std::string file_url(const fs::path& path) {
  static const char* const kHex = "0123456789ABCDEF";
  std::string url = "file://";
  for (const unsigned char c : fs::absolute(path).lexically_normal().string()) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '_' || c == '.' || c == '~') {
      url += static_cast<char>(c);
    } else {
      url += '%';
      url += kHex[c >> 4];
      url += kHex[c & 15];
    }
  }
  return url;
}

/// The last `count` lines of a text that are not Chromium's usual noise (D-Bus, GPU, fontconfig).
std::string last_lines(const std::string& text, std::size_t count) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line.find("dbus") == std::string::npos && line.find("Fontconfig") == std::string::npos) lines.push_back(line);
  std::string out;
  for (std::size_t k = lines.size() > count ? lines.size() - count : 0; k < lines.size(); ++k) out += (out.empty() ? "" : " | ") + lines[k];
  return out.empty() ? "(it printed nothing)" : out;
}

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Removes a folder when it goes out of scope.
struct TemporaryFolder {
  fs::path path;
  ~TemporaryFolder() {
    std::error_code ignored;
    if (!path.empty()) fs::remove_all(path, ignored);
  }
};

}  // namespace

std::string find_chromium() {
  const char* path = std::getenv("PATH");
  std::istringstream folders(path ? path : "");
  for (std::string folder; std::getline(folders, folder, ':');) {
    if (folder.empty()) continue;
    for (const char* name : {"chromium", "chromium-browser"}) {
      const fs::path candidate = fs::path(folder) / name;
      if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    }
  }
  return "";
}

std::string print_pdf(const std::string& html_path, const PdfOptions& options) {
  const std::string chromium = find_chromium();
  if (chromium.empty())
    throw InputError("--pdf: no chromium on PATH, which prints the report to PDF; install Debian's chromium "
                     "(`apt-get install chromium`, scripts/install-deps.sh does), or leave out --pdf and print " + html_path +
                     " from a browser");
  const fs::path page(html_path);
  const fs::path pdf = page.parent_path() / (page.stem().string() + ".pdf");
  const fs::path part = page.parent_path() / (page.stem().string() + ".pdf.part-" + std::to_string(::getpid()));
  TemporaryFolder profile;
  {
    std::string pattern = (fs::temp_directory_path() / "railcrash-chromium-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw InputError("--pdf: cannot make a temporary folder for chromium: " + std::string(std::strerror(errno)));
    profile.path = pattern;
  }
  const fs::path log = profile.path / "chromium.log";
  std::vector<std::string> arguments = {chromium, "--headless=new", "--disable-gpu", "--no-first-run", "--no-default-browser-check",
                                        "--disable-extensions", "--hide-scrollbars", "--user-data-dir=" + (profile.path / "profile").string(),
                                        // Virtual time runs the page's script and its charts' drawing to the end before printing.
                                        "--virtual-time-budget=" + std::to_string(options.virtual_time_budget_ms),
                                        "--run-all-compositor-stages-before-draw", "--no-pdf-header-footer",
                                        "--print-to-pdf=" + part.string(), file_url(page) + "#t=last"};
  if (::geteuid() == 0) arguments.insert(arguments.begin() + 1, "--no-sandbox");  // Chromium refuses to run as root with its sandbox
  std::vector<char*> argv;
  for (std::string& a : arguments) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t files;
  posix_spawnattr_t attributes;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&files, STDOUT_FILENO, STDERR_FILENO);
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);  // its own process group: a timeout ends chromium and its helpers
  pid_t pid = -1;
  const int spawned = ::posix_spawn(&pid, chromium.c_str(), &files, &attributes, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  posix_spawnattr_destroy(&attributes);
  if (spawned != 0) throw InputError("--pdf: cannot start " + chromium + ": " + std::strerror(spawned));

  int status = 0;
  bool timed_out = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(options.timeout_seconds);
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) break;
    if (std::chrono::steady_clock::now() > deadline) {
      timed_out = true;
      ::kill(-pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ::kill(-pid, SIGKILL);  // helpers it left behind, if any (an error when there are none)
  std::error_code ignored;
  const std::string bytes = fs::exists(part) ? slurp(part) : std::string();
  if (timed_out || !WIFEXITED(status) || WEXITSTATUS(status) != 0 || bytes.rfind("%PDF-", 0) != 0) {
    fs::remove(part, ignored);
    const std::string why = timed_out ? "did not finish within " + std::to_string(options.timeout_seconds) + " s"
                            : !WIFEXITED(status) ? "was killed by signal " + std::to_string(WTERMSIG(status))
                            : WEXITSTATUS(status) != 0 ? "exited with status " + std::to_string(WEXITSTATUS(status))
                                                       : "wrote no PDF";
    throw InputError("--pdf: " + chromium + " printing " + html_path + " " + why + ": " + last_lines(slurp(log), 4) +
                     "; the page itself is written, open it in a browser and print it from there");
  }
  fs::rename(part, pdf);
  return pdf.string();
}

}  // namespace railcrash::report
