// One writer per output folder: a command that writes a folder (run, sweep) holds an exclusive
// flock(2) on FOLDER/.railcrash.lock for as long as it writes there, taken before it removes or
// writes anything. A second process that asks for the same folder is refused at once with a
// message naming the folder and the holder's process id (the lock file holds it). The lock
// goes with the process (also on kill -9); the empty lock file stays in the folder.
// Within one process the lock nests: a folder already held by this process is not refused
// (the run command holds it, then its ResultWriter asks again).
//
// Stale temporary files: a writer killed between creating a whole file's temporary file and
// renaming it (kill -9, a crash, a power cut) leaves ".NAME.tmp-PID-N-T-A" in the folder
// (whole_file.hpp). The process that takes the lock first removes those of its folder whose
// writer is gone: only names of exactly that form, only regular files or links (never a
// folder), and only when no process PID is running (a live one may be a command that writes
// there without the lock, such as converge) and PID is not this process.
#pragma once

#include <cstddef>
#include <string>

namespace railcrash {

class FolderLock {
 public:
  /// Creates the folder if needed and locks it; InputError when another process holds it
  /// ("the output folder 'out' is being written by another railcrash process (pid 1234): ...")
  /// or the lock file cannot be made.
  explicit FolderLock(const std::string& folder);
  ~FolderLock();
  /// How many stale temporary files taking the lock removed (0 when this process already held it).
  std::size_t removed_temporary_files() const { return removed_temporary_files_; }
  /// "" when none were removed, else one line: "removed 2 temporary files of an interrupted
  /// railcrash from out/ (.NAME.tmp-PID-...: a writer killed before it renamed them)".
  std::string removal_note(const std::string& folder) const;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  unsigned long long device_ = 0, inode_ = 0;  // the folder's identity (the process's table of held folders)
  std::size_t removed_temporary_files_ = 0;
};

}  // namespace railcrash
