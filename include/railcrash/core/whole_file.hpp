// Whole files written so that a reader never sees half of one: the text goes to a new temporary
// file in the same folder (a unique name opened with O_CREAT | O_EXCL | O_NOFOLLOW, so that no
// planted file or link is written through), every write(2) is checked, the file is fsync'ed and
// closed (both checked), and only then renamed over the destination. rename(2) replaces a link
// at the destination instead of following it. On any failure the temporary file is removed,
// the destination keeps its old content (or stays absent), and FileWriteError names the file
// and the OS's reason (ENOSPC on a full disk, EIO, EDQUOT, ...).
// The study writers (converge, sensitivity, readings), the generated models of consist and
// scenario, and the plots write through it.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace railcrash {

/// A file could not be written: what() is "cannot write 'PATH': REASON"; the destination was
/// not changed.
class FileWriteError : public std::runtime_error {
 public:
  FileWriteError(const std::string& path, int error_number, const std::string& step = "");
  const std::string& path() const { return path_; }
  /// errno of the failed call (ENOSPC, EIO, ...).
  int error_number() const { return error_number_; }

 private:
  std::string path_;
  int error_number_;
};

/// Writes all of data to descriptor, retrying short writes and EINTR: 0 when every byte was
/// written, otherwise the errno of the failed write (EIO for a write that wrote nothing).
/// `written`, when given, receives the bytes the OS took (all of size on success, fewer after a
/// short write and a failure).
int write_all(int descriptor, const char* data, std::size_t size, std::size_t* written = nullptr);

/// Replaces path with text as described above; FileWriteError on any failure.
void write_whole_file(const std::string& path, std::string_view text);

}  // namespace railcrash
