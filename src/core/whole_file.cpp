#include "railcrash/core/whole_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>

namespace railcrash {

namespace {

/// A temporary name beside path, new to the folder with high probability: ".NAME.tmp-PID-N-T"
/// (N counts this process's files, T is the clock's low bits); O_EXCL refuses a name already
/// taken and the caller tries another.
std::string temporary_name(const std::string& path, unsigned attempt) {
  static std::atomic<unsigned long> counter{0};
  const std::size_t slash = path.rfind('/');
  const std::string folder = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const auto ticks = static_cast<unsigned long>(std::chrono::steady_clock::now().time_since_epoch().count());
  char suffix[96];
  std::snprintf(suffix, sizeof suffix, ".tmp-%ld-%lu-%lx-%u", static_cast<long>(::getpid()), counter++, ticks & 0xffffffUL,
                attempt);
  return folder + "." + name + suffix;
}

}  // namespace

FileWriteError::FileWriteError(const std::string& path, int error_number, const std::string& step)
    : std::runtime_error("cannot write '" + path + "': " + (step.empty() ? "" : step + ": ") + std::strerror(error_number)),
      path_(path),
      error_number_(error_number) {}

int write_all(int descriptor, const char* data, std::size_t size, std::size_t* written_out) {
  std::size_t written = 0;
  int error_number = 0;
  while (written < size) {
    const ssize_t count = ::write(descriptor, data + written, size - written);
    if (count < 0 && errno == EINTR) continue;
    if (count <= 0) {
      error_number = count < 0 ? errno : EIO;
      break;
    }
    written += static_cast<std::size_t>(count);
  }
  if (written_out) *written_out = written;
  return error_number;
}

void write_whole_file(const std::string& path, std::string_view text) {
  if (path.empty()) throw FileWriteError(path, ENOENT);
  std::string temporary;
  int descriptor = -1;
  constexpr unsigned kAttempts = 100;
  for (unsigned attempt = 0; attempt < kAttempts && descriptor < 0; ++attempt) {
    temporary = temporary_name(path, attempt);
    descriptor = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (descriptor < 0 && errno != EEXIST) throw FileWriteError(path, errno, "cannot create a temporary file in its folder");
  }
  if (descriptor < 0) throw FileWriteError(path, EEXIST, "no free temporary name in its folder");
  const auto give_up = [&](int error_number, const char* step) {
    if (descriptor >= 0) ::close(descriptor);
    ::unlink(temporary.c_str());
    throw FileWriteError(path, error_number, step);
  };
  if (const int error_number = write_all(descriptor, text.data(), text.size())) give_up(error_number, "");
  // fsync: a crash right after the rename must not leave an empty file under the final name.
  // Some file systems cannot sync (EINVAL, EROFS on special ones): nothing was lost there.
  if (::fsync(descriptor) != 0 && errno != EINVAL && errno != EROFS) give_up(errno, "");
  const int closed = ::close(descriptor);
  descriptor = -1;
  if (closed != 0 && errno != EINTR) give_up(errno, "");
  if (::rename(temporary.c_str(), path.c_str()) != 0) give_up(errno, "");
}

}  // namespace railcrash
