#include "railcrash/core/folder_lock.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

#include "railcrash/core/error.hpp"

namespace railcrash {

namespace {

struct HeldFolder {
  int descriptor = -1;  // the open, locked FOLDER/.railcrash.lock
  int holders = 0;      // FolderLock objects of this process on the folder
};

std::mutex& held_mutex() {
  static std::mutex mutex;
  return mutex;
}

std::map<std::pair<unsigned long long, unsigned long long>, HeldFolder>& held_folders() {
  static std::map<std::pair<unsigned long long, unsigned long long>, HeldFolder> folders;
  return folders;
}

/// Whether name is one whole_file.cpp gives a temporary file, ".NAME.tmp-PID-N-T-A" (PID, N and
/// A decimal, T hexadecimal), and if so its writer's process id.
bool temporary_file_pid(const std::string& name, long* pid) {
  const std::size_t tmp = name.rfind(".tmp-");
  if (name.size() < 2 || name[0] != '.' || tmp == std::string::npos || tmp < 2) return false;
  const std::string tail = name.substr(tmp + 5);  // PID-N-T-A
  const auto field_ok = [](const std::string& field, bool hex) {
    if (field.empty() || field.size() > 20) return false;
    for (const char c : field)
      if (!(c >= '0' && c <= '9') && !(hex && ((c >= 'a' && c <= 'f')))) return false;
    return true;
  };
  std::size_t at = 0;
  std::string fields[4];
  for (int k = 0; k < 4; ++k) {
    const std::size_t dash = k < 3 ? tail.find('-', at) : tail.size();
    if (dash == std::string::npos) return false;
    fields[k] = tail.substr(at, dash - at);
    if (!field_ok(fields[k], k == 2)) return false;
    at = dash + 1;
  }
  *pid = std::strtol(fields[0].c_str(), nullptr, 10);
  return *pid > 0;
}

/// Removes the stale temporary files of folder (see the header); returns how many.
std::size_t remove_stale_temporary_files(const std::string& folder) {
  DIR* directory = ::opendir(folder.c_str());
  if (!directory) return 0;
  std::vector<std::string> stale;
  while (const dirent* entry = ::readdir(directory)) {
    const std::string name = entry->d_name;
    long pid = 0;
    if (!temporary_file_pid(name, &pid) || pid == static_cast<long>(::getpid())) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // running (or not ours to ask): keep
    struct stat status {};
    if (::fstatat(::dirfd(directory), entry->d_name, &status, AT_SYMLINK_NOFOLLOW) != 0) continue;
    if (S_ISREG(status.st_mode) || S_ISLNK(status.st_mode)) stale.push_back(name);
  }
  std::size_t removed = 0;
  for (const std::string& name : stale) removed += ::unlinkat(::dirfd(directory), name.c_str(), 0) == 0;
  ::closedir(directory);
  return removed;
}

}  // namespace

std::string FolderLock::removal_note(const std::string& folder) const {
  if (removed_temporary_files_ == 0) return "";
  return "removed " + std::to_string(removed_temporary_files_) + " temporary file" + (removed_temporary_files_ == 1 ? "" : "s") +
         " of an interrupted railcrash from " + folder + "/ (.NAME.tmp-PID-...: its writer was killed before it renamed " +
         (removed_temporary_files_ == 1 ? "it" : "them") + ")";
}

FolderLock::FolderLock(const std::string& folder) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw InputError("cannot create the output folder '" + folder + "': " + error.message());
  struct stat status {};
  if (::stat(folder.c_str(), &status) != 0)
    throw InputError("cannot open the output folder '" + folder + "': " + std::strerror(errno));
  device_ = static_cast<unsigned long long>(status.st_dev);
  inode_ = static_cast<unsigned long long>(status.st_ino);
  const std::lock_guard<std::mutex> guard(held_mutex());
  HeldFolder& held = held_folders()[{device_, inode_}];
  if (held.holders > 0) {
    ++held.holders;
    return;
  }
  const std::string path = folder + "/.railcrash.lock";
  const int descriptor = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (descriptor < 0) {
    const int open_error = errno;
    held_folders().erase({device_, inode_});
    throw InputError("cannot lock the output folder '" + folder + "': " + path + ": " + std::strerror(open_error));
  }
  if (::flock(descriptor, LOCK_EX | LOCK_NB) != 0) {
    const int lock_error = errno;
    char text[32] = {};
    const ssize_t count = ::pread(descriptor, text, sizeof text - 1, 0);
    ::close(descriptor);
    held_folders().erase({device_, inode_});
    std::string pid = count > 0 ? std::string(text, static_cast<std::size_t>(count)) : "";
    pid = pid.substr(0, pid.find_first_not_of("0123456789"));
    if (lock_error == EWOULDBLOCK)
      throw InputError("the output folder '" + folder + "' is being written by another railcrash process" +
                       (pid.empty() ? "" : " (pid " + pid + ")") +
                       ": wait until it ends, or give another --out (two writers would mix their files)");
    throw InputError("cannot lock the output folder '" + folder + "': " + path + ": " + std::strerror(lock_error));
  }
  // This process's id, for the message of a second writer (the lock itself is the flock).
  const std::string pid = std::to_string(static_cast<long>(::getpid())) + "\n";
  if (::ftruncate(descriptor, 0) == 0) (void)!::pwrite(descriptor, pid.data(), pid.size(), 0);
  held.descriptor = descriptor;
  held.holders = 1;
  removed_temporary_files_ = remove_stale_temporary_files(folder);  // (no other run or sweep writes here now)
}

FolderLock::~FolderLock() {
  const std::lock_guard<std::mutex> guard(held_mutex());
  const auto it = held_folders().find({device_, inode_});
  if (it == held_folders().end() || --it->second.holders > 0) return;
  ::close(it->second.descriptor);  // releases the flock
  held_folders().erase(it);
}

}  // namespace railcrash
