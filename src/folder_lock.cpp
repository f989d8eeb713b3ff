#include "railcrash/folder_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <utility>

#include "railcrash/error.hpp"

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

}  // namespace

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
}

FolderLock::~FolderLock() {
  const std::lock_guard<std::mutex> guard(held_mutex());
  const auto it = held_folders().find({device_, inode_});
  if (it == held_folders().end() || --it->second.holders > 0) return;
  ::close(it->second.descriptor);  // releases the flock
  held_folders().erase(it);
}

}  // namespace railcrash
