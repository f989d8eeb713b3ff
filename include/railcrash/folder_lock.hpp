// One writer per output folder: a command that writes a folder (run, sweep) holds an exclusive
// flock(2) on FOLDER/.railcrash.lock for as long as it writes there, taken before it removes or
// writes anything. A second process that asks for the same folder is refused at once with a
// message naming the folder and the holder's process id (the lock file holds it). The lock
// goes with the process (also on kill -9); the empty lock file stays in the folder.
// Within one process the lock nests: a folder already held by this process is not refused
// (the run command holds it, then its ResultWriter asks again).
#pragma once

#include <string>

namespace railcrash {

class FolderLock {
 public:
  /// Creates the folder if needed and locks it; InputError when another process holds it
  /// ("the output folder 'out' is being written by another railcrash process (pid 1234): ...")
  /// or the lock file cannot be made.
  explicit FolderLock(const std::string& folder);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  unsigned long long device_ = 0, inode_ = 0;  // the folder's identity (the process's table of held folders)
};

}  // namespace railcrash
