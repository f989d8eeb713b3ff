// Reading a run folder's files for the report: regular files only, no links, size-limited
// (see the header).
#include "railcrash/report/folder_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "railcrash/core/error.hpp"

namespace railcrash::report {

namespace {

std::string megabytes(std::uint64_t bytes) {
  char text[48];
  std::snprintf(text, sizeof text, "%.1f MB", static_cast<double>(bytes) / 1e6);
  return text;
}

const char* kind_of(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISDIR(mode)) return "a folder";
  return "not a regular file";
}

/// The open descriptor of the regular file at path, or -1 when there is none (ENOENT);
/// InputError for a link, a file that is not regular or one that cannot be opened.
int open_regular(const std::string& path, struct stat& status) {
  // O_NONBLOCK: opening a FIFO for reading would wait for a writer; O_NOFOLLOW: a link fails (ELOOP).
  const int descriptor = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (descriptor < 0) {
    const int error_number = errno;
    if (error_number == ENOENT) return -1;
    if (error_number == ELOOP)
      throw InputError("'" + path + "' is a symbolic link: the report reads a folder's own files only and follows no link "
                       "(railcrash writes none); put the file itself there, or run the model again into this folder");
    throw InputError("cannot read '" + path + "': " + std::strerror(error_number));
  }
  if (::fstat(descriptor, &status) != 0) {
    const int error_number = errno;
    ::close(descriptor);
    throw InputError("cannot read '" + path + "': " + std::strerror(error_number));
  }
  if (!S_ISREG(status.st_mode)) {
    ::close(descriptor);
    throw InputError("'" + path + "' is " + kind_of(status.st_mode) +
                     ", not a regular file: the report reads regular files only (railcrash writes nothing else); "
                     "remove it, or run the model again into this folder");
  }
  return descriptor;
}

/// Up to `bytes` bytes from the descriptor (closed here); InputError when a read fails.
std::string read_up_to(int descriptor, const std::string& path, std::size_t bytes) {
  std::string text;
  text.resize(bytes);
  std::size_t have = 0;
  while (have < bytes) {
    const ssize_t count = ::read(descriptor, text.data() + have, bytes - have);
    if (count < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (count < 0) {
      const int error_number = errno;
      ::close(descriptor);
      throw InputError("cannot read '" + path + "': " + std::strerror(error_number));
    }
    if (count == 0) break;
    have += static_cast<std::size_t>(count);
  }
  ::close(descriptor);
  text.resize(have);
  return text;
}

}  // namespace

std::uint64_t max_table_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page_size = ::sysconf(_SC_PAGESIZE);
  const std::uint64_t memory = pages > 0 && page_size > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page_size) : 0;
  return std::max<std::uint64_t>(memory / 8, std::uint64_t{64} << 20);
}

FolderFile read_folder_file(const std::string& path, std::uint64_t limit, const std::string& advice) {
  struct stat status {};
  const int descriptor = open_regular(path, status);
  if (descriptor < 0) return {};
  const auto size = static_cast<std::uint64_t>(status.st_size);
  if (size > limit) {
    ::close(descriptor);
    throw InputError("'" + path + "' is " + megabytes(size) + " (" + std::to_string(size) + " bytes), more than the report's limit of " +
                     megabytes(limit) + " for this file: " + advice);
  }
  // One byte more than the size: a file that grows while it is read stops at the limit + 1 and is refused.
  FolderFile file{true, read_up_to(descriptor, path, static_cast<std::size_t>(std::min<std::uint64_t>(limit, size) + 1))};
  if (file.text.size() > limit)
    throw InputError("'" + path + "' grew past the report's limit of " + megabytes(limit) + " while it was read: " + advice);
  return file;
}

FolderFile read_folder_file_head(const std::string& path, std::size_t bytes) {
  struct stat status {};
  const int descriptor = open_regular(path, status);
  if (descriptor < 0) return {};
  return {true, read_up_to(descriptor, path, bytes)};
}

}  // namespace railcrash::report
